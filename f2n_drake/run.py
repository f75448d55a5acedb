"""``python -m f2n_drake.run PLAN``: drawing (or ResPlan .pkl / plan JSON) to a driven route.

Parse the plan, build the connectivity graph, plan a route for the robot, simulate it in Drake,
write the exports and figures to ``--out`` and print a short summary (``--json`` for machines).
"""

from __future__ import annotations

import argparse
import json
import logging
import sys
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from f2n_drake.core.errors import (
    InputError,
    count_or_any,
    non_negative_int,
    run_cli,
)
from f2n_drake.core.parsed import UNSURE_BELOW
from f2n_drake.outputs.writer import write_outputs
from f2n_drake.planning.endpoints import parse_place, unreachable_spaces
from f2n_drake.segmenter import DEFAULT_VIEWS, VIEW_COUNTS

log = logging.getLogger(__name__)

IMAGE_SUFFIXES = {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".webp", ".gif"}


@dataclass
class RunSummary:
    input: str
    perception: str
    scale_m_per_px: float
    scale_source: str
    rooms: dict[str, int]
    connectors: dict[str, int]
    robot: str
    start: str
    goal: str
    route: list[str]
    path_length_m: float
    planning_precompute_ms: float
    planning_query_ms: float
    simulation: list[dict] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    outputs: list[str] = field(default_factory=list)
    wall_time_s: float = 0.0
    unsure: dict[str, float] = field(default_factory=dict)
    unreachable: list[str] = field(default_factory=list)


@dataclass
class LoadedPlan:
    """What the pipeline knows about the input once it is parsed."""

    parsed: object  # ParsedPlan
    image: np.ndarray  # the drawing (rendered for vector inputs)
    floorplan: object | None  # FloorPlan when the input was vector ground truth
    perception: str


def load_plan(
    path: Path,
    *,
    metres_per_px: float | None,
    plan_index: int = 0,
    front_doors: int | None = 1,
    kitchens: int | None = 1,
    views: int = DEFAULT_VIEWS,
) -> LoadedPlan:
    """Read a drawing (perception, expecting ``front_doors`` front doors and at most
    ``kitchens`` kitchens: see ``f2n_drake.perception.priors.front_doors``,
    ``f2n_drake.perception.priors.kitchens``; the segmenter
    averages ``views`` views of it), a ResPlan .pkl or a plan JSON (ground truth)."""
    from f2n_drake.datasets.ground_truth import parse_ground_truth
    from f2n_drake.datasets.render import render

    if not path.exists():
        raise InputError(f"no such file: {path}")
    suffix = path.suffix.lower()
    if suffix in IMAGE_SUFFIXES:
        from f2n_drake import parse_drawing
        from f2n_drake.perception.image import load_image
        from f2n_drake.perception.scale import resolve_scale
        from f2n_drake.segmenter.inference import Segmenter

        image = load_image(path)
        parsed = parse_drawing(
            image,
            segmenter=Segmenter.load(views=views),
            metres_per_px=metres_per_px,
            front_doors=front_doors,
            kitchens=kitchens,
        )
        parsed = resolve_scale(parsed, metres_per_px=metres_per_px)
        return LoadedPlan(parsed, image, None, f"segmenter, {views} view{'s' * (views > 1)}")
    if suffix == ".pkl":
        from f2n_drake.datasets.resplan import load_resplan

        plans = load_resplan(path)
        if not 0 <= plan_index < len(plans):
            raise InputError(
                f"{path} holds {len(plans)} plans; --plan-index {plan_index} is out of range"
            )
        plan = plans[plan_index]
    elif suffix == ".json":
        from f2n_drake.core.plan import FloorPlan

        plan = FloorPlan.load(path)
    elif suffix in (".pdf", ".svg", ".dwg", ".dxf"):
        raise InputError(
            f"{path}: a {suffix[1:].upper()} file is not read; export the plan as a PNG first, "
            "about 1000 px across (for a PDF page: pdftoppm -png -r 150 plan.pdf plan)"
        )
    else:
        raise InputError(f"{path}: expected an image, a ResPlan .pkl or a plan .json")
    # Vector input: the planning grid is 512 px across, or as fine as --scale asks.
    rendered = (
        render(plan, 512) if metres_per_px is None else render(plan, metres_per_px=metres_per_px)
    )
    parsed = parse_ground_truth(plan, rendered.grid)
    return LoadedPlan(parsed, rendered.image, plan, "ground truth (vector input)")


