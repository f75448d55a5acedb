"""``python -m f2n_drake.evaluate replanning``: a door of the planned route closed in the building.

Each task is a generated plan and a ground-robot route between two rooms (as ``evaluate
navigation`` samples them); in the building one door the route passes is closed (its polygon is
a wall). Generated flats join their rooms by a tree of doors, so ``--extra-doors`` first cuts
doors in walls between rooms (default 2 per plan) to make loops a closed door can be gone round.
The robot knows only the plan: with continuous correction and the plan's ``Replanner`` it must
find the door closed and go round through another door, or, when none is left, stop with a
message naming the door. Reported: the tasks with another way and the share that reach the goal
without a collision, the tasks without one and the share that end with a "no route left"
message naming the closed door, collisions, replans, and the median realtime factor of these
runs beside the same routes driven with every door open, with the replanner (the costmap's
cost) and without it.
"""

from __future__ import annotations

import json
import logging
import sys

import numpy as np
import shapely
from shapely.geometry import Polygon, box
from tqdm import tqdm

from f2n_drake.core.errors import ArgumentParser, F2NError, InputError, non_negative_int
from f2n_drake.core.plan import FloorPlan, polygons_of

log = logging.getLogger(__name__)


def with_extra_doors(
    plan: FloorPlan, rng: np.random.Generator, n_doors: int, width_m: float = 0.85
) -> FloorPlan:
    """``plan`` with up to ``n_doors`` more doors, each ``width_m`` wide in the middle of a wall
    shared by two rooms that no door joins yet (at least ``width_m + 0.5`` m of it): generated
    flats are trees of doors, and a closed door can only be gone round where rooms form a loop.
    Axis-aligned walls only (generated apartments)."""
    if n_doors <= 0:
        return plan
    walls = shapely.union_all(plan["wall"])
    doors = list(plan["door"])
    spaces = [p for name, p in plan.spaces() if name != "balcony"]
    candidates = []
    for i, a in enumerate(spaces):
        for b in spaces[i + 1 :]:
            # the midline band of a wall between a and b (walls are at most 0.3 m thick)
            mid = a.buffer(0.16, join_style="mitre").intersection(
                b.buffer(0.16, join_style="mitre")
            )
            mid = mid.intersection(walls)
            if mid.is_empty or any(mid.buffer(0.3).intersects(d) for d in doors):
                continue
            mid = max(getattr(mid, "geoms", [mid]), key=lambda g: g.area)
            x0, y0, x1, y1 = mid.bounds
            if max(x1 - x0, y1 - y0) < width_m + 0.5:
                continue
            cx, cy, h = (x0 + x1) / 2, (y0 + y1) / 2, width_m / 2
            if x1 - x0 > y1 - y0:
                cut = box(cx - h, cy - 0.3, cx + h, cy + 0.3)
            else:
                cut = box(cx - 0.3, cy - h, cx + 0.3, cy + h)
            door = walls.intersection(cut)
            if door.geom_type == "Polygon" and door.distance(a) + door.distance(b) < 0.01:
                candidates.append(door)
    added = [
        candidates[int(k)]
        for k in rng.permutation(len(candidates))[: min(n_doors, len(candidates))]
    ]
    if not added:
        return plan
    polygons = dict(plan.polygons)
    polygons["wall"] = polygons_of(walls.difference(shapely.union_all(added)))
    polygons["door"] = doors + added
    meta = {**plan.metadata, "extra_doors": len(added)}
    return FloorPlan(polygons, plan.wall_thickness_m, plan.source, meta)


def door_polygon(plan: FloorPlan, centre_m: np.ndarray) -> Polygon:
    """The door or front door polygon of ``plan`` whose centroid is nearest ``centre_m``."""
    doors = plan["door"] + plan["front_door"]
    return min(doors, key=lambda p: float(np.hypot(*(np.array(p.centroid.coords[0]) - centre_m))))


def _record(result, expected_way: bool, door: str) -> dict:
    return dict(
        other_way=expected_way,
        success=result.success,
        collided=result.collided,
        replans=result.replans,
        message=result.message,
        names_door=result.message.startswith("no route left") and door in result.message,
        realtime_factor=result.realtime_factor,
    )


def _median(values: list[float]) -> float | None:
    return float(np.median(values)) if values else None


