"""A building that differs from its plan, from the plan, its graph and the route to drive.

:func:`make_building` draws, each from its own stream of the given generator (so adding people
leaves the furniture as it was): the closed doors (:mod:`f2n_drake.world.doors`), the walls'
displacement (:mod:`f2n_drake.world.deviation`), the furniture
(:mod:`f2n_drake.world.furniture`) and the people's walks (:mod:`f2n_drake.world.walkers`).
"""

from __future__ import annotations

from typing import Any

import networkx as nx
import numpy as np
import shapely
from shapely.geometry import Point, Polygon

from f2n_drake.core.classes import SPACE_CLASSES
from f2n_drake.core.errors import InputError
from f2n_drake.mapping.robots import GROUND
from f2n_drake.mapping.walls import PlanGeometry, dominant_angle
from f2n_drake.world.building import Building
from f2n_drake.world.deviation import AxisWarp
from f2n_drake.world.doors import door_wall, doors_to_close
from f2n_drake.world.free_space import FloorRaster
from f2n_drake.world.furniture import RouteGuard, place_furniture
from f2n_drake.world.options import WorldOptions
from f2n_drake.world.walkers import plan_walks

DOORWAY_CLEARANCE_M = 0.5
"""No furniture within this distance [m] of a door, front door or opening."""
END_CLEARANCE_M = 0.5
"""No furniture within this distance [m] of the route's start and goal."""
PASSAGE_CLASSES = ("door", "front_door", "opening")
INSIDE_MARGIN_M = 0.15
"""The inside of the building is its rooms and passages grown by this much [m] (the seams
between them); the robot's way and the people's walks stay inside."""


def _route_parts(route: Any) -> tuple[np.ndarray, list[str]]:
    waypoints = np.asarray(getattr(route, "waypoints_m", route), dtype=float).reshape(-1, 2)
    if len(waypoints) == 0:
        raise InputError("the route has no waypoints")
    return waypoints, list(getattr(route, "sequence", []))


def _passages(plan: PlanGeometry, graph: nx.Graph | None) -> list[Polygon]:
    """Doorway polygons [m]: the plan's doors and front doors, and the graph's connectors that
    a robot passes (openings included)."""
    found = [p for name, p in plan.connectors if name in PASSAGE_CLASSES]
    if graph is not None:
        found += [
            d["polygon_m"]
            for _, d in graph.nodes(data=True)
            if d.get("class_name") in PASSAGE_CLASSES and d.get("polygon_m") is not None
        ]
    return found


PASSAGE_RADIUS_M = GROUND.radius_m + GROUND.clearance_margin_m + 0.03
"""Half the narrowest way furniture leaves the robot [m]: its body, the clearance margin its
planner keeps and the 3 cm the replanner adds round what its LiDAR sees
(``planning.replanning``), so a way the building leaves is one the robot will take."""


def make_building(
    plan: PlanGeometry,
    graph: nx.Graph | None,
    route: Any,
    options: WorldOptions,
    rng: np.random.Generator,
    *,
    robot_radius_m: float = PASSAGE_RADIUS_M,
) -> Building:
    """The building as it is, for a robot that will drive ``route`` knowing only ``plan``.

    Args:
        plan: the plan's walls, floors and connectors [m].
        graph: the plan's connectivity graph (``f2n_drake.mapping.graph``): node classes and
            polygons name the doors; needed when ``options.closed_doors > 0``.
        route: a ``Route`` (``waypoints_m``, ``sequence`` of graph node keys) or (N, 2)
            waypoints [m]; its first and last waypoints are the start and the goal.
        options: what differs (:class:`~f2n_drake.world.options.WorldOptions`).
        rng: the only randomness; the same generator state gives the same building.
        robot_radius_m: half the width [m] of the way furniture must leave the robot
            (default ``PASSAGE_RADIUS_M``).

    Guarantees: no furniture in doorways or within ``END_CLEARANCE_M`` of start and goal; none
    that cuts start from goal for the robot's disc, with all doors open and with the chosen
    doors closed where they left a way (ways round the outside do not count); no closed door
    within 0.3 m of start or goal; walls displaced by at most ``options.deviation_m`` along
    their normals. Closed doors may cut the route: that is their purpose.

    Raises:
        InputError: closed doors asked for without a graph, or a route with no waypoints.
    """
    waypoints, sequence = _route_parts(route)
    if options.is_plan:
        return Building.as_planned(plan)
    if options.closed_doors and graph is None:
        raise InputError("closing doors needs the plan's connectivity graph")
    doors_rng, warp_rng, furniture_rng, people_rng = rng.spawn(4)
    start, goal = waypoints[0], waypoints[-1]

    closed = (
        doors_to_close(graph, sequence, options.closed_doors, doors_rng, [start, goal])
        if options.closed_doors
        else []
    )
    door_walls = [door_wall(graph.nodes[k]["polygon_m"]) for k in closed]
    walls = list(plan.walls)
    rooms = [p for name, p in plan.floors if name in SPACE_CLASSES]
    passages = _passages(plan, graph)
    if options.deviation_m > 0:
        longest = max(walls, key=lambda p: p.length)
        warp = AxisWarp.random(
            plan.bounds(), options.deviation_m, warp_rng, dominant_angle(longest)
        )
        walls, door_walls, rooms, passages = (
            [warp.apply(p) for p in group] for group in (walls, door_walls, rooms, passages)
        )

    open_walls = shapely.union_all(walls)
    built_walls = shapely.union_all([open_walls, *door_walls])
    raster = FloorRaster.covering(plan.bounds())
    inside = raster.cover(shapely.union_all([*rooms, *passages]).buffer(INSIDE_MARGIN_M))
    boxes, cylinders = [], []
    if options.clutter_fraction > 0:
        keep_out = shapely.union_all(
            [
                *(p.buffer(DOORWAY_CLEARANCE_M) for p in passages),
                Point(*start).buffer(END_CLEARANCE_M),
                Point(*goal).buffer(END_CLEARANCE_M),
            ]
        )
        guard = RouteGuard(raster, [open_walls, built_walls], start, goal, robot_radius_m, inside)
        boxes, cylinders = place_furniture(
            rooms, built_walls, keep_out, options.clutter_fraction, furniture_rng, guard
        )
    obstacles = shapely.union_all([built_walls, *boxes, *(c.footprint() for c in cylinders)])
    people = plan_walks(raster, obstacles, rooms, options.people, people_rng, [start], inside)
    return Building(
        walls=tuple([*walls, *door_walls]),
        furniture=tuple(boxes),
        people=tuple(people),
        closed_doors=tuple(closed),
        cylinders=tuple(cylinders),
        door_walls=tuple(door_walls),
    )


__all__ = ["DOORWAY_CLEARANCE_M", "END_CLEARANCE_M", "make_building"]
