"""The building the simulated sensors see may differ from the plan the robot knows."""

from __future__ import annotations

import numpy as np
import pytest
from shapely.geometry import box

from f2n_drake.mapping.walls import PlanGeometry
from f2n_drake.systems.diagram import MakeNavigationDiagram
from f2n_drake.world.building import Building, Cylinder, Person

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


def _lidar_at(building: Building, pose) -> tuple[np.ndarray, np.ndarray]:
    """(ranges of the scan from ``pose``, the circles the LiDAR sees) in ``building``."""
    plan = PlanGeometry([WALLS], [("living", ROOM)])
    diagram = MakeNavigationDiagram(plan, ROUTE, correction="off", building=building)
    context = diagram.CreateDefaultContext()
    lidar = diagram.GetSubsystemByName("lidar")
    lidar_context = lidar.GetMyContextFromRoot(context)
    walls, circles = lidar.wall_segments(lidar_context), lidar.circles(lidar_context)
    return lidar.measure(np.asarray(pose, float), walls, 0, circles), circles


def test_lidar_sees_round_furniture_and_people_but_not_itself():
    standing = Person(np.array([(1.0, 2.5), (1.0, 2.5)]), radius_m=0.25)
    building = Building(walls=(WALLS,), cylinders=(Cylinder((2.5, 1.5), 0.3),), people=(standing,))
    ranges, circles = _lidar_at(building, [1.0, 1.5, 0.0])
    assert len(circles) == 2  # the cylinder and the person; the robot's own body is not there
    assert ranges[0] == pytest.approx(1.2, abs=0.05)  # cylinder surface 1.2 m ahead
    assert ranges[90] == pytest.approx(0.75, abs=0.05)  # the person 1 m to the left
    assert ranges[270] == pytest.approx(1.5, abs=0.05)  # the wall behind, to the right


def test_a_closed_door_is_a_wall_for_the_lidar(plan_and_graph, route):
    from f2n_drake.world.generation import make_building
    from f2n_drake.world.options import WorldOptions

    plan, graph = plan_and_graph
    pose = np.array([2.7, 1.6, 0.0])  # facing the door, 0.3 m from the doorway
    scans = []
    for closed in (0, 1):
        options = WorldOptions(closed_doors=closed)
        building = make_building(plan, graph, route, options, np.random.default_rng(0))
        diagram = MakeNavigationDiagram(plan, route, correction="off", building=building)
        lidar = diagram.GetSubsystemByName("lidar")
        lidar_context = lidar.GetMyContextFromRoot(diagram.CreateDefaultContext())
        scans.append(lidar.measure(pose, lidar.wall_segments(lidar_context), 0)[0])
    assert scans[0] == pytest.approx(6.2 - 2.7, abs=0.05)  # through the door to the far wall
    assert scans[1] == pytest.approx(0.3, abs=0.05)  # the closed door
