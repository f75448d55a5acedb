"""LiDAR geometry, FloorPlan2Nav axis-aligned correction and point-to-line ICP (no Drake)."""

from __future__ import annotations

import numpy as np
import pytest

from f2n_drake.core.errors import InputError
from f2n_drake.localization.scan_matching import icp_point_to_line
from f2n_drake.localization.scans import (
    apply_pose_delta,
    cast_rays,
    correct_axis_aligned,
    extract_line_segments,
    pose_delta,
    scan_to_points,
    scan_to_points_robot,
    simulate_scan,
    visible_segments,
)

PERTURBATION = np.array([0.2, -0.15, np.deg2rad(5.0)])


def polygon_walls(vertices: list[tuple[float, float]]) -> np.ndarray:
    """Closed polygon outline as (N, 4) segments."""
    v = np.asarray(vertices, dtype=float)
    return np.concatenate([v, np.roll(v, -1, axis=0)], axis=1)


def thick_room(x0: float, y0: float, x1: float, y1: float, t: float = 0.2) -> np.ndarray:
    """A rectangular room whose walls have an inner and an outer face ``t`` apart."""
    inner = polygon_walls([(x0, y0), (x1, y0), (x1, y1), (x0, y1)])
    outer = polygon_walls([(x0 - t, y0 - t), (x1 + t, y0 - t), (x1 + t, y1 + t), (x0 - t, y1 + t)])
    return np.concatenate([inner, outer])


