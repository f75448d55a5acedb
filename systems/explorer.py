"""Careful motion while the robot does not know where it is: slow, from the scan alone.

The map cannot be used (the pose is unknown), so :class:`CarefulExplorer` steers by the latest
LiDAR scan: it picks the direction with the most room (:func:`free_distance`: how far the
centre can travel keeping ``stop_distance_m`` from every return), turns on the spot to face it,
and drives at no more than ``speed_mps``, slowing as the room ahead shrinks and stopping before
any return comes nearer than ``stop_distance_m``. Every ``leg_m`` (or when the way ahead closes)
it chooses again, preferring small turns and staying within ``leash_m`` of where it started (by
odometry, which is good over a few metres), so the route that starts there still applies.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydrake.systems.framework import Context, DiscreteValues, LeafSystem

from f2n_drake.localization.scans import scan_to_points_robot


@dataclass(frozen=True)
class CarefulMotion:
    """Tuning of :class:`CarefulExplorer` (SI units).

    Attributes:
        speed_mps: top speed [m/s].
        turn_rate_radps: top turn rate [rad/s].
        stop_distance_m: least distance kept between the robot's centre and any return [m].
        leg_m: distance driven before a new direction is chosen [m].
        leash_m: farthest the robot goes from its start (by odometry) [m].
        min_room_m: a direction with less room than this is not taken [m].
        aligned_rad: heading error below which the robot drives (above it, it turns) [rad].
        directions: candidate directions, evenly spaced.
        max_range_m, min_range_m: the LiDAR's range [m]; beams with no return count as open to
            ``max_range_m``.
    """

    speed_mps: float = 0.1
    turn_rate_radps: float = 0.6
    stop_distance_m: float = 0.25
    leg_m: float = 0.8
    leash_m: float = 1.0
    min_room_m: float = 0.15
    aligned_rad: float = 0.2
    directions: int = 72
    max_range_m: float = 3.5
    min_range_m: float = 0.12


def free_distance(points: np.ndarray, angles: np.ndarray, clearance_m: float, limit_m: float):
    """How far [m] the robot's centre can travel from the origin along each direction
    ``angles`` (D,) [rad], keeping ``clearance_m`` from every point ``points`` (M, 2) ahead of it
    [m] (at most ``limit_m``; 0 where a point already blocks the start)."""
    u = np.stack([np.cos(angles), np.sin(angles)], axis=1)  # (D, 2)
    along = points @ u.T  # (M, D)
    lateral = np.abs(points[:, :1] * u[:, 1] - points[:, 1:] * u[:, 0])
    blocking = (along > 0.0) & (lateral < clearance_m)
    reach = along - np.sqrt(np.maximum(clearance_m**2 - lateral**2, 0.0))
    reach = np.where(blocking, reach, limit_m)
    return np.clip(reach.min(axis=0, initial=limit_m), 0.0, limit_m)


MEMORY_SIZE = 6
"""[goal heading (odometry frame), has goal, leg start x, leg start y, anchor x, anchor y]."""


def initial_memory(pose: np.ndarray) -> np.ndarray:
    """The explorer's memory before its first step, anchored at ``pose`` (odometry frame)."""
    return np.array([0.0, 0.0, pose[0], pose[1], pose[0], pose[1]])