def evaluate(
    n_plans: int, n_tasks: int, seed: int, extra_doors: int = 2, baseline: bool = True
) -> dict:
    """Figures of the module docstring over ``n_plans`` generated plans with up to
    ``extra_doors`` doors added (:func:`with_extra_doors`), ``n_tasks`` routes each. Raises
    InputError when no task has a door to close."""
    from f2n_drake.datasets.generator import generate_plan
    from f2n_drake.evaluate.navigation import plan_tasks
    from f2n_drake.mapping.walls import PlanGeometry
    from f2n_drake.planning.replanning import NoRouteLeft, Replanner
    from f2n_drake.systems.simulation import route_time_limit_s, simulate_navigation
    from f2n_drake.world.building import Building

    rng = np.random.default_rng([seed, 34])
    runs, open_guarded, open_plain = [], [], []
    progress = tqdm(total=n_plans * n_tasks, desc="closed-door tasks", file=sys.stderr)
    for i in range(n_plans):
        plan = with_extra_doors(generate_plan(seed + i), rng, extra_doors)
        try:
            plan_map, profile, routes = plan_tasks(plan, n_tasks, rng)
            replanner = Replanner.from_plan(plan_map.parsed, plan_map.graph, profile)
        except F2NError as exc:
            log.warning("plan %d skipped: %s", seed + i, exc)
            routes = []
        geometry = PlanGeometry.from_floorplan(plan) if routes else None
        for k, route in enumerate(routes):
            progress.update()
            doors = [key for key in route.sequence if key in replanner.doorways]
            if not doors:
                continue
            key = str(rng.choice(doors))
            start, goal = route.waypoints_m[0], route.waypoints_m[-1]
            try:
                replanner.replan(start, goal, closed_connectors={key})
                other_way = True
            except NoRouteLeft:
                other_way = False
            closed = door_polygon(plan, replanner.doorways[key].centre_m)
            building = Building(
                walls=(*geometry.walls, closed), closed_doors=(key,), door_walls=(closed,)
            )
            run_seed = seed * 1000 + i * 37 + k
            common = dict(
                correction="continuous",
                seed=run_seed,
                time_limit_s=2.0 * route_time_limit_s(route.waypoints_m),
            )
            result = simulate_navigation(
                geometry, route, building=building, replanner=replanner, **common
            )
            runs.append(_record(result, other_way, key))
            log.info("plan %d task %d (%s closed): %s", seed + i, k, key, result.message)
            if baseline:
                guarded = simulate_navigation(geometry, route, replanner=replanner, **common)
                plain = simulate_navigation(geometry, route, **common)
                open_guarded.append((guarded.success, guarded.replans, guarded.realtime_factor))
                open_plain.append((plain.success, plain.realtime_factor))
    progress.close()
    if not runs:
        raise InputError("no task had a door on its route to close")
    way = [r for r in runs if r["other_way"]]
    no_way = [r for r in runs if not r["other_way"]]
    report = {
        "tasks": len(runs),
        "plans": n_plans,
        "seed": seed,
        "extra_doors": extra_doors,
        "other_way": {
            "tasks": len(way),
            "success_rate": sum(r["success"] for r in way) / len(way) if way else None,
            "collisions": sum(r["collided"] for r in way),
            "replans_mean": float(np.mean([r["replans"] for r in way])) if way else None,
            "failures": [r["message"] for r in way if not r["success"]],
        },
        "no_other_way": {
            "tasks": len(no_way),
            "message_rate": sum(r["names_door"] for r in no_way) / len(no_way) if no_way else None,
            "collisions": sum(r["collided"] for r in no_way),
            "messages": [r["message"] for r in no_way],
        },
        "realtime_factor": {"closed_door": _median([r["realtime_factor"] for r in runs])},
    }
    if baseline:
        report["open"] = {
            "success_rate_replanner": sum(g[0] for g in open_guarded) / len(open_guarded),
            "replans_replanner": sum(g[1] for g in open_guarded),
            "success_rate_plain": sum(p[0] for p in open_plain) / len(open_plain),
        }
        report["realtime_factor"]["open_replanner"] = _median([g[2] for g in open_guarded])
        report["realtime_factor"]["open_plain"] = _median([p[1] for p in open_plain])
    return report


def main(argv: list[str] | None = None) -> int:
    p = ArgumentParser(
        prog="python -m f2n_drake.evaluate replanning", description=__doc__.split("\n\n")[0]
    )
    p.add_argument("--plans", type=int, default=5)
    p.add_argument("--tasks", type=int, default=3, help="routes per plan")
    p.add_argument("--seed", type=non_negative_int, default=0)
    p.add_argument(
        "--extra-doors",
        type=non_negative_int,
        default=2,
        help="doors added between rooms per plan, so that some closed doors can be gone round",
    )
    p.add_argument(
        "--no-baseline", action="store_true", help="skip the open-door runs (realtime baseline)"
    )
    p.add_argument("--json", action="store_true")
    args = p.parse_args(argv)
    if args.plans < 1 or args.tasks < 1:
        raise InputError("--plans and --tasks must be at least 1")
    report = evaluate(
        args.plans, args.tasks, args.seed, args.extra_doors, baseline=not args.no_baseline
    )
    if args.json:
        print(json.dumps(report))
        return 0
    way, no_way, rtf = report["other_way"], report["no_other_way"], report["realtime_factor"]

    def pct(value: float | None) -> str:
        return "n/a" if value is None else f"{value * 100:.0f}%"

    print(f"{report['tasks']} tasks with a closed door on the route ({report['plans']} plans)")
    print(
        f"another way: {way['tasks']} tasks, {pct(way['success_rate'])} reached the goal, "
        f"{way['collisions']} collisions, {way['replans_mean'] or 0:.1f} replans per task"
    )
    print(
        f"no other way: {no_way['tasks']} tasks, {pct(no_way['message_rate'])} ended naming the "
        f"door, {no_way['collisions']} collisions"
    )
    print(
        "realtime factor (median): "
        + ", ".join(f"{k.replace('_', ' ')} {v:.0f}x" for k, v in rtf.items() if v is not None)
    )
    return 0
