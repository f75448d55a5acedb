"""What the LiDAR sees and the plan does not: unexplained returns and a world-frame costmap.

A return is *explained* when it lies within a few centimetres of a wall of the plan at the
estimated pose (:class:`WallDistance`, a distance raster of the plan's wall outlines). The
others (furniture, people, a closed door) are evidence of an obstacle: :class:`LocalCostmap`
counts it per cell of a world-frame grid (``hit`` per return, up to ``max_count``), and every
beam that passes through a cell takes ``miss`` off it (free-space clearing; a cell with a return
in the same scan keeps it), so a person who walks away is forgotten after a scan or two. A cell
with at least ``occupied`` is an obstacle. The counts are a plain int8 array the caller keeps
(a Drake state); the updates are pure and vectorised (one scan: a few thousand cells).
"""

from __future__ import annotations

import math

import cv2
import numpy as np
from numba import njit

from f2n_drake.localization.scans import beam_angles


class WallDistance:
    """Distance [m] from points to the nearest plan wall outline, from a raster.

    Args:
        wall_segments: (N, 4) plan walls [x0, y0, x1, y1] [m].
        resolution_m: raster cell [m].
        margin_m: the raster covers the walls' bounds plus this [m]; beyond it the distance is
            ``margin_m`` (far from every wall).
    """

    def __init__(
        self, wall_segments: np.ndarray, resolution_m: float = 0.02, margin_m: float = 1.0
    ) -> None:
        segments = np.asarray(wall_segments, float).reshape(-1, 4)
        points = segments.reshape(-1, 2)
        lo = points.min(axis=0) - margin_m if len(points) else np.zeros(2)
        hi = points.max(axis=0) + margin_m if len(points) else np.ones(2)
        self.origin, self.resolution_m, self.margin_m = lo, float(resolution_m), float(margin_m)
        cols, rows = np.ceil((hi - lo) / resolution_m).astype(int) + 1
        lines = np.full((rows, cols), 255, np.uint8)
        ends = np.rint((points - lo) / resolution_m).astype(np.int32).reshape(-1, 2, 2)
        for (c0, r0), (c1, r1) in ends:
            cv2.line(lines, (int(c0), int(r0)), (int(c1), int(r1)), 0, 1)
        distance = cv2.distanceTransform(lines, cv2.DIST_L2, cv2.DIST_MASK_PRECISE)
        self.raster = distance.astype(np.float32) * self.resolution_m

    def __call__(self, points_m: np.ndarray) -> np.ndarray:
        """(N,) distance [m] of each point to the nearest wall (``margin_m`` off the raster)."""
        points = np.asarray(points_m, float).reshape(-1, 2)
        col, row = np.rint((points - self.origin) / self.resolution_m).astype(int).T
        rows, cols = self.raster.shape
        inside = (row >= 0) & (row < rows) & (col >= 0) & (col < cols)
        out = np.full(len(points), self.margin_m)
        out[inside] = self.raster[row[inside], col[inside]]
        return out


