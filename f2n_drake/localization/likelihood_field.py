"""The likelihood field of a floor plan: how well a LiDAR return fits the plan's walls.

A :class:`LikelihoodField` rasterises the plan in metres: for every cell, the distance to the
nearest wall face (in millimetres, capped), which a :class:`BeamModel` turns into the
log-likelihood of a return ending there through a table (the "likelihood field" beam model of
Thrun, Burgard and Fox, *Probabilistic Robotics*, 2005, section 6.4):

    p(return | pose) = z_hit * exp(-d^2 / (2 sigma_hit^2)) + z_rand

with ``d`` the distance from the return's end point to the nearest wall. A return the plan does
not explain (furniture, a person) gets about ``z_rand`` whatever the pose, so it barely moves the
weights instead of pulling them. The likelihood field alone ignores what a beam crossed; but
what the plan lacks can only cut a beam short, never let it through a wall, so a return whose
beam passed through the plan's walls (or out of the building) on its way is given ``z_through``
instead: a few points on the beam before its end are looked up in the cells rays can cross
(the plan's rooms and doors). That negative evidence is what tells a cluttered room from a
place where the returns happen to fall near walls.

The field also holds the cells where the robot's centre can be (the plan's floors and doors,
farther than the robot's radius from any wall), which seed and bound a particle filter
(:mod:`f2n_drake.localization.particle_filter`).

Grid convention: cell ``(row, col)`` covers ``x in origin_x + [col, col + 1) * resolution`` and
``y in origin_y + [row, row + 1) * resolution`` (row 0 at the bottom, y up).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import cv2
import numpy as np
from shapely.geometry import Polygon

from f2n_drake.core.errors import InputError
from f2n_drake.mapping.walls import PlanGeometry

MAX_CELLS = 16_000_000
"""Largest grid allocated [cells] (a 100 x 100 m plan at 2.5 cm)."""

MAX_DISTANCE_MM = 2000
"""Distances to the walls are stored in whole millimetres up to this [mm]."""


@dataclass(frozen=True)
class BeamModel:
    """Parameters of the likelihood-field beam model.

    Attributes:
        sigma_hit_m: standard deviation of a return around the wall it hit [m].
        z_hit: weight of the Gaussian around the walls.
        z_rand: weight of returns the plan does not explain (furniture, people, noise).
        z_through: likelihood of a return whose beam crossed a wall of the plan on its way.
        through_offsets_m: where a beam is checked for crossing: these distances [m] before
            its end (those nearer the robot than 0.15 m are not checked).
    """

    sigma_hit_m: float = 0.1
    z_hit: float = 0.9
    z_rand: float = 0.1
    z_through: float = 0.02
    through_offsets_m: tuple[float, ...] = (0.15, 0.5, 1.0, 2.0)

    def log_likelihood(self, distance_m: np.ndarray) -> np.ndarray:
        """Log-likelihood of returns ending ``distance_m`` [m] from the nearest wall."""
        d = np.asarray(distance_m, dtype=float)
        return np.log(self.z_hit * np.exp(-0.5 * (d / self.sigma_hit_m) ** 2) + self.z_rand)

    def table(self) -> np.ndarray:
        """Log-likelihood (float32) per whole millimetre, 0 to ``MAX_DISTANCE_MM``."""
        return _table(self)


@lru_cache(maxsize=16)
def _table(model: BeamModel) -> np.ndarray:
    table = model.log_likelihood(np.arange(MAX_DISTANCE_MM + 1) / 1000.0).astype(np.float32)
    table.flags.writeable = False
    return table


@dataclass(frozen=True)
class LikelihoodField:
    """Per-cell distance to the walls and the free cells, in the plan frame [m].

    Attributes:
        distance_mm: (H, W) uint16 distance from each cell's centre to the nearest wall face
            [mm], capped at ``MAX_DISTANCE_MM``; the border cells hold the cap, so clipped
            indices read "far from every wall".
        free: (H, W) bool, the cells where the robot's centre can be.
        passable: (H, W) bool, the cells a LiDAR beam can cross (rooms and doors, not walls).
        origin_m: (x, y) of the lower-left corner of cell (0, 0) [m].
        resolution_m: side of a cell [m].
    """

    distance_mm: np.ndarray
    free: np.ndarray
    passable: np.ndarray
    origin_m: tuple[float, float]
    resolution_m: float

    @classmethod
    def from_geometry(
        cls,
        geometry: PlanGeometry,
        *,
        resolution_m: float = 0.025,
        robot_radius_m: float = 0.105,
        margin_m: float = 4.0,
    ) -> LikelihoodField:
        """The field of ``geometry``'s walls (every polygon edge is a wall face), on a grid of
        ``resolution_m`` cells reaching ``margin_m`` beyond the plan (at least the LiDAR's
        range, so every return seen from the plan lands on the grid).

        Free cells: inside the floors and doors (the connectors that are not windows), outside
        the walls, farther than ``robot_radius_m`` from them; without floors, the wall-free
        cells not connected to the outside of the plan. Passable cells: the same before the
        radius is taken off, grown by 0.15 m (floors drawn short of the wall faces) and
        without the walls.

        Raises:
            InputError: no walls, a non-positive resolution, a grid above ``MAX_CELLS``, or no
                free cell.
        """
        segments = geometry.wall_segments()
        if len(segments) == 0:
            raise InputError("the plan has no walls to localise against")
        if not resolution_m > 0:
            raise InputError(f"resolution_m must be positive, got {resolution_m}")
        xmin, ymin, xmax, ymax = geometry.bounds()
        origin = (xmin - margin_m, ymin - margin_m)
        shape = (
            int(np.ceil((ymax - ymin + 2 * margin_m) / resolution_m)),
            int(np.ceil((xmax - xmin + 2 * margin_m) / resolution_m)),
        )
        if shape[0] * shape[1] > MAX_CELLS:
            raise InputError(f"plan too large for a {resolution_m} m likelihood field: {shape}")
        to_px = lambda xy: (np.asarray(xy) - origin) / resolution_m - 0.5  # noqa: E731

        distance = _face_distance(segments, shape, origin, resolution_m)
        distance_mm = np.minimum(np.round(distance * 1000), MAX_DISTANCE_MM)
        distance_mm = distance_mm.astype(np.uint16)
        distance_mm[[0, -1], :], distance_mm[:, [0, -1]] = MAX_DISTANCE_MM, MAX_DISTANCE_MM

        walls = _fill(geometry.walls, shape, to_px)
        floors = [p for _, p in geometry.floors]
        floors += [p for name, p in geometry.connectors if name != "window"]
        if floors:
            inside = _fill(floors, shape, to_px) & ~walls
        else:
            inside = _enclosed(~walls)
        free = inside & (distance > robot_radius_m)
        if not free.any():
            raise InputError("the plan has no free space for the robot")
        grow = 2 * int(np.ceil(0.15 / resolution_m)) + 1
        passable = cv2.dilate(inside.astype(np.uint8), np.ones((grow, grow), np.uint8)) > 0
        return cls(distance_mm, free, passable & ~walls, origin, float(resolution_m))

    @property
    def free_area_m2(self) -> float:
        """Area of the free cells [m^2]."""
        return float(self.free.sum()) * self.resolution_m**2

    def cells(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(rows, cols) of the cells holding the points ``xy`` (..., 2) [m], clipped to the
        grid (the border cells hold the value of a point far from the plan)."""
        h, w = self.free.shape
        col = np.floor((xy[..., 0] - self.origin_m[0]) / self.resolution_m).astype(np.intp)
        row = np.floor((xy[..., 1] - self.origin_m[1]) / self.resolution_m).astype(np.intp)
        return np.clip(row, 0, h - 1), np.clip(col, 0, w - 1)

    def distance(self, xy: np.ndarray) -> np.ndarray:
        """Distance [m] from the points ``xy`` (..., 2) [m] to the nearest wall face (to the
        cell's centre; capped at ``MAX_DISTANCE_MM``)."""
        return self.distance_mm[self.cells(xy)] / 1000.0

    def lookup(self, xy: np.ndarray, model: BeamModel) -> np.ndarray:
        """Log-likelihood (float32) of returns ending at ``xy`` (..., 2) [m] under ``model``."""
        return model.table()[self.distance_mm[self.cells(xy)]]

    def scan_log_likelihood(
        self, poses: np.ndarray, points_robot: np.ndarray, model: BeamModel, chunk: int = 4096
    ) -> np.ndarray:
        """Sum over the returns ``points_robot`` (K, 2) [m, robot frame] of their log-likelihood
        seen from each pose (N, 3): (N,) (module docstring: the field at the end point, or
        ``z_through`` when a point checked on the beam is not passable).

        The hot loop of a particle filter: cell indices are computed in float32, a chunk of
        particles at a time, and read from the flattened grids (an end point off the grid reads
        a clipped index: the margin keeps returns seen from the plan on it).
        """
        points = np.asarray(points_robot, dtype=float).reshape(-1, 2)
        ranges = np.maximum(np.hypot(points[:, 0], points[:, 1]), 1e-9)
        back = ranges[:, None] - np.asarray(model.through_offsets_m, float)[None, :]  # (K, J)
        back = np.where(back >= 0.15, back, 0.0)  # not checked: the robot's own cell
        checked = points[None, :, :] / ranges[None, :, None] * back.T[..., None]  # (J, K, 2)
        both = np.vstack([points, checked.reshape(-1, 2)])  # end points, then checked points
        k, j = len(points), back.shape[1]
        table, log_through = model.table(), np.float32(np.log(model.z_through))
        distance, passable = self.distance_mm.ravel(), self.passable.ravel()
        width, inverse = np.int32(self.distance_mm.shape[1]), 1.0 / self.resolution_m
        px, py = (both * inverse).astype(np.float32).T
        total = np.empty(len(poses))
        for start in range(0, len(poses), chunk):
            x, y, theta = poses[start : start + chunk].T
            c = np.cos(theta).astype(np.float32)[:, None]
            s = np.sin(theta).astype(np.float32)[:, None]
            col = ((x - self.origin_m[0]) * inverse).astype(np.float32)[:, None] + c * px - s * py
            row = ((y - self.origin_m[1]) * inverse).astype(np.float32)[:, None] + s * px + c * py
            flat = row.astype(np.int32) * width + col.astype(np.int32)
            log_p = table[distance.take(flat[:, :k], mode="clip")]
            if j:
                clear = passable.take(flat[:, k:], mode="clip")  # (n, J * K): K per offset
                for offset in range(1, j):
                    clear[:, :k] &= clear[:, offset * k : (offset + 1) * k]
                log_p = np.where(clear[:, :k], log_p, log_through)
            total[start : start + chunk] = log_p.sum(axis=1, dtype=np.float64)
        return total

    def crossed(
        self, pose: np.ndarray, points_robot: np.ndarray, offsets_m: tuple[float, ...]
    ) -> np.ndarray:
        """Whether each return ``points_robot`` (K, 2) [m] seen from ``pose`` [x, y, theta]
        crossed a wall of the plan: a point ``offsets_m`` before its end is not passable (points
        nearer the robot than 0.15 m are not checked)."""
        points = np.asarray(points_robot, dtype=float).reshape(-1, 2)
        ranges = np.maximum(np.hypot(points[:, 0], points[:, 1]), 1e-9)
        back = ranges[:, None] - np.asarray(offsets_m, float)[None, :]
        checked = points[:, None, :] / ranges[:, None, None] * back[..., None]  # (K, J, 2)
        c, s = np.cos(pose[2]), np.sin(pose[2])
        world = checked @ np.array([[c, s], [-s, c]]) + np.asarray(pose[:2], float)
        return ((back >= 0.15) & ~self.passable[self.cells(world)]).any(axis=1)

    def is_free(self, xy: np.ndarray) -> np.ndarray:
        """Whether the robot's centre can be at each point ``xy`` (..., 2) [m]."""
        h, w = self.free.shape
        col = np.floor((xy[..., 0] - self.origin_m[0]) / self.resolution_m)
        row = np.floor((xy[..., 1] - self.origin_m[1]) / self.resolution_m)
        inside = (col >= 0) & (col < w) & (row >= 0) & (row < h)
        return inside & self.free[self.cells(xy)]

    def sample_free(self, n: int, rng: np.random.Generator) -> np.ndarray:
        """``n`` points (n, 2) [m] drawn uniformly over the free cells."""
        rows, cols = np.nonzero(self.free)
        pick = rng.integers(0, len(rows), n)
        jitter = rng.random((n, 2))
        return np.stack(
            [
                self.origin_m[0] + (cols[pick] + jitter[:, 0]) * self.resolution_m,
                self.origin_m[1] + (rows[pick] + jitter[:, 1]) * self.resolution_m,
            ],
            axis=1,
        )


