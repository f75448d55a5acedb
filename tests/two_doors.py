"""Two rooms joined by two doors, for the replanning tests (importable as ``two_doors``).

A 3 x 3 m bedroom and a 3 x 3 m living room, 0.2 m walls, the upper door (``door_0``,
y 2.0-2.8 m) and the lower door (``door_1``, y 0.2-1.0 m) in the wall between them at
x 3.0-3.2 m. The planned route from ``START`` to ``GOAL`` goes straight through the upper door.
"""

from __future__ import annotations

from functools import cache

import numpy as np
import shapely
from shapely.geometry import box

from f2n_drake.core.plan import FloorPlan
from f2n_drake.mapping.robots import GROUND
from f2n_drake.mapping.walls import PlanGeometry
from f2n_drake.planning.replanning import Replanner
from f2n_drake.world.building import Building

BEDROOM, LIVING = box(0, 0, 3, 3), box(3.2, 0, 6.2, 3)
UPPER, LOWER = box(3.0, 2.0, 3.2, 2.8), box(3.0, 0.2, 3.2, 1.0)
START, GOAL = np.array([1.0, 2.4]), np.array([5.2, 2.4])


def two_doors() -> FloorPlan:
    walls = box(-0.2, -0.2, 6.4, 3.2).difference(shapely.union_all([BEDROOM, LIVING, UPPER, LOWER]))
    polygons = {"bedroom": [BEDROOM], "living": [LIVING], "wall": [walls], "door": [UPPER, LOWER]}
    return FloorPlan(polygons, 0.2, "test")


def geometry() -> PlanGeometry:
    return PlanGeometry.from_floorplan(two_doors())


@cache
def replanner() -> Replanner:
    """The plan's replanner (rasterised at 256 px, about 3 cm per cell)."""
    from f2n_drake import build_graph
    from f2n_drake.datasets.ground_truth import parse_ground_truth

    plan_map = build_graph(parse_ground_truth(two_doors(), size_px=256), planning_cell_m=None)
    return Replanner.from_plan(plan_map.parsed, plan_map.graph, GROUND)


def door_key(door) -> str:
    """The graph key of the door polygon ``UPPER`` or ``LOWER``."""
    centre = np.array(door.centroid.coords[0])
    return min(replanner().doorways.values(), key=lambda d: np.hypot(*(d.centre_m - centre))).key


def with_closed(*doors) -> Building:
    """The building with ``doors`` (``UPPER``, ``LOWER``) closed: walls there."""
    return Building(
        walls=(*geometry().walls, *doors),
        closed_doors=tuple(door_key(d) for d in doors),
        door_walls=tuple(doors),
    )