def scan_endpoints(pose: np.ndarray, ranges: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """World points [m] of the finite returns of a scan taken at ``pose`` [x, y, theta], and
    the beam index of each; beam i at ``2 pi i / len(ranges)`` from the heading."""
    ranges = np.asarray(ranges, float)
    beams = np.flatnonzero(np.isfinite(ranges))
    angles = beam_angles(len(ranges))[beams] + pose[2]
    r = ranges[beams]
    points = np.column_stack([pose[0] + r * np.cos(angles), pose[1] + r * np.sin(angles)])
    return points, beams


@njit(cache=True, nogil=True)
def _cells_passed(x0, y0, cos, sin, reach, rows, cols):
    """Flat indices of the grid cells the beams pass through, each once (grid units: the
    start (x0, y0), each beam's direction and reach [cells]); half-cell steps."""
    total = 0
    for b in range(cos.shape[0]):
        total += int(reach[b] * 2.0)
    seen = np.zeros(rows * cols, np.bool_)
    out = np.empty(min(total, rows * cols), np.int64)
    n = 0
    for b in range(cos.shape[0]):
        for k in range(int(reach[b] * 2.0)):
            t = 0.5 * k
            col = int(np.floor(x0 + cos[b] * t))
            row = int(np.floor(y0 + sin[b] * t))
            if row < 0 or row >= rows or col < 0 or col >= cols:
                break
            i = row * cols + col
            if not seen[i]:
                seen[i] = True
                out[n] = i
                n += 1
    return out[:n]


class LocalCostmap:
    """A world-frame grid of obstacle evidence over ``bounds`` (see the module docstring).

    Args:
        bounds: (xmin, ymin, xmax, ymax) [m] the grid covers (the plan's, with a margin).
        resolution_m: cell side [m].
        hit, miss, occupied, max_count: evidence per return, taken off per beam passing
            through, the count that makes an obstacle, and the cap.
        mark_range_m: returns farther than this do not mark [m].
        clear_range_m: beams clear cells up to this range [m] (no return: all of it).
    """

    def __init__(
        self,
        bounds: tuple[float, float, float, float],
        resolution_m: float = 0.05,
        *,
        hit: int = 2,
        miss: int = 1,
        occupied: int = 3,
        max_count: int = 6,
        mark_range_m: float = 3.0,
        clear_range_m: float = 3.0,
    ) -> None:
        xmin, ymin, xmax, ymax = (float(b) for b in bounds)
        if not (xmax > xmin and ymax > ymin and resolution_m > 0):
            raise ValueError("LocalCostmap needs bounds with xmax > xmin, ymax > ymin")
        self.origin = np.array([xmin, ymin])
        self.resolution_m = float(resolution_m)
        self.shape = (
            math.ceil((ymax - ymin) / resolution_m) + 1,
            math.ceil((xmax - xmin) / resolution_m) + 1,
        )
        self.hit, self.miss, self.occupied, self.max_count = hit, miss, occupied, max_count
        self.mark_range_m, self.clear_range_m = float(mark_range_m), float(clear_range_m)
        _cells_passed(0.0, 0.0, np.ones(1), np.zeros(1), np.ones(1), 1, 1)  # compile or load

    def empty(self) -> np.ndarray:
        """A grid without evidence (int8 counts)."""
        return np.zeros(self.shape, np.int8)

    def cells(self, points_m: np.ndarray) -> np.ndarray:
        """Flat indices of the cells of ``points_m`` ((N, 2) [m]); -1 off the grid."""
        points = np.asarray(points_m, float).reshape(-1, 2)
        col, row = np.floor((points - self.origin) / self.resolution_m).astype(np.int64).T
        inside = (row >= 0) & (row < self.shape[0]) & (col >= 0) & (col < self.shape[1])
        return np.where(inside, row * self.shape[1] + col, -1)

    def update(
        self,
        counts: np.ndarray,
        pose: np.ndarray,
        ranges: np.ndarray,
        unexplained: np.ndarray,
    ) -> np.ndarray:
        """New counts after one scan at ``pose`` [x, y, theta].

        Args:
            counts: the grid so far (not modified).
            ranges: the scan [m] (``inf``: no return).
            unexplained: (len(ranges),) bool, returns the plan does not explain.
        """
        ranges = np.asarray(ranges, float)
        angles = beam_angles(len(ranges)) + pose[2]
        # Clear up to a cell short of each return (all the way without one).
        reach = np.where(np.isfinite(ranges), ranges - self.resolution_m, self.clear_range_m)
        passed = _cells_passed(
            float(pose[0] - self.origin[0]) / self.resolution_m,
            float(pose[1] - self.origin[1]) / self.resolution_m,
            np.cos(angles),
            np.sin(angles),
            np.minimum(reach, self.clear_range_m) / self.resolution_m,
            self.shape[0],
            self.shape[1],
        )
        marks = np.isfinite(ranges) & unexplained & (ranges <= self.mark_range_m)
        r = ranges[marks]
        hits = self.cells(
            np.column_stack(
                [pose[0] + r * np.cos(angles[marks]), pose[1] + r * np.sin(angles[marks])]
            )
        )
        hits = hits[hits >= 0]
        out = counts.astype(np.int16).ravel()
        before = out[hits]
        out[passed] -= self.miss
        out[hits] = before + self.hit  # a cell hit in this scan is not cleared by it
        return np.clip(out, 0, self.max_count).astype(np.int8).reshape(self.shape)

    def mark(self, counts: np.ndarray, points_m: np.ndarray) -> np.ndarray:
        """New counts with the cells of ``points_m`` set to obstacles at once."""
        out = counts.copy().ravel()
        cells = self.cells(points_m)
        out[cells[cells >= 0]] = self.max_count
        return out.reshape(self.shape)

    def obstacles(self, counts: np.ndarray, mask: np.ndarray | None = None) -> np.ndarray:
        """(M, 2) centres [m] of the obstacle cells (and of ``mask``, if given)."""
        occupied = counts >= self.occupied
        rows, cols = np.nonzero(occupied if mask is None else occupied & mask)
        return self.origin + (np.column_stack([cols, rows]) + 0.5) * self.resolution_m

    def since(self, counts: np.ndarray, previous: np.ndarray | None, time_s: float) -> np.ndarray:
        """(H, W) float32: when [s] each cell with evidence first became an obstacle, nan for
        the others; ``previous`` is the last scan's (None: none yet). A cell keeps its time
        while it has evidence left (a count dipping below ``occupied`` for a scan does not
        make an old obstacle new); cleared to zero, it forgets it."""
        new = counts >= self.occupied
        if previous is None:
            return np.where(new, np.float32(time_s), np.float32(np.nan)).astype(np.float32)
        out = np.where(np.isnan(previous) & new, np.float32(time_s), previous)
        out[counts == 0] = np.nan
        return out.astype(np.float32, copy=False)


__all__ = ["LocalCostmap", "WallDistance", "scan_endpoints"]
