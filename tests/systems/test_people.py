"""The People system: ports, walking at speed to and fro, waiting for the robot, and how the
collision monitor tells contacts with people from collisions with walls."""

from __future__ import annotations

import numpy as np
import pytest
from pydrake.geometry import SceneGraph
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource
from shapely.geometry import box

from f2n_drake.mapping.walls import PlanGeometry
from f2n_drake.systems.collision_monitor import CollisionMonitor
from f2n_drake.systems.people import People
from f2n_drake.systems.scene import AddPlanGeometry
from f2n_drake.systems.unicycle_plant import UnicyclePlant
from f2n_drake.systems.vectors import CollisionStatus, PersonCollisions
from f2n_drake.world.building import Person

WALK = Person(np.array([(0.0, 0.0), (2.0, 0.0)]), speed_mps=1.0, radius_m=0.25)


def walking(people, robot_xy, seconds: float) -> np.ndarray:
    """(N, 2) positions after ``seconds`` with the robot held at ``robot_xy``."""
    builder = DiagramBuilder()
    system = builder.AddNamedSystem("people", People(people))
    robot = builder.AddSystem(ConstantVectorSource([*robot_xy, 0.0]))
    builder.Connect(robot.get_output_port(), system.GetInputPort("true_pose"))
    simulator = Simulator(builder.Build())
    simulator.AdvanceTo(seconds)
    context = system.GetMyContextFromRoot(simulator.get_context())
    return system.GetOutputPort("positions").Eval(context).reshape(-1, 2)


def test_ports():
    system = People([WALK, WALK])
    assert system.GetInputPort("true_pose").size() == 3
    assert system.GetOutputPort("positions").size() == 4
    assert system.HasOutputPort("geometry_pose")
    with pytest.raises(ValueError):
        People([])


def test_walks_at_its_speed_and_turns_back_at_the_end():
    fast = Person(WALK.path_m, speed_mps=1.3, radius_m=0.25)
    (at_1s, back), far = walking([fast, WALK], (50.0, 50.0), 1.0), (50.0, 50.0)
    assert at_1s == pytest.approx([1.3, 0.0], abs=0.14)  # one 10 Hz step of slack
    assert back[0] == pytest.approx(1.0, abs=0.11)
    (returning,) = walking([WALK], far, 3.0)  # 2 m out, then 1 m back
    assert returning[0] == pytest.approx(1.0, abs=0.11)


def test_waits_for_a_robot_ahead_and_walks_on_past_one_behind():
    (waiting,) = walking([WALK], (1.5, 0.1), 2.5)
    reach = WALK.radius_m + 0.105
    assert 0.3 < waiting[0] < 1.5 - reach  # walked, then stopped short of the robot
    (passing,) = walking([Person(WALK.path_m, 1.0, 0.25, offset_m=1.0)], (0.5, 0.0), 0.5)
    assert passing[0] > 1.3  # the robot behind does not hold it up


def test_kept_waiting_a_person_turns_back():
    long_walk = Person(np.array([(-3.0, 0.0), (2.0, 0.0)]), 1.0, 0.25, offset_m=3.0)
    (stopped,) = walking([long_walk], (1.5, 0.1), 3.0)
    (turned,) = walking([long_walk], (1.5, 0.1), 6.0)  # 3 s of patience, then back
    assert 0.3 < stopped[0] < 1.5 - 0.355 and turned[0] < stopped[0] - 1.5


def test_a_person_walking_away_from_a_robot_close_behind_does_not_wait():
    system = People([WALK])  # (0, 0) -> (2, 0) and back: a 4 m round trip
    robot = np.array([0.6, 0.0])  # 0.3 m from a person standing at x = 0.3
    assert system.waits(0, 0.3, robot) is True  # walking out, toward the robot
    assert system.waits(0, 4.0 - 0.3, robot) is False  # walking back, away from it


def contact_sample(robot_x: float, person_in_wall: bool = True):
    """(collision, person_collision) with a person at (2, 0), inside a wall when asked."""
    builder = DiagramBuilder()
    scene_graph = builder.AddNamedSystem("scene_graph", SceneGraph())
    wall = box(1.9, -1.0, 2.1, 1.0) if person_in_wall else box(5.0, -1.0, 5.2, 1.0)
    AddPlanGeometry(scene_graph, PlanGeometry([wall]))
    plant = UnicyclePlant.AddToBuilder(builder, scene_graph, [robot_x, 0.0, 0.0])
    person = Person(np.array([(2.0, 0.0), (2.0, 0.0)]), radius_m=0.25)
    people = People.AddToBuilder(builder, scene_graph, [person, person])  # two, overlapping
    builder.Connect(plant.GetOutputPort("state"), people.GetInputPort("true_pose"))
    monitor = builder.AddNamedSystem("monitor", CollisionMonitor())
    builder.Connect(scene_graph.get_query_output_port(), monitor.GetInputPort("geometry_query"))
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    plant.GetInputPort("command").FixValue(plant.GetMyContextFromRoot(context), [0.0, 0.0])
    monitor_context = monitor.GetMyContextFromRoot(context)
    for _ in range(3):  # three samples in contact are one contact
        monitor_context.SetDiscreteState(monitor.EvalUniquePeriodicDiscreteUpdate(monitor_context))
    return (
        CollisionStatus(monitor.GetOutputPort("collision").Eval(monitor_context)),
        PersonCollisions(monitor.GetOutputPort("person_collision").Eval(monitor_context)),
    )


def test_people_collide_with_nothing_but_the_robot():
    collision, person = contact_sample(robot_x=1.4)  # people in a wall and in each other
    assert collision.count == 0 and person.contacts == 0 and person.in_contact == 0
    assert person.min_clearance_m == pytest.approx(2.0 - 1.4 - 0.25 - 0.105, abs=1e-3)
    assert collision.min_clearance_m == pytest.approx(1.9 - 1.4 - 0.105, abs=1e-3)


def test_contact_with_a_person_is_counted_apart_from_collisions():
    collision, person = contact_sample(robot_x=1.7, person_in_wall=False)
    assert collision.count == 0 and collision.collided == 0
    assert person.in_contact == 1 and person.contacts == 1 and person.min_clearance_m < 0
