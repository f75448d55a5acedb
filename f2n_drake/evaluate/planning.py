"""Planning benchmark: global A* vs the hierarchical planner on generated plans.

``python -m f2n_drake.evaluate planning --plans 100 --pairs 10 --seed 0 [--building]
[--robot ground|uav] [--size 512] [--json] [--compare-pyastar]``

Ground truth comes from ``parse_ground_truth``; start/goal pairs are drawn uniformly (seeded) from
the free cells of functional spaces where the robot fits. Both planners share the same inflated
grid, cost model and compiled A*. Query times exclude the hierarchical precompute (reported
apart); the hierarchical time covers its whole call (endpoints in metres to smoothed metric
waypoints), the global time only its A* search (the baseline is never handicapped). The cost
ratio is hierarchical smoothed length / global A* raw path length (the paper's metric), the
smoothed ratio compares with the global path after the same smoothing.
A failure is a task one planner solves and the other does not, or any path crossing a wall
(every segment checked against the un-inflated free grid). Node counts: global A* cells
expanded vs the hierarchical query's (portal-graph nodes, descended path cells, in-room A*);
the precompute's expansions are reported apart. ``cost_ratio_over_1`` counts tasks whose
hierarchical length exceeds the global raw length by more than 1e-6 (relative).
"""

from __future__ import annotations

import argparse
import json
import math
import time

import numpy as np
from tqdm import tqdm

from f2n_drake.core.errors import InputError, PlanningError, non_negative_int
from f2n_drake.core.raster import PixelGrid

BUILDING_SIZES = (50, 100, 200)
BUILDING_METRES_PER_PX = 0.04
MAX_SIDE_PX = 4096


def _parse(plan, size_px: int, building: bool):
    from f2n_drake.datasets.ground_truth import parse_ground_truth

    if not building:
        return parse_ground_truth(plan, size_px=size_px)
    xmin, ymin, xmax, ymax = plan.bounds
    span = max(xmax - xmin, ymax - ymin)
    side = int(min(MAX_SIDE_PX, math.ceil(span / BUILDING_METRES_PER_PX) + 32))
    return parse_ground_truth(plan, PixelGrid.fit(plan.bounds, side))


def _sample_pairs(planner, n: int, rng: np.random.Generator) -> list[tuple]:
    grids = planner.grids
    spaces = [iid for iid, key in grids.keys.items() if planner.graph.nodes[key]["kind"] == "space"]
    cells = np.argwhere(grids.clear & np.isin(grids.owner, spaces))
    if len(cells) < 2:
        return []
    picks = rng.integers(len(cells), size=(n, 2))
    to_m = planner.parsed.grid.to_m
    return [
        tuple(tuple(float(v) for v in to_m(cells[k][::-1].astype(float))) for k in pair)
        for pair in picks
    ]


def run_plan(parsed, graph, profile, pairs: int, rng: np.random.Generator, workers: int) -> dict:
    """Benchmark one plan; returns per-task records and the precompute time."""
    from f2n_drake.planning.hierarchical import HierarchicalPlanner
    from f2n_drake.planning.smoothing import polyline_clear, shortcut

    planner = HierarchicalPlanner(parsed, graph, profile, workers=workers)
    free = planner.grids.free
    tasks = []
    for start, goal in _sample_pairs(planner, pairs, rng):
        rec = {}
        for name, fn in (("global", planner.plan_global), ("hier", planner.plan)):
            try:
                route = fn(start, goal)
            except PlanningError:
                rec[name] = None
                continue
            crossed = not (
                polyline_clear(route.cells, free) and polyline_clear(route.waypoint_cells, free)
            )
            rec[name] = {
                "ms": route.timings["query"],
                "nodes": route.nodes_expanded,
                "length": route.length_m,
                "raw": route.raw_length_m,
                "crossed": crossed,
            }
            if name == "global":
                smoothed = shortcut(route.cells, planner.grids.clear)
                rec[name]["smoothed"] = float(
                    np.hypot(*np.diff(smoothed, axis=0).T).sum() * planner.grids.metres_per_px
                )
        tasks.append(rec)
    return {
        "tasks": tasks,
        "precompute_ms": planner.precompute_ms,
        "precompute_expanded": planner.precompute_expanded,
    }


