"""``python -m f2n_drake.evaluate navigation``: drive planned routes in Drake, per correction mode.

Each task is a generated plan and a start/goal pair of functional spaces; the route is planned
once for the ground robot and driven with LiDAR correction ``off``, ``paper`` and ``continuous``
under the same odometry noise seed. A run succeeds when the TRUE robot ends within 0.25 m of the
goal, without a collision, within the time limit (see ``NavigationResult``). Routes keep the
robot profile's clearance margin from the walls (``--margin`` overrides it). ``--rotate`` turns
every plan (the paper's corrector assumes axis-aligned walls; the continuous one should not care).

``--clutter``, ``--people``, ``--closed-doors`` and ``--deviation`` drive every task in a building
that differs from its plan (``f2n_drake.world``): made per task from the plan and the route, the
same for every mode; the robot still knows only the plan. The report adds the world settings
(``world``), person contacts per mode and the tasks whose building leaves no way to the goal.

``--unknown-start`` drops the start pose: the robot localizes itself on the plan first (Monte
Carlo localization while moving carefully), and the report adds, per mode, the converged rate,
the time to converge, the wrong convergences and the collisions before convergence
(``global_localization``, beside ``modes``).
"""

from __future__ import annotations

import dataclasses
import json
import logging
import sys

import numpy as np
from shapely import affinity
from tqdm import tqdm

from f2n_drake.core.errors import (
    ArgumentParser,
    F2NError,
    InputError,
    finite_float,
    non_negative_int,
)
from f2n_drake.core.plan import FloorPlan
from f2n_drake.evaluate.navigation_report import (
    localization_summary,
    print_report,
    run_line,
    summary,
)
from f2n_drake.mapping.robots import GROUND
from f2n_drake.world.options import WorldOptions, add_world_options, world_options_of

log = logging.getLogger(__name__)

MODES = ("off", "paper", "continuous")


def rotate_plan(plan: FloorPlan, degrees: float) -> FloorPlan:
    """The plan turned by ``degrees`` about its centre."""
    if degrees == 0:
        return plan
    xmin, ymin, xmax, ymax = plan.bounds
    centre = ((xmin + xmax) / 2, (ymin + ymax) / 2)
    polygons = {
        k: [affinity.rotate(p, degrees, origin=centre) for p in ps]
        for k, ps in plan.polygons.items()
    }
    meta = {**plan.metadata, "rotation_deg": degrees}
    return FloorPlan(polygons, plan.wall_thickness_m, plan.source, meta)


def plan_map_of(plan: FloorPlan):
    """The PlanMap (parse, graph, planner) the tasks of ``plan`` are planned on."""
    from f2n_drake import build_graph
    from f2n_drake.datasets.ground_truth import parse_ground_truth

    return build_graph(parse_ground_truth(plan, size_px=512), planning_cell_m=None)


def sample_tasks(
    plan: FloorPlan,
    n_tasks: int,
    rng: np.random.Generator,
    margin_m: float | None = None,
    plan_map=None,
) -> list:
    """Up to ``n_tasks`` ground-robot routes between random pairs of rooms (balconies excluded),
    keeping ``margin_m`` [m] (default: the profile's) beside the robot; unreachable pairs are
    skipped. ``plan_map``: :func:`plan_map_of` the plan, if already made."""
    from f2n_drake import plan_route
    from f2n_drake.mapping.robots import traversable_subgraph

    profile = (
        GROUND if margin_m is None else dataclasses.replace(GROUND, clearance_margin_m=margin_m)
    )
    plan_map = plan_map_of(plan) if plan_map is None else plan_map
    sub = traversable_subgraph(plan_map.graph, profile)
    rooms = sorted(
        k
        for k, d in sub.nodes(data=True)
        if d.get("kind") == "space" and d.get("class_name") != "balcony"
    )
    routes = []
    for _ in range(20 * n_tasks):
        if len(routes) == n_tasks or len(rooms) < 2:
            break
        start, goal = rng.choice(rooms, size=2, replace=False)
        try:
            routes.append(plan_route(plan_map, robot=profile, start=str(start), goal=str(goal)))
        except F2NError:  # an unreachable pair is skipped; planning is benchmarked elsewhere
            continue
    return routes


def plan_tasks(
    plan: FloorPlan, n_tasks: int, rng: np.random.Generator, margin_m: float | None = None
) -> tuple:
    """``(plan_map, profile, routes)``: the routes of :func:`sample_tasks` with the plan map
    and robot profile they were planned on (what a replanner is built from)."""
    profile = (
        GROUND if margin_m is None else dataclasses.replace(GROUND, clearance_margin_m=margin_m)
    )
    plan_map = plan_map_of(plan)
    return plan_map, profile, sample_tasks(plan, n_tasks, rng, margin_m, plan_map)


