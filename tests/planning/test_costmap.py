"""The costmap of what the LiDAR sees and the plan lacks, and closed-door detection."""

from __future__ import annotations

import numpy as np
from shapely.geometry import box
from two_doors import UPPER, door_key, geometry, replanner

from f2n_drake.localization.scans import beam_angles, cast_rays
from f2n_drake.planning.costmap import LocalCostmap, WallDistance, scan_endpoints

ROOM = (0.0, 0.0, 6.2, 3.0)


def _scan(pose, segments, n=360):
    return cast_rays(np.asarray(pose[:2]), beam_angles(n) + pose[2], segments, 3.5)


def _box_segments(b):
    xy = np.asarray(b.exterior.coords)
    return np.hstack([xy[:-1], xy[1:]])


def test_wall_distance_explains_wall_returns_only():
    walls = WallDistance(geometry().wall_segments())
    pose = np.array([1.5, 1.5, 0.0])
    obstacle = box(2.0, 1.3, 2.3, 1.7)
    ranges = _scan(pose, np.vstack([geometry().wall_segments(), _box_segments(obstacle)]))
    points, beams = scan_endpoints(pose, ranges)
    far = walls(points) > 0.1
    assert far[beams == 0].all()  # straight ahead: the box at 0.5 m, not a wall
    assert not far[beams == 90].any()  # left: the wall at y = 3
    assert np.allclose(points[far][:, 0].min(), 2.0, atol=0.02)


def test_costmap_marks_an_unexplained_return_and_a_free_beam_clears_it():
    costmap = LocalCostmap(ROOM, 0.05)
    pose = np.array([1.0, 1.5, 0.0])
    ranges = np.full(360, np.inf)
    ranges[0] = 1.0  # a return at (2.0, 1.5)
    unexplained = np.zeros(360, bool)
    unexplained[0] = True
    counts = costmap.empty()
    for _ in range(2):
        counts = costmap.update(counts, pose, ranges, unexplained)
    obstacles = costmap.obstacles(counts)
    assert len(obstacles) == 1 and np.hypot(*(obstacles[0] - [2.0, 1.5])) < 0.05
    walked_away = np.full(360, np.inf)  # beam 0 now passes through the cell
    for _ in range(3):
        counts = costmap.update(counts, pose, walked_away, np.zeros(360, bool))
    assert len(costmap.obstacles(counts)) == 0


def test_explained_returns_mark_nothing_and_mark_forces_an_obstacle():
    costmap = LocalCostmap(ROOM, 0.05)
    pose = np.array([1.0, 1.5, 0.0])
    ranges = _scan(pose, geometry().wall_segments())
    counts = costmap.update(costmap.empty(), pose, ranges, np.zeros(360, bool))
    assert len(costmap.obstacles(counts)) == 0
    counts = costmap.mark(counts, np.array([[2.0, 2.0]]))
    assert len(costmap.obstacles(counts)) == 1


def test_closed_door_face_blocks_the_doorway_a_person_does_not():
    door = replanner().doorways[door_key(UPPER)]
    pose = np.array([2.0, 2.4, 0.0])
    walls = geometry().wall_segments()
    distance = WallDistance(walls)

    def seen(extra):
        points, _ = scan_endpoints(pose, _scan(pose, np.vstack([walls, extra])))
        return points[distance(points) > 0.1]

    assert door.blocked_by(seen(_box_segments(UPPER)))
    person = np.asarray(box(0, 0, 1, 1).centroid.buffer(0.25).exterior.coords) + [2.6, 1.9]
    person_segments = np.hstack([person[:-1], person[1:]])
    assert not door.blocked_by(seen(person_segments))
    assert not door.blocked_by(seen(np.zeros((0, 4))))


def test_an_obstacle_keeps_its_age_through_a_dip_and_forgets_it_once_cleared():
    costmap = LocalCostmap(ROOM, 0.05)
    pose = np.array([1.0, 1.5, 0.0])
    hit, free = np.full(360, np.inf), np.full(360, np.inf)
    hit[0] = 1.0
    mark = np.zeros(360, bool)
    mark[0] = True
    counts = costmap.update(costmap.update(costmap.empty(), pose, hit, mark), pose, hit, mark)
    since = costmap.since(counts, None, 2.0)
    cell = np.isfinite(since)
    assert cell.sum() == 1 and since[cell][0] == 2.0
    counts = costmap.update(counts, pose, free, mark)  # 4 -> 3: still an obstacle
    counts = costmap.update(counts, pose, free, mark)  # 3 -> 2: a dip
    since = costmap.since(counts, since, 2.4)
    assert since[cell][0] == 2.0  # evidence left: not a new obstacle
    for _ in range(2):
        counts = costmap.update(counts, pose, free, mark)
    assert np.isnan(costmap.since(counts, since, 2.8)).all()
    persistent = np.zeros(counts.shape, bool)
    assert len(costmap.obstacles(costmap.mark(counts, np.array([[2.0, 1.5]])), persistent)) == 0