def summarise(runs: list[dict]) -> dict:
    """Aggregate figures (keys as documented in the module docstring)."""
    tasks = [t for r in runs for t in r["tasks"]]
    both = [t for t in tasks if t["global"] and t["hier"]]
    one = [t for t in tasks if (t["global"] is None) != (t["hier"] is None)]
    crossed = [t for t in tasks if any(t[k] and t[k]["crossed"] for k in ("global", "hier"))]

    def stat(fn, values):
        values = [v for v in values if math.isfinite(v)]
        return float(fn(values)) if values else float("nan")

    return {
        "tasks": len(tasks),
        "solved_by_both": len(both),
        "unsolvable_for_both": sum(1 for t in tasks if not t["global"] and not t["hier"]),
        "global_ms_median": stat(np.median, [t["global"]["ms"] for t in both]),
        "hierarchical_ms_median": stat(np.median, [t["hier"]["ms"] for t in both]),
        "global_ms_mean": stat(np.mean, [t["global"]["ms"] for t in both]),
        "hierarchical_ms_mean": stat(np.mean, [t["hier"]["ms"] for t in both]),
        "hierarchical_precompute_ms_median": stat(np.median, [r["precompute_ms"] for r in runs]),
        "hierarchical_precompute_ms_max": stat(np.max, [r["precompute_ms"] for r in runs]),
        "hierarchical_precompute_expanded_median": stat(
            np.median, [r["precompute_expanded"] for r in runs]
        ),
        "speedup": stat(np.median, [t["global"]["ms"] / t["hier"]["ms"] for t in both]),
        "speedup_of_mean_times": stat(np.mean, [t["global"]["ms"] for t in both])
        / stat(np.mean, [t["hier"]["ms"] for t in both]),
        "global_nodes_mean": stat(np.mean, [t["global"]["nodes"] for t in both]),
        "hierarchical_nodes_mean": stat(np.mean, [t["hier"]["nodes"] for t in both]),
        "cost_ratio_mean": stat(
            np.mean,
            [t["hier"]["length"] / t["global"]["raw"] for t in both if t["global"]["raw"] > 0],
        ),
        "cost_ratio_max": stat(
            np.max,
            [t["hier"]["length"] / t["global"]["raw"] for t in both if t["global"]["raw"] > 0],
        ),
        "cost_ratio_over_1": sum(
            1
            for t in both
            if t["global"]["raw"] > 0 and t["hier"]["length"] > t["global"]["raw"] * (1 + 1e-6)
        ),
        "smoothed_cost_ratio_mean": stat(
            np.mean,
            [
                t["hier"]["length"] / t["global"]["smoothed"]
                for t in both
                if t["global"]["smoothed"] > 0
            ],
        ),
        "failures": len(one) + len(crossed),
        "wall_crossings": len(crossed),
    }


