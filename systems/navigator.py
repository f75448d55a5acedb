"""Follows a route that may change during the run: obstacles, closed doors, replan requests."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import BasicVector, Context, DiscreteValues, LeafSystem, State

from f2n_drake.core.errors import InputError
from f2n_drake.planning.replanning import Replanner
from f2n_drake.planning.route_guard import GuardState, RouteGuard
from f2n_drake.systems.waypoint_source import densify_route, waypoint_reached


@dataclass(frozen=True)
class RouteTrack:
    """A route as followed: waypoints (N, 2) [m] resampled by ``densify_route``, their corner
    flags, leg ends and reach tolerances [m], distance along the route [m], and the doors it
    passes as (connector key, index of the first waypoint in the doorway). ``detour``: a
    short drive aside, not a way to the goal; ``short_m``: how far its end lies from the goal
    [m] (a goal inside an obstacle's margin moves to a clear cell nearby)."""

    waypoints_m: np.ndarray
    corners: np.ndarray
    leg_ends: np.ndarray
    tolerances_m: np.ndarray
    along_m: np.ndarray
    doors: tuple[tuple[str, int], ...]
    detour: bool = False
    short_m: float = 0.0

    def __deepcopy__(self, memo: dict) -> RouteTrack:
        return self  # immutable: replaced, never modified (Drake clones abstract state)

    def ahead(self, index: int, length_m: float) -> np.ndarray:
        """The waypoints from ``index`` on, up to ``length_m`` [m] along the route."""
        end = int(np.searchsorted(self.along_m, self.along_m[index] + length_m, side="right"))
        return self.waypoints_m[index : max(end, index + 1)]

    def remaining_m(self, index: int) -> float:
        """Length [m] of the route from waypoint ``index`` on."""
        return float(self.along_m[-1] - self.along_m[index])

    def doors_from(self, index: int) -> tuple[str, ...]:
        """The doors not yet passed (their first waypoint at or after ``index``)."""
        return tuple(key for key, at in self.doors if at >= index)


class Navigator(LeafSystem):
    """The route's current waypoint and segment, kept clear by a :class:`RouteGuard`.

    Between scans it advances through the waypoints like
    :class:`~f2n_drake.systems.waypoint_source.WaypointSource` (every ``period_s``, same
    ``tolerance_m`` / ``corner_tolerance_m`` / ``spacing_m``). After each LiDAR scan
    (``scan_period_s``, at ``scan_offset_s``: when the estimate belongs to the scan's instant)
    the :class:`~f2n_drake.planning.route_guard.RouteGuard` updates the costmap, watches the
    route's doors, holds the robot before something close ahead, and replans from the estimate
    to the goal (the last waypoint) when the route is blocked, a door is closed or
    ``replan_request`` rises (which also forgets the costmap and the closed doors: they were
    found from the estimates the request says were wrong). A new route replaces the old one at
    once (abstract state); the progress index keeps counting waypoints across routes. A robot
    held too long steps aside (a detour that does not end the run) and tries again; a route
    whose end was moved off a blocked goal is not done at its end but replanned from there.
    With no route left the robot holds and ``navigation_status`` says so (:meth:`message` gives
    the sentence). ``on_route(waypoints_m, time_s)``, if given, is told of each new route or
    detour when it is taken, e.g. to draw it.

    .. pydrake_system::

        name: Navigator
        input_ports:
        - estimated_pose
        - scan
        - replan_request
        output_ports:
        - target
        - segment
        - progress
        - guidance
        - navigation_status

    ``estimated_pose`` [x, y, theta] (m, rad); ``scan`` ranges [m]; ``replan_request``
    1-vector, a replan each time its value rises (may be left unconnected); ``target`` [x, y]
    (m); ``segment`` [x0, y0, x1, y1] (m) as WaypointSource's; ``progress`` [waypoints passed
    over all routes, done (0/1)]; ``guidance`` [final, corner, hold] (0/1): the segment ends the
    route, ends at a corner, no forward motion; ``navigation_status`` [replans, no route left
    (0/1), closed doors found, hold (0/1)].
    """

    def __init__(
        self,
        waypoints_m: np.ndarray,
        replanner: Replanner,
        wall_segments_m: np.ndarray,
        *,
        num_beams: int = 360,
        tolerance_m: float = 0.1,
        corner_tolerance_m: float | None = None,
        spacing_m: float | None = None,
        period_s: float = 0.1,
        scan_period_s: float = 0.2,
        scan_offset_s: float = 0.0,
        guard_options: dict[str, Any] | None = None,
        on_route: Callable[[np.ndarray, float], None] | None = None,
    ) -> None:
        super().__init__()
        self.on_route = on_route
        route = np.asarray(waypoints_m, dtype=float).reshape(-1, 2)
        if len(route) == 0 or not np.all(np.isfinite(route)):
            raise InputError("Navigator needs at least one finite (x, y) waypoint")
        if not tolerance_m > 0:
            raise ValueError(f"tolerance_m must be positive, got {tolerance_m}")
        self.replanner = replanner
        self.guard = RouteGuard(replanner, wall_segments_m, **(guard_options or {}))
        self.goal_xy = route[-1].copy()
        self.tolerance_m, self.spacing_m = float(tolerance_m), spacing_m
        self.corner_tolerance_m = (
            self.tolerance_m if corner_tolerance_m is None else float(corner_tolerance_m)
        )
        first = self.track(route)
        self._pose_port = self.DeclareVectorInputPort("estimated_pose", 3)
        self._scan_port = self.DeclareVectorInputPort("scan", num_beams)
        self._request_port = self.DeclareVectorInputPort("replan_request", 1)
        self._track_index = self.DeclareAbstractState(AbstractValue.Make(first))
        self._guard_index = self.DeclareAbstractState(
            AbstractValue.Make(self.guard.initial_state())
        )
        self._progress_index = self.DeclareDiscreteState(np.zeros(2))
        self._book_index = self.DeclareDiscreteState(np.zeros(3))  # [index, offset, request seen]
        self._guidance_index = self.DeclareDiscreteState(self._guidance(first, 0, False))
        self._status_index = self.DeclareDiscreteState(np.zeros(4))
        self.DeclarePeriodicDiscreteUpdateEvent(period_s, 0.0, self._advance)
        self.DeclarePeriodicUnrestrictedUpdateEvent(scan_period_s, scan_offset_s, self._on_scan)
        ticket = {self.all_state_ticket()}
        self.DeclareVectorOutputPort("target", 2, self._calc_target, prerequisites_of_calc=ticket)
        self.DeclareVectorOutputPort("segment", 4, self._calc_segment, prerequisites_of_calc=ticket)
        self.DeclareStateOutputPort("progress", self._progress_index)
        self.DeclareStateOutputPort("guidance", self._guidance_index)
        self.DeclareStateOutputPort("navigation_status", self._status_index)

    def track(self, waypoints_m: np.ndarray, detour: bool = False) -> RouteTrack:
        """The :class:`RouteTrack` of a route (or of a ``detour``): resampled, with its doors."""
        points, corners, leg_ends = densify_route(waypoints_m, self.spacing_m)
        tolerances = np.where(corners, self.corner_tolerance_m, self.tolerance_m)
        along = np.r_[0.0, np.cumsum(np.hypot(*np.diff(points, axis=0).T))]
        doors = []
        for key, door in self.replanner.doorways.items():
            uv = door.local(points)
            inside = np.flatnonzero(
                (np.abs(uv[:, 0]) <= door.half_width_m)
                & (np.abs(uv[:, 1]) <= door.half_depth_m + 0.05)
            )
            if len(inside):
                doors.append((key, int(inside[0])))
        doors.sort(key=lambda d: d[1])
        short = 0.0 if detour else float(np.hypot(*(points[-1] - self.goal_xy)))
        return RouteTrack(points, corners, leg_ends, tolerances, along, tuple(doors), detour, short)

    def _advanced(self, track: RouteTrack, index: int, xy: np.ndarray) -> tuple[int, bool]:
        n = len(track.waypoints_m)
        while index < n and waypoint_reached(
            track.waypoints_m, track.leg_ends, track.tolerances_m, self.tolerance_m, index, xy
        ):
            index += 1
        ends_run = not track.detour and track.short_m <= self.tolerance_m
        return min(index, n - 1), index >= n and ends_run

    @staticmethod
    def _guidance(track: RouteTrack, index: int, hold: bool) -> np.ndarray:
        end = int(track.leg_ends[index])
        final = end >= len(track.waypoints_m) - 1
        return np.array([float(final), float(track.corners[end]), float(hold)])

    # -- state access ---------------------------------------------------------------------------
    def _track(self, context: Context) -> RouteTrack:
        return context.get_abstract_state(self._track_index).get_value()

    def guard_state(self, context: Context) -> GuardState:
        """The guard's state (costmap, closed doors, replans, message) in ``context``."""
        return context.get_abstract_state(self._guard_index).get_value()

    def message(self, context: Context) -> str:
        """Why the robot gave up ("" while it has a route)."""
        return self.guard_state(context).message

    def blocked(self, context: Context) -> str:
        """How obstacles block every route for now, else what holds the robot ("" when
        nothing does)."""
        guard = self.guard_state(context)
        return guard.blocked or guard.why

    def waypoints(self, context: Context) -> np.ndarray:
        """The waypoints [m] of the route followed in ``context``."""
        return self._track(context).waypoints_m

    # -- events ---------------------------------------------------------------------------------
    def _advance(self, context: Context, discrete_state: DiscreteValues) -> None:
        progress = context.get_discrete_state(self._progress_index).CopyToVector()
        if progress[1]:
            return
        book = context.get_discrete_state(self._book_index).CopyToVector()
        track = self._track(context)
        index, done = self._advanced(track, int(book[0]), self._pose_port.Eval(context)[:2])
        hold = bool(context.get_discrete_state(self._guidance_index).GetAtIndex(2))
        discrete_state.set_value(self._progress_index, [book[1] + index, float(done)])
        discrete_state.set_value(self._book_index, [index, book[1], book[2]])
        discrete_state.set_value(self._guidance_index, self._guidance(track, index, hold))

    def _on_scan(self, context: Context, state: State) -> None:
        if context.get_discrete_state(self._progress_index).GetAtIndex(1):
            return
        book = context.get_discrete_state(self._book_index).CopyToVector()
        index, offset, seen = int(book[0]), book[1], book[2]
        request = False
        if self._request_port.HasValue(context):
            value = float(self._request_port.Eval(context)[0])
            request, seen = value > seen, max(value, seen)
        track = self._track(context)
        pose = self._pose_port.Eval(context)
        if not np.isfinite(pose).all():  # not localized yet: nothing to guard or replan from
            return
        at_end = index == len(track.waypoints_m) - 1 and waypoint_reached(
            track.waypoints_m, track.leg_ends, track.tolerances_m, self.tolerance_m, index, pose[:2]
        )
        guard, decision = self.guard.step(
            self.guard_state(context),
            time_s=context.get_time(),
            pose=pose,
            ranges=self._scan_port.Eval(context),
            ahead_xy=track.ahead(index, self.guard.lookahead_m),
            doors_ahead=track.doors_from(index),
            goal_xy=self.goal_xy,
            request=request,
            remaining_m=0.0 if track.detour else track.remaining_m(index),
            short_of_goal=at_end and not track.detour and track.short_m > self.tolerance_m,
        )
        done = False
        if decision.route is not None or decision.detour_xy is not None:
            if decision.route is not None:
                track = self.track(decision.route.waypoints_m)
            else:
                track = self.track(decision.detour_xy, detour=True)
            offset += index
            index, done = self._advanced(track, 0, pose[:2])
            state.get_mutable_abstract_state(self._track_index).set_value(track)
            if self.on_route is not None:
                self.on_route(track.waypoints_m, context.get_time())
        state.get_mutable_abstract_state(self._guard_index).set_value(guard)
        hold = decision.hold or decision.stop
        discrete = state.get_mutable_discrete_state()
        discrete.set_value(self._progress_index, [offset + index, float(done)])
        discrete.set_value(self._book_index, [index, offset, seen])
        discrete.set_value(self._guidance_index, self._guidance(track, index, hold))
        discrete.set_value(
            self._status_index,
            [guard.replans, float(decision.stop), len(guard.closed), float(hold)],
        )

    # -- outputs --------------------------------------------------------------------------------
    def _index(self, context: Context) -> int:
        return int(context.get_discrete_state(self._book_index).GetAtIndex(0))

    def _calc_target(self, context: Context, output: BasicVector) -> None:
        output.SetFromVector(self._track(context).waypoints_m[self._index(context)])

    def _calc_segment(self, context: Context, output: BasicVector) -> None:
        track, i = self._track(context), self._index(context)
        end = track.waypoints_m[track.leg_ends[i]]
        output.SetFromVector(np.concatenate([track.waypoints_m[max(i - 1, 0)], end]))


__all__ = ["Navigator", "RouteTrack"]
