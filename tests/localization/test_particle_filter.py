"""Monte Carlo localization on hand-made plans: the likelihood field, the filter, its clusters."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from shapely.geometry import box

from f2n_drake.core.errors import InputError
from f2n_drake.core.plan import FloorPlan
from f2n_drake.localization.heading_prior import dominant_direction, heading_hypotheses
from f2n_drake.localization.likelihood_field import BeamModel, LikelihoodField
from f2n_drake.localization.particle_clusters import (
    ConvergenceTest,
    clusters,
    estimate_pose,
)
from f2n_drake.localization.particle_filter import (
    FilterOptions,
    ParticleCloud,
    beam_subset,
    moved_enough,
    predict,
    relative_motion,
    resample,
    scan_log_likelihood,
    step,
    uniform_cloud,
)
from f2n_drake.localization.scans import scan_to_points_robot, simulate_scan
from f2n_drake.mapping.walls import PlanGeometry

SMALL = FilterOptions(num_particles=1500, initial_per_m2=1500.0, initial_min=5000)


def plan_geometry(rooms: list, doors: list) -> PlanGeometry:
    """Rooms and doors (shapely boxes) inside 0.2 m walls."""
    spaces = shapely.union_all(rooms + doors)
    xmin, ymin, xmax, ymax = spaces.bounds
    walls = box(xmin - 0.2, ymin - 0.2, xmax + 0.2, ymax + 0.2).difference(spaces)
    polygons = {"bedroom": rooms, "wall": [walls], "door": doors}
    return PlanGeometry.from_floorplan(FloorPlan(polygons, 0.2, "test"))


def asymmetric_rooms() -> PlanGeometry:
    """A 4 x 3 m room beside a 2 x 2 m one, joined by a door."""
    return plan_geometry([box(0, 0, 4, 3), box(4.2, 0, 6.2, 2)], [box(4, 0.6, 4.2, 1.4)])


def symmetric_rooms() -> PlanGeometry:
    """Two 3 x 3 m rooms joined by a centred door: turned half round about the door, the plan
    is itself, so every pose has a twin."""
    return plan_geometry([box(0, 0, 3, 3), box(3.2, 0, 6.2, 3)], [box(3, 1.1, 3.2, 1.9)])


def localize(geometry, true_pose, scans, rng, options=SMALL, outliers=None):
    """Run the filter on ``scans`` scans from a robot that turns 0.2 rad each step."""
    field = LikelihoodField.from_geometry(geometry)
    walls = geometry.wall_segments()
    cloud, pose = uniform_cloud(field, options, rng), np.array(true_pose, float)
    turn = np.array([0.0, 0.0, 0.2])
    for k in range(scans):
        pose = pose + (turn if k else 0.0)
        scan = simulate_scan(pose, walls, noise_std_m=0.01, rng=rng)
        if outliers is not None:
            scan = outliers(scan)
        motion = turn if k else np.zeros(3)
        cloud, _ = step(cloud, motion, scan, field, options, rng, index=k)
    return cloud, pose


def xy_error(pose, truth) -> float:
    return float(np.hypot(pose[0] - truth[0], pose[1] - truth[1]))


def test_field_distance_and_free_space():
    geometry = asymmetric_rooms()
    field = LikelihoodField.from_geometry(geometry)
    assert field.distance(np.array([[2.0, 0.0]]))[0] < 0.03  # on the bottom wall face
    assert field.distance(np.array([[2.0, 1.5]]))[0] == pytest.approx(1.5, abs=0.03)
    inside = np.array([[2.0, 1.5], [5.2, 1.0], [4.1, 1.0]])
    outside = np.array([[2.0, 0.05], [4.1, 2.5], [-1.0, 1.0], [5.2, 2.5]])
    assert field.is_free(inside).all()
    assert not field.is_free(outside).any()
    assert field.free_area_m2 == pytest.approx(3.79 * 2.79 + 1.79 * 1.79 + 0.2 * 0.59, rel=0.05)
    points = field.sample_free(500, np.random.default_rng(0))
    assert field.is_free(points).all()
    with pytest.raises(InputError):
        LikelihoodField.from_geometry(PlanGeometry([]))


def test_beam_model_is_robust_to_returns_the_plan_lacks():
    model = BeamModel(sigma_hit_m=0.1, z_hit=0.9, z_rand=0.1)
    near, far = model.log_likelihood(np.array([0.0, 5.0]))
    assert near == pytest.approx(0.0)
    assert far == pytest.approx(np.log(0.1))  # bounded: an outlier costs at most this much


def test_likelihood_ignores_an_outlier_return():
    geometry = asymmetric_rooms()
    field = LikelihoodField.from_geometry(geometry)
    truth, shifted = np.array([1.5, 1.2, 0.3]), np.array([1.8, 1.2, 0.3])
    scan = simulate_scan(truth, geometry.wall_segments())
    cluttered = scan.copy()
    cluttered[10:40] = 0.6  # a person in front of 30 beams
    options, model = FilterOptions(beams=360), BeamModel()
    clean = scan_log_likelihood(
        np.array([truth, shifted]), beam_subset(scan, options), field, model
    )
    seen = scan_log_likelihood(
        np.array([truth, shifted]), beam_subset(cluttered, options), field, model
    )
    assert seen[0] > seen[1]  # the true pose still wins
    assert clean[0] - seen[0] <= 30 * -np.log(0.1) + 1e-6  # each outlier costs at most z_rand's


def test_a_return_beyond_a_wall_of_the_plan_is_unlikely():
    field = LikelihoodField.from_geometry(asymmetric_rooms())
    model = BeamModel()
    robot = np.array([[1.0, 2.5, 0.0]])
    inside = scan_log_likelihood(robot, np.array([[2.75, 0.0]]), field, model)  # 0.25 m short
    beyond = scan_log_likelihood(robot, np.array([[3.5, 0.0]]), field, model)  # in the wall
    far = np.log(model.z_hit * np.exp(-0.5 * (0.25 / model.sigma_hit_m) ** 2) + model.z_rand)
    assert inside[0] == pytest.approx(far, abs=0.15)  # the distance of the cell centre
    assert beyond[0] == pytest.approx(np.log(model.z_through))
    assert field.passable[field.cells(np.array([2.0, 1.5]))]
    assert not field.passable[field.cells(np.array([4.1, 2.5]))]


def test_no_return_crosses_a_wall_from_the_true_pose():
    geometry = asymmetric_rooms()
    field = LikelihoodField.from_geometry(geometry)
    truth = np.array([1.2, 2.1, -2.0])
    cluttered = simulate_scan(truth, geometry.wall_segments())
    cluttered[50:120] = 0.7  # furniture only shortens beams
    points = scan_to_points_robot(cluttered)
    offsets = BeamModel().through_offsets_m
    assert not field.crossed(truth, points, offsets).any()
    assert field.crossed(truth + [0.3, 0.0, 0.0], points, offsets).any()
    assert field.crossed(np.array([5.0, 1.0, -2.0]), points, offsets).mean() > 0.3


def test_filter_converges_on_an_asymmetric_plan():
    truth = np.array([1.2, 2.1, -2.0])
    cloud, pose = localize(asymmetric_rooms(), truth, 10, np.random.default_rng(1))
    estimate = estimate_pose(cloud)
    assert estimate.converged
    assert xy_error(estimate.pose, pose) < 0.1
    assert abs((estimate.pose[2] - pose[2] + np.pi) % (2 * np.pi) - np.pi) < 0.05


def test_filter_converges_despite_clutter():
    truth = np.array([2.5, 1.0, 0.4])

    def person(scan):
        scan = scan.copy()
        scan[100:140] = 0.5
        return scan

    cloud, pose = localize(asymmetric_rooms(), truth, 10, np.random.default_rng(2), outliers=person)
    estimate = estimate_pose(cloud)
    assert xy_error(estimate.pose, pose) < 0.1


def test_symmetric_plan_keeps_both_twins_without_motion():
    truth = np.array([1.0, 0.9, 0.5])
    twin = np.array([6.2 - 1.0, 3.0 - 0.9])
    cloud, pose = localize(symmetric_rooms(), truth, 8, np.random.default_rng(3))
    found = clusters(cloud)
    assert len(found) >= 2
    assert not estimate_pose(cloud).converged
    heavy = [c for c in found if c.weight > 0.2]
    assert any(xy_error(c.pose, pose) < 0.1 for c in heavy)
    assert any(xy_error(c.pose, twin) < 0.1 for c in heavy)


def test_motion_update_follows_the_odometry_increment():
    previous, current = np.array([1.0, 2.0, 0.5]), np.array([1.3, 2.4, 0.9])
    motion = relative_motion(previous, current)
    quiet = FilterOptions(xy_sigma_m=0, xy_sigma_per_m=0, theta_sigma_rad=0, theta_sigma_per_rad=0)
    cloud = ParticleCloud(np.array([previous, [0.0, 0.0, 0.5 + np.pi]]), np.full(2, 0.5))
    moved = predict(cloud, motion, quiet, np.random.default_rng(0))
    np.testing.assert_allclose(moved.poses[0], current, atol=1e-12)
    np.testing.assert_allclose(moved.poses[1, :2], -(current - previous)[:2], atol=1e-12)
    assert moved_enough(motion, FilterOptions())
    assert not moved_enough(np.array([0.01, 0.0, 0.02]), FilterOptions())


def test_low_variance_resampling_keeps_the_weights():
    poses = np.arange(12.0).reshape(4, 3)
    cloud = ParticleCloud(poses, np.array([0.5, 0.25, 0.25, 0.0]))
    drawn = resample(cloud, 8, np.random.default_rng(0))
    counts = [int((drawn.poses[:, 0] == p).sum()) for p in poses[:, 0]]
    assert counts == [4, 2, 2, 0]
    np.testing.assert_allclose(drawn.weights, 1 / 8)


def test_clusters_and_convergence_test():
    rng = np.random.default_rng(0)
    a = np.column_stack(
        [rng.normal(1, 0.03, 700), rng.normal(1, 0.03, 700), rng.normal(0, 0.01, 700)]
    )
    b = np.column_stack(
        [rng.normal(4, 0.03, 300), rng.normal(2, 0.03, 300), rng.normal(3, 0.01, 300)]
    )
    two = ParticleCloud(np.vstack([a, b]), np.full(1000, 1e-3))
    found = clusters(two)
    assert [round(c.weight, 2) for c in found] == [0.7, 0.3]
    np.testing.assert_allclose(found[0].pose, [1, 1, 0], atol=0.01)
    assert found[0].spread_m < 0.06
    assert not estimate_pose(two).converged
    one = ParticleCloud(a, np.full(700, 1 / 700))
    assert estimate_pose(one).converged
    assert not estimate_pose(one, ConvergenceTest(radius_m=0.02)).converged


def test_first_cloud_covers_the_free_space_and_every_heading():
    field = LikelihoodField.from_geometry(asymmetric_rooms())
    cloud = uniform_cloud(field, SMALL, np.random.default_rng(0))
    assert len(cloud) >= SMALL.initial_min
    assert field.is_free(cloud.poses[:, :2]).all()
    assert (
        np.histogram(cloud.poses[:, 2], bins=8, range=(-np.pi, np.pi))[0].min()
        > 0.1 * len(cloud) / 8
    )


@pytest.mark.parametrize("plan_deg", [0.0, 20.0])
def test_heading_hypotheses_align_the_scan_walls_with_the_plan(plan_deg):
    walls = asymmetric_rooms().wall_segments()
    c, s = np.cos(np.radians(plan_deg)), np.sin(np.radians(plan_deg))
    turned = np.hstack([walls[:, :2] @ [[c, s], [-s, c]], walls[:, 2:] @ [[c, s], [-s, c]]])
    pose = np.array([*(np.array([1.5, 1.2]) @ [[c, s], [-s, c]]), 1.0])
    points = scan_to_points_robot(simulate_scan(pose, turned))
    headings = heading_hypotheses(points, turned)
    assert len(headings) == 4
    assert np.min(np.abs((headings - pose[2] + np.pi) % (2 * np.pi) - np.pi)) < 0.01


def test_no_heading_prior_without_dominant_directions():
    angles = np.linspace(0, 2 * np.pi, 7)  # a hexagon: walls 60 degrees apart
    ring = np.column_stack([np.cos(angles), np.sin(angles)]) * 3.0
    hexagon = np.hstack([ring[:-1], ring[1:]])
    assert dominant_direction(hexagon) is None
    points = scan_to_points_robot(simulate_scan(np.array([0.2, 0.1, 0.3]), hexagon))
    assert len(heading_hypotheses(points, hexagon)) == 0