FIXED_SHIFT = 4
"""Fractional bits of the OpenCV drawing coordinates (1/16 px)."""


def _fixed(point_px: np.ndarray) -> tuple[int, int]:
    scale = 1 << FIXED_SHIFT
    return int(round(point_px[0] * scale)), int(round(point_px[1] * scale))


def _face_distance(
    segments: np.ndarray, shape: tuple[int, int], origin: tuple[float, float], resolution_m: float
) -> np.ndarray:
    """(H, W) distance [m] from each cell centre to the nearest of ``segments`` (N, 4) [m].

    The segments are drawn with their index, a distance transform finds each cell's nearest
    drawn pixel and so its segment, and the distance to that segment is computed exactly: a
    wall face lying on a cell boundary is not moved half a cell to one side.
    """
    ids = np.zeros(shape, np.int32)
    to_px = lambda xy: (np.asarray(xy) - origin) / resolution_m - 0.5  # noqa: E731
    for i, (x0, y0, x1, y1) in enumerate(segments):
        a, b = to_px([x0, y0]), to_px([x1, y1])
        cv2.line(ids, _fixed(a), _fixed(b), i + 1, 1, cv2.LINE_8, FIXED_SHIFT)
    faces = ids > 0
    _, labels = cv2.distanceTransformWithLabels(
        (~faces).astype(np.uint8), cv2.DIST_L2, 5, labelType=cv2.DIST_LABEL_PIXEL
    )
    segment_of_label = np.zeros(labels.max() + 1, np.int32)
    segment_of_label[labels[faces]] = ids[faces] - 1
    nearest = segments[segment_of_label[labels]]  # (H, W, 4)
    rows, cols = np.indices(shape)
    x = origin[0] + (cols + 0.5) * resolution_m
    y = origin[1] + (rows + 0.5) * resolution_m
    ax, ay = nearest[..., 0], nearest[..., 1]
    bx, by = nearest[..., 2] - ax, nearest[..., 3] - ay
    t = np.clip(((x - ax) * bx + (y - ay) * by) / np.maximum(bx * bx + by * by, 1e-18), 0, 1)
    return np.hypot(x - ax - t * bx, y - ay - t * by)


