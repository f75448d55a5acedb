"""The one place where metres and pixels meet.

A :class:`PixelGrid` maps plan coordinates in metres (x right, y up) to image pixel coordinates
(column right, row down). Pixel coordinates name pixel centres: pixel ``(col, row)`` covers
``[col - 0.5, col + 0.5) x [row - 0.5, row + 0.5)``, which is OpenCV's convention for drawing.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class PixelGrid:
    """An image raster placed in the plan frame.

    Attributes:
        metres_per_px: side of one pixel [m].
        origin_m: (x, y) in metres of the top-left corner of the image (not of a pixel centre).
        shape: (rows, cols) of the image [px].
    """

    metres_per_px: float
    origin_m: tuple[float, float]
    shape: tuple[int, int]

    def __post_init__(self) -> None:
        if not self.metres_per_px > 0:
            raise ValueError(f"metres_per_px must be positive, got {self.metres_per_px}")

    @classmethod
    def fit(
        cls,
        bounds_m: tuple[float, float, float, float],
        size_px: int,
        margin_px: int = 16,
    ) -> PixelGrid:
        """A square ``size_px`` grid showing ``bounds_m`` (xmin, ymin, xmax, ymax) centred,
        at the largest scale that leaves ``margin_px`` free on every side."""
        xmin, ymin, xmax, ymax = bounds_m
        span = max(xmax - xmin, ymax - ymin, 1e-9)
        metres_per_px = span / (size_px - 2 * margin_px)
        cx, cy = (xmin + xmax) / 2, (ymin + ymax) / 2
        half = size_px * metres_per_px / 2
        return cls(metres_per_px, (cx - half, cy + half), (size_px, size_px))

    @classmethod
    def from_scale(cls, metres_per_px: float, shape: tuple[int, int]) -> PixelGrid:
        """A grid for an image of known scale, origin at its top-left corner (y up)."""
        return cls(metres_per_px, (0.0, shape[0] * metres_per_px), shape)

    def to_px(self, xy_m: np.ndarray) -> np.ndarray:
        """(..., 2) metres -> (..., 2) pixel-centre coordinates (col, row), float."""
        xy_m = np.asarray(xy_m, dtype=float)
        col = (xy_m[..., 0] - self.origin_m[0]) / self.metres_per_px - 0.5
        row = (self.origin_m[1] - xy_m[..., 1]) / self.metres_per_px - 0.5
        return np.stack([col, row], axis=-1)

    def to_m(self, px: np.ndarray) -> np.ndarray:
        """(..., 2) pixel coordinates (col, row) -> (..., 2) metres (x, y)."""
        px = np.asarray(px, dtype=float)
        x = self.origin_m[0] + (px[..., 0] + 0.5) * self.metres_per_px
        y = self.origin_m[1] - (px[..., 1] + 0.5) * self.metres_per_px
        return np.stack([x, y], axis=-1)

    def length_px(self, metres: float) -> float:
        """A length in metres expressed in pixels."""
        return metres / self.metres_per_px

    def area_m2(self, area_px: float) -> float:
        """An area in pixels expressed in square metres."""
        return area_px * self.metres_per_px**2

    def with_shape(self, shape: tuple[int, int]) -> PixelGrid:
        return PixelGrid(self.metres_per_px, self.origin_m, shape)

    def to_dict(self) -> dict:
        return {
            "metres_per_px": self.metres_per_px,
            "origin_m": list(self.origin_m),
            "shape": list(self.shape),
        }

    @classmethod
    def from_dict(cls, data: dict) -> PixelGrid:
        return cls(
            float(data["metres_per_px"]),
            (float(data["origin_m"][0]), float(data["origin_m"][1])),
            (int(data["shape"][0]), int(data["shape"][1])),
        )