def careful_command(
    scan: np.ndarray, pose: np.ndarray, memory: np.ndarray, motion: CarefulMotion
) -> tuple[np.ndarray, np.ndarray]:
    """One step of careful motion: ``([v, omega], memory)`` from the ``scan`` (ranges [m]) and
    the odometry ``pose`` [x, y, theta] (any frame, consistent over time)."""
    goal, has_goal, leg_x, leg_y, anchor_x, anchor_y = memory
    points = scan_to_points_robot(scan, motion.min_range_m, motion.max_range_m)
    if len(points) == 0:  # no scan yet, or nothing seen: nothing to steer by
        return np.zeros(2), np.asarray(memory, dtype=float)
    limit = motion.max_range_m
    angles = 2.0 * np.pi * np.arange(motion.directions) / motion.directions
    room = free_distance(points, angles, motion.stop_distance_m, limit)
    ahead = float(free_distance(points, np.zeros(1), motion.stop_distance_m, limit)[0])
    travelled = float(np.hypot(pose[0] - leg_x, pose[1] - leg_y))
    goal_error = (goal - pose[2] + np.pi) % (2.0 * np.pi) - np.pi
    goal_room = free_distance(points, np.array([goal_error]), motion.stop_distance_m, limit)[0]
    if not has_goal or travelled >= motion.leg_m or goal_room < motion.min_room_m:
        world = pose[2] + angles
        step = np.minimum(room, motion.leg_m)
        ends = np.stack([pose[0] + step * np.cos(world), pose[1] + step * np.sin(world)], axis=1)
        beyond = np.hypot(ends[:, 0] - anchor_x, ends[:, 1] - anchor_y) - motion.leash_m
        turn = np.abs((angles + np.pi) % (2.0 * np.pi) - np.pi)
        score = step - 2.0 * np.maximum(beyond, 0.0) - 0.1 * turn / np.pi
        score[room < motion.min_room_m] = -np.inf
        if not np.isfinite(score).any():  # boxed in: stay put
            return np.zeros(2), np.array([pose[2], 0.0, pose[0], pose[1], anchor_x, anchor_y])
        best = int(np.argmax(score))
        goal, leg_x, leg_y = float(world[best]), pose[0], pose[1]
        goal_error = (goal - pose[2] + np.pi) % (2.0 * np.pi) - np.pi
    omega = float(np.clip(2.0 * goal_error, -motion.turn_rate_radps, motion.turn_rate_radps))
    v = 0.0
    if abs(goal_error) < motion.aligned_rad:
        v = float(np.clip(0.5 * (ahead - 0.05), 0.0, motion.speed_mps))
    return np.array([v, omega]), np.array([goal, 1.0, leg_x, leg_y, anchor_x, anchor_y])


class CarefulExplorer(LeafSystem):
    """Slow, safe motion from the scan alone (:func:`careful_command`), at 1 / ``period_s`` Hz
    (default 5 Hz, with the LiDAR: give ``offset_s`` just after the scan, so each step steers by
    a fresh scan taken where the robot is).

    .. pydrake_system::

        name: CarefulExplorer
        input_ports:
        - scan
        - odometry_pose
        output_ports:
        - command

    ``scan``: ``num_beams`` ranges [m] (``inf`` for no return); ``odometry_pose`` [x, y, theta]
    (m, rad) in the odometry's own frame (only its changes matter); ``command`` [v (m/s),
    omega (rad/s)], held between updates (a state output). The memory is anchored at
    ``odometry_pose`` at the first update.
    """

    def __init__(
        self,
        motion: CarefulMotion | None = None,
        *,
        num_beams: int = 360,
        period_s: float = 0.2,
        offset_s: float = 0.0,
    ) -> None:
        super().__init__()
        self.motion = CarefulMotion() if motion is None else motion
        self._scan_port = self.DeclareVectorInputPort("scan", num_beams)
        self._pose_port = self.DeclareVectorInputPort("odometry_pose", 3)
        self._command_index = self.DeclareDiscreteState(np.zeros(2))
        # [started (0/1), memory...]
        self._memory_index = self.DeclareDiscreteState(np.zeros(1 + MEMORY_SIZE))
        self.DeclarePeriodicDiscreteUpdateEvent(period_s, offset_s, self._update)
        self.DeclareStateOutputPort("command", self._command_index)

    def _update(self, context: Context, discrete_state: DiscreteValues) -> None:
        pose = np.asarray(self._pose_port.Eval(context), dtype=float)
        book = context.get_discrete_state(self._memory_index).CopyToVector()
        memory = book[1:] if book[0] else initial_memory(pose)
        command, memory = careful_command(self._scan_port.Eval(context), pose, memory, self.motion)
        discrete_state.set_value(self._command_index, command)
        discrete_state.set_value(self._memory_index, np.concatenate([[1.0], memory]))


__all__ = ["CarefulExplorer", "CarefulMotion", "careful_command", "free_distance"]
