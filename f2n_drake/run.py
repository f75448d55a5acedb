"""``python -m f2n_drake.run PLAN``: drawing (or ResPlan .pkl / plan JSON) to a driven route.

Parse the plan, build the connectivity graph, plan a route for the robot, simulate it in Drake,
write the exports and figures to ``--out`` and print a short summary (``--json`` for machines).

``--out`` is written as one unit (``f2n_drake.core.output_dir``): checked before the work starts,
replaced as a whole when the run ends, never half-written. Exit codes:

  0  the route was planned (and, when simulated, driven to its goal)
  2  bad input: file, image, option, scale or robot profile; nothing is written
  3  no route: the parse is written to --out, the error line names the unreachable rooms
  4  the simulated robot did not reach its goal (any mode, with --correction all); all written
  130, 143  interrupted (Ctrl-C) or terminated (SIGTERM); nothing is written
"""

from __future__ import annotations

import contextlib
import json
import logging
import sys
import time
from collections.abc import Callable
from dataclasses import asdict
from pathlib import Path

from f2n_drake.core.errors import (
    EXIT_GOAL_NOT_REACHED,
    EXIT_OK,
    InputError,
    PlanningError,
    run_cli,
)
from f2n_drake.core.output_dir import StagedDir, StagedFile
from f2n_drake.core.parsed import UNSURE_BELOW
from f2n_drake.core.progress import Progress
from f2n_drake.loading import LoadedPlan, load_plan
from f2n_drake.outputs.exports import Georeference, parse_origin
from f2n_drake.outputs.summary import (
    RunSummary,
    add_localization_summary,
    building_note,
    format_summary,
    listed,
    natural_order,
    simulation_summary,
)
from f2n_drake.outputs.writer import write_outputs
from f2n_drake.planning.endpoints import (
    default_goal,
    default_start,
    parse_place,
    resolve_node,
    spaces_apart,
    unreachable_spaces,
)
from f2n_drake.run_options import build_parser
from f2n_drake.segmenter import DEFAULT_VIEWS
from f2n_drake.world.options import WorldOptions, world_options_of

