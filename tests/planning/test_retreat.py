"""Stepping aside: a spot away from what holds the robot, clear of walls and obstacles."""

from __future__ import annotations

import numpy as np
from two_doors import geometry

from f2n_drake.planning.costmap import WallDistance
from f2n_drake.planning.retreat import retreat_point, segment_clear

CLEARANCE = 0.155


def test_the_spot_is_away_from_the_blocker_and_off_the_line_driven():
    walls = WallDistance(geometry().wall_segments())
    pose = np.array([1.5, 1.5, 0.0])  # the bedroom's middle, facing +x
    blocker = np.array([[1.9, 1.5]])  # a person 0.4 m ahead
    spot = retreat_point(pose, blocker, walls, np.zeros((0, 2)), clearance_m=CLEARANCE)
    assert spot is not None
    assert np.hypot(*(spot - blocker[0])) > np.hypot(*(pose[:2] - blocker[0])) + 0.3
    assert abs(spot[1] - pose[1]) > 0.3  # aside, not straight back along the line
    assert segment_clear(pose[:2], spot, walls, np.zeros((0, 2)), CLEARANCE)


def test_obstacles_and_walls_rule_spots_out():
    walls = WallDistance(geometry().wall_segments())
    pose = np.array([0.3, 0.3, 0.0])  # in the bedroom's corner
    ring = 0.55 * np.column_stack(
        [np.cos(np.linspace(0, 6.3, 80)), np.sin(np.linspace(0, 6.3, 80))]
    )
    boxed_in = pose[:2] + ring
    spot = retreat_point(pose, np.array([[0.6, 0.3]]), walls, boxed_in, clearance_m=CLEARANCE)
    assert spot is None
    free = retreat_point(pose, np.array([[0.6, 0.3]]), walls, np.zeros((0, 2)), clearance_m=0.155)
    assert free is not None and walls(free[None])[0] >= CLEARANCE
    assert not segment_clear(pose[:2], np.array([-0.5, 0.3]), walls, np.zeros((0, 2)), 0.155)
