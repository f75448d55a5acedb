"""LidarCorrector: corrects the odometry's pose estimate by matching LiDAR scans to the plan."""

from __future__ import annotations

from typing import Any, Literal

import numpy as np
from pydrake.systems.framework import BasicVector, LeafSystem

from f2n_drake.localization.scan_matching import fit_quality, icp_point_to_line
from f2n_drake.localization.scans import (
    as_segments,
    correct_axis_aligned,
    extract_line_segments,
    pose_delta,
    scan_to_points_robot,
)
from f2n_drake.systems.vectors import PoseCorrection


class LidarCorrector(LeafSystem):
    """Periodically localises the robot against the floor plan's walls from a 2D LiDAR scan.

    .. pydrake_system::

        name: LidarCorrector
        input_ports:
        - scan
        - estimated_pose
        - waypoint_index
        output_ports:
        - pose_correction
        - fit_quality
        - correction_delta

    Input ports:
        scan: ``num_beams`` ranges [m]; beam i at ``2*pi*i/num_beams`` rad counter-clockwise from
            the robot's heading; no return is ``+inf`` or beyond ``max_range_m``.
        estimated_pose: odometry's ``[x, y, theta]`` estimate [m, m, rad] in the world.
        waypoint_index: index of the current waypoint (1-vector); read in ``"paper"`` mode only
            and may be left unconnected in ``"continuous"`` mode.

    Output ports (state outputs, so no direct feedthrough and no algebraic loop):
        pose_correction: ``[count, x, y, theta]``; ``count`` increments each time a correction
            is issued, ``x, y, theta`` [m, m, rad] is the corrected pose at that tick.
        fit_quality: ``[inlier_ratio, rms_m]`` of the last attempted fit (inlier ratio of scan
            points within 0.1 m of a wall; rms [m] of their distances).
        correction_delta: ``[dx, dy, dtheta]`` world-frame rigid correction of the last issued
            correction (``corrected = delta o estimate``, see
            :func:`f2n_drake.localization.scans.apply_pose_delta`): applying it to the current
            estimate keeps motion integrated since the scan.

    Modes: ``"paper"`` (FloorPlan2Nav) corrects each time ``waypoint_index`` crosses a
    multiple of ``every_n_waypoints``, fixing x and y from axis-aligned scan lines (yaw is left
    as it is; axis-aligned plans only). Deviation from the paper: an attempt that matches no
    line (or is rejected) is retried on every following scan until one succeeds.
    ``"continuous"`` runs point-to-line ICP on every scan, fixing x, y and yaw in the
    directions the scan constrains, on any plan. Returns the plan cannot explain (furniture,
    people, a closed door) are rejected, not averaged in: a return is paired with a wall only if
    its range agrees within 0.3 m with the plan's range along its beam and it lies within the
    shrinking gate of that wall; the kept ones are Huber-weighted; a fit with fewer than 30
    such inliers is refused (:func:`~f2n_drake.localization.scan_matching.icp_point_to_line`).

    Args:
        wall_segments_m: ``(N, 4)`` plan walls ``[x0, y0, x1, y1]`` [m].
        mode: ``"paper"`` or ``"continuous"``.
        every_n_waypoints: paper-mode trigger spacing [waypoints].
        num_beams, min_range_m, max_range_m: LiDAR geometry [-, m, m].
        period_s, offset_s: update period and first update time [s] (5 Hz LiDAR); use the
            offset to order the corrector after the LiDAR's update.
        angle_tolerance_deg, gate_m, min_matches: paper-mode line classification [deg], matching
            gate [m] and the fewest matched lines that make a correction.
        max_correction_m, max_correction_rad: larger jumps are rejected as bad fits.
        icp_options: keyword arguments passed to
            :func:`f2n_drake.localization.scan_matching.icp_point_to_line` (thresholds, gates).
    """

    def __init__(
        self,
        wall_segments_m: np.ndarray,
        mode: Literal["paper", "continuous"],
        *,
        every_n_waypoints: int = 5,
        num_beams: int = 360,
        min_range_m: float = 0.12,
        max_range_m: float = 3.5,
        period_s: float = 0.2,
        offset_s: float = 0.0,
        angle_tolerance_deg: float = 10.0,
        gate_m: float = 0.3,
        min_matches: int = 1,
        max_correction_m: float = 0.6,
        max_correction_rad: float = 0.3,
        icp_options: dict[str, Any] | None = None,
    ) -> None:
        super().__init__()
        if mode not in ("paper", "continuous"):
            raise ValueError(f"mode must be 'paper' or 'continuous', got {mode!r}")
        if every_n_waypoints < 1 or num_beams < 1 or not period_s > 0:
            raise ValueError("every_n_waypoints, num_beams and period_s must be positive")
        self._walls = as_segments(wall_segments_m)
        self._mode = mode
        self._every_n = int(every_n_waypoints)
        self._min_range, self._max_range = float(min_range_m), float(max_range_m)
        self._angle_tolerance_deg, self._gate_m = float(angle_tolerance_deg), float(gate_m)
        self._min_matches = int(min_matches)
        self._max_correction = (float(max_correction_m), float(max_correction_rad))
        self._icp_options = dict(icp_options or {})

        self._scan_port = self.DeclareVectorInputPort("scan", num_beams)
        self._pose_port = self.DeclareVectorInputPort("estimated_pose", 3)
        self._waypoint_port = self.DeclareVectorInputPort("waypoint_index", 1)

        self._correction_state = self.DeclareDiscreteState(BasicVector(np.zeros(4)))
        self._quality_state = self.DeclareDiscreteState(BasicVector(np.array([0.0, np.inf])))
        self._delta_state = self.DeclareDiscreteState(BasicVector(np.zeros(3)))
        # [last waypoint index seen, paper correction pending (0/1)]
        self._last_waypoint_state = self.DeclareDiscreteState(BasicVector(np.zeros(2)))
        self.DeclareStateOutputPort("pose_correction", self._correction_state)
        self.DeclareStateOutputPort("fit_quality", self._quality_state)
        self.DeclareStateOutputPort("correction_delta", self._delta_state)
        self.DeclarePeriodicDiscreteUpdateEvent(period_s, offset_s, self._update)

    @property
    def mode(self) -> str:
        """``"paper"`` or ``"continuous"``."""
        return self._mode

    def _due(self, context, discrete_state) -> bool:
        """Paper mode: whether a correction is pending (the waypoint index crossed a multiple of
        ``every_n_waypoints`` and no correction succeeded since)."""
        index = float(self._waypoint_port.Eval(context)[0])
        last, pending = context.get_discrete_state(self._last_waypoint_state).CopyToVector()
        crossed = np.floor(index / self._every_n) > np.floor(last / self._every_n)
        pending = float(bool(pending) or crossed)
        discrete_state.get_mutable_vector(self._last_waypoint_state).SetFromVector([index, pending])
        return bool(pending)

    def _update(self, context, discrete_state) -> None:
        if self._mode == "paper" and not self._due(context, discrete_state):
            return
        estimate = np.asarray(self._pose_port.Eval(context), dtype=float)
        points = scan_to_points_robot(
            self._scan_port.Eval(context), self._min_range, self._max_range
        )
        if self._mode == "paper":
            lines = extract_line_segments(points)
            pose, matches = correct_axis_aligned(
                lines,
                estimate,
                self._walls,
                angle_tolerance_deg=self._angle_tolerance_deg,
                gate_m=self._gate_m,
                max_range=self._max_range,
            )
            quality = fit_quality(points, self._walls, pose)
            ok = matches >= self._min_matches
        else:
            options = {"max_range": self._max_range, **self._icp_options}
            result = icp_point_to_line(points, self._walls, estimate, **options)
            pose, quality, ok = result.pose, (result.inlier_ratio, result.rms_m), result.accepted
        discrete_state.get_mutable_vector(self._quality_state).SetFromVector(np.array(quality))
        jump = pose - estimate
        if (
            not ok
            or np.hypot(jump[0], jump[1]) > self._max_correction[0]
            or abs(jump[2]) > self._max_correction[1]
        ):
            return
        if self._mode == "paper":
            discrete_state.get_mutable_vector(self._last_waypoint_state).SetAtIndex(1, 0.0)
        correction = PoseCorrection(
            context.get_discrete_state(self._correction_state).CopyToVector()
        )
        correction.count += 1.0
        correction.x, correction.y, correction.theta = pose
        discrete_state.get_mutable_vector(self._correction_state).SetFromVector(correction[:])
        discrete_state.get_mutable_vector(self._delta_state).SetFromVector(
            pose_delta(pose, estimate)
        )
