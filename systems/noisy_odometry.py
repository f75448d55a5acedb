"""Wheel odometry with an accurate IMU yaw: dead reckoning that drifts in x and y."""

from __future__ import annotations

import numpy as np
from pydrake.systems.framework import Context, DiscreteValues, LeafSystem

from f2n_drake.systems.vectors import PoseCorrection

ODOMETRY_STREAM = 1
"""Noise stream id; the noise of tick k is drawn from ``default_rng([seed, 1, k])``."""


class NoisyOdometry(LeafSystem):
    """Dead-reckoned pose estimate updated at 1 / ``period_s`` Hz (default 10 Hz).

    Each tick measures the true motion since the previous tick in the robot frame (what wheel
    encoders and the IMU see), applies it to the estimate, and adds Gaussian noise: N(0,
    ``xy_sigma_m``^2) to x and y and N(0, ``yaw_sigma_rad``^2) to theta, per tick, as in
    FloorPlan2Nav (sigma = 20 mm per step, accurate IMU yaw). Noise is drawn from
    ``numpy.random.default_rng([seed, 1, tick])`` so a run reproduces exactly.

    When ``pose_correction``'s count rises above the last one seen, the corrected pose is
    output at once (the correction must refer to the estimate of the latest tick, as a
    corrector updating between ticks gives) and becomes the state at the next tick, before that
    tick's motion is applied, so no motion is lost. The port may be left unconnected.
    ``offset_s`` shifts the ticks (the navigation diagram uses it to order odometry, LiDAR and
    corrector updates). The estimate starts at ``x0`` (the true start), or at ``initial_estimate``
    when given (a robot that does not know where it starts: its own frame).

    .. pydrake_system::

        name: NoisyOdometry
        input_ports:
        - true_pose
        - pose_correction
        output_ports:
        - estimated_pose

    ``true_pose`` [x, y, theta] (m, rad); ``pose_correction`` [count, x, y, theta];
    ``estimated_pose`` [x, y, theta] (m, rad): the state, or a newer correction (direct
    feedthrough from ``pose_correction`` only; connect it to a corrector whose output is state).
    """

    def __init__(
        self,
        x0: np.ndarray,
        seed: int,
        period_s: float = 0.1,
        xy_sigma_m: float = 0.02,
        yaw_sigma_rad: float = 0.0,
        offset_s: float = 0.0,
        initial_estimate: np.ndarray | None = None,
    ) -> None:
        super().__init__()
        x0 = np.asarray(x0, dtype=float).reshape(3)
        estimate0 = x0 if initial_estimate is None else np.asarray(initial_estimate, float)
        if seed < 0 or xy_sigma_m < 0 or yaw_sigma_rad < 0:
            raise ValueError("seed and noise sigmas must be non-negative")
        self.seed, self.xy_sigma_m, self.yaw_sigma_rad = int(seed), xy_sigma_m, yaw_sigma_rad
        self._true_pose_port = self.DeclareVectorInputPort("true_pose", 3)
        self._correction_port = self.DeclareVectorInputPort("pose_correction", 4)
        self._estimate_index = self.DeclareDiscreteState(estimate0.reshape(3))
        # [previous true x, y, theta, tick, last correction count]
        self._book_index = self.DeclareDiscreteState(np.concatenate([x0, [0.0, 0.0]]))
        self.DeclarePeriodicDiscreteUpdateEvent(period_s, offset_s, self._update)
        self._estimate_port = self.DeclareVectorOutputPort(
            "estimated_pose",
            3,
            self._calc_estimate,
            prerequisites_of_calc={
                self.xd_ticket(),
                self._correction_port.ticket(),
            },
        )

    def _newer_correction(self, context: Context, seen: float) -> np.ndarray | None:
        """The corrected pose if ``pose_correction`` is connected and newer than ``seen``."""
        if not self._correction_port.HasValue(context):
            return None
        correction = PoseCorrection(self._correction_port.Eval(context))
        return np.array(correction[:], dtype=float) if correction.count > seen else None

    def _calc_estimate(self, context: Context, output) -> None:
        seen = context.get_discrete_state(self._book_index).GetAtIndex(4)
        correction = self._newer_correction(context, seen)
        if correction is None:
            output.SetFromVector(context.get_discrete_state(self._estimate_index).value())
        else:
            output.SetFromVector(correction[1:])

    def _update(self, context: Context, discrete_state: DiscreteValues) -> None:
        estimate = context.get_discrete_state(self._estimate_index).CopyToVector()
        book = context.get_discrete_state(self._book_index).CopyToVector()
        previous, tick, seen = book[:3], int(book[3]), book[4]
        correction = self._newer_correction(context, seen)
        if correction is not None:
            seen, estimate = correction[0], correction[1:]
        true = self._true_pose_port.Eval(context)
        c, s = np.cos(previous[2]), np.sin(previous[2])
        dx, dy = true[:2] - previous[:2]
        forward, left = c * dx + s * dy, -s * dx + c * dy  # motion in the robot frame
        dtheta = true[2] - previous[2]
        noise = np.random.default_rng([self.seed, ODOMETRY_STREAM, tick]).standard_normal(3)
        ce, se = np.cos(estimate[2]), np.sin(estimate[2])
        estimate = estimate + [
            ce * forward - se * left + self.xy_sigma_m * noise[0],
            se * forward + ce * left + self.xy_sigma_m * noise[1],
            dtheta + self.yaw_sigma_rad * noise[2],
        ]
        discrete_state.set_value(self._estimate_index, estimate)
        discrete_state.set_value(self._book_index, np.concatenate([true, [tick + 1, seen]]))