def run(
    input_path: str | Path,
    *,
    start: str | None = None,
    goal: str | None = None,
    robot: str = "ground",
    scale: float | None = None,
    correction: str = "continuous",
    seed: int = 0,
    out: str | Path | None = "out",
    html: str | Path | None = None,
    meshcat=None,
    simulate: bool = True,
    plan_index: int = 0,
    front_doors: int | None = 1,
    kitchens: int | None = 1,
    views: int = DEFAULT_VIEWS,
) -> RunSummary:
    """The whole pipeline; raises InputError/PlanningError on bad input or no route.

    One occupancy map per run: the planner, the Nav2 map and the simulated walls read the same
    array (``PlanMap.occupancy``)."""
    from f2n_drake import build_graph, plan_route
    from f2n_drake.mapping.robots import load_profile
    from f2n_drake.mapping.walls import PlanGeometry
    from f2n_drake.pipeline import route_ends

    t0 = time.perf_counter()
    input_path = Path(input_path)
    profile = load_profile(robot)
    loaded = load_plan(
        input_path,
        metres_per_px=scale,
        plan_index=plan_index,
        front_doors=front_doors,
        kitchens=kitchens,
        views=views,
    )
    plan_map = build_graph(loaded.parsed)
    parsed, graph = plan_map.parsed, plan_map.graph
    start_place, goal_place = route_ends(plan_map, profile, parse_place(start), parse_place(goal))
    route = plan_route(plan_map, robot=profile, start=start_place, goal=goal_place)
    free = plan_map.occupancy(profile)
    world = None

    counts: dict[str, int] = {}
    for inst in parsed.instances:
        counts[inst.class_name] = counts.get(inst.class_name, 0) + 1
    from f2n_drake.core.classes import CONNECTOR_CLASSES, OPENING, SPACE_CLASSES

    summary = RunSummary(
        input=str(input_path),
        perception=loaded.perception,
        scale_m_per_px=float(loaded.parsed.grid.metres_per_px),  # the drawing's
        scale_source=parsed.scale_source,
        rooms={c: counts[c] for c in SPACE_CLASSES if c in counts},
        connectors={c: counts[c] for c in (*CONNECTOR_CLASSES, OPENING) if c in counts},
        robot=profile.name,
        start=str(start_place),
        goal=str(goal_place),
        route=[k for k in route.sequence],
        path_length_m=round(float(route.length_m), 3),
        planning_precompute_ms=round(float(route.timings.get("precompute", 0.0)), 2),
        planning_query_ms=round(float(route.timings.get("query", 0.0)), 3),
        unsure={
            key: round(float(d["confidence"]), 3)
            for key, d in graph.nodes(data=True)
            if d.get("confidence") is not None and d["confidence"] < UNSURE_BELOW
        },
    )

    if loaded.parsed.sheet_note:
        summary.notes.append(loaded.parsed.sheet_note)
    summary.unreachable = unreachable_spaces(graph, profile, start_place)
    if summary.unreachable:
        summary.notes.append(
            f"{', '.join(summary.unreachable)} cannot be reached by the {profile.name} robot from "
            f"{start_place}: no usable door into them was found (check the drawing)"
        )
    results = {}
    if simulate and not drives_like_turtlebot(profile):
        summary.notes.append(
            f"simulation skipped: the Drake model is the TurtleBot3 Burger ground robot; the "
            f"{profile.name!r} route is planned only"
        )
    elif simulate:
        from f2n_drake import simulate as simulate_route
        from f2n_drake.systems.viewer import show_only_run, write_replay_html
        from f2n_drake.systems.visualization import REPLAY_FPS

        world = (
            PlanGeometry.from_floorplan(loaded.floorplan)
            if loaded.floorplan is not None
            else PlanGeometry.from_parsed(parsed, free)
        )
        modes = CORRECTION_MODES if correction == "all" else (correction,)
        if html is not None:
            if meshcat is None:
                from pydrake.geometry import Meshcat

                meshcat = Meshcat()
            meshcat.StartRecording(REPLAY_FPS)  # every run plays from t = 0 in one replay
        for mode in modes:
            results[mode] = simulate_route(
                world, route, correction=mode, seed=seed, meshcat=meshcat
            )
            summary.simulation.append(simulation_summary(mode, results[mode]))
        if meshcat is not None:
            show_only_run(meshcat, list(modes), modes[-1])
        if html is not None:
            write_replay_html(meshcat, html)
    if out is not None:
        summary.outputs = write_outputs(
            Path(out), loaded, parsed, graph, route, profile, results, free=free, world=world
        )
    summary.wall_time_s = round(time.perf_counter() - t0, 2)
    return summary


