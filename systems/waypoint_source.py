"""Hands out the waypoints of a route one at a time as the robot reaches them."""

from __future__ import annotations

import numpy as np
from pydrake.systems.framework import BasicVector, Context, DiscreteValues, LeafSystem

from f2n_drake.errors import InputError


class WaypointSource(LeafSystem):
    """The current target waypoint, advanced when the estimated pose comes within tolerance.

    Checked every ``period_s`` (default 0.1 s). After the last waypoint is reached ``done`` is
    1 and the target stays at the last waypoint.

    .. pydrake_system::

        name: WaypointSource
        input_ports:
        - estimated_pose
        output_ports:
        - target
        - segment
        - progress

    ``estimated_pose`` [x, y, theta] (m, rad); ``target`` [x, y] (m); ``segment``
    [x0, y0, x1, y1] (m) from the previous waypoint (the target itself for the first) to the
    target, for path-following controllers; ``progress`` [index of the target, done (0/1)].
    """

    def __init__(
        self, waypoints_m: np.ndarray, tolerance_m: float = 0.1, period_s: float = 0.1
    ) -> None:
        super().__init__()
        self.waypoints_m = np.asarray(waypoints_m, dtype=float).reshape(-1, 2)
        if len(self.waypoints_m) == 0 or not np.all(np.isfinite(self.waypoints_m)):
            raise InputError("WaypointSource needs at least one finite (x, y) waypoint")
        if not tolerance_m > 0:
            raise ValueError(f"tolerance_m must be positive, got {tolerance_m}")
        self.tolerance_m = float(tolerance_m)
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

    def _update(self, context: Context, discrete_state: DiscreteValues) -> None:
        index, done = context.get_discrete_state(self._progress_index).CopyToVector()
        if done:
            return
        xy = self._pose_port.Eval(context)[:2]
        index = int(index)
        # Skip every consecutive waypoint already within tolerance (e.g. the start point).
        while index < len(self.waypoints_m) and (
            np.hypot(*(self.waypoints_m[index] - xy)) <= self.tolerance_m
        ):
            index += 1
        done = index >= len(self.waypoints_m)
        index = min(index, len(self.waypoints_m) - 1)
        discrete_state.set_value(self._progress_index, [float(index), float(done)])

    def _calc_target(self, context: Context, output: BasicVector) -> None:
        output.SetFromVector(self.waypoints_m[self._index(context)])

    def _calc_segment(self, context: Context, output: BasicVector) -> None:
        i = self._index(context)
        output.SetFromVector(np.concatenate([self.waypoints_m[max(i - 1, 0)], self.waypoints_m[i]]))