def _run(
    plan: FloorPlan,
    route,
    mode: str,
    seed: int,
    sigma: float,
    spacing: float,
    building=None,
    no_way: bool = False,
    unknown_start: bool = False,
    replanner=None,
) -> dict:
    """One simulated run as a plain record; a simulation error is a failed run, not a crash.
    ``building``: the building as it is (default: the plan); ``no_way``: it leaves none;
    ``unknown_start``: the robot localizes itself first; ``replanner``: the plan's
    ``planning.replanning.Replanner`` (avoid, replan)."""
    from f2n_drake import simulate

    try:
        r = simulate(
            plan,
            route,
            correction=mode,
            seed=seed,
            odometry_sigma_m=sigma,
            waypoint_spacing_m=spacing,
            building=building,
            unknown_start=unknown_start,
            replanner=replanner,
        )
    except (F2NError, RuntimeError) as exc:
        log.warning("navigation run failed (%s, seed %d): %s", mode, seed, exc)
        nan = float("nan")
        return dict(
            success=False,
            collided=False,
            route_done=False,
            error=True,
            mean_error_m=nan,
            max_error_m=nan,
            final_error_m=nan,
            realtime_factor=nan,
            person_collisions=0,
            no_way=no_way,
            converged=False,
            time_to_converge_s=nan,
            converged_error_m=nan,
            wrong_convergence=False,
            collided_before_converged=False,
            replans=0,
            message=f"error: {exc}",
        )
    return dict(
        success=r.success,
        collided=r.collided,
        route_done=r.route_done,
        error=False,
        mean_error_m=r.mean_error_m,
        max_error_m=r.max_error_m,
        final_error_m=r.final_error_m,
        realtime_factor=r.realtime_factor,
        person_collisions=r.person_collisions,
        no_way=no_way,
        converged=r.converged,
        time_to_converge_s=r.time_to_converge_s,
        converged_error_m=r.converged_error_m,
        wrong_convergence=r.wrong_convergence,
        collided_before_converged=r.collided_before_converged,
        replans=r.replans,
        message=r.message,
    )


def task_building(plan: FloorPlan, plan_map, route, world: WorldOptions, seed: list[int]):
    """(the building of one task, whether it leaves the robot no way to the goal); (None,
    False) for the plain plan."""
    if world.is_plan:
        return None, False
    from f2n_drake.mapping.walls import PlanGeometry
    from f2n_drake.world.generation import PASSAGE_RADIUS_M, make_building
    from f2n_drake.world.reachability import way_exists

    geometry = PlanGeometry.from_floorplan(plan)
    rng = np.random.default_rng(seed)
    building = make_building(geometry, plan_map.graph, route, world, rng)
    ends = route.waypoints_m[0], route.waypoints_m[-1]
    return building, not way_exists(building, geometry, *ends, PASSAGE_RADIUS_M)


