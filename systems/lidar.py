"""A planar 2D LiDAR (TurtleBot3 LDS-01) that ray-casts against the walls, the furniture and the
people in SceneGraph."""

from __future__ import annotations

import numpy as np
import shapely
from pydrake.common.value import AbstractValue
from pydrake.geometry import Box, Cylinder, QueryObject, Role
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


def anchored_circles_from_query(query: QueryObject) -> np.ndarray:
    """(K, 3) [x, y, radius] [m] of the anchored upright proximity Cylinders (round furniture)."""
    inspector = query.inspector()
    world = inspector.world_frame_id()
    circles = []
    for geometry_id in inspector.GetAllGeometryIds(Role.kProximity):
        shape = inspector.GetShape(geometry_id)
        if isinstance(shape, Cylinder) and inspector.GetFrameId(geometry_id) == world:
            xy = inspector.GetPoseInFrame(geometry_id).translation()[:2]
            circles.append([xy[0], xy[1], shape.radius()])
    return np.array(circles).reshape(-1, 3)


def moving_cylinders_from_query(query: QueryObject, own_source: str) -> list[tuple]:
    """(GeometryId, radius [m]) of the upright proximity Cylinders on moving frames (people),
    except those of the SceneGraph source named ``own_source`` (the robot's own body)."""
    inspector = query.inspector()
    world = inspector.world_frame_id()
    found = []
    for geometry_id in inspector.GetAllGeometryIds(Role.kProximity):
        shape = inspector.GetShape(geometry_id)
        if (
            isinstance(shape, Cylinder)
            and inspector.GetFrameId(geometry_id) != world
            and inspector.GetOwningSourceName(geometry_id) != own_source
        ):
            found.append((geometry_id, shape.radius()))
    return found


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
    walls are the upright anchored proximity Boxes of SceneGraph and the round furniture its
    anchored Cylinders, read once per context from ``geometry_query`` (cached, never
    invalidated: they must not move); the people are the Cylinders on moving frames, whose poses
    are read from the query at each scan, except the robot's own body (the geometry of the
    source named ``own_source``). Ranges get Gaussian
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
        own_source: str = "robot",
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
        self._own_source = own_source
        self._anchored_cache = self.DeclareCacheEntry(
            description="anchored cylinders and moving cylinder ids",
            value_producer=ValueProducer(
                allocate=lambda: AbstractValue.Make((np.zeros((0, 3)), [])),
                calc=self._calc_cylinders,
            ),
            prerequisites_of_calc={self.nothing_ticket()},
        )
        self._scan_index = self.DeclareDiscreteState(np.full(self.num_beams, np.inf))
        self._tick_index = self.DeclareDiscreteState(np.zeros(1))
        self.DeclarePeriodicDiscreteUpdateEvent(period_s, offset_s, self._update)
        self._scan_port = self.DeclareStateOutputPort("scan", self._scan_index)

    def _calc_walls(self, context: Context, value: AbstractValue) -> None:
        value.set_value(wall_segments_from_query(self._query_port.Eval(context)))

    def _calc_cylinders(self, context: Context, value: AbstractValue) -> None:
        query = self._query_port.Eval(context)
        value.set_value(
            (
                anchored_circles_from_query(query),
                moving_cylinders_from_query(query, self._own_source),
            )
        )

    def wall_segments(self, context: Context) -> np.ndarray:
        """The (N, 4) wall segments this LiDAR sees [m]."""
        return self._walls_cache.Eval(context)

    def circles(self, context: Context) -> np.ndarray:
        """The (K, 3) [x, y, radius] [m] round obstacles this LiDAR sees now: round furniture and
        people at their current poses."""
        anchored, moving = self._anchored_cache.Eval(context)
        if not moving:
            return anchored
        query = self._query_port.Eval(context)
        now = [[*query.GetPoseInWorld(gid).translation()[:2], r] for gid, r in moving]
        return np.vstack([anchored, np.array(now)])

    def measure(
        self,
        pose: np.ndarray,
        walls: np.ndarray,
        scan_index: int,
        circles: np.ndarray | None = None,
    ) -> np.ndarray:
        """A noisy scan [m] from ``pose`` against ``walls`` and ``circles`` ((K, 3) [x, y, r]);
        pure given ``scan_index``."""
        ranges = cast_rays(
            np.asarray(pose[:2], float), self._angles + pose[2], walls, self.max_range, circles
        )
        if self.range_sigma_m > 0:
            rng = np.random.default_rng([self.seed, LIDAR_STREAM, scan_index])
            ranges = ranges + self.range_sigma_m * rng.standard_normal(self.num_beams)
        ranges[(ranges < self.min_range) | (ranges > self.max_range)] = np.inf
        return ranges

    def _update(self, context: Context, discrete_state: DiscreteValues) -> None:
        tick = int(context.get_discrete_state(self._tick_index).GetAtIndex(0))
        pose = self._pose_port.Eval(context)
        scan = self.measure(pose, self.wall_segments(context), tick, self.circles(context))
        discrete_state.set_value(self._scan_index, scan)
        discrete_state.set_value(self._tick_index, [tick + 1.0])
