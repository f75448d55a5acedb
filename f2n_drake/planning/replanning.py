"""Replanning on the known plan when the building differs from it: closed connectors, obstacles.

A :class:`Replanner` keeps one :class:`~f2n_drake.planning.hierarchical.HierarchicalPlanner`
(the plan's raster, connectivity graph and robot). :meth:`Replanner.replan` closes connectors
by cutting their portals from the portal graph (:meth:`HierarchicalPlanner.closing`, cached per
set of closed connectors, so a query stays a few look-ups) and, when obstacle points are given,
searches the inflated free grid with those points blocked (each point inflated by the robot's
radius plus its clearance margin plus ``obstacle_margin_m``) and smooths the path on the same
grid. A start or goal that the blocking leaves inside an obstacle's or wall's margin moves to
the nearest clear cell within ``snap_m``.

Two failures are told apart: :class:`NoRouteLeft` when the closed connectors alone leave no way
(the robot should stop and say so), :class:`RouteBlocked` when only the obstacles do (people may
walk away: wait and try again).
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Iterable
from dataclasses import dataclass

import cv2
import networkx as nx
import numpy as np

from f2n_drake.core.classes import OPENING
from f2n_drake.core.errors import PlanningError
from f2n_drake.core.parsed import ParsedPlan
from f2n_drake.mapping.occupancy import to_cell, to_metres
from f2n_drake.mapping.robots import RobotProfile
from f2n_drake.planning.astar import astar
from f2n_drake.planning.hierarchical import HierarchicalPlanner
from f2n_drake.planning.route import Route, make_route, region_sequence
from f2n_drake.planning.smoothing import polyline_clear


class NoRouteLeft(PlanningError):
    """The closed connectors leave no route to the goal."""


class RouteBlocked(PlanningError):
    """Obstacles block every route to the goal; ``route`` is the one without them (closed
    connectors still closed), or None when not known."""

    def __init__(self, message: str, route: Route | None = None) -> None:
        super().__init__(message)
        self.route = route


@dataclass(frozen=True)
class Doorway:
    """A connector of the plan as a rectangle [m]: centre, unit ``axis`` along its opening,
    half its width (along the axis) and half its depth (across, the wall's thickness)."""

    key: str
    centre_m: np.ndarray
    axis: np.ndarray
    half_width_m: float
    half_depth_m: float

    def local(self, points_m: np.ndarray) -> np.ndarray:
        """(N, 2) [along, across] coordinates [m] of world points relative to the doorway."""
        d = np.asarray(points_m, float).reshape(-1, 2) - self.centre_m
        normal = np.array([-self.axis[1], self.axis[0]])
        return np.column_stack([d @ self.axis, d @ normal])

    def blocked_by(
        self,
        points_m: np.ndarray,
        *,
        band: float = 0.6,
        bin_m: float = 0.05,
        min_coverage: float = 0.75,
        max_spread_m: float = 0.02,
        reach_m: float = 0.1,
    ) -> bool:
        """True if ``points_m`` (LiDAR returns the plan does not explain) close the opening.

        Looks at the middle ``band`` of the opening's width, within ``reach_m`` of its depth:
        closed when returns fall in at least ``min_coverage`` of its ``bin_m`` bins and lie on a
        flat face along the opening (standard deviation across it at most ``max_spread_m``), as
        a closed door does (measured: 0.4-1 cm); a person in the doorway is round (2.5-4 cm).
        """
        uv = self.local(points_m)
        half = band * self.half_width_m
        inside = (np.abs(uv[:, 0]) <= half) & (np.abs(uv[:, 1]) <= self.half_depth_m + reach_m)
        if inside.sum() < 3:
            return False
        n_bins = max(3, math.ceil(2 * half / bin_m))
        bins = np.clip(((uv[inside, 0] + half) / (2 * half) * n_bins).astype(int), 0, n_bins - 1)
        coverage = len(np.unique(bins)) / n_bins
        return coverage >= min_coverage and float(np.std(uv[inside, 1])) <= max_spread_m


def doorways(planner: HierarchicalPlanner) -> dict[str, Doorway]:
    """The connectors the planner's robot may pass (openings left out: they cannot close), as
    :class:`Doorway` rectangles fitted to their instance's pixels."""
    parsed, graph = planner.parsed, planner.graph
    out = {}
    for iid, key in planner.grids.keys.items():
        data = graph.nodes[key] if key in graph else {}
        if data.get("kind") != "connector" or data.get("class_name") == OPENING:
            continue
        cells = np.argwhere(parsed.instance_ids == iid)
        if len(cells) < 3:
            continue
        points = to_metres(parsed, cells)
        centre = points.mean(axis=0)
        _, vectors = np.linalg.eigh(np.cov((points - centre).T))
        axis = vectors[:, -1]  # the longer side: along the opening
        door = Doorway(key, centre, axis, 0.0, 0.0)
        uv = door.local(points)
        half_px = 0.5 * parsed.grid.metres_per_px
        out[key] = dataclasses.replace(
            door,
            half_width_m=float(np.abs(uv[:, 0]).max()) + half_px,
            half_depth_m=float(np.abs(uv[:, 1]).max()) + half_px,
        )
    return out


class Replanner:
    """Routes on a known plan around what the robot found: closed connectors and obstacles.

    Args:
        planner: the plan's hierarchical planner (its raster, graph and robot).
        obstacle_margin_m: added to the robot radius and clearance margin around each obstacle
            point [m] (a point stands for a costmap cell).
        snap_m: farthest a blocked start or goal is moved to a clear cell [m].

    Attributes: ``doorways`` (connector key -> :class:`Doorway`), ``planner``.
    """

    def __init__(
        self, planner: HierarchicalPlanner, *, obstacle_margin_m: float = 0.03, snap_m: float = 0.3
    ) -> None:
        self.planner = planner
        self.parsed = planner.parsed
        self.grids = planner.grids
        self.obstacle_margin_m = float(obstacle_margin_m)
        self.snap_m = float(snap_m)
        self.doorways = doorways(planner)
        self._closed: dict[frozenset[str], HierarchicalPlanner] = {frozenset(): planner}

    @classmethod
    def from_plan(
        cls, parsed: ParsedPlan, graph: nx.Graph, profile: RobotProfile | str, **options
    ) -> Replanner:
        """A Replanner from a plan's raster, connectivity graph and robot (the precompute)."""
        return cls(HierarchicalPlanner(parsed, graph, profile), **options)

    @property
    def robot_radius_m(self) -> float:
        """The robot's footprint radius [m]."""
        return self.planner.profile.radius_m

    def place_name(self, xy_m: np.ndarray) -> str:
        """The graph key of the room or connector at ``xy_m`` [m], or its coordinates."""
        try:
            r, c = to_cell(self.parsed, (float(xy_m[0]), float(xy_m[1])))
        except PlanningError:
            r = c = -1
        key = self.grids.keys.get(int(self.grids.owner[r, c])) if r >= 0 else None
        return key or f"({float(xy_m[0]):.2f}, {float(xy_m[1]):.2f}) m"

    def closed_planner(self, closed: Iterable[str]) -> HierarchicalPlanner:
        """The planner with ``closed`` connectors closed (cached per set)."""
        key = frozenset(closed)
        if key not in self._closed:
            self._closed[key] = self.planner.closing(key)
        return self._closed[key]

    def obstacle_mask(self, obstacles_xy: np.ndarray) -> np.ndarray:
        """(H, W) bool: cells within robot radius + clearance + ``obstacle_margin_m`` of a
        point of ``obstacles_xy`` ((N, 2) [m])."""
        shape = self.grids.clear.shape
        mask = np.zeros(shape, bool)
        points = np.asarray(obstacles_xy, float).reshape(-1, 2)
        if not len(points):
            return mask
        col, row = np.rint(self.parsed.grid.to_px(points)).astype(int).T
        radius = self.grids.radius_px + self.obstacle_margin_m / self.grids.metres_per_px
        pad = math.ceil(radius) + 1
        inside = (row >= -pad) & (row < shape[0] + pad) & (col >= -pad) & (col < shape[1] + pad)
        if not inside.any():
            return mask
        row, col = row[inside], col[inside]
        r0, c0 = max(row.min() - pad, 0), max(col.min() - pad, 0)
        r1, c1 = min(row.max() + pad + 1, shape[0]), min(col.max() + pad + 1, shape[1])
        if r0 >= r1 or c0 >= c1:
            return mask
        window = np.ones((r1 - r0 + 2 * pad, c1 - c0 + 2 * pad), np.uint8)
        window[row - r0 + pad, col - c0 + pad] = 0
        distance = cv2.distanceTransform(window, cv2.DIST_L2, cv2.DIST_MASK_PRECISE)
        mask[r0:r1, c0:c1] = distance[pad:-pad, pad:-pad] <= radius
        return mask

    def snap(self, clear: np.ndarray, xy_m: np.ndarray, what: str) -> tuple[int, int]:
        """The clear cell nearest ``xy_m`` within ``snap_m``; raises RouteBlocked if none."""
        r, c = to_cell(self.parsed, (float(xy_m[0]), float(xy_m[1])), what)
        if clear[r, c]:
            return r, c
        k = math.ceil(self.snap_m / self.grids.metres_per_px)
        r0, c0 = max(r - k, 0), max(c - k, 0)
        rows, cols = np.nonzero(clear[r0 : r + k + 1, c0 : c + k + 1])
        d2 = (rows + r0 - r) ** 2 + (cols + c0 - c) ** 2
        if not len(d2) or d2.min() > k * k:
            raise RouteBlocked(f"the {what} has no clear cell within {self.snap_m:.2f} m")
        i = int(np.argmin(d2))
        return int(rows[i] + r0), int(cols[i] + c0)

    def replan(
        self,
        start_xy: np.ndarray,
        goal_xy: np.ndarray,
        *,
        closed_connectors: Iterable[str] = (),
        obstacles_xy: np.ndarray | None = None,
    ) -> Route:
        """A route from ``start_xy`` to ``goal_xy`` [m] avoiding closed connectors (graph keys)
        and obstacle points ((N, 2) [m]).

        Raises:
            NoRouteLeft: the closed connectors leave no route (message names them and the goal).
            RouteBlocked: only the obstacles block every route (``route``: the way without
                them).
            PlanningError: start or goal outside the plan, or no route even with all open.
        """
        closed = frozenset(closed_connectors)
        planner = self.closed_planner(closed)
        clear = self._clear_of(closed)
        obstacles = np.zeros((0, 2)) if obstacles_xy is None else np.asarray(obstacles_xy, float)
        if len(obstacles):
            passable = clear & ~self.obstacle_mask(obstacles)
            try:
                return self._grid_route(passable, start_xy, goal_xy)
            except RouteBlocked as exc:  # NoRouteLeft from the open route, else blocked
                route = self._open_route(planner, clear, start_xy, goal_xy, closed)
                raise RouteBlocked(str(exc), route) from exc
        return self._open_route(planner, clear, start_xy, goal_xy, closed)

    def _clear_of(self, closed: frozenset[str]) -> np.ndarray:
        ids = [iid for iid, key in self.grids.keys.items() if key in closed]
        return self.grids.clear & ~np.isin(self.grids.owner, ids) if ids else self.grids.clear

    def _no_route(self, goal_xy: np.ndarray, closed: frozenset[str]) -> NoRouteLeft:
        doors = ", ".join(sorted(closed))
        verb = "is" if len(closed) == 1 else "are"
        return NoRouteLeft(f"no route left to {self.place_name(goal_xy)}: {doors} {verb} closed")

    def _open_route(self, planner, clear, start_xy, goal_xy, closed) -> Route:
        """The hierarchical route with only ``closed`` connectors shut (validated on
        ``clear``, else the grid route)."""
        try:
            s = self.snap(clear, start_xy, "start")
            g = self.snap(clear, goal_xy, "goal")
        except RouteBlocked as exc:
            raise PlanningError(str(exc)) from exc
        start_m, goal_m = to_metres(self.parsed, np.array([s, g]))
        try:
            route = planner.plan(tuple(start_m), tuple(goal_m))
        except PlanningError as exc:
            if closed:
                raise self._no_route(goal_xy, closed) from exc
            raise
        if polyline_clear(route.waypoint_cells, clear):
            return route
        try:
            return self._grid_route(clear, start_xy, goal_xy)
        except RouteBlocked as exc:
            if closed:
                raise self._no_route(goal_xy, closed) from exc
            raise PlanningError(str(exc)) from exc

    def _grid_route(self, passable: np.ndarray, start_xy, goal_xy) -> Route:
        """A* on ``passable`` (raises RouteBlocked when disconnected), smoothed on it."""
        t0 = time.perf_counter()
        s = self.snap(passable, start_xy, "start")
        g = self.snap(passable, goal_xy, "goal")
        found = astar(passable, s, g, cost=self.grids.cost)
        if not found.found:
            raise RouteBlocked(f"obstacles block every route to {self.place_name(goal_xy)}")
        grids = dataclasses.replace(self.grids, clear=passable)
        return make_route(
            self.parsed,
            grids,
            found.cells,
            region_sequence(grids, found.cells),
            found.cost,
            {"query": (time.perf_counter() - t0) * 1e3},
            found.expanded,
        )


__all__ = ["Doorway", "NoRouteLeft", "Replanner", "RouteBlocked", "doorways"]
