"""The building the simulated sensors see may differ from the plan the robot knows."""

from __future__ import annotations

import numpy as np
from shapely.geometry import box

from f2n_drake.mapping.walls import PlanGeometry
from f2n_drake.systems.diagram import MakeNavigationDiagram
from f2n_drake.world.building import Building

ROOM = box(0, 0, 4, 3)
WALLS = ROOM.buffer(0.2, join_style="mitre").difference(ROOM)
ROUTE = np.array([(1.0, 1.5), (3.5, 1.5)])


def _scan_ahead(building: Building | None) -> float:
    plan = PlanGeometry([WALLS], [("living", ROOM)])
    diagram = MakeNavigationDiagram(plan, ROUTE, correction="off", building=building)
    context = diagram.CreateDefaultContext()
    lidar = diagram.GetSubsystemByName("lidar")
    walls = lidar.wall_segments(lidar.GetMyContextFromRoot(context))
    return float(lidar.measure(np.array([1.0, 1.5, 0.0]), walls, 0)[0])


def test_as_planned_building_is_the_plan():
    plan = PlanGeometry([WALLS], [("living", ROOM)])
    assert _scan_ahead(Building.as_planned(plan)) == _scan_ahead(None)
    assert abs(_scan_ahead(None) - 3.0) < 0.05  # the far wall, 3 m ahead


def test_lidar_sees_furniture_the_plan_lacks():
    building = Building(walls=(WALLS,), furniture=(box(1.5, 1.2, 1.9, 1.8),))
    assert abs(_scan_ahead(building) - 0.5) < 0.05
