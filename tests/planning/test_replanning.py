"""Replanning on a known plan: closed doors cut from the graph, obstacle points avoided."""

from __future__ import annotations

import numpy as np
import pytest
from shapely.geometry import LineString, Point
from two_doors import GOAL, LOWER, START, UPPER, door_key, replanner

from f2n_drake.planning.replanning import NoRouteLeft, RouteBlocked


def _through(route, door) -> bool:
    return LineString(route.waypoints_m).intersects(door)


def test_open_plan_goes_through_the_upper_door():
    route = replanner().replan(START, GOAL)
    assert _through(route, UPPER) and not _through(route, LOWER)
    assert door_key(UPPER) in route.sequence


def test_closed_door_is_dropped_and_the_other_door_taken():
    closed = door_key(UPPER)
    route = replanner().replan(START, GOAL, closed_connectors={closed})
    assert _through(route, LOWER) and not _through(route, UPPER)
    assert closed not in route.sequence and door_key(LOWER) in route.sequence
    np.testing.assert_allclose(route.waypoints_m[-1], GOAL, atol=0.05)


def test_no_route_left_names_the_doors_and_the_goal():
    closed = {door_key(UPPER), door_key(LOWER)}
    with pytest.raises(NoRouteLeft) as error:
        replanner().replan(START, GOAL, closed_connectors=closed)
    message = str(error.value)
    assert message.startswith("no route left to living")
    assert all(key in message for key in closed)


def test_obstacle_points_are_avoided_with_the_robot_radius():
    obstacle = np.array([[4.2, 2.4], [4.2, 2.45], [4.25, 2.4]])
    route = replanner().replan(START, GOAL, obstacles_xy=obstacle)
    path = LineString(route.waypoints_m)
    radius = replanner().robot_radius_m
    assert min(path.distance(Point(p)) for p in obstacle) > radius + 0.05
    assert _through(route, UPPER)  # around the obstacle, not the long way


def test_obstacles_across_the_room_block_and_give_the_way_without_them():
    wall_of_points = np.column_stack([np.full(61, 2.0), np.linspace(0.0, 3.0, 61)])
    with pytest.raises(RouteBlocked) as error:
        replanner().replan(START, GOAL, obstacles_xy=wall_of_points)
    assert error.value.route is not None and _through(error.value.route, UPPER)


def test_closed_planner_is_cached_and_the_open_one_untouched():
    r = replanner()
    closed = r.closed_planner({door_key(UPPER)})
    assert closed is r.closed_planner([door_key(UPPER)]) and closed is not r.planner
    assert _through(r.replan(START, GOAL), UPPER)


def test_a_blocked_start_moves_to_the_nearest_clear_cell():
    near_wall = np.array([0.05, 2.4])  # closer to the wall than the robot radius
    route = replanner().replan(near_wall, GOAL)
    assert np.hypot(*(route.waypoints_m[0] - near_wall)) < replanner().snap_m
