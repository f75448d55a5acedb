"""Whether the building leaves the robot a way from start to goal (ground truth, for the
evaluation: the robot never asks)."""

from __future__ import annotations

import numpy as np
import shapely

from f2n_drake.mapping.walls import PlanGeometry
from f2n_drake.world.building import Building
from f2n_drake.world.free_space import FloorRaster, same_component

INSIDE_MARGIN_M = 0.15
"""The inside of the building: its floors and connectors grown by this much [m]."""


def way_exists(
    building: Building,
    plan: PlanGeometry,
    start_xy: np.ndarray,
    goal_xy: np.ndarray,
    robot_radius_m: float,
    cell_m: float = 0.05,
) -> bool:
    """Whether a disc of ``robot_radius_m`` [m] can go from ``start_xy`` to ``goal_xy`` [m]
    inside the building (its floors and connectors) past its walls and furniture, on a
    ``cell_m`` raster (:mod:`f2n_drake.world.free_space`; a way found is one the disc fits
    along, a way narrower than a cell more than the disc may be missed)."""
    raster = FloorRaster.covering(plan.bounds(), cell_m)
    inside = shapely.union_all(
        [p for _, p in plan.floors] + [p for _, p in plan.connectors]
    ).buffer(INSIDE_MARGIN_M)
    obstacles = shapely.union_all(
        [*building.walls, *building.furniture, *(c.footprint() for c in building.cylinders)]
    )
    free = raster.cover(inside) & ~raster.blocked_by(obstacles, robot_radius_m)
    return same_component(free, raster.cell_of(start_xy), raster.cell_of(goal_xy))


__all__ = ["way_exists"]
