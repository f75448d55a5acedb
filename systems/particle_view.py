"""Draws the global localizer's particle cloud in meshcat until the handover, recorded for replay.

Each particle is a small triangle pointing along its heading (meshcat draws points a pixel or
two wide in the top-down view). Meshcat animations can hide objects but not move a mesh's
vertices, so each drawing is its own mesh (``<path>/<k>``), shown from its publish time until the
next; at the handover the last one is hidden and drawing stops.
"""

from __future__ import annotations

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.geometry import Meshcat, Rgba
from pydrake.systems.framework import Context, EventStatus, LeafSystem

from f2n_drake.localization.particle_filter import ParticleCloud

PARTICLE_RGBA = Rgba(0.55, 0.1, 0.75, 0.8)
PARTICLE_HEIGHT_M = 0.06  # above the floor and the paths, under the robot [m]


def particle_triangles(
    cloud: ParticleCloud, max_points: int, size_m: float, z_m: float = PARTICLE_HEIGHT_M
) -> tuple[np.ndarray, np.ndarray]:
    """(3, 3K) vertices [m] and (3, K) faces of a triangle ``size_m`` long pointing along the
    heading for each of at most ``max_points`` particles (an even subsample), at ``z_m``."""
    poses = cloud.poses
    if len(poses) > max_points:
        poses = poses[np.linspace(0, len(poses) - 1, max_points).astype(int)]
    c, s = np.cos(poses[:, 2]), np.sin(poses[:, 2])
    corners = np.array([[0.6, 0.0], [-0.4, 0.3], [-0.4, -0.3]]) * size_m  # robot frame
    x = poses[:, 0, None] + c[:, None] * corners[:, 0] - s[:, None] * corners[:, 1]
    y = poses[:, 1, None] + s[:, None] * corners[:, 0] + c[:, None] * corners[:, 1]
    vertices = np.vstack([x.reshape(-1), y.reshape(-1), np.full(x.size, z_m)])
    faces = np.arange(3 * len(poses), dtype=np.int32).reshape(-1, 3).T
    return vertices, faces


class ParticleView(LeafSystem):
    """Publishes the particle cloud to meshcat under ``path`` every ``period_s`` until localized.

    .. pydrake_system::

        name: ParticleView
        input_ports:
        - particles
        - localized

    ``particles``: a :class:`~f2n_drake.localization.particle_filter.ParticleCloud`;
    ``localized``: ``[converged (0/1), ...]``.
    """

    def __init__(
        self,
        meshcat: Meshcat,
        path: str,
        *,
        period_s: float = 0.4,
        offset_s: float = 0.0,
        max_points: int = 1500,
        size_m: float = 0.08,
        localized_size: int = 2,
    ) -> None:
        super().__init__()
        self._meshcat, self._path = meshcat, path
        self._period_s, self._offset_s = period_s, offset_s
        self._max_points, self._size_m = int(max_points), float(size_m)
        empty = ParticleCloud(np.zeros((0, 3)), np.zeros(0))
        self._particles_port = self.DeclareAbstractInputPort("particles", AbstractValue.Make(empty))
        self._localized_port = self.DeclareVectorInputPort("localized", localized_size)
        self.DeclareInitializationPublishEvent(self._initialize)
        self.DeclarePeriodicPublishEvent(period_s, offset_s, self._publish)

    def _initialize(self, context: Context) -> EventStatus:
        self._meshcat.Delete(self._path)
        return EventStatus.Succeeded()

    def _publish(self, context: Context) -> EventStatus:
        t = context.get_time()
        k = round((t - self._offset_s) / self._period_s)
        previous = f"{self._path}/{k - 1}"
        if self._localized_port.Eval(context)[0] > 0.5:
            if self._meshcat.HasPath(previous):
                self._meshcat.SetProperty(previous, "visible", False, t)
            return EventStatus.DidNothing()
        cloud = self._particles_port.Eval(context)
        if len(cloud) == 0:
            return EventStatus.DidNothing()
        vertices, faces = particle_triangles(cloud, self._max_points, self._size_m)
        path = f"{self._path}/{k}"
        self._meshcat.SetTriangleMesh(path, vertices, faces, PARTICLE_RGBA)
        self._meshcat.SetProperty(path, "visible", False, 0.0)
        self._meshcat.SetProperty(path, "visible", True, t)
        if self._meshcat.HasPath(previous):
            self._meshcat.SetProperty(previous, "visible", False, t)
        return EventStatus.Succeeded()


__all__ = ["PARTICLE_RGBA", "ParticleView", "particle_triangles"]
