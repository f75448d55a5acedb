"""RouteGuard decisions on hand-made scans: stop, door closed, blocked route, requests."""

from __future__ import annotations

import numpy as np
from shapely.geometry import LineString, Point, box
from two_doors import GOAL, LOWER, UPPER, door_key, geometry, replanner

from f2n_drake.localization.scans import beam_angles, cast_rays
from f2n_drake.planning.route_guard import RouteGuard


def _segments(*polygons) -> np.ndarray:
    out = [geometry().wall_segments()]
    for p in polygons:
        xy = np.asarray(p.exterior.coords)
        out.append(np.hstack([xy[:-1], xy[1:]]))
    return np.vstack(out)


def _scan(pose, *polygons) -> np.ndarray:
    return cast_rays(pose[:2], beam_angles(360) + pose[2], _segments(*polygons), 3.5)


def _ahead(pose, length=1.5):
    return np.column_stack([np.linspace(pose[0], pose[0] + length, 60), np.full(60, pose[1])])


def _guard() -> RouteGuard:
    return RouteGuard(replanner(), geometry().wall_segments())


def test_something_close_ahead_holds_then_is_marked_and_replanned():
    guard, pose = _guard(), np.array([1.0, 2.4, 0.0])
    person = box(1.35, 2.3, 1.55, 2.5)  # 0.35 m ahead of the centre: inside the stop corridor
    turning_away = np.column_stack([np.full(20, 1.0), np.linspace(2.4, 2.0, 20)])
    kw = dict(ahead_xy=turning_away, doors_ahead=(), goal_xy=GOAL)
    state = guard.initial_state()
    for t in (0.0, 1.6):
        state, decision = guard.step(state, time_s=t, pose=pose, ranges=_scan(pose, person), **kw)
        assert decision.hold and decision.route is None and not decision.reasons
    state, later = guard.step(state, time_s=3.2, pose=pose, ranges=_scan(pose, person), **kw)
    assert later.reasons == ("held",) and later.route is not None
    assert LineString(later.route.waypoints_m).distance(person) > guard.radius_m
    _, clear = guard.step(guard.initial_state(), time_s=0.0, pose=pose, ranges=_scan(pose), **kw)
    assert not clear.hold and clear.route is None and not clear.reasons


def test_an_obstacle_on_the_route_ahead_is_gone_round():
    guard, pose = _guard(), np.array([1.0, 2.4, 0.0])
    chair = box(2.0, 2.2, 2.3, 2.6)
    kw = dict(ahead_xy=_ahead(pose), doors_ahead=(), goal_xy=GOAL)
    state, first = guard.step(
        guard.initial_state(), time_s=0.0, pose=pose, ranges=_scan(pose, chair), **kw
    )
    assert not first.hold and first.route is None  # one scan is not yet an obstacle
    state, second = guard.step(state, time_s=0.2, pose=pose, ranges=_scan(pose, chair), **kw)
    assert not second.reasons and second.route is None  # an obstacle, but a fresh one
    state, later = guard.step(state, time_s=1.2, pose=pose, ranges=_scan(pose, chair), **kw)
    assert later.reasons == ("blocked",) and not later.hold  # seen for persist_s: go round
    assert LineString(later.route.waypoints_m).distance(chair) > guard.radius_m + 0.05


def test_closed_door_seen_three_times_is_dropped_and_the_other_door_taken():
    guard, pose = _guard(), np.array([2.2, 2.4, 0.0])
    key = door_key(UPPER)
    state = guard.initial_state()
    kw = dict(ahead_xy=_ahead(pose, 0.3), doors_ahead=(key,), goal_xy=GOAL)
    for t in (0.0, 0.2):
        state, early = guard.step(state, time_s=t, pose=pose, ranges=_scan(pose, UPPER), **kw)
        assert key not in state.closed and early.route is None
    state, third = guard.step(state, time_s=0.4, pose=pose, ranges=_scan(pose, UPPER), **kw)
    assert key in state.closed and f"{key} closed" in third.reasons
    assert LineString(third.route.waypoints_m).intersects(LOWER)
    assert state.replans == 1