def evaluate(
    n_plans: int,
    n_tasks: int,
    seed: int,
    rotate_deg: float = 0.0,
    modes: tuple[str, ...] = MODES,
    odometry_sigma_m: float = 0.02,
    margin_m: float | None = None,
    waypoint_spacing_m: float | None = None,
    world: WorldOptions | None = None,
    unknown_start: bool = False,
    replan: bool = False,
    only: frozenset[tuple[int, int]] | None = None,
) -> dict:
    """Benchmark figures (see the module docstring); raises InputError if no task is planned.

    ``waypoint_spacing_m``: route resampling of the simulation (default
    ``f2n_drake.systems.diagram.WAYPOINT_SPACING_M``); paper mode corrects every 5 waypoints.
    ``world``: how the building differs from its plan (default: not at all).
    ``replan``: the robot avoids what its LiDAR sees and the plan lacks and replans
    (``planning.replanning.Replanner`` of the task's plan map).
    ``only``: simulate just these (plan index, task index) pairs (the others are still drawn,
    so each task is the one of the full run).
    """
    from f2n_drake.datasets.generator import generate_plan
    from f2n_drake.planning.replanning import Replanner
    from f2n_drake.systems.diagram import WAYPOINT_SPACING_M

    spacing = WAYPOINT_SPACING_M if waypoint_spacing_m is None else waypoint_spacing_m
    world = WorldOptions() if world is None else world

    rng = np.random.default_rng([seed, 7])
    runs: dict[str, list[dict]] = {m: [] for m in modes}
    n_tasks_run = 0
    progress = tqdm(total=n_plans * n_tasks, desc="navigation tasks", file=sys.stderr)
    for i in range(n_plans):
        plan = rotate_plan(generate_plan(seed + i), rotate_deg)
        try:
            plan_map, profile, routes = plan_tasks(plan, n_tasks, rng, margin_m)
            replanner = (
                Replanner.from_plan(plan_map.parsed, plan_map.graph, profile)
                if replan and routes
                else None
            )
        except F2NError as exc:
            log.warning("plan %d skipped: %s", seed + i, exc)
            routes = []
        for k, route in enumerate(routes):
            if only is not None and (i, k) not in only:
                continue
            n_tasks_run += 1
            building, no_way = task_building(plan, plan_map, route, world, [seed, i, k, 11])
            for mode in modes:
                run_seed = seed * 1000 + i * 37 + k
                runs[mode].append(
                    {"plan": i, "task": k, "route": f"{route.sequence[0]} -> {route.sequence[-1]}"}
                    | _run(
                        plan,
                        route,
                        mode,
                        run_seed,
                        odometry_sigma_m,
                        spacing,
                        building,
                        no_way,
                        unknown_start,
                        replanner,
                    )
                )
            progress.update()
    progress.close()
    if n_tasks_run == 0:
        raise InputError("no navigation task could be planned")
    all_rt = [r["realtime_factor"] for rs in runs.values() for r in rs if not r["error"]]
    report = {
        "tasks": n_tasks_run,
        "plans": n_plans,
        "seed": seed,
        "rotate_deg": rotate_deg,
        "odometry_sigma_m": odometry_sigma_m,
        "margin_m": GROUND.clearance_margin_m if margin_m is None else margin_m,
        "waypoint_spacing_m": spacing,
        "world": world.as_dict(),
        "replan": replan,
        "modes": {m: summary(rs) for m, rs in runs.items()},
        "realtime_factor": float(np.median(all_rt)) if all_rt else None,
    }
    report["runs"] = {m: [run_line(r) for r in rs] for m, rs in runs.items()}
    if unknown_start:
        report["unknown_start"] = True
        report["global_localization"] = {m: localization_summary(rs) for m, rs in runs.items()}
    return report


def main(argv: list[str] | None = None) -> int:
    p = ArgumentParser(
        prog="python -m f2n_drake.evaluate navigation", description=__doc__.split("\n\n")[0]
    )
    p.add_argument("--plans", type=int, default=10)
    p.add_argument("--tasks", type=int, default=3, help="routes per plan")
    p.add_argument("--seed", type=non_negative_int, default=0)
    p.add_argument(
        "--rotate",
        type=finite_float(-360.0, 360.0),
        default=0.0,
        help="rotate plans by this many degrees",
    )
    p.add_argument(
        "--sigma",
        type=finite_float(0.0, 0.5),
        default=0.02,
        help="odometry XY noise per step [m]",
    )
    p.add_argument(
        "--margin",
        type=finite_float(0.0, 1.0),
        default=None,
        help="clearance kept beside the robot when planning [m] (default: the profile's)",
    )
    p.add_argument(
        "--spacing",
        type=finite_float(0.0, 1.0, low_open=True),
        default=None,
        help="route resampling [m] (paper mode corrects every 5 waypoints); default 0.025",
    )
    p.add_argument("--modes", default=",".join(MODES), help="comma-separated subset of modes")
    add_world_options(p)
    p.add_argument(
        "--unknown-start",
        action="store_true",
        help="the robot does not know its start pose: it localizes itself on the plan first",
    )
    p.add_argument(
        "--replan",
        action="store_true",
        help="avoid what the LiDAR sees and the plan lacks, replan past closed doors",
    )
    p.add_argument(
        "--only",
        default=None,
        help="simulate only these tasks, as PLAN:TASK indices (e.g. 17:0,17:2)",
    )
    p.add_argument("--json", action="store_true")
    args = p.parse_args(argv)
    modes = tuple(m.strip() for m in args.modes.split(","))
    if unknown := set(modes) - set(MODES):
        raise InputError(f"unknown correction modes {sorted(unknown)}; choose from {MODES}")
    if args.plans < 1 or args.tasks < 1:
        raise InputError("--plans and --tasks must be at least 1")
    world = world_options_of(args)
    only = None
    if args.only:
        try:
            only = frozenset(
                (int(a), int(b)) for a, b in (pair.split(":") for pair in args.only.split(","))
            )
        except ValueError as exc:
            raise InputError(f"--only takes PLAN:TASK pairs, got {args.only!r}") from exc
    report = evaluate(
        args.plans,
        args.tasks,
        args.seed,
        args.rotate,
        modes,
        args.sigma,
        args.margin,
        args.spacing,
        world=world,
        unknown_start=args.unknown_start,
        replan=args.replan,
        only=only,
    )
    if args.json:
        print(json.dumps(report))
        return 0
    print_report(report, args.seed, args.rotate, args.sigma, world)
    return 0