log = logging.getLogger(__name__)


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
    page: int = 1,
    paper_scale: float | None = None,
    front_doors: int | None = 1,
    kitchens: int | None = 1,
    views: int = DEFAULT_VIEWS,
    georeference: Georeference | None = None,
    world_options: WorldOptions | None = None,
    unknown_start: bool = False,
    replan: bool = False,
    progress: Callable[[str], None] | None = None,
) -> RunSummary:
    """The whole pipeline. ``out`` and ``html`` are checked before the work and written only
    when it ends; a parse with no route is written too, then its ``PlanningError`` raised.

    ``world_options``: the simulated building differs from the plan (furniture, people, closed
    doors, displaced walls; ``f2n_drake.world``), made from the plan, its graph and the route
    with ``seed``; the robot still knows only the plan.

    One occupancy map per run: the planner, the Nav2 map and the simulated walls read the same
    array (``PlanMap.occupancy``). ``replan``: the simulated robot avoids what its LiDAR sees
    and the plan lacks and replans past closed doors (always so in a building that differs
    from the plan or with an unknown start). ``unknown_start``: the simulated robot does not
    know its start pose and localizes itself on the plan before it follows the route (see
    ``f2n_drake.systems.simulation.simulate_navigation``). ``progress`` is told each step as it
    starts (``core.progress.Progress``).

    Raises:
        InputError: bad input (nothing written). PlanningError: no route (the parse written).
    """
    from f2n_drake import build_graph
    from f2n_drake.mapping.robots import load_profile
    from f2n_drake.mapping.walls import PlanGeometry

    t0 = time.perf_counter()
    step = progress or (lambda name: None)
    step("loading the input")
    input_path = Path(input_path)
    profile = load_profile(robot)
    with contextlib.ExitStack() as stack:
        staged = stack.enter_context(StagedDir(out)) if out is not None else None
        replay = stack.enter_context(StagedFile(html, option="--html")) if html else None
        loaded = load_plan(
            input_path,
            metres_per_px=scale,
            plan_index=plan_index,
            page=page,
            paper_scale=paper_scale,
            front_doors=front_doors,
            kitchens=kitchens,
            views=views,
            progress=progress,
        )
        step("building the graph")
        plan_map = build_graph(loaded.parsed)
        parsed, graph = plan_map.parsed, plan_map.graph
        free = plan_map.occupancy(profile)
        summary = parse_summary(input_path, loaded, parsed, graph, profile)
        failure = None
        step("planning the route")
        try:
            route = plan_summary_route(summary, plan_map, profile, start, goal)
        except PlanningError as exc:
            route, failure = None, exc
            summary.status, summary.error = "no route", no_route_message(exc, summary)
        results, world = {}, None
        if route is not None and simulate and not drives_like_turtlebot(profile):
            summary.notes.append(
                f"simulation skipped: the Drake model is the TurtleBot3 Burger ground robot; the "
                f"{profile.name!r} route is planned only"
            )
        elif route is not None and simulate:
            world = (
                PlanGeometry.from_floorplan(loaded.floorplan)
                if loaded.floorplan is not None
                else PlanGeometry.from_parsed(parsed, free)
            )
            extra = {}
            if world_options is not None and not world_options.is_plan:
                building = world_building(world, graph, route, world_options, seed)
                summary.notes.append(building_note(building, world_options))
                extra["building"] = building
            if unknown_start:
                extra["unknown_start"] = True
            if replan or "building" in extra or unknown_start:
                from f2n_drake.planning.replanning import Replanner

                extra["replanner"] = Replanner.from_plan(parsed, graph, "ground")
            results = simulate_route(
                world, route, correction, seed, meshcat, replay, progress=step, **extra
            )
            summary.simulation = [simulation_summary(m, r) for m, r in results.items()]
            if unknown_start:
                add_localization_summary(summary, results)
            if not all(r.success for r in results.values()):
                summary.status = "goal not reached"
        summary.wall_time_s = round(time.perf_counter() - t0, 2)
        if staged is not None:
            step("writing the outputs")
            names = write_outputs(
                staged.scratch,
                loaded,
                parsed,
                graph,
                route,
                profile,
                results,
                free=free,
                world=world,
                georeference=georeference,
            )
            summary.outputs = [str(Path(out) / n) for n in names]  # as the user named it
            (staged.scratch / "summary.json").write_text(json.dumps(asdict(summary), indent=1))
            staged.commit()
        if replay is not None and results:
            replay.commit()
    if failure is not None:
        raise PlanningError(summary.error) from failure
    return summary


def parse_summary(input_path: Path, loaded: LoadedPlan, parsed, graph, profile) -> RunSummary:
    """What the parse found, before any route: counts, scale, unsure instances, notes."""
    from f2n_drake.core.classes import CONNECTOR_CLASSES, OPENING, SPACE_CLASSES

    counts: dict[str, int] = {}
    for inst in parsed.instances:
        counts[inst.class_name] = counts.get(inst.class_name, 0) + 1
    return RunSummary(
        input=str(input_path),
        perception=loaded.perception,
        scale_m_per_px=float(loaded.parsed.grid.metres_per_px),  # the drawing's
        scale_source=parsed.scale_source,
        rooms={c: counts[c] for c in SPACE_CLASSES if c in counts},
        connectors={c: counts[c] for c in (*CONNECTOR_CLASSES, OPENING) if c in counts},
        robot=profile.name,
        unsure={
            key: round(float(d["confidence"]), 3)
            for key, d in graph.nodes(data=True)
            if d.get("confidence") is not None and d["confidence"] < UNSURE_BELOW
        },
        notes=[
            *loaded.notes,
            *loaded.parsed.drawing_notes,
            *filter(None, [loaded.parsed.sheet_note]),
        ],
    )