def _fill(polygons: list[Polygon], shape: tuple[int, int], to_px) -> np.ndarray:
    """(H, W) bool: the cells whose centre lies in one of ``polygons`` (holes left out)."""
    mask = np.zeros(shape, np.uint8)
    for poly in polygons:
        for part in getattr(poly, "geoms", [poly]):
            if part.is_empty:
                continue
            rings = [np.asarray(part.exterior.coords)[:, :2]]
            rings += [np.asarray(r.coords)[:, :2] for r in part.interiors]
            pts = [np.round(to_px(r) * (1 << FIXED_SHIFT)).astype(np.int32) for r in rings]
            layer = np.zeros(shape, np.uint8)
            cv2.fillPoly(layer, pts[:1], 1, cv2.LINE_8, FIXED_SHIFT)
            if len(pts) > 1:
                cv2.fillPoly(layer, pts[1:], 0, cv2.LINE_8, FIXED_SHIFT)
            mask |= layer
    return mask > 0


def _enclosed(open_cells: np.ndarray) -> np.ndarray:
    """The ``open_cells`` not connected (4-neighbours) to the border of the grid."""
    count, labels = cv2.connectedComponents(open_cells.astype(np.uint8), connectivity=4)
    border = np.unique(np.concatenate([labels[0], labels[-1], labels[:, 0], labels[:, -1]]))
    return open_cells & ~np.isin(labels, border)


__all__ = ["MAX_CELLS", "MAX_DISTANCE_MM", "BeamModel", "LikelihoodField"]
