"""A system that draws one run's LiDAR scan and estimated pose in meshcat, recorded for replay.

Meshcat animations can move and hide objects but not change a line's vertices, so each scan is
its own line set (``<path>/lidar/<k>``), shown from its scan time until the next scan; the
estimate is a disc moved to the estimated pose. Both go into meshcat's recording when it records
(``Meshcat.StartRecording``), so an HTML replay plays them with the robot.
"""

from __future__ import annotations

import numpy as np
from pydrake.geometry import Cylinder, Meshcat
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.systems.framework import Context, EventStatus, LeafSystem

from f2n_drake.systems.viewer import ESTIMATE_RGBA, LIDAR_RGBA

LIDAR_HEIGHT_M = 0.15  # the beams are drawn at this height [m]
ESTIMATE_HEIGHT_M = 0.05  # the estimate disc: above the paths, under the robot (0.19 m) [m]


def beam_segments(
    pose: np.ndarray, scan: np.ndarray, stride: int = 1, z_m: float = LIDAR_HEIGHT_M
) -> tuple[np.ndarray, np.ndarray]:
    """(3, K) starts and ends [m] of every ``stride``-th beam with a return, the scan taken at
    ``pose`` [x, y, theta] with beam i at bearing ``2 pi i / len(scan)`` from the heading."""
    scan = np.asarray(scan, dtype=float)
    index = np.arange(0, len(scan), stride)
    index = index[np.isfinite(scan[index])]
    angles = pose[2] + 2 * np.pi * index / len(scan)
    ends = np.stack(
        [
            pose[0] + scan[index] * np.cos(angles),
            pose[1] + scan[index] * np.sin(angles),
            np.full(len(index), z_m),
        ]
    )
    starts = np.repeat(np.array([[pose[0]], [pose[1]], [z_m]]), len(index), axis=1)
    return starts, ends


class RunVisualizer(LeafSystem):
    """Publishes the current scan's beams and the estimated pose to meshcat under ``path``.

    .. pydrake_system::

        name: RunVisualizer
        input_ports:
        - true_pose
        - estimated_pose
        - scan

    ``true_pose``, ``estimated_pose``: [x, y, theta]; ``scan``: ranges [m], inf for no return.
    Publishes every ``period_s`` from ``offset_s`` (with the LiDAR: a publish sees the scan
    taken at the same instant).
    """

    def __init__(
        self,
        meshcat: Meshcat,
        path: str,
        *,
        num_beams: int,
        period_s: float,
        offset_s: float,
        beam_stride: int = 4,
        estimate_radius_m: float = 0.16,
    ):
        super().__init__()
        self._meshcat, self._path = meshcat, path
        self._period_s, self._offset_s, self._stride = period_s, offset_s, beam_stride
        self._radius_m = estimate_radius_m
        self._true_pose_port = self.DeclareVectorInputPort("true_pose", 3)
        self._estimated_pose_port = self.DeclareVectorInputPort("estimated_pose", 3)
        self._scan_port = self.DeclareVectorInputPort("scan", num_beams)
        self.DeclareInitializationPublishEvent(self._initialize)
        self.DeclarePeriodicPublishEvent(period_s, offset_s, self._publish)

    def _initialize(self, context: Context) -> EventStatus:
        self._meshcat.Delete(f"{self._path}/lidar")
        self._meshcat.SetObject(
            f"{self._path}/estimate", Cylinder(self._radius_m, 0.01), ESTIMATE_RGBA
        )
        self._set_estimate(context)
        return EventStatus.Succeeded()

    def _set_estimate(self, context: Context) -> None:
        x, y, theta = self._estimated_pose_port.Eval(context)
        X_WE = RigidTransform(RotationMatrix.MakeZRotation(theta), [x, y, ESTIMATE_HEIGHT_M])
        self._meshcat.SetTransform(f"{self._path}/estimate", X_WE, context.get_time())

    def _publish(self, context: Context) -> EventStatus:
        t = context.get_time()
        k = round((t - self._offset_s) / self._period_s)
        starts, ends = beam_segments(
            self._true_pose_port.Eval(context), self._scan_port.Eval(context), self._stride
        )
        scan_path = f"{self._path}/lidar/{k}"
        self._meshcat.SetLineSegments(scan_path, starts, ends, 1.0, LIDAR_RGBA)
        self._meshcat.SetProperty(scan_path, "visible", False, 0.0)
        self._meshcat.SetProperty(scan_path, "visible", True, t)
        if k > 0:
            self._meshcat.SetProperty(f"{self._path}/lidar/{k - 1}", "visible", False, t)
        self._set_estimate(context)
        return EventStatus.Succeeded()


__all__ = ["RunVisualizer", "beam_segments"]