CORRECTION_MODES = ("off", "paper", "continuous")


def drives_like_turtlebot(profile) -> bool:
    """Whether the simulated TurtleBot3 can stand in for ``profile`` (same body, no windows)."""
    from f2n_drake.mapping.robots import GROUND

    return profile.radius_m <= GROUND.radius_m and set(profile.traversable) <= GROUND.traversable


def simulation_summary(mode: str, result) -> dict:
    return {
        "correction": mode,
        "reached": bool(result.reached),
        "collided": bool(result.collided),
        "sim_time_s": round(float(result.time_s), 2),
        "final_error_m": round(float(result.final_error_m), 4),
        "mean_error_m": round(float(result.mean_error_m), 4),
        "max_error_m": round(float(result.max_error_m), 4),
        "min_clearance_m": round(float(result.min_clearance_m), 4),
        "realtime_factor": round(float(result.realtime_factor), 1),
    }


def format_summary(s: RunSummary) -> str:
    rooms = ", ".join(f"{n} {c}" for c, n in s.rooms.items())
    conns = ", ".join(f"{n} {c}" for c, n in s.connectors.items())
    lines = [
        f"plan        {s.input}  ({s.perception})",
        f"scale       {s.scale_m_per_px * 100:.2f} cm/px ({s.scale_source})",
        f"found       {rooms}; {conns}",
    ]
    if s.unsure:
        unsure = ", ".join(f"{k} {100 * c:.0f} %" for k, c in sorted(s.unsure.items()))
        lines.append(f"unsure      {unsure} (mean class probability < {100 * UNSURE_BELOW:.0f} %)")
    lines += [
        f"route       {s.robot}: {' -> '.join(s.route)}",
        f"path        {s.path_length_m:.2f} m; planning {s.planning_precompute_ms:.1f} ms "
        f"precompute + {s.planning_query_ms:.2f} ms query",
    ]
    for sim in s.simulation:
        verdict = (
            "COLLIDED"
            if sim["collided"]
            else ("reached the goal" if sim["reached"] else "did NOT reach the goal")
        )
        lines.append(
            f"simulation  correction {sim['correction']:10s} {verdict} after "
            f"{sim['sim_time_s']:.1f} s simulated; position error final "
            f"{sim['final_error_m'] * 100:.1f} cm, mean {sim['mean_error_m'] * 100:.1f} cm; "
            f"{sim['realtime_factor']:.0f}x real time"
        )
    lines += [f"note        {n}" for n in s.notes]
    if s.outputs:
        lines.append(f"wrote       {len(s.outputs)} files to {Path(s.outputs[0]).parent}")
    lines.append(f"wall time   {s.wall_time_s:.1f} s")
    return "\n".join(lines)


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m f2n_drake.run",
        description="Floor plan in, robot navigation out. PLAN is a drawing (PNG/JPG), a ResPlan "
        ".pkl (pickle: trusted files only, it can run code) or a plan JSON.",
    )
    p.add_argument("plan", help="floor-plan drawing, ResPlan .pkl or plan .json")
    p.add_argument(
        "--start", help="room (e.g. living_0, kitchen) or X,Y in metres [default: the front door]"
    )
    p.add_argument("--goal", help="room or X,Y in metres [default: the farthest room]")
    p.add_argument("--robot", default="ground", help="ground, uav or a profile YAML [ground]")
    p.add_argument(
        "--scale",
        type=float,
        metavar="M_PER_PX",
        help="metres per pixel of the drawing [default: estimated from door widths]",
    )
    p.add_argument(
        "--correction",
        default="continuous",
        choices=["paper", "continuous", "off", "all"],
        help="LiDAR drift correction; 'all' drives the route once per mode and draws "
        "them together [continuous]",
    )
    p.add_argument("--seed", type=non_negative_int, default=0, help="simulation noise seed [0]")
    p.add_argument("--out", default="out", help="output directory [out]")
    p.add_argument(
        "--html",
        help="write a self-contained meshcat HTML replay here (opens framed on the plan; with "
        "--correction all each run is a folder under runs/ in the controls)",
    )
    p.add_argument("--meshcat", action="store_true", help="open a live meshcat viewer")
    p.add_argument("--no-sim", action="store_true", help="stop after planning")
    p.add_argument("--plan-index", type=int, default=0, help="which plan of a .pkl [0]")
    p.add_argument(
        "--front-doors",
        type=count_or_any,
        default=1,
        metavar="N|any",
        help="front doors in a drawing: the N connectors most like one get the class; 'any' "
        "keeps the network's vote [1, an apartment]",
    )
    p.add_argument(
        "--kitchens",
        type=count_or_any,
        default=1,
        metavar="N|any",
        help="kitchens in a drawing at most: the N most kitchen-like keep the class, and a "
        "drawing with none gets its most kitchen-like room; 'any' keeps the network's vote "
        "[1, an apartment]",
    )
    p.add_argument(
        "--views",
        type=int,
        choices=VIEW_COUNTS,
        default=DEFAULT_VIEWS,
        help="views of a drawing (flips and quarter turns) whose segmentations are averaged; "
        f"network time grows with the count [{DEFAULT_VIEWS}]",
    )
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    return p


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    if args.scale is not None and not args.scale > 0:
        raise InputError(f"--scale must be positive, got {args.scale}")
    if Path(args.out).exists() and not Path(args.out).is_dir():
        raise InputError(f"output path {args.out} exists and is not a directory")
    if args.html is not None and (Path(args.html).is_dir() or not Path(args.html).parent.is_dir()):
        raise InputError(
            f"--html {args.html}: not a writable file path (is it a folder, or is "
            f"its folder missing?)"
        )
    meshcat = None
    if args.meshcat:
        from pydrake.geometry import StartMeshcat

        meshcat = StartMeshcat()
        print(f"meshcat: {meshcat.web_url()}", file=sys.stderr)
    summary = run(
        args.plan,
        start=args.start,
        goal=args.goal,
        robot=args.robot,
        scale=args.scale,
        correction=args.correction,
        seed=args.seed,
        out=args.out,
        html=args.html,
        meshcat=meshcat,
        simulate=not args.no_sim,
        plan_index=args.plan_index,
        front_doors=args.front_doors,
        kitchens=args.kitchens,
        views=args.views,
    )
    print(json.dumps(asdict(summary), indent=1) if args.json else format_summary(summary))
    if meshcat is not None and sys.stdin.isatty():
        input("meshcat is live; press Enter to quit ")
    return 0


if __name__ == "__main__":
    sys.exit(run_cli(main))
