"""The building's floor on a square raster: obstacles, the free space of a disc, connectivity.

Cells are ``cell_m`` squares; cell (row, col) has its centre at ``origin_m + (col, row) *
cell_m`` (rows go along +y, no image flip). A polygon covers the cells whose centres it
contains. The free space of a disc of radius ``r`` keeps the cells whose centres lie farther than
``r + cell_m / sqrt(2)`` from every obstacle: between two neighbouring free centres the disc
then keeps ``r`` of clearance too, so a path of free cells is one the disc truly fits along.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import shapely
from scipy import ndimage
from shapely.geometry.base import BaseGeometry

CELL_M = 0.05
"""Default raster cell [m]."""


@dataclass(frozen=True)
class FloorRaster:
    """A raster over a rectangle of the floor (metres)."""

    origin_m: tuple[float, float]
    cell_m: float
    shape: tuple[int, int]

    @classmethod
    def covering(
        cls,
        bounds: tuple[float, float, float, float],
        cell_m: float = CELL_M,
        margin_m: float = 0.5,
    ) -> FloorRaster:
        """The raster covering ``bounds`` (xmin, ymin, xmax, ymax) [m] plus ``margin_m``."""
        xmin, ymin, xmax, ymax = bounds
        cols = int(math.ceil((xmax - xmin + 2 * margin_m) / cell_m)) + 1
        rows = int(math.ceil((ymax - ymin + 2 * margin_m) / cell_m)) + 1
        return cls((xmin - margin_m, ymin - margin_m), float(cell_m), (rows, cols))

    def centres(self, window: tuple[slice, slice] | None = None) -> tuple[np.ndarray, np.ndarray]:
        """x and y [m] of the cell centres (of ``window`` if given), each of the window's shape."""
        rows, cols = window or (slice(0, self.shape[0]), slice(0, self.shape[1]))
        ys = self.origin_m[1] + np.arange(rows.start, rows.stop) * self.cell_m
        xs = self.origin_m[0] + np.arange(cols.start, cols.stop) * self.cell_m
        return np.meshgrid(xs, ys)

    def cell_of(self, xy: np.ndarray) -> tuple[int, int]:
        """(row, col) of the cell nearest to the point ``xy`` [m], clipped to the raster."""
        col = int(round((xy[0] - self.origin_m[0]) / self.cell_m))
        row = int(round((xy[1] - self.origin_m[1]) / self.cell_m))
        return min(max(row, 0), self.shape[0] - 1), min(max(col, 0), self.shape[1] - 1)

    def points_of(self, cells: np.ndarray) -> np.ndarray:
        """(N, 2) centres [m] of (N, 2) (row, col) cells."""
        cells = np.asarray(cells, dtype=float).reshape(-1, 2)
        return np.asarray(self.origin_m) + cells[:, ::-1] * self.cell_m

    def window(self, bounds: tuple[float, float, float, float]) -> tuple[slice, slice]:
        """The cells whose centres may fall in ``bounds`` (xmin, ymin, xmax, ymax) [m]."""
        r0, c0 = self.cell_of((bounds[0], bounds[1]))
        r1, c1 = self.cell_of((bounds[2], bounds[3]))
        return slice(max(r0 - 1, 0), r1 + 2), slice(max(c0 - 1, 0), c1 + 2)

    def cover(self, geometry: BaseGeometry, out: np.ndarray | None = None) -> np.ndarray:
        """Bool raster of the cells whose centres lie in ``geometry`` (or'ed into ``out``)."""
        out = np.zeros(self.shape, bool) if out is None else out
        if geometry.is_empty:
            return out
        window = self.window(geometry.bounds)
        xs, ys = self.centres(window)
        shapely.prepare(geometry)
        out[window] |= shapely.contains_xy(geometry, xs, ys)
        return out

    def blocked_by(
        self, geometry: BaseGeometry, radius_m: float, out: np.ndarray | None = None
    ) -> np.ndarray:
        """The cells where a disc of ``radius_m`` [m] would not fit beside ``geometry`` (module
        docstring: radius plus a half-diagonal), or'ed into ``out``."""
        margin = radius_m + self.cell_m / math.sqrt(2.0)
        return self.cover(geometry.buffer(margin, quad_segs=4), out)


def same_component(free: np.ndarray, a: tuple[int, int], b: tuple[int, int]) -> bool:
    """Whether cells ``a`` and ``b`` (row, col) are free and joined through 8-connected free
    cells."""
    if not (free[a] and free[b]):
        return False
    labels, _ = ndimage.label(free, structure=np.ones((3, 3), bool))
    return bool(labels[a] == labels[b])


__all__ = ["CELL_M", "FloorRaster", "same_component"]
