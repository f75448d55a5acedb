"""Hands out the waypoints of a route one at a time as the robot reaches them."""

from __future__ import annotations

import numpy as np
from pydrake.systems.framework import BasicVector, Context, DiscreteValues, LeafSystem

from f2n_drake.core.errors import InputError


def densify_route(
    waypoints_m: np.ndarray, spacing_m: float | None, corner_deg: float = 5.0
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The route resampled to at most ``spacing_m`` [m] between waypoints, its corners and legs.

    Every original vertex is kept and each leg is cut into equal pieces no longer than
    ``spacing_m`` (``None`` keeps the route as it is), so the geometry is unchanged. Returns
    ``(waypoints (N, 2) [m], corner (N,) bool, leg_end (N,) int)``: a corner is an original
    vertex where the route turns by more than ``corner_deg`` [deg], or the last waypoint;
    ``leg_end[i]`` is the index of the original vertex that ends the straight leg waypoint ``i``
    lies on (``i`` itself for a vertex).
    """
    route = np.asarray(waypoints_m, dtype=float).reshape(-1, 2)
    if len(route) > 1:  # drop repeated points
        route = route[np.r_[True, np.hypot(*np.diff(route, axis=0).T) > 1e-9]]
    is_vertex_corner = np.zeros(len(route), bool)
    is_vertex_corner[-1] = True
    for i in range(1, len(route) - 1):
        a, b = route[i] - route[i - 1], route[i + 1] - route[i]
        turn = np.arctan2(a[0] * b[1] - a[1] * b[0], a @ b)
        is_vertex_corner[i] = abs(turn) > np.radians(corner_deg)
    if spacing_m is None or len(route) == 1:
        return route, is_vertex_corner, np.arange(len(route))
    if not spacing_m > 0:
        raise ValueError(f"spacing_m must be positive, got {spacing_m}")
    points, corners, leg_ends = [route[:1]], [is_vertex_corner[:1]], [np.zeros(1, int)]
    for i in range(1, len(route)):
        pieces = max(1, int(np.ceil(np.hypot(*(route[i] - route[i - 1])) / spacing_m - 1e-9)))
        t = np.arange(1, pieces + 1)[:, None] / pieces
        points.append(route[i - 1] + t * (route[i] - route[i - 1]))
        flags = np.zeros(pieces, bool)
        flags[-1] = is_vertex_corner[i]
        corners.append(flags)
        leg_ends.append(np.full(pieces, sum(map(len, leg_ends)) + pieces - 1))
    return np.vstack(points), np.concatenate(corners), np.concatenate(leg_ends)


def waypoint_reached(
    waypoints_m: np.ndarray,
    leg_ends: np.ndarray,
    tolerances_m: np.ndarray,
    tolerance_m: float,
    index: int,
    xy: np.ndarray,
) -> bool:
    """Whether the estimate at ``xy`` [m] has reached or passed waypoint ``index`` (the rule of
    :class:`WaypointSource`: within ``tolerances_m[index]``, or past it along the way in: within
    ``2 tolerance_m`` of a vertex, or beside the leg for a waypoint inside one)."""
    target = waypoints_m[index]
    distance = float(np.hypot(*(target - xy)))
    if distance <= tolerances_m[index]:
        return True
    if index == 0:
        return False
    leg = target - waypoints_m[index - 1]
    leg = leg / max(float(np.hypot(*leg)), 1e-12)
    offset = xy - target
    if offset @ leg <= 0.0:  # not past the target along the way in
        return False
    if leg_ends[index] == index:  # a vertex: only when passing close by
        return distance <= 2.0 * tolerance_m
    # Inside a leg: anywhere beside the leg beyond it (e.g. after a correction jumped ahead).
    return abs(leg[0] * offset[1] - leg[1] * offset[0]) <= 2.0 * tolerance_m


class WaypointSource(LeafSystem):
    """The current target waypoint, advanced when the estimated pose reaches or passes it.

    The route is first resampled by :func:`densify_route` (``spacing_m``), so the waypoint
    index measures distance travelled (the paper-mode corrector counts it). Every ``period_s``
    (default 0.1 s) the target advances while the estimate is within ``tolerance_m`` of it, or
    has passed it: beyond it along the way in, within ``2 tolerance_m`` of a route vertex or,
    for a waypoint inside a leg, within ``2 tolerance_m`` beside the leg at any distance ahead
    (so a correction that moves the estimate forward does not leave the target behind);
    at a corner (see :func:`densify_route`) the tolerance is ``corner_tolerance_m`` instead, so
    the robot does not cut corners that the planner laid next to walls. After the last waypoint
    ``done`` is 1 and the target stays there.

    .. pydrake_system::

        name: WaypointSource
        input_ports:
        - estimated_pose
        output_ports:
        - target
        - segment
        - progress

    ``estimated_pose`` [x, y, theta] (m, rad); ``target`` [x, y] (m); ``segment``
    [x0, y0, x1, y1] (m) from the previous waypoint (the target itself for the first) to the end
    of the straight leg the target lies on (``leg_ends``; the target itself when the route is not
    resampled), so a path-following controller can look ahead past closely spaced waypoints;
    ``progress`` [index of the target, done (0/1)].
    """

    def __init__(
        self,
        waypoints_m: np.ndarray,
        tolerance_m: float = 0.1,
        period_s: float = 0.1,
        *,
        spacing_m: float | None = None,
        corner_tolerance_m: float | None = None,
    ) -> None:
        super().__init__()
        route = np.asarray(waypoints_m, dtype=float).reshape(-1, 2)
        if len(route) == 0 or not np.all(np.isfinite(route)):
            raise InputError("WaypointSource needs at least one finite (x, y) waypoint")
        if not tolerance_m > 0:
            raise ValueError(f"tolerance_m must be positive, got {tolerance_m}")
        self.waypoints_m, self.corners, self.leg_ends = densify_route(route, spacing_m)
        self.tolerance_m = float(tolerance_m)
        corner_tol = self.tolerance_m if corner_tolerance_m is None else float(corner_tolerance_m)
        self._tolerances = np.where(self.corners, corner_tol, self.tolerance_m)
        self._pose_port = self.DeclareVectorInputPort("estimated_pose", 3)
        self._progress_index = self.DeclareDiscreteState(np.array([0.0, 0.0]))
        self.DeclarePeriodicDiscreteUpdateEvent(period_s, 0.0, self._update)
        ticket = {self.xd_ticket()}
        self._target_port = self.DeclareVectorOutputPort(
            "target", 2, self._calc_target, prerequisites_of_calc=ticket
        )
        self._segment_port = self.DeclareVectorOutputPort(
            "segment", 4, self._calc_segment, prerequisites_of_calc=ticket
        )
        self._progress_port = self.DeclareStateOutputPort("progress", self._progress_index)

    def _index(self, context: Context) -> int:
        return int(context.get_discrete_state(self._progress_index).GetAtIndex(0))

    def _reached(self, index: int, xy: np.ndarray) -> bool:
        return waypoint_reached(
            self.waypoints_m, self.leg_ends, self._tolerances, self.tolerance_m, index, xy
        )

    def _update(self, context: Context, discrete_state: DiscreteValues) -> None:
        index, done = context.get_discrete_state(self._progress_index).CopyToVector()
        if done:
            return
        xy = self._pose_port.Eval(context)[:2]
        index = int(index)
        # Skip every consecutive waypoint already reached (e.g. the start point).
        while index < len(self.waypoints_m) and self._reached(index, xy):
            index += 1
        done = index >= len(self.waypoints_m)
        index = min(index, len(self.waypoints_m) - 1)
        discrete_state.set_value(self._progress_index, [float(index), float(done)])

    def _calc_target(self, context: Context, output: BasicVector) -> None:
        output.SetFromVector(self.waypoints_m[self._index(context)])

    def _calc_segment(self, context: Context, output: BasicVector) -> None:
        i = self._index(context)
        end = self.waypoints_m[self.leg_ends[i]]
        output.SetFromVector(np.concatenate([self.waypoints_m[max(i - 1, 0)], end]))
