"""Planning results (``Route``) and the baseline entry point ``plan_global`` (A* over the whole
inflated grid); the hierarchical entry point is ``f2n_drake.planning.hierarchical.plan_route``.

Start and goal are (x, y) in metres or a graph node key ("bedroom_1": the room's deepest free
cell; "front_door_0": the reachable cell nearest the door's centroid).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import networkx as nx
import numpy as np

from f2n_drake.core.errors import PlanningError
from f2n_drake.core.parsed import ParsedPlan
from f2n_drake.mapping.occupancy import (
    PlanningGrids,
    build_grids,
    endpoint_cell,
    node_cell,
    to_metres,
)
from f2n_drake.mapping.robots import RobotProfile, load_profile
from f2n_drake.planning.astar import astar, path_length
from f2n_drake.planning.smoothing import shortcut

Endpoint = tuple[float, float] | str


@dataclass(frozen=True)
class Route:
    """A planned path.

    Attributes:
        waypoints_m: (N, 2) smoothed waypoints (x, y) [m], start and goal included.
        cells: (M, 2) raw path vertices (row, col) before smoothing.
        waypoint_cells: (N, 2) the smoothed waypoints as cells (row, col).
        sequence: node keys crossed in order: rooms and connectors.
        length_m: length of the smoothed path [m].
        raw_length_m: length of the raw (unsmoothed) path [m].
        cost: search cost of the raw path [m x cost multiplier].
        timings: milliseconds: "query" (the global planner: its A* search; the hierarchical
            planner: the whole call, metres in to smoothed metric waypoints out), and for the
            hierarchical planner "precompute" (its constructor).
        nodes_expanded: nodes the query's searches expanded (global: A* cells; hierarchical:
            portal-graph nodes, descended field cells and in-room A* cells; look-ups count 0).
    """

    waypoints_m: np.ndarray
    cells: np.ndarray
    waypoint_cells: np.ndarray
    sequence: list[str]
    length_m: float
    raw_length_m: float
    cost: float
    timings: dict[str, float] = field(default_factory=dict)
    nodes_expanded: int = 0


def make_route(
    parsed: ParsedPlan,
    grids: PlanningGrids,
    cells: np.ndarray,
    sequence: list[str],
    cost_px: float,
    timings: dict[str, float],
    expanded: int,
    *,
    smooth: bool = True,
) -> Route:
    """A Route from a raw polyline of cells; smooths it on ``grids.clear`` unless told not to."""
    t0 = time.perf_counter()
    waypoints = shortcut(cells, grids.clear) if smooth else np.asarray(cells, np.int64)
    timings = {**timings, "smooth": (time.perf_counter() - t0) * 1e3}
    mpp = grids.metres_per_px
    return Route(
        waypoints_m=to_metres(parsed, waypoints),
        cells=np.asarray(cells, np.int64),
        waypoint_cells=waypoints,
        sequence=sequence,
        length_m=path_length(waypoints) * mpp,
        raw_length_m=path_length(cells) * mpp,
        cost=cost_px * mpp,
        timings=timings,
        nodes_expanded=int(expanded),
    )


def region_sequence(grids: PlanningGrids, cells: np.ndarray) -> list[str]:
    """Node keys of the regions a path of cells visits, in order, loops erased."""
    owners = grids.owner[cells[:, 0], cells[:, 1]]
    keep = np.r_[True, owners[1:] != owners[:-1]]
    return erase_loops([grids.keys.get(int(o), "?") for o in owners[keep] if o > 0])


def erase_loops(keys: list[str]) -> list[str]:
    """A region sequence without its loops: a path that grazes a room and comes back the way it
    went (living -> opening -> kitchen -> opening -> living) lists only what it goes through."""
    sequence: list[str] = []
    for key in keys:
        if key in sequence:
            del sequence[sequence.index(key) + 1 :]
        else:
            sequence.append(key)
    return sequence


def resolve(
    parsed: ParsedPlan, grids: PlanningGrids, graph: nx.Graph | None, point: Endpoint, what: str
) -> tuple[int, int]:
    """The grid cell of a start/goal given in metres or as a node key."""
    if isinstance(point, str):
        if graph is None:
            raise PlanningError(f"{what} {point!r} is a node key but no graph was given")
        return node_cell(grids, graph, point)
    return endpoint_cell(parsed, grids, point, what)


def global_search(
    parsed: ParsedPlan,
    grids: PlanningGrids,
    start: tuple[int, int],
    goal: tuple[int, int],
    *,
    smooth: bool = False,
) -> Route:
    """Global A* between two cells of ``grids.clear``; raises PlanningError when disconnected."""
    t0 = time.perf_counter()
    found = astar(grids.clear, start, goal, cost=grids.cost)
    query_ms = (time.perf_counter() - t0) * 1e3
    if not found.found:
        raise PlanningError(f"no route between cells {start} and {goal} for this robot")
    return make_route(
        parsed,
        grids,
        found.cells,
        region_sequence(grids, found.cells),
        found.cost,
        {"query": query_ms},
        found.expanded,
        smooth=smooth,
    )


def plan_global(
    parsed: ParsedPlan,
    profile: RobotProfile | str,
    start: Endpoint,
    goal: Endpoint,
    *,
    graph: nx.Graph | None = None,
    smooth: bool = False,
) -> Route:
    """Baseline: one A* over the whole inflated free grid (raw path unless ``smooth``).

    With ``graph`` the traversable instances follow ``traversable_subgraph`` (as the
    hierarchical planner's do); without it they follow the profile's classes.
    """
    profile = load_profile(profile)
    grids = build_grids(parsed, profile, graph)
    return global_search(
        parsed,
        grids,
        resolve(parsed, grids, graph, start, "start"),
        resolve(parsed, grids, graph, goal, "goal"),
        smooth=smooth,
    )
