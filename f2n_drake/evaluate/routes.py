"""``python -m f2n_drake.evaluate routes``: drawing in, routes out, checked end to end.

Each synthetic plan is drawn (``--styles random`` by default: thick, filled, turned, blurred,
noisy or JPEG drawings, as scans are), parsed by the segmenter at the drawing's true scale and
turned into its connectivity graph; the ground robot then plans a route from the front door to
every space the graph says it can reach. Reported:

- ``unroutable``: routes the planner cannot find although the graph joins the rooms (a doorway
  the planning grid closes, e.g. a drawn outline thicker than the grid bridges);
- ``wall_crossings``: routes whose waypoints run more than 5 cm inside a true wall of the plan,
  checked on the drawings that are not turned (only there do pixels map exactly onto the plan's
  metres).

What perception gets wrong (a door missed, a room voted wrong, a window taken for the front door
so that routes start in it) is the segmentation benchmark's business; this checks that what the
parse claims can be driven, and never through a wall.
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import dataclass

import networkx as nx
import numpy as np
from shapely.geometry import LineString
from tqdm import tqdm

from f2n_drake.core.errors import InputError, PlanningError, non_negative_int
from f2n_drake.core.plan import FloorPlan
from f2n_drake.datasets.render import DrawingStyle, RenderedPlan, render

CROSSING_TOLERANCE_M = 0.05
"""Length of a route inside true walls [m] counted as a crossing (the drawing's pixels and line
widths blur the wall faces by a few centimetres)."""


@dataclass(frozen=True)
class RouteCheck:
    """One front-door-to-space route: the goal's graph key, whether the planner found a route,
    and how far it runs inside the plan's true walls [m] (None: not checked)."""

    goal: str
    routed: bool
    inside_walls_m: float | None = None


def inside_walls_m(waypoints_px: np.ndarray, rendered: RenderedPlan, plan: FloorPlan) -> float:
    """Length [m] of the polyline through ``waypoints_px`` ((N, 2) col, row on the drawing)
    that lies inside the plan's walls; the drawing must not be turned."""
    if len(waypoints_px) < 2:
        return 0.0
    path = LineString(rendered.grid.to_m(np.asarray(waypoints_px, float)))
    return float(path.intersection(plan.union("wall")).length)


def check_routes(plan: FloorPlan, rendered: RenderedPlan, parsed, profile) -> list[RouteCheck]:
    """Plan from the parsed front door to every space the parsed graph reaches for ``profile``
    (none when no front door was found) and check each route against the true plan. Like a run,
    it plans on the parse at planning resolution (``f2n_drake.build_graph``), with one planner
    for all the goals (its precompute amortised)."""
    from f2n_drake import build_graph
    from f2n_drake.mapping.robots import traversable_subgraph
    from f2n_drake.planning.hierarchical import HierarchicalPlanner

    drawing_grid = parsed.grid  # the drawing's pixels; the coarse grid shares its frame
    plan_map = build_graph(parsed)
    parsed, graph = plan_map.parsed, plan_map.graph
    reachable = traversable_subgraph(graph, profile)
    doors = sorted(k for k, d in reachable.nodes(data=True) if d.get("class_name") == "front_door")
    if not doors:
        return []
    goals = sorted(
        k
        for k in nx.node_connected_component(reachable, doors[0])
        if reachable.nodes[k].get("kind") == "space"
    )
    exact = rendered.style.rotation_deg == 0.0
    try:
        planner = HierarchicalPlanner(parsed, graph, profile)
    except PlanningError:
        return [RouteCheck(goal, False) for goal in goals]
    checks = []
    for goal in goals:
        try:
            route = planner.plan(doors[0], goal)
        except PlanningError:
            checks.append(RouteCheck(goal, False))
            continue
        inside = (
            inside_walls_m(drawing_grid.to_px(route.waypoints_m), rendered, plan) if exact else None
        )
        checks.append(RouteCheck(goal, True, inside))
    return checks


def evaluate_routes(
    seeds: range, *, styles: str, size_px: int, views: int, progress: bool = True
) -> dict:
    """Draw, parse and route every plan of ``seeds``; the report printed by the CLI."""
    from f2n_drake import parse_drawing
    from f2n_drake.datasets.generator import generate_plan
    from f2n_drake.mapping.robots import GROUND
    from f2n_drake.segmenter.inference import Segmenter

    segmenter = Segmenter.load(views=views)
    failures, crossings, checked, spaces = [], [], 0, 0
    for seed in tqdm(seeds, desc="routes", unit="plan", disable=not progress, file=sys.stderr):
        rng = np.random.default_rng(seed)
        plan = generate_plan(seed)
        style = DrawingStyle.random(rng) if styles == "random" else DrawingStyle()
        rendered = render(plan, size_px, style=style, rng=rng)
        parsed = parse_drawing(
            rendered.image, segmenter=segmenter, metres_per_px=rendered.grid.metres_per_px
        )
        for check in check_routes(plan, rendered, parsed, GROUND):
            spaces += 1
            if not check.routed:
                failures.append(f"{seed}:{check.goal}")
            elif check.inside_walls_m is not None:
                checked += 1
                if check.inside_walls_m > CROSSING_TOLERANCE_M:
                    crossings.append(f"{seed}:{check.goal}")
    return {
        "n_images": len(seeds),
        "seed": seeds.start,
        "styles": styles,
        "size_px": size_px,
        "views": views,
        "spaces_reached_in_graph": spaces,
        "unroutable": len(failures),
        "plans_with_unroutable": len({f.split(":")[0] for f in failures}),
        "routes_checked_against_walls": checked,
        "wall_crossings": len(crossings),
        "unroutable_routes": failures,
        "crossing_routes": crossings,
    }


def main(argv: list[str] | None = None) -> int:
    from f2n_drake.segmenter import DEFAULT_VIEWS, VIEW_COUNTS

    parser = argparse.ArgumentParser(
        prog="python -m f2n_drake.evaluate routes", description=__doc__.splitlines()[0]
    )
    parser.add_argument("--synthetic", type=int, default=100, help="plans to draw and route")
    parser.add_argument("--seed", type=non_negative_int, default=500000, help="first plan seed")
    parser.add_argument("--styles", choices=("clean", "random"), default="random")
    parser.add_argument("--size", type=int, default=512, help="drawing side [px]")
    parser.add_argument("--views", type=int, choices=VIEW_COUNTS, default=DEFAULT_VIEWS)
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    args = parser.parse_args(argv)
    if args.synthetic < 1 or args.seed + args.synthetic > 1_000_000:
        raise InputError("plan seeds must lie in 0..999999 (training uses >= 1000000)")
    if args.size < 64:
        raise InputError(f"--size must be at least 64 px, got {args.size}")
    report = evaluate_routes(
        range(args.seed, args.seed + args.synthetic),
        styles=args.styles,
        size_px=args.size,
        views=args.views,
        progress=not args.json,
    )
    if args.json:
        print(json.dumps(report))
        return 0
    print(
        f"{report['n_images']} {args.styles} drawings (seeds {args.seed}.."
        f"{args.seed + args.synthetic - 1}, {args.size} px): "
        f"{report['spaces_reached_in_graph']} spaces the graph reaches from the front door"
    )
    print(
        f"  unroutable: {report['unroutable']} (in {report['plans_with_unroutable']} plans) "
        f"{report['unroutable_routes']}"
    )
    print(
        f"  through a true wall: {report['wall_crossings']} of "
        f"{report['routes_checked_against_walls']} routes on unturned drawings "
        f"{report['crossing_routes']}"
    )
    return 0