def plan_summary_route(summary: RunSummary, plan_map, profile, start, goal):
    """Resolve the endpoints (defaults: the front door, the farthest room), plan the route and
    fill the summary's route fields. Raises PlanningError when there is no route, InputError
    for an endpoint that names nothing."""
    from f2n_drake import plan_route

    graph = plan_map.graph
    start_place = inside_plan(parse_place(start), plan_map.parsed.grid, "--start")
    goal_place = inside_plan(parse_place(goal), plan_map.parsed.grid, "--goal")
    if start_place is None:
        start_place = default_start(graph, profile)
        fronts = sorted(k for k, d in graph.nodes(data=True) if d.get("class_name") == "front_door")
        if fronts and start_place not in fronts:
            summary.notes.append(
                f"no front door ({', '.join(fronts)}) leads into a room the {profile.name} robot "
                f"can use; the route starts in {start_place} (give --start to choose)"
            )
    if isinstance(start_place, str):
        start_place = resolve_node(graph, start_place)
    summary.start = str(start_place)
    summary.unreachable = unreachable_spaces(graph, profile, start_place)
    if plan_map.parsed.plans > 1:  # floors drawn side by side: no route joins them
        summary.on_other_plans = spaces_apart(graph, start_place, summary.unreachable)
    farthest = None
    if goal_place is None:
        farthest = default_goal(graph, profile, start_place)
    elif isinstance(goal_place, str):
        goal_place = resolve_node(graph, goal_place)
    summary.goal = str(farthest or goal_place)
    route = plan_route(plan_map, robot=profile, start=start_place, goal=goal_place)
    if farthest is not None and route.sequence[-1] != farthest:  # the next farthest, reached
        summary.notes.append(
            f"no route for the {profile.name} robot to {farthest} or other rooms farther than "
            f"{route.sequence[-1]}, though the graph joins them (a doorway too narrow, or a room "
            "it cannot cross); the route goes there"
        )
        summary.goal = route.sequence[-1]
    summary.route = list(route.sequence)
    summary.path_length_m = round(float(route.length_m), 3)
    summary.planning_precompute_ms = round(float(route.timings.get("precompute", 0.0)), 2)
    summary.planning_query_ms = round(float(route.timings.get("query", 0.0)), 3)
    cut_off, apart = unreachable_parts(summary)
    if cut_off:
        summary.notes.append(
            f"{cut_off} cannot be reached by the {profile.name} robot from {start_place}: no "
            "usable door into them was found (check the drawing)"
        )
    if apart:
        summary.notes.append(f"{apart} lie on another plan of the sheet than {start_place}")
    return route


def unreachable_parts(summary: RunSummary) -> tuple[str, str]:
    """The unreachable rooms listed in two parts: cut off on the start's plan, and drawn apart on
    another plan of the sheet ("" for none)."""
    apart = set(summary.on_other_plans)
    cut_off = [k for k in summary.unreachable if k not in apart]
    return tuple(
        listed(sorted(part, key=natural_order)) if part else "" for part in (cut_off, apart)
    )


def inside_plan(place, grid, option: str):
    """``place`` unchanged; InputError when it is a point [m] outside the drawing."""
    if not isinstance(place, tuple):
        return place
    rows, cols = grid.shape
    x0, y1 = grid.origin_m
    x1, y0 = x0 + cols * grid.metres_per_px, y1 - rows * grid.metres_per_px
    if not (x0 <= place[0] <= x1 and y0 <= place[1] <= y1):
        raise InputError(
            f"{option} {place[0]:g},{place[1]:g} m lies outside the plan "
            f"(x {x0:.2f}..{x1:.2f} m, y {y0:.2f}..{y1:.2f} m)"
        )
    return place


def no_route_message(exc: PlanningError, summary: RunSummary) -> str:
    """One line: why no route, and which rooms the robot cannot reach from its start."""
    message = f"no route for the {summary.robot} robot: {exc}"
    cut_off, apart = unreachable_parts(summary)
    if cut_off:
        message += (
            f"; unreachable from {summary.start}: {cut_off} (no usable door into them was found; "
            "see segmentation.png)"
        )
    if apart:
        message += f"; on another plan of the sheet: {apart}"
    return message


