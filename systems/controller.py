"""Pure-pursuit path following for a unicycle (velocity commands)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from pydrake.systems.framework import BasicVector, Context, LeafSystem

ARRIVED_M = 0.03
"""Within this of the end of the final segment [m] the command is zero."""


def pure_pursuit_command(
    pose: np.ndarray,
    segment: np.ndarray,
    final: bool,
    *,
    lookahead_m: float,
    v_max: float,
    omega_max: float,
    corner: bool = False,
) -> np.ndarray:
    """[v (m/s), omega (rad/s)] toward a look-ahead point on ``segment`` [x0, y0, x1, y1].

    The look-ahead point lies ``lookahead_m`` past the robot's projection on the segment (the
    segment end when nearer). With heading error alpha to that point: omega = k alpha,
    k = 2 v_max / lookahead (pure pursuit's gain at full speed), v = v_max cos(alpha)^2 for
    |alpha| < 90 deg and 0 beyond (turn on the spot); toward a ``corner`` or the end of the
    ``final`` segment v is also capped at 0.05 m/s + 1.0/s x (distance to it), so the robot
    reaches the corner before it turns, and the goal briskly (odometry drifts per tick, so a
    slow approach costs accuracy); within ``ARRIVED_M`` of that end the command is zero.
    """
    p, a, b = np.asarray(pose[:2], float), np.asarray(segment[:2], float), np.asarray(segment[2:])
    ab = b - a
    length = float(np.hypot(*ab))
    if length > 1e-9:
        s = float(np.clip((p - a) @ ab / length, 0.0, length))
        aim = a + ab / length * min(s + lookahead_m, length)
        if np.hypot(*(b - p)) < lookahead_m:
            aim = b
    else:
        aim = b
    to_aim = aim - p
    if final and float(np.hypot(*(b - p))) < ARRIVED_M:
        return np.zeros(2)  # there: no turning on the spot toward a point underneath
    alpha = float(np.arctan2(to_aim[1], to_aim[0]) - pose[2])
    alpha = (alpha + np.pi) % (2 * np.pi) - np.pi
    v = v_max * max(np.cos(alpha), 0.0) ** 2
    if final or corner:
        v = min(v, 0.05 + 1.0 * float(np.hypot(*(b - p))))
    omega = float(np.clip(2.0 * v_max / lookahead_m * alpha, -omega_max, omega_max))
    return np.array([v, omega])


class PurePursuitController(LeafSystem):
    """Velocity commands that follow the current route segment; zero once the route is done.

    .. pydrake_system::

        name: PurePursuitController
        input_ports:
        - estimated_pose
        - segment
        - progress
        - guidance (guided only)
        output_ports:
        - command

    ``estimated_pose`` [x, y, theta] (m, rad); ``segment`` [x0, y0, x1, y1] (m) from the
    previous waypoint to the target or to the end of its leg; ``progress`` [index, done] (the
    last segment slows to a stop; done gives zero); ``command`` [v (m/s), omega (rad/s)]. See
    :func:`pure_pursuit_command`. Set ``num_waypoints`` so the final segment is known,
    ``corners`` (the waypoint indices where the route turns) to slow down before them, and
    ``leg_ends`` (per waypoint index, the waypoint that ends the segment, as in
    :func:`f2n_drake.systems.waypoint_source.densify_route`; default: the target itself) when
    segments run past the target. With ``guided`` the route may change during the run: an
    input ``guidance`` [final, corner, hold] (0/1, from
    :class:`~f2n_drake.systems.navigator.Navigator`) says whether the segment ends the route or
    at a corner, and ``hold`` stops forward motion (turning stays allowed); ``num_waypoints``,
    ``corners`` and ``leg_ends`` are then unused.
    """

    def __init__(
        self,
        num_waypoints: int,
        lookahead_m: float = 0.25,
        v_max: float = 0.22,
        omega_max: float = 2.84,
        corners: Sequence[int] = (),
        leg_ends: Sequence[int] | None = None,
        *,
        guided: bool = False,
    ) -> None:
        super().__init__()
        if not (lookahead_m > 0 and v_max > 0 and omega_max > 0):
            raise ValueError("lookahead_m, v_max and omega_max must be positive")
        self.num_waypoints = int(num_waypoints)
        self.corners = frozenset(int(i) for i in corners)
        self.leg_ends = np.arange(num_waypoints) if leg_ends is None else np.asarray(leg_ends)
        if len(self.leg_ends) != self.num_waypoints:
            raise ValueError("leg_ends needs one entry per waypoint")
        self.lookahead_m, self.v_max, self.omega_max = lookahead_m, v_max, omega_max
        self._pose_port = self.DeclareVectorInputPort("estimated_pose", 3)
        self._segment_port = self.DeclareVectorInputPort("segment", 4)
        self._progress_port = self.DeclareVectorInputPort("progress", 2)
        self.guided = bool(guided)
        if self.guided:
            self._guidance_port = self.DeclareVectorInputPort("guidance", 3)
        self._command_port = self.DeclareVectorOutputPort(
            "command", 2, self._calc_command, prerequisites_of_calc={self.all_input_ports_ticket()}
        )

    def _calc_command(self, context: Context, output: BasicVector) -> None:
        index, done = self._progress_port.Eval(context)
        if done:
            output.SetFromVector([0.0, 0.0])
            return
        if self.guided:
            final, corner, hold = (bool(g) for g in self._guidance_port.Eval(context))
        else:
            end = int(self.leg_ends[min(int(index), self.num_waypoints - 1)])
            final, corner, hold = end >= self.num_waypoints - 1, end in self.corners, False
        command = pure_pursuit_command(
            self._pose_port.Eval(context),
            self._segment_port.Eval(context),
            final=final,
            lookahead_m=self.lookahead_m,
            v_max=self.v_max,
            omega_max=self.omega_max,
            corner=corner,
        )
        if hold:  # something close ahead: turn if need be, no forward motion
            command[0] = 0.0
        output.SetFromVector(command)