def rotate(segments: np.ndarray, angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    r = np.array([[c, -s], [s, c]])
    return np.concatenate([segments[:, :2] @ r.T, segments[:, 2:] @ r.T], axis=1)


def rotate_pose(pose: np.ndarray, angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([c * pose[0] - s * pose[1], s * pose[0] + c * pose[1], pose[2] + angle])


RECTANGLE = thick_room(0.0, 0.0, 5.0, 4.0)
L_SHAPE = polygon_walls([(0, 0), (6, 0), (6, 3), (3, 3), (3, 6), (0, 6)])
ROOMS = {
    "rectangle": (RECTANGLE, np.array([2.0, 1.5, 0.3])),
    "l_shape": (L_SHAPE, np.array([1.5, 2.5, -0.4])),
    "rotated_20deg": (
        rotate(RECTANGLE, np.deg2rad(20)),
        rotate_pose(np.array([2.0, 1.5, 0.3]), np.deg2rad(20)),
    ),
}


def cluttered_scan(pose, walls, rng, *, noise=0.01, clutter=0.1) -> np.ndarray:
    """Noisy scan where a ``clutter`` fraction of beams hit random objects in front of walls."""
    ranges = simulate_scan(pose, walls, noise_std_m=noise, rng=rng)
    hit = rng.random(ranges.size) < clutter
    ranges[hit] = np.where(np.isfinite(ranges[hit]), ranges[hit], 3.0) * rng.uniform(
        0.2, 0.8, hit.sum()
    )
    return ranges


def test_cast_rays_hits_square_walls_and_reports_inf_beyond_range():
    square = polygon_walls([(0, 0), (4, 0), (4, 4), (0, 4)])
    angles = np.array([0.0, np.pi / 2, np.pi, -np.pi / 2, np.pi / 4])
    ranges = cast_rays(np.array([1.0, 1.0]), angles, square, max_range=10.0)
    np.testing.assert_allclose(ranges, [3.0, 3.0, 1.0, 1.0, 3.0 * np.sqrt(2)], atol=1e-9)
    assert np.isinf(cast_rays(np.array([1.0, 1.0]), angles, square, max_range=2.0)[0])
    per_ray = cast_rays(np.array([[1.0, 1.0], [3.0, 3.0]]), np.array([0.0, 0.0]), square, 10.0)
    np.testing.assert_allclose(per_ray, [3.0, 1.0])


def test_visible_segments_hide_the_back_faces_of_thick_walls():
    visible = visible_segments(np.array([2.5, 2.0]), RECTANGLE, max_range=10.0)
    np.testing.assert_array_equal(visible, RECTANGLE[:4])  # the inner faces only
    assert len(visible_segments(np.array([2.5, 2.0]), RECTANGLE, max_range=1.0)) == 0


def test_bad_segments_raise_input_error():
    with pytest.raises(InputError):
        cast_rays(np.zeros(2), np.zeros(3), np.zeros((3, 3)), 1.0)


def test_scan_points_land_on_walls_and_respect_range_limits():
    pose = np.array([2.0, 1.5, 0.7])
    ranges = simulate_scan(pose, RECTANGLE, num_beams=90, max_range=3.5)
    assert np.isinf(ranges).any() and np.isfinite(ranges).sum() > 40
    world = scan_to_points(ranges, pose)
    on_wall = (
        np.isclose(world[:, 0], 0)
        | np.isclose(world[:, 0], 5)
        | np.isclose(world[:, 1], 0)
        | np.isclose(world[:, 1], 4)
    )
    assert on_wall.all()
    assert len(scan_to_points_robot(ranges, max_range=2.0)) < len(world)


def test_pose_delta_round_trip():
    old, new = np.array([1.0, 2.0, 0.3]), np.array([1.2, 1.9, 0.35])
    delta = pose_delta(new, old)
    np.testing.assert_allclose(apply_pose_delta(delta, old), new, atol=1e-12)


def test_extract_line_segments_finds_the_four_walls_of_a_room():
    pose = np.array([2.5, 2.0, 0.0])
    square = polygon_walls([(0, 0), (5, 0), (5, 4), (0, 4)])
    rng = np.random.default_rng(1)
    points = scan_to_points_robot(
        simulate_scan(pose, square, max_range=5.0, noise_std_m=0.01, rng=rng), max_range=5.0
    )
    lines = extract_line_segments(points)
    assert len(lines) == 4
    angles = np.rad2deg(
        np.mod(np.arctan2(lines[:, 3] - lines[:, 1], lines[:, 2] - lines[:, 0]), np.pi)
    )
    assert np.all(np.minimum(np.abs(angles - 90), np.minimum(angles, 180 - angles)) < 2)
    lengths = np.hypot(lines[:, 2] - lines[:, 0], lines[:, 3] - lines[:, 1])
    assert np.all(lengths > 3.0)


@pytest.mark.parametrize("name", sorted(ROOMS))
def test_icp_recovers_perturbed_pose(name):
    walls, true_pose = ROOMS[name]
    points = scan_to_points_robot(simulate_scan(true_pose, walls))
    result = icp_point_to_line(points, walls, true_pose + PERTURBATION)
    assert result.accepted and result.converged and len(result.constrained_dirs) == 3
    assert np.hypot(*(result.pose[:2] - true_pose[:2])) < 0.01
    assert abs(result.pose[2] - true_pose[2]) < np.deg2rad(0.5)
    assert result.inlier_ratio > 0.95 and result.rms_m < 0.005


@pytest.mark.parametrize("name", sorted(ROOMS))
def test_icp_with_noise_and_clutter(name):
    walls, true_pose = ROOMS[name]
    rng = np.random.default_rng(7)
    points = scan_to_points_robot(cluttered_scan(true_pose, walls, rng))
    result = icp_point_to_line(points, walls, true_pose + PERTURBATION)
    assert result.accepted
    assert np.hypot(*(result.pose[:2] - true_pose[:2])) < 0.02
    assert abs(result.pose[2] - true_pose[2]) < np.deg2rad(0.5)
    assert 0.75 < result.inlier_ratio < 0.97  # the clutter is counted as outliers


def test_icp_in_a_corridor_leaves_the_axis_alone():
    corridor = np.array([[0.0, 0.0, 20.0, 0.0], [0.0, 1.2, 20.0, 1.2]])
    true_pose = np.array([10.0, 0.6, 0.1])
    rng = np.random.default_rng(3)
    points = scan_to_points_robot(simulate_scan(true_pose, corridor, noise_std_m=0.01, rng=rng))
    start = true_pose + np.array([0.3, -0.1, np.deg2rad(3.0)])
    result = icp_point_to_line(points, corridor, start)
    assert len(result.constrained_dirs) == 2
    assert abs(result.pose[0] - start[0]) < 0.02  # not pulled along the corridor
    assert abs(result.pose[1] - true_pose[1]) < 0.02
    assert abs(result.pose[2] - true_pose[2]) < np.deg2rad(0.5)


def test_icp_rejects_a_scan_of_another_room():
    walls, true_pose = ROOMS["rectangle"]
    other = polygon_walls([(0, 0), (2.2, 0), (2.2, 9), (0, 9)])
    points = scan_to_points_robot(simulate_scan(np.array([1.1, 4.0, 0.0]), other))
    result = icp_point_to_line(points, walls, true_pose)
    assert not result.accepted


def test_icp_with_too_few_points_returns_initial_pose():
    walls, true_pose = ROOMS["rectangle"]
    result = icp_point_to_line(np.zeros((3, 2)), walls, true_pose)
    assert not result.accepted
    np.testing.assert_array_equal(result.pose, true_pose)


def test_paper_correction_fixes_xy_and_keeps_yaw():
    true_pose = np.array([2.0, 1.5, 0.05])
    rng = np.random.default_rng(5)
    points = scan_to_points_robot(simulate_scan(true_pose, RECTANGLE, noise_std_m=0.01, rng=rng))
    estimate = true_pose + np.array([0.2, -0.15, 0.0])
    pose, matches = correct_axis_aligned(extract_line_segments(points), estimate, RECTANGLE)
    assert matches >= 3
    assert np.hypot(*(pose[:2] - true_pose[:2])) < 0.02
    assert pose[2] == estimate[2]


def test_paper_correction_matches_the_visible_face_of_thick_walls():
    # Offset of 0.25 m toward the outer face (0.2 m behind the inner one): the outer face is
    # hidden, so the inner face is matched and the pose comes back.
    true_pose = np.array([2.5, 2.0, 0.0])
    points = scan_to_points_robot(simulate_scan(true_pose, RECTANGLE, max_range=3.5))
    estimate = true_pose + np.array([0.25, 0.25, 0.0])
    pose, matches = correct_axis_aligned(extract_line_segments(points), estimate, RECTANGLE)
    assert matches >= 2
    np.testing.assert_allclose(pose[:2], true_pose[:2], atol=0.01)


def test_paper_correction_in_a_corridor_only_moves_across_it():
    corridor = np.array([[0.0, 0.0, 20.0, 0.0], [0.0, 1.2, 20.0, 1.2]])
    true_pose = np.array([10.0, 0.6, 0.0])
    points = scan_to_points_robot(simulate_scan(true_pose, corridor))
    estimate = true_pose + np.array([0.3, 0.1, 0.0])
    pose, matches = correct_axis_aligned(extract_line_segments(points), estimate, corridor)
    assert matches == 2
    assert pose[0] == estimate[0]
    assert abs(pose[1] - true_pose[1]) < 0.01


def test_paper_correction_without_lines_is_a_no_op():
    estimate = np.array([1.0, 1.0, 0.0])
    pose, matches = correct_axis_aligned(np.zeros((0, 4)), estimate, RECTANGLE)
    assert matches == 0
    np.testing.assert_array_equal(pose, estimate)


def furnished_scan(
    room: np.ndarray, pose: np.ndarray, seed: int, cupboard_x: tuple[float, float] = (1.2, 4.8)
) -> np.ndarray:
    """Robot-frame points of a noisy scan of ``room`` with a 0.4 m deep cupboard along the
    bottom wall (from ``cupboard_x[0]`` to ``[1]``) and two round obstacles (a table, a person),
    none of them in the plan."""
    x0, x1 = cupboard_x
    cupboard = polygon_walls([(x0, 0.02), (x1, 0.02), (x1, 0.42), (x0, 0.42)])
    circles = np.array([[4.5, 2.0, 0.3], [1.5, 1.8, 0.25]])
    rng = np.random.default_rng(seed)
    ranges = simulate_scan(
        pose, np.concatenate([room, cupboard]), noise_std_m=0.01, rng=rng, circles=circles
    )
    return scan_to_points_robot(ranges)


@pytest.mark.parametrize("seed", range(3))
def test_icp_rejects_returns_the_plan_lacks_instead_of_averaging_them(seed):
    room, pose = thick_room(0.0, 0.0, 6.0, 6.0), np.array([3.0, 1.0, 0.1])
    points = furnished_scan(room, pose, seed)
    start = pose + np.array([0.05, 0.05, np.deg2rad(2.0)])
    robust = icp_point_to_line(points, room, start)
    assert robust.accepted
    assert abs(robust.pose[0] - pose[0]) < 0.01 and abs(robust.pose[2] - pose[2]) < np.deg2rad(0.2)
    assert abs(robust.pose[1] - start[1]) < 0.01  # y: the cupboard hides the wall; left alone
    assert robust.inlier_ratio < 0.5  # the furniture's returns are counted as outliers
    naive = icp_point_to_line(points, room, start, beam_gate_m=None, min_inliers=0)
    assert naive.accepted and naive.pose[1] - pose[1] < -0.3  # took the cupboard for the wall


def test_icp_refuses_a_fit_with_too_few_plan_returns():
    hall, pose = thick_room(0.0, 0.0, 10.0, 6.0), np.array([5.0, 1.0, 0.1])
    points = furnished_scan(hall, pose, 0, (2.0, 8.0))  # the side walls are out of range
    start = pose + np.array([0.05, 0.05, np.deg2rad(2.0)])
    assert not icp_point_to_line(points, hall, start).accepted
    assert icp_point_to_line(points, hall, start, beam_gate_m=None, min_inliers=0).accepted


def test_cast_rays_hits_circles_from_outside_only():
    circles = np.array([[2.0, 0.0, 0.5], [0.0, 0.0, 0.3]])  # the second one round the origin
    ranges = cast_rays(
        np.zeros(2), np.array([0.0, np.pi / 2, np.pi]), np.zeros((0, 4)), 5.0, circles
    )
    assert ranges[0] == pytest.approx(1.5) and np.isinf(ranges[1]) and np.isinf(ranges[2])
