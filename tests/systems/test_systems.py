"""Each navigation LeafSystem with pinned inputs, plus the plan-to-SceneGraph geometry."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from pydrake.geometry import Role, SceneGraph
from pydrake.systems.framework import DiagramBuilder
from shapely import affinity
from shapely.geometry import box

from f2n_drake.mapping.walls import PlanGeometry, decompose_rectangles
from f2n_drake.systems.collision_monitor import CollisionMonitor
from f2n_drake.systems.controller import PurePursuitController
from f2n_drake.systems.lidar import Lidar2D
from f2n_drake.systems.noisy_odometry import NoisyOdometry
from f2n_drake.systems.scene import AddPlanGeometry
from f2n_drake.systems.unicycle_plant import UnicyclePlant
from f2n_drake.systems.waypoint_source import WaypointSource, densify_route


def rect_polygons(rects):
    out = []
    for x, y, length, width, yaw in rects:
        b = affinity.rotate(
            box(-length / 2, -width / 2, length / 2, width / 2),
            yaw,
            origin=(0, 0),
            use_radians=True,
        )
        out.append(affinity.translate(b, x, y))
    return out


@pytest.mark.parametrize("angle_deg", [0.0, 20.0, -45.0])
def test_decompose_rectilinear_wall_exactly(angle_deg):
    walls = shapely.union_all(
        [
            box(0, 0, 5, 0.2),
            box(0, 0, 0.2, 4),
            box(4.8, 0, 5, 4),
            box(0, 3.8, 2, 4),
            box(3, 3.8, 5, 4),
        ]
    )
    walls = affinity.rotate(walls, angle_deg, origin=(0, 0))
    pieces = rect_polygons(decompose_rectangles(walls))
    assert len(pieces) <= 6
    assert walls.symmetric_difference(shapely.union_all(pieces)).area < 1e-9
    assert sum(p.area for p in pieces) == pytest.approx(walls.area, abs=1e-9)  # no overlap


def test_decompose_curved_shape_is_approximated():
    disc = shapely.Point(0, 0).buffer(1.0)
    pieces = rect_polygons(decompose_rectangles(disc, resolution_m=0.02))
    # on a 1 nm grid: GEOS (3.13) unions these edge-sharing rotated boxes wrongly without one,
    # depending on the disc's arbitrary dominant angle (0.19 m^2 lost at -0.48 rad)
    covered = shapely.union_all(pieces, grid_size=1e-9)
    assert disc.symmetric_difference(covered).area < 0.05
    assert sum(p.area for p in pieces) == pytest.approx(covered.area, rel=1e-6)  # no overlap


def test_plan_geometry_segments_and_scene_graph_roles():
    geometry = PlanGeometry(
        [box(0, 0, 1, 0.2), box(2, 0, 2.2, 1)], [("bedroom", box(0, 0.2, 2, 1))]
    )
    assert geometry.wall_segments().shape == (8, 4)
    scene_graph = SceneGraph()
    AddPlanGeometry(scene_graph, geometry)
    inspector = scene_graph.model_inspector()
    assert len(inspector.GetAllGeometryIds(Role.kProximity)) == 2
    assert len(inspector.GetAllGeometryIds(Role.kIllustration)) == 3  # floor: illustration only


def test_unicycle_clips_command_and_integrates():
    plant = UnicyclePlant([1.0, 2.0, np.pi / 2])
    context = plant.CreateDefaultContext()
    plant.GetInputPort("command").FixValue(context, [1.0, -10.0])
    np.testing.assert_allclose(plant.GetOutputPort("state").Eval(context), [1.0, 2.0, np.pi / 2])
    derivatives = plant.EvalTimeDerivatives(context).CopyToVector()
    np.testing.assert_allclose(derivatives, [0.0, 0.22, -2.84], atol=1e-12)


def test_waypoint_source_advances_and_finishes():
    source = WaypointSource(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]), tolerance_m=0.1)
    context = source.CreateDefaultContext()
    pose_port = source.GetInputPort("estimated_pose")
    pose_port.FixValue(context, [0.05, 0.0, 0.0])
    context.SetDiscreteState(0, source.EvalUniquePeriodicDiscreteUpdate(context).value(0))
    np.testing.assert_allclose(source.GetOutputPort("target").Eval(context), [1.0, 0.0])
    np.testing.assert_allclose(source.GetOutputPort("segment").Eval(context), [0, 0, 1, 0])
    np.testing.assert_allclose(source.GetOutputPort("progress").Eval(context), [1, 0])
    pose_port.FixValue(context, [0.5, 0.0, 0.0])  # not there yet
    context.SetDiscreteState(0, source.EvalUniquePeriodicDiscreteUpdate(context).value(0))
    np.testing.assert_allclose(source.GetOutputPort("progress").Eval(context), [1, 0])
    for xy in ([1.0, 0.05], [1.0, 0.95]):
        pose_port.FixValue(context, [*xy, 0.0])
        context.SetDiscreteState(0, source.EvalUniquePeriodicDiscreteUpdate(context).value(0))
    np.testing.assert_allclose(source.GetOutputPort("progress").Eval(context), [2, 1])


def odometry_run(seed, correction=None, steps=20):
    odometry = NoisyOdometry([0.0, 0.0, 0.0], seed=seed, xy_sigma_m=0.02)
    context = odometry.CreateDefaultContext()
    if correction is not None:
        odometry.GetInputPort("pose_correction").FixValue(context, correction)
    for k in range(steps):
        odometry.GetInputPort("true_pose").FixValue(context, [0.02 * (k + 1), 0.0, 0.0])
        values = odometry.EvalUniquePeriodicDiscreteUpdate(context)
        for i in range(values.num_groups()):
            context.SetDiscreteState(i, values.value(i))
    return odometry.GetOutputPort("estimated_pose").Eval(context).copy()


def test_odometry_noise_reproducible_per_seed():
    a, b, c = odometry_run(1), odometry_run(1), odometry_run(2)
    np.testing.assert_array_equal(a, b)
    assert np.linalg.norm(a - c) > 1e-3
    assert 0.0 < np.hypot(a[0] - 0.4, a[1]) < 0.4  # 20 steps of 20 mm noise around the truth
    assert a[2] == pytest.approx(0.0)  # accurate IMU yaw


def test_odometry_follows_motion_without_noise():
    odometry = NoisyOdometry([1.0, 1.0, np.pi / 2], seed=0, xy_sigma_m=0.0)
    context = odometry.CreateDefaultContext()
    odometry.GetInputPort("true_pose").FixValue(context, [1.0, 1.3, np.pi / 2 + 0.1])
    context.SetDiscreteState(0, odometry.EvalUniquePeriodicDiscreteUpdate(context).value(0))
    np.testing.assert_allclose(
        odometry.GetOutputPort("estimated_pose").Eval(context),
        [1.0, 1.3, np.pi / 2 + 0.1],
        atol=1e-12,
    )


def test_odometry_applies_correction_when_count_increases():
    corrected = odometry_run(3, correction=[1.0, 5.0, 6.0, 0.5], steps=1)
    # The correction replaces the estimate, then this tick's motion (0.02 m forward) and noise.
    assert np.hypot(corrected[0] - 5.0 - 0.02 * np.cos(0.5), corrected[1] - 6.0) < 0.1
    assert corrected[2] == pytest.approx(0.5)
    unchanged = odometry_run(3, correction=[0.0, 5.0, 6.0, 0.5], steps=1)
    assert np.hypot(*unchanged[:2]) < 0.1


def lidar_scene(walls, pose):
    builder = DiagramBuilder()
    scene_graph = builder.AddNamedSystem("scene_graph", SceneGraph())
    AddPlanGeometry(scene_graph, PlanGeometry(walls))
    lidar = builder.AddNamedSystem("lidar", Lidar2D(seed=0, range_sigma_m=0.0))
    builder.Connect(scene_graph.get_query_output_port(), lidar.GetInputPort("geometry_query"))
    builder.ExportInput(lidar.GetInputPort("true_pose"), "true_pose")
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    diagram.GetInputPort("true_pose").FixValue(context, pose)
    lidar_context = lidar.GetMyContextFromRoot(context)
    values = lidar.EvalUniquePeriodicDiscreteUpdate(lidar_context)
    for i in range(values.num_groups()):
        lidar_context.SetDiscreteState(i, values.value(i))
    return lidar, lidar_context


def test_lidar_range_to_box_wall_and_max_range():
    wall = box(1.0, -2.0, 1.2, 2.0)  # faces the robot 1 m ahead
    lidar, context = lidar_scene([wall], [0.0, 0.0, 0.0])
    scan = lidar.GetOutputPort("scan").Eval(context)
    assert scan.shape == (360,)
    assert scan[0] == pytest.approx(1.0, abs=1e-9)
    assert scan[30] == pytest.approx(1.0 / np.cos(np.radians(30)), abs=1e-9)
    assert np.all(np.isinf(scan[90:271]))  # nothing behind: no return is +inf
    assert lidar.wall_segments(context).shape == (4, 4)
    lidar, context = lidar_scene([wall], [0.0, 0.0, np.pi / 2])  # facing +y: wall at beam 270
    scan = lidar.GetOutputPort("scan").Eval(context)
    assert scan[270] == pytest.approx(1.0, abs=1e-9) and np.isinf(scan[0])
    lidar, context = lidar_scene([box(5.0, -2.0, 5.2, 2.0)], [0.0, 0.0, 0.0])  # beyond 3.5 m
    assert np.all(np.isinf(lidar.GetOutputPort("scan").Eval(context)))


def collision_sample(x):
    builder = DiagramBuilder()
    scene_graph = builder.AddNamedSystem("scene_graph", SceneGraph())
    AddPlanGeometry(scene_graph, PlanGeometry([box(1.0, -2.0, 1.2, 2.0)]))
    UnicyclePlant.AddToBuilder(builder, scene_graph, [x, 0.0, 0.0])
    monitor = builder.AddNamedSystem("monitor", CollisionMonitor())
    builder.Connect(scene_graph.get_query_output_port(), monitor.GetInputPort("geometry_query"))
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    diagram.GetSubsystemByName("plant").GetInputPort("command").FixValue(
        diagram.GetSubsystemByName("plant").GetMyContextFromRoot(context), [0.0, 0.0]
    )
    monitor_context = monitor.GetMyContextFromRoot(context)
    monitor_context.SetDiscreteState(monitor.EvalUniquePeriodicDiscreteUpdate(monitor_context))
    return monitor.GetOutputPort("collision").Eval(monitor_context)


def test_collision_monitor_flags_robot_in_wall():
    inside = collision_sample(1.1)  # centre inside the wall
    assert inside[0] == 1.0 and inside[1] < -0.1 and inside[2] == 1.0
    touching = collision_sample(0.95)  # 5 cm overlap
    assert touching[0] == 1.0 and touching[1] == pytest.approx(-0.055, abs=1e-3)
    clear = collision_sample(0.5)
    assert clear[0] == 0.0 and clear[1] == pytest.approx(0.395, abs=1e-3) and clear[2] == 0.0


def test_controller_turns_toward_target_and_stops_when_done():
    controller = PurePursuitController(num_waypoints=3)
    context = controller.CreateDefaultContext()
    controller.GetInputPort("estimated_pose").FixValue(context, [0.0, 0.0, 0.0])
    controller.GetInputPort("segment").FixValue(context, [0.0, 0.0, 2.0, 0.0])
    controller.GetInputPort("progress").FixValue(context, [1.0, 0.0])
    np.testing.assert_allclose(controller.GetOutputPort("command").Eval(context), [0.22, 0.0])
    controller.GetInputPort("segment").FixValue(context, [0.0, 0.0, 0.0, 2.0])  # 90 deg left
    v, omega = controller.GetOutputPort("command").Eval(context)
    assert v == pytest.approx(0.0, abs=1e-12) and omega == pytest.approx(1.76 * np.pi / 2)
    controller.GetInputPort("segment").FixValue(context, [0.0, 0.0, 0.1, 0.0])
    controller.GetInputPort("progress").FixValue(context, [2.0, 0.0])  # final: slow down
    assert controller.GetOutputPort("command").Eval(context)[0] == pytest.approx(0.15)
    controller.GetInputPort("progress").FixValue(context, [2.0, 1.0])
    np.testing.assert_allclose(controller.GetOutputPort("command").Eval(context), [0.0, 0.0])


def test_densify_route_keeps_shape_and_marks_corners():
    route = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [2.0, 0.55]])
    dense, corners, leg_ends = densify_route(route, 0.25)
    assert len(dense) == 1 + 4 + 4 + 3
    assert np.all(np.hypot(*np.diff(dense, axis=0).T) <= 0.25 + 1e-9)
    for vertex in route:  # every original vertex is kept
        assert np.min(np.hypot(*(dense - vertex).T)) < 1e-12
    # Only the real turn (at (2, 0)) and the goal are corners, not the straight-through (1, 0).
    np.testing.assert_allclose(dense[corners], [[2.0, 0.0], [2.0, 0.55]])
    # Each waypoint's leg ends at the next original vertex.
    np.testing.assert_array_equal(leg_ends, [0, 4, 4, 4, 4, 8, 8, 8, 8, 11, 11, 11])
    same, _, same_legs = densify_route(route, None)
    np.testing.assert_array_equal(same, route)
    np.testing.assert_array_equal(same_legs, np.arange(len(route)))


def test_dense_route_segment_spans_the_leg_so_pursuit_looks_ahead():
    # 2 cm waypoints: the segment runs to the end of the leg, not just to the next waypoint, so
    # a robot 10 cm beside the route merges back driving forward instead of turning to the
    # waypoint at its side; on the last leg it slows down only near the goal.
    route = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 1.0]])
    source = WaypointSource(route, tolerance_m=0.1, spacing_m=0.02)
    context = source.CreateDefaultContext()
    source.GetInputPort("estimated_pose").FixValue(context, [0.5, 0.104, 0.0])
    context.SetDiscreteState(0, np.array([26.0, 0.0]))  # target (0.52, 0), not reached
    segment = source.GetOutputPort("segment").Eval(context)
    np.testing.assert_allclose(segment, [0.5, 0.0, 2.0, 0.0], atol=1e-12)

    n = len(source.waypoints_m)
    pursuit = PurePursuitController(
        n, corners=np.flatnonzero(source.corners), leg_ends=source.leg_ends
    )
    short_sighted = PurePursuitController(n, corners=np.flatnonzero(source.corners))
    commands = []
    for controller, seg in ((pursuit, segment), (short_sighted, [0.5, 0.0, 0.52, 0.0])):
        ctx = controller.CreateDefaultContext()
        controller.GetInputPort("estimated_pose").FixValue(ctx, [0.5, 0.104, 0.0])
        controller.GetInputPort("segment").FixValue(ctx, seg)
        controller.GetInputPort("progress").FixValue(ctx, [26.0, 0.0])
        commands.append(controller.GetOutputPort("command").Eval(ctx))
    assert commands[0][0] > 0.15 > 0.01 > commands[1][0]  # forward vs nearly turning on the spot

    ctx = pursuit.CreateDefaultContext()
    pursuit.GetInputPort("estimated_pose").FixValue(ctx, [2.0, 0.5, np.pi / 2])
    pursuit.GetInputPort("segment").FixValue(ctx, [2.0, 0.48, 2.0, 1.0])
    pursuit.GetInputPort("progress").FixValue(ctx, [n - 25.0, 0.0])  # on the last leg
    assert pursuit.GetOutputPort("command").Eval(ctx)[0] == pytest.approx(0.22)
    pursuit.GetInputPort("estimated_pose").FixValue(ctx, [2.0, 0.9, np.pi / 2])
    assert pursuit.GetOutputPort("command").Eval(ctx)[0] == pytest.approx(0.15)


def test_waypoint_source_passes_waypoints_but_not_corners():
    source = WaypointSource(
        np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]),
        tolerance_m=0.1,
        spacing_m=0.5,
        corner_tolerance_m=0.03,
    )
    np.testing.assert_allclose(source.waypoints_m, [[0, 0], [0.5, 0], [1, 0], [1, 0.5], [1, 1]])
    context = source.CreateDefaultContext()
    pose_port = source.GetInputPort("estimated_pose")

    def at(xy) -> np.ndarray:
        pose_port.FixValue(context, [*xy, 0.0])
        context.SetDiscreteState(0, source.EvalUniquePeriodicDiscreteUpdate(context).value(0))
        return source.GetOutputPort("progress").Eval(context)

    np.testing.assert_allclose(at([0.0, 0.0]), [1, 0])
    np.testing.assert_allclose(at([0.62, 0.05]), [2, 0])  # passed (0.5, 0), 12 cm beyond it
    np.testing.assert_allclose(at([0.95, 0.0]), [2, 0])  # 5 cm from the corner: not yet
    np.testing.assert_allclose(at([0.98, 0.0]), [3, 0])  # within the corner tolerance


def test_waypoint_source_catches_up_when_a_correction_jumps_the_estimate_ahead():
    source = WaypointSource(np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 1.0]]), spacing_m=0.025)
    context = source.CreateDefaultContext()

    def after_update(index, xy) -> int:
        context.SetDiscreteState(0, np.array([float(index), 0.0]))
        source.GetInputPort("estimated_pose").FixValue(context, [*xy, 0.0])
        context.SetDiscreteState(0, source.EvalUniquePeriodicDiscreteUpdate(context).value(0))
        return int(source.GetOutputPort("progress").Eval(context)[0])

    # 0.55 m ahead of the target (x = 0.25) beside the leg: every waypoint passed is skipped, up
    # to the first one farther than the 0.1 m tolerance ahead (x = 0.9).
    assert source.waypoints_m[after_update(10, [0.8, 0.05])][0] == pytest.approx(0.9)
    assert after_update(10, [0.8, 0.3]) == 10  # too far beside the leg: not skipped
    # A corner is never skipped from afar: 0.3 m past (2, 0) the target stays at the corner.
    corner = int(np.flatnonzero(source.corners)[0])
    assert after_update(corner - 1, [2.3, 0.0]) == corner


def test_odometry_outputs_a_newer_correction_at_once():
    odometry = NoisyOdometry([0.0, 0.0, 0.0], seed=0, xy_sigma_m=0.0)
    context = odometry.CreateDefaultContext()
    port = odometry.GetInputPort("pose_correction")
    port.FixValue(context, [1.0, 5.0, 6.0, 0.5])
    np.testing.assert_allclose(odometry.GetOutputPort("estimated_pose").Eval(context), [5, 6, 0.5])
    port.FixValue(context, [0.0, 5.0, 6.0, 0.5])  # not newer than the count seen (0)
    np.testing.assert_allclose(odometry.GetOutputPort("estimated_pose").Eval(context), [0, 0, 0])


def test_lidar_walls_merge_adjacent_boxes():
    # One L-shaped wall cut into two boxes: the shared edge is not a LiDAR segment.
    wall = shapely.union_all([box(1.0, -1.0, 1.2, 1.0), box(1.2, 0.8, 2.0, 1.0)])
    lidar, context = lidar_scene([wall], [0.0, 0.0, 0.0])
    segments = lidar.wall_segments(context)
    assert len(segments) == 6  # the L outline
    mid_x = 0.5 * (segments[:, 0] + segments[:, 2])
    mid_y = 0.5 * (segments[:, 1] + segments[:, 3])
    assert not np.any(np.isclose(mid_x, 1.2) & (mid_y > 0.8) & (mid_y < 1.0))
