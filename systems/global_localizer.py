"""GlobalLocalizer: Monte Carlo localization from an unknown start, then a handover to tracking.

Until it is sure, the localizer runs the particle filter of
:mod:`f2n_drake.localization.particle_filter` on the scans, moved by the odometry's increments
(the odometry's own frame is arbitrary: only its changes are used; the first cloud favours the
headings that align the first scan's walls with the plan's; a scan is used once the robot
has moved enough since the last one, see
:func:`~f2n_drake.localization.particle_filter.moved_enough`). Once the cloud has passed the
convergence test (:mod:`f2n_drake.localization.particle_clusters`) for ``confirm_updates``
filter steps in a row, the estimate is refined by point-to-line ICP against the plan's walls; it
is handed over when ICP accepts the fit and the scan constrains x, y and heading (a room seen
along a corridor does not: the robot keeps moving until it does), or after ``patience_updates``
converged steps whatever ICP says; never while more than ``max_crossing_share`` of the scan's
returns would have crossed the plan's walls from that pose (what the plan lacks shortens beams,
it does not let them through walls). The handover is a pose correction to the odometry; from then
on the localizer forwards the tracking corrector's corrections and stops filtering.
"""

from __future__ import annotations

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import BasicVector, Context, LeafSystem, State

from f2n_drake.localization.heading_prior import heading_hypotheses
from f2n_drake.localization.likelihood_field import LikelihoodField
from f2n_drake.localization.particle_clusters import ConvergenceTest, estimate_pose
from f2n_drake.localization.particle_filter import (
    FilterOptions,
    ParticleCloud,
    moved_enough,
    relative_motion,
    step,
    uniform_cloud,
)
from f2n_drake.localization.scan_matching import icp_point_to_line
from f2n_drake.localization.scans import as_segments, scan_to_points_robot
from f2n_drake.systems.vectors import PoseCorrection

LOCALIZER_STREAM = 3
"""Random stream id; the filter's randomness at step k is ``default_rng([seed, 3, k])``."""

# Layout of the bookkeeping state.
STEPS, STREAK, LATCHED, TRAVEL, PREVIOUS = 0, 1, 2, 3, slice(4, 7)


