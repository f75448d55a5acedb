"""The navigation Diagram on a hand-made two-room plan: structure, reaching the goal, drift."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
import shapely
from shapely import affinity
from shapely.geometry import LineString, box

from f2n_drake.core.parsed import Instance, ParsedPlan
from f2n_drake.core.plan import FloorPlan
from f2n_drake.core.raster import PixelGrid
from f2n_drake.mapping.walls import PlanGeometry
from f2n_drake.systems.diagram import MakeNavigationDiagram
from f2n_drake.systems.simulation import simulate_navigation
from f2n_drake.systems.vectors import CollisionStatus, Pose, PoseCorrection, Progress

BEDROOM, LIVING, DOOR = box(0, 0, 3, 3), box(3.2, 0, 6.2, 3), box(3.0, 1.2, 3.2, 2.0)
ROUTE = np.array([(1.0, 1.0), (2.5, 1.6), (3.7, 1.6), (5.2, 0.8)])


def two_rooms(angle_deg: float = 0.0) -> FloorPlan:
    """Two 3 x 3 m rooms, 0.2 m walls, joined by a 0.8 m door."""
    walls = box(-0.2, -0.2, 6.4, 3.2).difference(shapely.union_all([BEDROOM, LIVING, DOOR]))
    rotate = lambda g: affinity.rotate(g, angle_deg, origin=(0, 0))  # noqa: E731
    polygons = {
        "bedroom": [rotate(BEDROOM)],
        "living": [rotate(LIVING)],
        "wall": [rotate(walls)],
        "door": [rotate(DOOR)],
    }
    return FloorPlan(polygons, 0.2, "test")


def rotated_route(angle_deg: float) -> np.ndarray:
    c, s = np.cos(np.radians(angle_deg)), np.sin(np.radians(angle_deg))
    return ROUTE @ np.array([[c, -s], [s, c]]).T


def passed_door(true_path: np.ndarray) -> bool:
    crossing = true_path[np.abs(true_path[:, 0] - 3.1) < 0.05]
    return len(crossing) > 0 and bool(np.all((crossing[:, 1] > 1.3) & (crossing[:, 1] < 1.9)))


def test_diagram_structure_and_exported_ports():
    diagram = MakeNavigationDiagram(two_rooms(), ROUTE, correction="off")
    for name in (
        "scene_graph",
        "plant",
        "odometry",
        "lidar",
        "waypoints",
        "controller",
        "collision_monitor",
    ):
        assert diagram.HasSubsystemNamed(name), name
    assert not diagram.HasSubsystemNamed("corrector")
    sizes = {"true_pose": 3, "estimated_pose": 3, "collision": 3, "progress": 2, "scan": 360}
    for name, size in sizes.items():
        assert diagram.GetOutputPort(name).size() == size
    with_corrector = MakeNavigationDiagram(two_rooms(), ROUTE, correction="continuous")
    assert with_corrector.HasSubsystemNamed("corrector")
    assert with_corrector.GetOutputPort("pose_correction").size() == 4


def test_exported_outputs_read_by_name():
    diagram = MakeNavigationDiagram(two_rooms(), ROUTE, correction="continuous")
    views = {
        "true_pose": Pose,
        "estimated_pose": Pose,
        "collision": CollisionStatus,
        "progress": Progress,
        "pose_correction": PoseCorrection,
    }
    context = diagram.CreateDefaultContext()
    for name, view in views.items():
        assert diagram.GetOutputPort(name).size() == len(view.get_fields()), name
    start = Pose(diagram.GetOutputPort("true_pose").Eval(context))
    assert (start.x, start.y) == tuple(ROUTE[0])
    status = CollisionStatus(diagram.GetOutputPort("collision").Eval(context))
    assert status.collided == 0.0 and status.count == 0.0 and status.min_clearance_m > 0
    assert Progress(diagram.GetOutputPort("progress").Eval(context)).done == 0.0


def test_reaches_goal_through_door_with_continuous_correction():
    result = simulate_navigation(two_rooms(), ROUTE, correction="continuous", seed=1)
    assert result.reached and not result.collided
    assert result.goal_distance_m < 0.2
    assert result.corrections > 10 and result.max_error_m < 0.15
    assert result.min_clearance_m > 0.05
    assert passed_door(result.true_path)
    np.testing.assert_allclose(result.true_path[0, :2], ROUTE[0])


def test_reaches_goal_without_correction_when_noise_is_small():
    result = simulate_navigation(
        two_rooms(), ROUTE, correction="off", seed=1, odometry_sigma_m=0.002
    )
    assert result.reached and not result.collided and passed_door(result.true_path)


def test_drifts_more_without_correction():
    off = simulate_navigation(
        two_rooms(), ROUTE, correction="off", seed=2, odometry_sigma_m=0.05, time_limit_s=8.0
    )
    on = simulate_navigation(
        two_rooms(), ROUTE, correction="continuous", seed=2, odometry_sigma_m=0.05, time_limit_s=8.0
    )
    assert off.mean_error_m > 2 * on.mean_error_m
    assert off.max_error_m > 0.2


def test_same_seed_same_run_and_seeds_differ():
    runs = [
        simulate_navigation(
            two_rooms(), ROUTE, correction="off", seed=seed, odometry_sigma_m=0.02, time_limit_s=4.0
        )
        for seed in (5, 5, 6)
    ]
    np.testing.assert_array_equal(runs[0].true_path, runs[1].true_path)
    np.testing.assert_array_equal(runs[0].estimated_path, runs[1].estimated_path)
    assert not np.array_equal(runs[0].estimated_path, runs[2].estimated_path)


def test_rotated_plan_reaches_goal():
    result = simulate_navigation(
        two_rooms(20.0), rotated_route(20.0), correction="continuous", seed=3
    )
    assert result.reached and not result.collided and result.goal_distance_m < 0.2


def test_parsed_plan_walls_from_free_mask():
    plan = two_rooms(20.0)
    grid = PixelGrid.fit(plan.bounds, 256, 8)
    free = np.zeros(grid.shape, np.uint8)
    for poly in plan["bedroom"] + plan["living"] + plan["door"]:
        cv2.fillPoly(
            free, [np.round(grid.to_px(np.asarray(poly.exterior.coords))).astype(np.int32)], 1
        )
    parsed = ParsedPlan(np.zeros(grid.shape, np.int32), np.zeros(grid.shape, np.uint8), [], grid)
    geometry = PlanGeometry.from_parsed(parsed, free.astype(bool))
    assert len(geometry.wall_segments()) < 100  # squared up, not a pixel staircase
    inner_walls = shapely.union_all(plan["wall"])
    assert shapely.union_all(geometry.walls).intersection(inner_walls).area > 0.9 * inner_walls.area
    result = simulate_navigation(geometry, rotated_route(20.0), correction="continuous", seed=3)
    assert result.reached and not result.collided


def _drawn_two_rooms(stroke_px: int) -> ParsedPlan:
    """Two rooms and a wall with a door, as parsed from a drawing whose outlines are
    ``stroke_px`` thick (instance-free pixels), at 1 cm/px: a scan at high resolution."""
    ids = np.zeros((120, 200), np.int32)
    s = stroke_px
    ids[10:110, 10 : 96 - s] = 1  # living
    ids[10:110, 104 + s : 190] = 2  # bedroom
    ids[10:40, 96:104] = ids[80:110, 96:104] = 3  # wall, drawn between the strokes
    ids[40 + s : 80 - s, 96:104] = 4  # door, 0.4 m minus its outline
    classes = {1: "living", 2: "bedroom", 3: "wall", 4: "door"}
    instances = [
        Instance(i, c, np.zeros((0, 2)), int((ids == i).sum()), (0.0, 0.0))
        for i, c in classes.items()
    ]
    grid = PixelGrid.from_scale(0.01, ids.shape)
    return ParsedPlan(ids, np.zeros(ids.shape, np.uint8), instances, grid)


@pytest.mark.parametrize("stroke_px", [2, 6])
def test_parsed_plan_walls_leave_the_doors_the_planner_uses(stroke_px):
    parsed = _drawn_two_rooms(stroke_px)
    walls = shapely.union_all(PlanGeometry.from_parsed(parsed).walls)
    to_m = parsed.grid.to_m
    through_door = LineString(to_m(np.array([(50.0, 60.0), (150.0, 60.0)])))
    through_wall = LineString(to_m(np.array([(50.0, 25.0), (150.0, 25.0)])))
    assert not walls.intersects(through_door)
    assert walls.intersects(through_wall)


def test_meshcat_recording_html(tmp_path, monkeypatch):
    monkeypatch.setenv("DRAKE_ALLOW_NETWORK", "meshcat")
    html = tmp_path / "run.html"
    result = simulate_navigation(
        two_rooms(),
        ROUTE,
        correction="off",
        seed=0,
        odometry_sigma_m=0.0,
        time_limit_s=2.0,
        html_path=html,
    )
    assert result.time_s == pytest.approx(2.0)
    text = html.read_text()
    assert text.startswith("<!DOCTYPE html>") or "<html" in text[:500]
    assert len(text) > 100_000


def test_result_fields_and_true_goal_check():
    result = simulate_navigation(two_rooms(), ROUTE, correction="paper", seed=1)
    assert result.correction == "paper" and result.sample_period_s == pytest.approx(0.1)
    assert result.route_done and result.reached == (result.goal_distance_m <= 0.25)
    assert result.success == (result.reached and not result.collided)
    # An estimate that finishes far from the true goal is not "reached".
    drifted = simulate_navigation(
        two_rooms(),
        ROUTE[:2],
        correction="off",
        seed=4,
        odometry_sigma_m=0.15,
        goal_tolerance_m=0.01,
    )
    assert not drifted.reached and drifted.goal_distance_m > 0.01


def test_collision_is_reported_not_raised():
    through_wall = np.array([(1.5, 1.5), (4.5, 0.5)])  # misses the door
    result = simulate_navigation(
        two_rooms(), through_wall, correction="off", seed=0, odometry_sigma_m=0.0
    )
    assert result.collided and not result.success and result.min_clearance_m <= 0.0
