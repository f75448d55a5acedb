"""The unknown-start systems: global localizer, careful explorer, handover switches, particle view,
and a short run that localizes, hands over and drives the route."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from pydrake.systems.analysis import Simulator
from shapely.geometry import box

from f2n_drake.core.plan import FloorPlan
from f2n_drake.localization.likelihood_field import LikelihoodField
from f2n_drake.localization.particle_filter import FilterOptions, ParticleCloud
from f2n_drake.localization.scans import simulate_scan
from f2n_drake.mapping.walls import PlanGeometry
from f2n_drake.systems.diagram import MakeNavigationDiagram
from f2n_drake.systems.explorer import (
    CarefulExplorer,
    CarefulMotion,
    careful_command,
    free_distance,
    initial_memory,
)
from f2n_drake.systems.global_localizer import GlobalLocalizer
from f2n_drake.systems.handover import CommandSwitch, PoseGate
from f2n_drake.systems.particle_view import ParticleView, particle_triangles
from f2n_drake.systems.simulation import simulate_navigation

ROOMS = [box(0, 0, 4, 3), box(4.2, 0, 6.2, 2)]
DOOR = box(4, 0.6, 4.2, 1.4)
ROUTE = np.array([(1.5, 1.5), (3.0, 1.0), (4.6, 1.0), (5.4, 1.2)])


def rooms_plan() -> FloorPlan:
    """A 4 x 3 m room beside a 2 x 2 m one, joined by a door, 0.2 m walls."""
    spaces = shapely.union_all([*ROOMS, DOOR])
    walls = box(-0.2, -0.2, 6.4, 3.2).difference(spaces)
    return FloorPlan({"bedroom": ROOMS, "wall": [walls], "door": [DOOR]}, 0.2, "test")


@pytest.fixture(scope="module")
def geometry() -> PlanGeometry:
    return PlanGeometry.from_floorplan(rooms_plan())


def localizer(geometry: PlanGeometry, **kwargs) -> GlobalLocalizer:
    """A localizer that steps on every scan (no motion needed), with a small cloud."""
    options = FilterOptions(
        num_particles=1500, initial_per_m2=1500, initial_min=5000, update_min_m=0, update_min_rad=0
    )
    field = LikelihoodField.from_geometry(geometry)
    return GlobalLocalizer(field, geometry.wall_segments(), 0, options=options, **kwargs)


def test_localizer_ports(geometry):
    system = localizer(geometry)
    inputs = {"scan": 360, "odometry_pose": 3, "tracking_correction": 4}
    outputs = {"localized": 2, "pose_estimate": 3, "pose_correction": 4, "handover": 4}
    for name, size in inputs.items():
        assert system.GetInputPort(name).size() == size
    for name, size in outputs.items():
        assert system.GetOutputPort(name).size() == size
    context = system.CreateDefaultContext()
    np.testing.assert_array_equal(system.GetOutputPort("localized").Eval(context), [0, 0])
    np.testing.assert_array_equal(system.GetOutputPort("pose_correction").Eval(context), 0)
    assert len(system.GetOutputPort("particles").Eval(context)) == 0


def test_localizer_converges_hands_over_and_forwards_tracking(geometry):
    truth = np.array([1.3, 2.2, 2.5])
    system = localizer(geometry)
    context = system.CreateDefaultContext()
    system.GetInputPort("scan").FixValue(context, simulate_scan(truth, geometry.wall_segments()))
    system.GetInputPort("odometry_pose").FixValue(context, np.zeros(3))
    tracking = system.GetInputPort("tracking_correction").FixValue(context, [4.0, 0, 0, 0])
    simulator = Simulator(system, context)
    simulator.AdvanceTo(3.0)
    localized = system.GetOutputPort("localized").Eval(context)
    handover = system.GetOutputPort("handover").Eval(context)
    correction = system.GetOutputPort("pose_correction").Eval(context)
    np.testing.assert_array_equal(localized, [1, 1])
    assert 0 < handover[0] < 3.0
    assert np.hypot(*(handover[1:3] - truth[:2])) < 0.05
    assert abs(handover[3] - truth[2]) < 0.03
    np.testing.assert_allclose(correction, [1.0, *handover[1:]])
    # Later tracking corrections pass through, counted on from the handover.
    tracking.GetMutableData().set_value(np.array([5.0, 1.0, 2.0, 0.1]))
    np.testing.assert_allclose(
        system.GetOutputPort("pose_correction").Eval(context), [2, 1, 2, 0.1]
    )


def test_switch_and_gate_follow_localized():
    switch, gate = CommandSwitch(), PoseGate()
    sc, gc = switch.CreateDefaultContext(), gate.CreateDefaultContext()
    switch.GetInputPort("explorer_command").FixValue(sc, [0.1, 0.2])
    switch.GetInputPort("route_command").FixValue(sc, [0.2, -0.5])
    gate.GetInputPort("estimated_pose").FixValue(gc, [1.0, 2.0, 0.3])
    for localized, command in (([0, 0], [0.1, 0.2]), ([1, 1], [0.2, -0.5])):
        switch.GetInputPort("localized").FixValue(sc, localized)
        gate.GetInputPort("localized").FixValue(gc, localized)
        np.testing.assert_allclose(switch.GetOutputPort("command").Eval(sc), command)
        pose = gate.GetOutputPort("route_pose").Eval(gc)
        assert np.isnan(pose).all() if localized[0] == 0 else np.allclose(pose, [1, 2, 0.3])


def test_free_distance_keeps_the_clearance():
    wall = np.column_stack([np.full(21, 1.0), np.linspace(-1, 1, 21)])  # x = 1 m
    room = free_distance(wall, np.array([0.0, np.pi / 2, np.pi]), 0.25, 3.5)
    np.testing.assert_allclose(room, [0.75, 3.5, 3.5], atol=1e-9)


def test_careful_command_turns_away_from_a_close_wall_and_drives_slowly(geometry):
    walls, motion = geometry.wall_segments(), CarefulMotion()
    facing = np.array([3.65, 1.5, 0.0])  # 0.35 m from the wall ahead
    command, _ = careful_command(
        simulate_scan(facing, walls), facing, initial_memory(facing), motion
    )
    assert command[0] == 0.0 and abs(command[1]) > 0  # turns on the spot
    open_ahead = np.array([1.0, 1.5, 0.0])
    command, memory = careful_command(
        simulate_scan(open_ahead, walls), open_ahead, initial_memory(open_ahead), motion
    )
    assert 0 < command[0] <= motion.speed_mps
    assert memory[1] == 1.0  # a goal heading was chosen
    blind, _ = careful_command(np.full(360, np.inf), open_ahead, memory, motion)
    np.testing.assert_array_equal(blind, [0, 0])  # no scan, no motion


def test_explorer_system_ports():
    explorer = CarefulExplorer()
    assert explorer.GetInputPort("scan").size() == 360
    assert explorer.GetInputPort("odometry_pose").size() == 3
    assert explorer.GetOutputPort("command").size() == 2


def test_particle_view_draws_until_localized(monkeypatch):
    monkeypatch.setenv("DRAKE_ALLOW_NETWORK", "meshcat")
    from pydrake.geometry import Meshcat

    meshcat = Meshcat()
    view = ParticleView(meshcat, "runs/test/particles", period_s=0.5)
    context = view.CreateDefaultContext()
    poses = np.random.default_rng(0).uniform(0, 3, (5000, 3))
    view.GetInputPort("particles").FixValue(context, ParticleCloud(poses, np.full(5000, 2e-4)))
    localized = view.GetInputPort("localized").FixValue(context, [0.0, 0.0])
    simulator = Simulator(view, context)
    simulator.AdvanceTo(0.1)  # initialization, then the publish at t = 0
    assert meshcat.HasPath("runs/test/particles/0")
    vertices, faces = particle_triangles(ParticleCloud(poses, np.full(5000, 2e-4)), 1500, 0.1)
    assert vertices.shape == (3, 4500) and faces.shape == (3, 1500)
    tip = vertices[:, 0] - [*poses[0, :2], vertices[2, 0]]  # the first triangle's tip
    np.testing.assert_allclose(tip[:2], 0.06 * np.array([np.cos(poses[0, 2]), np.sin(poses[0, 2])]))
    localized.GetMutableData().set_value(np.array([1.0, 1.0]))
    simulator.AdvanceTo(1.1)
    assert not meshcat.HasPath("runs/test/particles/1")  # nothing new drawn once localized


def test_unknown_start_diagram_structure():
    diagram = MakeNavigationDiagram(rooms_plan(), ROUTE, unknown_start=True)
    for name in ("global_localizer", "explorer", "command_switch", "pose_gate", "corrector"):
        assert diagram.HasSubsystemNamed(name), name
    assert diagram.GetOutputPort("localized").size() == 2
    assert diagram.GetOutputPort("handover").size() == 4
    context = diagram.CreateDefaultContext()
    np.testing.assert_array_equal(diagram.GetOutputPort("estimated_pose").Eval(context), 0)
    known = MakeNavigationDiagram(rooms_plan(), ROUTE)
    assert not known.HasSubsystemNamed("global_localizer")
    assert not known.HasOutputPort("localized")


def test_unknown_start_run_localizes_then_drives_the_route():
    result = simulate_navigation(rooms_plan(), ROUTE, unknown_start=True, seed=1)
    assert result.converged and not result.wrong_convergence
    assert result.converged_error_m < 0.1
    assert 0 < result.time_to_converge_s < 20.0
    assert not result.collided_before_converged and not result.collided
    assert result.success
    assert result.mean_error_m < 0.05  # counted from the handover