def compare_pyastar(rng: np.random.Generator, parsed_list: list, profile, repeats: int = 5) -> dict:
    """Our compiled A* vs pyastar2d on the same inflated grids (uniform weights, inf walls).

    pyastar2d charges 1 per diagonal step with no corner rule, so the ratio is given both for
    our octile model and for ours with ``diagonal_cost=1`` (its model)."""
    import pyastar2d

    from f2n_drake.mapping.occupancy import build_grids
    from f2n_drake.planning.astar import astar

    ours, ours_cheb, theirs = [], [], []
    for parsed in parsed_list:
        clear = build_grids(parsed, profile).clear
        weights = np.where(clear, 1.0, np.inf).astype(np.float32)
        cells = np.argwhere(clear)
        for _ in range(repeats):
            s, g = (tuple(int(v) for v in cells[k]) for k in rng.integers(len(cells), size=2))
            for out, diag in ((ours, None), (ours_cheb, 1.0), (theirs, "pyastar")):
                t0 = time.perf_counter()
                if diag == "pyastar":
                    pyastar2d.astar_path(weights, s, g, allow_diagonal=True)
                elif diag is None:
                    astar(clear, s, g)
                else:
                    astar(clear, s, g, diagonal_cost=diag)
                out.append((time.perf_counter() - t0) * 1e3)
    return {
        "pyastar_ms_total": float(np.sum(theirs)),
        "ours_ms_total": float(np.sum(ours)),
        "ours_chebyshev_ms_total": float(np.sum(ours_cheb)),
        "time_ratio_ours_over_pyastar": float(np.sum(ours) / np.sum(theirs)),
        "time_ratio_chebyshev_over_pyastar": float(np.sum(ours_cheb) / np.sum(theirs)),
        "searches": len(theirs),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m f2n_drake.evaluate planning", description=__doc__.split("\n\n")[0]
    )
    parser.add_argument("--plans", type=int, default=100)
    parser.add_argument("--pairs", type=int, default=10)
    parser.add_argument("--seed", type=non_negative_int, default=0)
    parser.add_argument(
        "--building",
        action="store_true",
        help=f"buildings of {BUILDING_SIZES} rooms at "
        f"{BUILDING_METRES_PER_PX} m/px (<= {MAX_SIDE_PX} px)",
    )
    parser.add_argument("--robot", default="ground", help="ground, uav or a profile YAML")
    parser.add_argument("--size", type=int, default=512, help="residential raster side [px]")
    parser.add_argument("--workers", type=int, default=1, help="precompute threads")
    parser.add_argument("--compare-pyastar", action="store_true")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args(argv)
    if args.plans < 1 or args.pairs < 1 or args.size < 64:
        raise InputError("--plans and --pairs must be >= 1 and --size >= 64")

    from f2n_drake.datasets.generator import generate_building, generate_plan
    from f2n_drake.mapping.graph import build_connectivity_graph
    from f2n_drake.mapping.robots import load_profile
    from f2n_drake.planning.astar import warm_up
    from f2n_drake.planning.hierarchical import warm_up_kernels

    profile = load_profile(args.robot)
    warm_up()
    warm_up_kernels()
    rng = np.random.default_rng(args.seed)
    groups = {str(n): n for n in BUILDING_SIZES} if args.building else {"residential": None}
    result: dict = {"robot": profile.name, "seed": args.seed, "workers": args.workers}
    parsed_all = []
    for name, n_rooms in groups.items():
        runs = []
        for i in tqdm(range(args.plans), desc=f"planning {name}", disable=args.json):
            seed = args.seed + i
            if n_rooms is None:
                plan = generate_plan(seed)
            else:
                plan = generate_building(np.random.default_rng(seed), n_rooms=n_rooms)
            parsed = _parse(plan, args.size, args.building)
            graph = build_connectivity_graph(parsed)
            if i == 0:  # untimed warm-up query on the first plan
                run_plan(parsed, graph, profile, 1, np.random.default_rng(0), args.workers)
            runs.append(run_plan(parsed, graph, profile, args.pairs, rng, args.workers))
            if len(parsed_all) < 10:
                parsed_all.append(parsed)
        result[name] = summarise(runs)
    if not args.building:
        result.update(result.pop("residential"))
    if args.compare_pyastar:
        result["pyastar2d"] = compare_pyastar(rng, parsed_all, profile)
    if args.json:
        print(json.dumps(result, indent=2))
    else:
        for key, value in result.items():
            if isinstance(value, dict):
                print(f"{key}:")
                for k, v in value.items():
                    print(f"  {k:36s} {v:.4g}" if isinstance(v, float) else f"  {k:36s} {v}")
            else:
                text = f"{value:.4g}" if isinstance(value, float) else str(value)
                print(f"{key:38s} {text}")
    return 0