class GlobalLocalizer(LeafSystem):
    """Global localization on the plan, with a handover to the tracking corrector.

    .. pydrake_system::

        name: GlobalLocalizer
        input_ports:
        - scan
        - odometry_pose
        - tracking_correction
        output_ports:
        - localized
        - pose_estimate
        - pose_correction
        - handover
        - particles

    Input ports:
        scan: ``num_beams`` ranges [m] (``inf``: no return).
        odometry_pose: the odometry's ``[x, y, theta]`` [m, m, rad]; before the handover only
            its increments matter; it must be the estimate the corrections apply to.
        tracking_correction: ``[count, x, y, theta]`` of the tracking corrector; forwarded after
            the handover. May be left unconnected.

    Output ports:
        localized: ``[converged (0/1), handovers]`` (state).
        pose_estimate: ``[x, y, theta]`` of the dominant cluster [m, m, rad] (state).
        pose_correction: ``[count, x, y, theta]``: count 0 until the handover, 1 with the handover
            pose, then 1 + each tracking correction issued after it (with its pose); connect it to
            the odometry's ``pose_correction``.
        handover: ``[time_s, x, y, theta]`` of the handover (``[-1, 0, 0, 0]`` before it).
        particles: the :class:`~f2n_drake.localization.particle_filter.ParticleCloud` (empty
            before the first scan; frozen at the handover).

    Updates every ``period_s`` from ``offset_s``: put it after the LiDAR's update and the
    odometry's tick, like the tracking corrector, so a scan and the odometry pose belong to the
    same instant and the handover correction refers to the latest odometry tick.

    Args:
        field: the plan's likelihood field; wall_segments_m: its walls (N, 4) [m] for ICP.
        seed: the filter's randomness (``default_rng([seed, 3, step])``).
        options: the particle filter's; test: the convergence test.
        confirm_updates, patience_updates: converged steps in a row before a handover is tried,
            and after which it no longer waits for ICP to pin the pose down.
        min_travel_m: distance [m] the odometry must have travelled before a handover.
        max_refinement_m: ICP may move the estimate this far [m].
        max_crossing_share: largest share of returns that may cross the plan's walls from the
            handover pose.
    """

    def __init__(
        self,
        field: LikelihoodField,
        wall_segments_m: np.ndarray,
        seed: int,
        *,
        options: FilterOptions | None = None,
        test: ConvergenceTest | None = None,
        confirm_updates: int = 3,
        patience_updates: int = 25,
        min_travel_m: float = 0.0,
        max_refinement_m: float = 0.3,
        max_crossing_share: float = 0.05,
        num_beams: int = 360,
        period_s: float = 0.2,
        offset_s: float = 0.0,
    ) -> None:
        super().__init__()
        if seed < 0 or confirm_updates < 1 or patience_updates < confirm_updates:
            raise ValueError("need seed >= 0 and 1 <= confirm_updates <= patience_updates")
        self._field, self._walls = field, as_segments(wall_segments_m)
        self._seed = int(seed)
        self._options = FilterOptions() if options is None else options
        self._test = ConvergenceTest() if test is None else test
        self._confirm, self._patience = int(confirm_updates), int(patience_updates)
        self._min_travel_m = float(min_travel_m)
        self._max_refinement_m = float(max_refinement_m)
        self._max_crossing_share = float(max_crossing_share)

        self._scan_port = self.DeclareVectorInputPort("scan", num_beams)
        self._odometry_port = self.DeclareVectorInputPort("odometry_pose", 3)
        self._tracking_port = self.DeclareVectorInputPort("tracking_correction", 4)

        self._localized_index = self.DeclareDiscreteState(np.zeros(2))
        self._estimate_index = self.DeclareDiscreteState(np.zeros(3))
        self._handover_index = self.DeclareDiscreteState(np.array([-1.0, 0.0, 0.0, 0.0]))
        self._book_index = self.DeclareDiscreteState(np.array([0, 0, -1, 0, 0, 0, 0], float))
        empty = ParticleCloud(np.zeros((0, 3)), np.zeros(0))
        self._cloud_index = self.DeclareAbstractState(AbstractValue.Make(empty))
        self.DeclarePeriodicUnrestrictedUpdateEvent(period_s, offset_s, self._update)

        self.DeclareStateOutputPort("localized", self._localized_index)
        self.DeclareStateOutputPort("pose_estimate", self._estimate_index)
        self.DeclareVectorOutputPort(
            "pose_correction",
            4,
            self._calc_correction,
            prerequisites_of_calc={self.xd_ticket(), self._tracking_port.ticket()},
        )
        self.DeclareStateOutputPort("handover", self._handover_index)
        self.DeclareStateOutputPort("particles", self._cloud_index)

    def _tracking(self, context: Context) -> np.ndarray | None:
        if not self._tracking_port.HasValue(context):
            return None
        return np.asarray(self._tracking_port.Eval(context), dtype=float)

    def _calc_correction(self, context: Context, output: BasicVector) -> None:
        handover = context.get_discrete_state(self._handover_index).CopyToVector()
        latched = context.get_discrete_state(self._book_index).GetAtIndex(LATCHED)
        if handover[0] < 0:
            output.SetFromVector(np.zeros(4))
            return
        tracking = self._tracking(context)
        if latched >= 0 and tracking is not None and tracking[0] > latched:
            output.SetFromVector([1.0 + tracking[0] - latched, *tracking[1:]])
        else:
            output.SetFromVector([1.0, *handover[1:]])

    def _update(self, context: Context, state: State) -> None:
        book = context.get_discrete_state(self._book_index).CopyToVector()
        if context.get_discrete_state(self._handover_index).GetAtIndex(0) >= 0:
            if book[LATCHED] < 0:  # the first update after the handover: latch the tracker
                tracking = self._tracking(context)
                book[LATCHED] = 0.0 if tracking is None else PoseCorrection(tracking).count
                state.get_mutable_discrete_state(self._book_index).SetFromVector(book)
            return
        steps = int(book[STEPS])
        rng = np.random.default_rng([self._seed, LOCALIZER_STREAM, steps])
        odometry = np.asarray(self._odometry_port.Eval(context), dtype=float)
        scan = np.asarray(self._scan_port.Eval(context), dtype=float)
        if steps == 0:
            headings = heading_hypotheses(self._points(scan), self._walls)
            cloud = uniform_cloud(self._field, self._options, rng, headings)
            motion = np.zeros(3)
        else:
            cloud = context.get_abstract_state(self._cloud_index).get_value()
            motion = relative_motion(book[PREVIOUS], odometry)
            if not moved_enough(motion, self._options):
                return
        cloud, _ = step(cloud, motion, scan, self._field, self._options, rng, index=steps)
        estimate = estimate_pose(cloud, self._test)
        streak = book[STREAK] + 1 if estimate.converged else 0
        book[STEPS], book[STREAK], book[PREVIOUS] = steps + 1, streak, odometry
        book[TRAVEL] += np.hypot(motion[0], motion[1])
        state.get_mutable_abstract_state(self._cloud_index).set_value(cloud)
        state.get_mutable_discrete_state(self._estimate_index).SetFromVector(estimate.pose)
        state.get_mutable_discrete_state(self._book_index).SetFromVector(book)
        if streak < self._confirm or book[TRAVEL] < self._min_travel_m:
            return
        pose = self._handover_pose(scan, estimate.pose, streak >= self._patience)
        if pose is None:
            return
        state.get_mutable_discrete_state(self._localized_index).SetFromVector([1.0, 1.0])
        state.get_mutable_discrete_state(self._handover_index).SetFromVector(
            [context.get_time(), *pose]
        )

    def _points(self, scan: np.ndarray) -> np.ndarray:
        return scan_to_points_robot(scan, self._options.min_range_m, self._options.max_range_m)

    def _handover_pose(self, scan: np.ndarray, pose: np.ndarray, impatient: bool):
        """The ICP-refined pose when the scan pins it down; the best available pose when
        ``impatient``; else None (keep going). None too when the pose lets the scan through
        the plan's walls."""
        points = self._points(scan)
        fit = icp_point_to_line(points, self._walls, pose, max_range=self._options.max_range_m)
        close = np.hypot(*(fit.pose[:2] - pose[:2])) <= self._max_refinement_m
        if fit.accepted and close and len(fit.constrained_dirs) == 3:
            chosen = fit.pose
        elif impatient:
            chosen = fit.pose if fit.accepted and close else pose
        else:
            return None
        offsets = self._options.fine.through_offsets_m
        crossed = self._field.crossed(chosen, points, offsets) if len(points) else np.zeros(1)
        return chosen if crossed.mean() <= self._max_crossing_share else None


__all__ = ["LOCALIZER_STREAM", "GlobalLocalizer"]