def world_building(world, graph, route, options: WorldOptions, seed: int):
    """The building that differs from the plan ``world`` as ``options`` say, seeded by
    ``seed`` (``f2n_drake.world.generation.make_building``)."""
    import numpy as np

    from f2n_drake.world.generation import make_building

    return make_building(world, graph, route, options, np.random.default_rng([seed, 34]))


def simulate_route(
    world,
    route,
    correction,
    seed,
    meshcat,
    replay,
    *,
    building=None,
    unknown_start: bool = False,
    replanner=None,
    progress: Callable[[str], None] = lambda step: None,
) -> dict:
    """Drive the route in ``world`` (``mapping.walls.PlanGeometry``) once per correction mode,
    all of them recorded in one replay written to ``replay`` (a ``StagedFile``) when given.
    ``building``: the building as it is (default: the plan); ``unknown_start``: the robot
    localizes itself first; ``replanner``: avoid and replan
    (``planning.replanning.Replanner``); ``progress`` is told each drive as it starts."""
    from f2n_drake import simulate
    from f2n_drake.systems.viewer import show_only_run, write_replay_html
    from f2n_drake.systems.visualization import REPLAY_FPS

    modes = CORRECTION_MODES if correction == "all" else (correction,)
    if replay is not None:
        if meshcat is None:
            from pydrake.geometry import Meshcat

            meshcat = Meshcat()
        meshcat.StartRecording(REPLAY_FPS)  # every run plays from t = 0 in one replay
    results = {}
    for mode in modes:
        progress(f"driving the route in Drake, correction {mode}")
        results[mode] = simulate(
            world,
            route,
            correction=mode,
            seed=seed,
            meshcat=meshcat,
            building=building,
            unknown_start=unknown_start,
            replanner=replanner,
        )
    if meshcat is not None:
        show_only_run(meshcat, list(modes), modes[-1])
    if replay is not None:
        write_replay_html(meshcat, replay.scratch)
    return results


CORRECTION_MODES = ("off", "paper", "continuous")


def drives_like_turtlebot(profile) -> bool:
    """Whether the simulated TurtleBot3 can stand in for ``profile`` (same body, no windows)."""
    from f2n_drake.mapping.robots import GROUND

    return profile.radius_m <= GROUND.radius_m and set(profile.traversable) <= GROUND.traversable


def main(argv: list[str] | None = None) -> int:
    """The CLI; returns the exit code (module docstring). Errors raise (``run_cli``)."""
    args = build_parser().parse_args(argv)
    georeference = None
    if args.origin is not None:
        georeference = Georeference(*parse_origin(args.origin), heading_deg=args.heading)
    meshcat = None
    if args.meshcat:
        from pydrake.geometry import StartMeshcat

        meshcat = StartMeshcat()
        print(f"meshcat: {meshcat.web_url()}", file=sys.stderr)
    with Progress() as progress:
        summary = run(
            args.plan,
            start=args.start,
            goal=args.goal,
            robot=args.robot,
            scale=args.scale,
            correction=args.correction,
            seed=args.seed,
            out=args.out if args.out is not None else Path("out") / Path(args.plan).stem,
            html=args.html,
            meshcat=meshcat,
            simulate=not args.no_sim,
            plan_index=args.plan_index,
            page=args.page,
            paper_scale=args.paper_scale,
            front_doors=args.front_doors,
            kitchens=args.kitchens,
            views=args.views,
            georeference=georeference,
            world_options=world_options_of(args),
            unknown_start=args.unknown_start,
            replan=args.replan,
            progress=progress,
        )
    print(json.dumps(asdict(summary), indent=1) if args.json else format_summary(summary))
    if meshcat is not None and sys.stdin.isatty():
        input("meshcat is live; press Enter to quit ")
    if summary.status == "goal not reached":
        failed = [s["correction"] for s in summary.simulation if not s["success"]]
        print(
            f"error: the simulated robot did not reach its goal (correction {', '.join(failed)})",
            file=sys.stderr,
        )
        return EXIT_GOAL_NOT_REACHED
    return EXIT_OK


if __name__ == "__main__":
    sys.exit(run_cli(main))