def test_the_last_door_closed_stops_with_a_message():
    guard, pose = _guard(), np.array([2.2, 2.4, 0.0])
    both = (door_key(UPPER), door_key(LOWER))
    state = guard.initial_state()
    state = state.__class__(**{**state.__dict__, "closed": frozenset({both[1]})})
    kw = dict(ahead_xy=_ahead(pose, 0.3), doors_ahead=both[:1], goal_xy=GOAL)
    for t in (0.0, 0.2, 0.4):
        state, decision = guard.step(state, time_s=t, pose=pose, ranges=_scan(pose, UPPER), **kw)
    assert decision.stop and decision.hold
    assert state.message.startswith("no route left to living_0") and both[0] in state.message


def test_a_request_replans_and_forgets_the_costmap():
    guard, pose = _guard(), np.array([1.0, 2.4, 0.0])
    state = guard.initial_state()
    state = state.__class__(
        **{**state.__dict__, "counts": guard.costmap.mark(state.counts, np.array([[2.0, 1.0]]))}
    )
    state, decision = guard.step(
        state,
        time_s=0.0,
        pose=pose,
        ranges=np.full(360, np.inf),
        ahead_xy=_ahead(pose),
        doors_ahead=(),
        goal_xy=GOAL,
        request=True,
    )
    assert "request" in decision.reasons and decision.route is not None
    assert len(guard.costmap.obstacles(state.counts)) == 0


def test_held_too_long_steps_aside_waits_and_tries_again():
    guard, pose = _guard(), np.array([2.6, 2.4, 0.0])
    person = box(2.95, 2.2, 3.35, 2.6)  # standing in the upper door, 0.35 m ahead
    other = box(2.9, 0.4, 3.3, 0.8)  # and someone in the lower door: no way round
    kw = dict(ahead_xy=_ahead(pose), doors_ahead=(), goal_xy=GOAL)
    state, decision = guard.initial_state(), None
    for t in np.arange(0.0, guard.retreat_after_s + 0.1, 0.2):
        ranges = _scan(pose, person, other)
        state, decision = guard.step(state, time_s=float(t), pose=pose, ranges=ranges, **kw)
        if decision.detour_xy is not None:
            break
    assert decision.reasons == ("step aside",) and t >= guard.retreat_after_s
    spot = decision.detour_xy[-1]
    assert np.hypot(*(spot - pose[:2])) >= 0.4 and person.distance(Point(spot)) > 0.5
    assert state.retreat[:2] == tuple(spot)
    there = np.array([*spot, 0.0])
    t0 = float(t) + 0.2
    state, waiting = guard.step(state, time_s=t0, pose=there, ranges=_scan(there, person), **kw)
    assert waiting.hold and waiting.route is None and state.why.startswith("stepped aside")
    t1 = t0 + guard.retreat_wait_s + 0.2
    state, retry = guard.step(state, time_s=t1, pose=there, ranges=_scan(there), **kw)
    assert "retry" in retry.reasons and retry.route is not None and not state.retreat


def test_a_clearly_shorter_route_is_taken_a_slightly_shorter_one_is_not():
    guard, pose = _guard(), np.array([1.0, 2.4, 0.0])
    kw = dict(ahead_xy=_ahead(pose), doors_ahead=(), goal_xy=GOAL, ranges=_scan(pose))
    direct = guard.replanner.replan(pose[:2], GOAL).length_m
    state, same = guard.step(guard.initial_state(), time_s=0.0, pose=pose, remaining_m=direct, **kw)
    assert same.route is None and state.next_shortcut_s == guard.shortcut_interval_s
    state, detour = guard.step(
        guard.initial_state(), time_s=0.0, pose=pose, remaining_m=3 * direct, **kw
    )
    assert detour.reasons == ("shorter",) and detour.route.length_m == direct
