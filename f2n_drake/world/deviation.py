"""Walls a little off their plan: a seeded warp of the plane that moves every wall face by at
most ``deviation_m`` along its normal.

The warp acts on each axis of the plan's dominant frame separately: ``u' = u + f(u)``,
``v' = v + g(v)``, with ``f`` and ``g`` piecewise linear through random knot values in
``[-deviation_m, deviation_m]`` spaced at least ``4 * deviation_m`` (and 1.5 m) apart. A wall
face along the v axis (constant u) therefore stays straight and parallel and moves by
``|f(u)| <= deviation_m``, neighbouring faces move by different amounts (rooms grow or shrink by
up to twice the deviation), and since ``|f'| <= 1/2`` the warp is one-to-one: walls that met
still meet and no gap opens at a corner (shifting each wall rectangle on its own would open
slits the LiDAR sees through). A slanted face moves by at most ``sqrt(2) * deviation_m``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import shapely
from shapely.geometry.base import BaseGeometry

MIN_KNOT_SPACING_M = 1.5


@dataclass(frozen=True)
class AxisWarp:
    """The warp (module docstring) of the plane about ``centre_m``, axes turned by ``angle_rad``.

    ``knots_m`` (K,) are positions along either axis of the turned frame [m]; ``shift_u_m`` and
    ``shift_v_m`` (K,) are the displacements at the knots [m] of u and v.
    """

    centre_m: tuple[float, float]
    angle_rad: float
    knots_m: np.ndarray
    shift_u_m: np.ndarray
    shift_v_m: np.ndarray

    @classmethod
    def random(
        cls,
        bounds: tuple[float, float, float, float],
        deviation_m: float,
        rng: np.random.Generator,
        angle_rad: float = 0.0,
    ) -> AxisWarp:
        """A warp moving faces by at most ``deviation_m`` [m] over ``bounds`` [m]."""
        xmin, ymin, xmax, ymax = bounds
        centre = ((xmin + xmax) / 2, (ymin + ymax) / 2)
        half = math.hypot(xmax - xmin, ymax - ymin) / 2 + 1.0  # reach of the turned frame
        spacing = max(MIN_KNOT_SPACING_M, 4.0 * deviation_m)
        knots = np.arange(-half, half + spacing, spacing)
        shift_u = rng.uniform(-deviation_m, deviation_m, knots.size)
        shift_v = rng.uniform(-deviation_m, deviation_m, knots.size)
        return cls(centre, float(angle_rad), knots, shift_u, shift_v)

    def apply_xy(self, xy: np.ndarray) -> np.ndarray:
        """(N, 2) points [m] warped."""
        c, s = math.cos(self.angle_rad), math.sin(self.angle_rad)
        rotation = np.array([[c, -s], [s, c]])
        local = (np.asarray(xy, float) - self.centre_m) @ rotation  # turned frame
        local[:, 0] += np.interp(local[:, 0], self.knots_m, self.shift_u_m)
        local[:, 1] += np.interp(local[:, 1], self.knots_m, self.shift_v_m)
        return local @ rotation.T + self.centre_m

    def apply(self, geometry: BaseGeometry) -> BaseGeometry:
        """A shapely geometry with every vertex warped."""
        return shapely.transform(geometry, self.apply_xy)


__all__ = ["AxisWarp"]
