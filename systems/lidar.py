"""A planar 2D LiDAR (TurtleBot3 LDS-01) that ray-casts against the walls in SceneGraph."""

from __future__ import annotations

import numpy as np
import shapely
from pydrake.common.value import AbstractValue
from pydrake.geometry import Box, QueryObject, Role
from pydrake.systems.framework import (
    Context,
    DiscreteValues,
    LeafSystem,
    ValueProducer,
)
from shapely.geometry import Polygon

from f2n_drake.localization.scans import beam_angles, cast_rays

LIDAR_STREAM = 2
"""Noise stream id; the noise of scan k is drawn from ``default_rng([seed, 2, k])``."""


def wall_segments_from_query(query: QueryObject) -> np.ndarray:
    """(N, 4) [x0, y0, x1, y1] [m]: the outline of the footprints of the anchored proximity Boxes.

    Boxes are assumed upright (rotated about z only), as :func:`AddPlanGeometry` makes them.
    Their footprints are merged, so the edges shared by adjacent boxes (never hit by a ray from
    free space) are dropped and each straight wall face is one segment.
    """
    inspector = query.inspector()
    world = inspector.world_frame_id()
    segments = []
    for geometry_id in inspector.GetAllGeometryIds(Role.kProximity):
        shape = inspector.GetShape(geometry_id)
        if not isinstance(shape, Box) or inspector.GetFrameId(geometry_id) != world:
            continue
        X_WG = inspector.GetPoseInFrame(geometry_id)
        hx, hy = shape.width() / 2, shape.depth() / 2
        corners_G = np.array([[-hx, -hy, 0], [hx, -hy, 0], [hx, hy, 0], [-hx, hy, 0]])
        corners_W = (X_WG.rotation().matrix() @ corners_G.T).T + X_WG.translation()
        segments.append(Polygon(corners_W[:, :2]))
    return outline_segments(segments)


def outline_segments(polygons: list[Polygon], snap_m: float = 1e-4) -> np.ndarray:
    """(N, 4) edges [m] of the union of ``polygons`` (snapped to ``snap_m``, collinear runs
    joined)."""
    if not polygons:
        return np.zeros((0, 4))
    merged = shapely.union_all(shapely.set_precision(polygons, snap_m)).simplify(snap_m)
    edges = []
    for poly in getattr(merged, "geoms", [merged]):
        for ring in (poly.exterior, *poly.interiors):
            xy = np.asarray(ring.coords)[:, :2]
            edges.append(np.hstack([xy[:-1], xy[1:]]))
    return np.vstack(edges) if edges else np.zeros((0, 4))


class Lidar2D(LeafSystem):
    """360-beam planar LiDAR at 1 / ``period_s`` Hz (default 5 Hz, LDS-01: 0.12-3.5 m).

    Beam i points at ``2*pi*i/num_beams`` rad counter-clockwise from the robot's heading. The
    walls are the upright anchored proximity Boxes of SceneGraph, read once per context from
    ``geometry_query`` (cached, never invalidated: the walls must not move). Ranges get Gaussian
    noise N(0, ``range_sigma_m``^2) from ``default_rng([seed, 2, scan_index])``; a beam with no
    return, or one reading below ``min_range`` or above ``max_range``, is ``+inf``. The scan is
    discrete state (all ``+inf`` before the first update).

    .. pydrake_system::

        name: Lidar2D
        input_ports:
        - true_pose
        - geometry_query
        output_ports:
        - scan

    ``true_pose`` [x, y, theta] (m, rad); ``scan`` ``num_beams`` ranges (m).
    """

    def __init__(
        self,
        seed: int,
        num_beams: int = 360,
        min_range: float = 0.12,
        max_range: float = 3.5,
        period_s: float = 0.2,
        range_sigma_m: float = 0.01,
        offset_s: float = 0.0,
    ) -> None:
        super().__init__()
        if seed < 0 or num_beams < 1 or not 0 <= min_range < max_range or range_sigma_m < 0:
            raise ValueError("Lidar2D: need seed >= 0, num_beams >= 1, 0 <= min < max, sigma >= 0")
        self.seed, self.num_beams = int(seed), int(num_beams)
        self.min_range, self.max_range, self.range_sigma_m = min_range, max_range, range_sigma_m
        self._angles = beam_angles(self.num_beams)
        self._pose_port = self.DeclareVectorInputPort("true_pose", 3)
        self._query_port = self.DeclareAbstractInputPort(
            "geometry_query", AbstractValue.Make(QueryObject())
        )
        self._walls_cache = self.DeclareCacheEntry(
            description="wall segments",
            value_producer=ValueProducer(
                allocate=lambda: AbstractValue.Make(np.zeros((0, 4))), calc=self._calc_walls
            ),
            prerequisites_of_calc={self.nothing_ticket()},
        )
        self._scan_index = self.DeclareDiscreteState(np.full(self.num_beams, np.inf))
        self._tick_index = self.DeclareDiscreteState(np.zeros(1))
        self.DeclarePeriodicDiscreteUpdateEvent(period_s, offset_s, self._update)
        self._scan_port = self.DeclareStateOutputPort("scan", self._scan_index)

    def _calc_walls(self, context: Context, value: AbstractValue) -> None:
        value.set_value(wall_segments_from_query(self._query_port.Eval(context)))

    def wall_segments(self, context: Context) -> np.ndarray:
        """The (N, 4) wall segments this LiDAR sees [m]."""
        return self._walls_cache.Eval(context)

    def measure(self, pose: np.ndarray, walls: np.ndarray, scan_index: int) -> np.ndarray:
        """A noisy scan [m] from ``pose`` against ``walls``; pure given ``scan_index``."""
        ranges = cast_rays(
            np.asarray(pose[:2], float), self._angles + pose[2], walls, self.max_range
        )
        if self.range_sigma_m > 0:
            rng = np.random.default_rng([self.seed, LIDAR_STREAM, scan_index])
            ranges = ranges + self.range_sigma_m * rng.standard_normal(self.num_beams)
        ranges[(ranges < self.min_range) | (ranges > self.max_range)] = np.inf
        return ranges

    def _update(self, context: Context, discrete_state: DiscreteValues) -> None:
        tick = int(context.get_discrete_state(self._tick_index).GetAtIndex(0))
        pose = self._pose_port.Eval(context)
        discrete_state.set_value(
            self._scan_index, self.measure(pose, self.wall_segments(context), tick)
        )
        discrete_state.set_value(self._tick_index, [tick + 1.0])
