"""Per LiDAR scan: keep the route clear of what the plan does not show, stop, or replan.

:meth:`RouteGuard.step` takes one scan at the estimated pose, the route ahead and the doors it
still has to pass, and decides:

1. Costmap: returns farther than ``explained_m`` from the plan's walls mark a world-frame
   :class:`~f2n_drake.planning.costmap.LocalCostmap`; free beams clear it. Each obstacle cell
   remembers since when it is one.
2. Closed doors: a door of the route within ``door_watch_m`` whose opening the unexplained
   returns close (:meth:`~f2n_drake.planning.replanning.Doorway.blocked_by`) in
   ``door_confirm_scans`` scans in a row is closed for good: replan without it.
3. Stop: an unexplained return in the corridor ``stop_distance_m`` ahead of the robot's front
   (as wide as the robot plus ``side_margin_m``) holds the robot (no forward motion; it may
   turn); held for ``hold_replan_s``, those returns become obstacles and the route is replanned.
4. Blocked route: the next ``lookahead_m`` of the route passing within the robot's radius plus
   ``blocked_margin_m`` of an obstacle seen for ``persist_s`` or longer replans around the
   obstacles (at most once per ``replan_interval_s``). Fresh marks (someone walking across) do
   not: replanning is sticky, and the stop check halts the robot if they stay in its way.
5. Shortcut: every ``shortcut_interval_s`` a robot driving freely takes a new route only if it
   is clearly shorter than the rest of its own (``shortcut_ratio``, ``shortcut_gain_m``).
6. Step aside: held for ``retreat_after_s``, new routes or not (a person waiting for the
   robot while the robot waits for them, a gap too narrow), the robot drives to a spot a little
   away (:func:`~f2n_drake.planning.retreat.retreat_point`) and waits there until the way
   is clear (a replan every ``replan_interval_s`` finds one) or ``retreat_wait_s`` passed,
   then heads for the way again; so does a robot at the end of a route short of the goal (item 7).
7. A route that ends short of the goal (the goal was inside an obstacle's margin) is
   replanned from its end until one reaches the goal.
8. A replan request (global localization settled) replans at once, after forgetting the costmap
   and the closed doors (they were found from the estimates the request says were wrong).

A replan that finds no way because of closed doors stops the run with the replanner's message.
One blocked only by obstacles keeps the route (the stop check halts the robot before them) and
tries again every ``replan_interval_s``; after a door closed it takes the way left through the
open doors, obstacles or not, to find out what lies there. ``GuardState.why`` says what holds
the robot now, so a run that ends at its time limit can say why.
Everything is plain data; the state is replaced, never modified, so a Drake state can hold it.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from f2n_drake.core.errors import PlanningError
from f2n_drake.planning.costmap import LocalCostmap, WallDistance, scan_endpoints
from f2n_drake.planning.guard_state import Decision, GuardState
from f2n_drake.planning.replanning import NoRouteLeft, Replanner, RouteBlocked
from f2n_drake.planning.retreat import retreat_point


class RouteGuard:
    """See the module docstring. ``wall_segments``: (N, 4) plan walls [m]; ``bounds``: the
    costmap's (xmin, ymin, xmax, ymax) [m] (default: the walls' bounds plus 1 m)."""

    def __init__(
        self,
        replanner: Replanner,
        wall_segments: np.ndarray,
        *,
        bounds: tuple[float, float, float, float] | None = None,
        explained_m: float = 0.12,
        lookahead_m: float = 1.5,
        door_watch_m: float = 1.5,
        door_confirm_scans: int = 3,
        stop_distance_m: float = 0.35,
        side_margin_m: float = 0.05,
        hold_replan_s: float = 3.0,
        blocked_margin_m: float = 0.05,
        replan_interval_s: float = 1.0,
        persist_s: float = 1.0,
        shortcut_interval_s: float = 3.0,
        shortcut_ratio: float = 0.7,
        shortcut_gain_m: float = 1.0,
        retreat_after_s: float = 6.0,
        retreat_wait_s: float = 3.0,
        retreat_timeout_s: float = 8.0,
    ) -> None:
        self.replanner = replanner
        segments = np.asarray(wall_segments, float).reshape(-1, 4)
        if bounds is None:
            xy = segments.reshape(-1, 2)
            bounds = (*(xy.min(axis=0) - 1.0), *(xy.max(axis=0) + 1.0))
        self.walls = WallDistance(segments)
        self.costmap = LocalCostmap(bounds)
        self.radius_m = replanner.robot_radius_m
        self.explained_m, self.lookahead_m = explained_m, lookahead_m
        self.door_watch_m, self.door_confirm_scans = door_watch_m, door_confirm_scans
        self.stop_distance_m, self.side_margin_m = stop_distance_m, side_margin_m
        self.hold_replan_s, self.blocked_margin_m = hold_replan_s, blocked_margin_m
        self.replan_interval_s, self.persist_s = replan_interval_s, persist_s
        self.shortcut_interval_s, self.shortcut_ratio = shortcut_interval_s, shortcut_ratio
        self.shortcut_gain_m = shortcut_gain_m
        self.retreat_after_s, self.retreat_wait_s = retreat_after_s, retreat_wait_s
        self.retreat_timeout_s = retreat_timeout_s

    def initial_state(self) -> GuardState:
        return GuardState(self.costmap.empty())

    def unexplained(self, pose: np.ndarray, ranges: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(per-beam bool, (M, 2) world points [m]) of the returns the plan does not explain."""
        points, beams = scan_endpoints(pose, ranges)
        far = self.walls(points) > self.explained_m
        flags = np.zeros(len(ranges), bool)
        flags[beams[far]] = True
        return flags, points[far]

    def ahead_of_robot(self, pose: np.ndarray, points: np.ndarray) -> np.ndarray:
        """Bool per point: in the stop corridor ahead of the robot."""
        c, s = math.cos(pose[2]), math.sin(pose[2])
        d = points - np.asarray(pose[:2])
        forward, left = d @ np.array([c, s]), d @ np.array([-s, c])
        return (
            (forward > 0.0)
            & (forward <= self.radius_m + self.stop_distance_m)
            & (np.abs(left) <= self.radius_m + self.side_margin_m)
        )

    def route_blocked(self, obstacles: np.ndarray, ahead_xy: np.ndarray) -> bool:
        """True if the route points ``ahead_xy`` pass within radius + margin of an obstacle."""
        if not len(obstacles) or not len(ahead_xy):
            return False
        reach = self.radius_m + self.blocked_margin_m
        lo, hi = ahead_xy.min(axis=0) - reach, ahead_xy.max(axis=0) + reach
        near = obstacles[np.all((obstacles >= lo) & (obstacles <= hi), axis=1)]
        if not len(near):
            return False
        d2 = ((near[:, None, :] - ahead_xy[None, :, :]) ** 2).sum(-1)
        return bool(d2.min() <= reach * reach)

    def watch_doors(
        self, state: GuardState, pose: np.ndarray, seen: np.ndarray, doors_ahead: tuple[str, ...]
    ) -> tuple[frozenset[str], tuple[tuple[str, int], ...], list[str]]:
        """Closed set, door streaks and newly closed doors after one scan."""
        streaks = dict(state.door_streaks)
        closed, newly, out = set(state.closed), [], []
        for key in doors_ahead:
            door = self.replanner.doorways.get(key)
            if door is None or key in closed:
                continue
            if np.hypot(*(door.centre_m - pose[:2])) > self.door_watch_m:
                continue
            n = streaks.get(key, 0) + 1 if door.blocked_by(seen) else 0
            if n >= self.door_confirm_scans:
                closed.add(key)
                newly.append(key)
            elif n:
                out.append((key, n))
        return frozenset(closed), tuple(out), newly

    def step(
        self,
        state: GuardState,
        *,
        time_s: float,
        pose: np.ndarray,
        ranges: np.ndarray,
        ahead_xy: np.ndarray,
        doors_ahead: tuple[str, ...],
        goal_xy: np.ndarray,
        request: bool = False,
        remaining_m: float = 0.0,
        short_of_goal: bool = False,
    ) -> tuple[GuardState, Decision]:
        """One scan [m] at the estimated ``pose`` [x, y, theta] and time ``time_s`` [s]:
        ``ahead_xy`` (K, 2) the route's next ``lookahead_m``, ``doors_ahead`` the connector
        keys it still passes, ``request`` a replan request, ``remaining_m`` the length of the
        route left [m] (0: never look for a shortcut), ``short_of_goal`` the route ends
        before the goal and the robot is at its end. Returns the new state and what to do.
        """
        pose = np.asarray(pose, float)
        if request:  # the estimates the costmap and the door watch were built on were wrong
            state = dataclasses.replace(
                self.initial_state(), replans=state.replans, message=state.message
            )
        flags, seen = self.unexplained(pose, ranges)
        counts = self.costmap.update(state.counts, pose, ranges, flags)
        if state.message:
            return dataclasses.replace(state, counts=counts), Decision(hold=True, stop=True)
        closed, streaks, newly = self.watch_doors(state, pose, seen, doors_ahead)
        in_front = self.ahead_of_robot(pose, seen)
        hold = bool(in_front.any())
        held_since = (
            (time_s if math.isnan(state.held_since_s) else state.held_since_s) if hold else math.nan
        )
        stuck = hold or short_of_goal  # held, or at a route's end the goal is not free
        stuck_since = (
            (time_s if math.isnan(state.stuck_since_s) else state.stuck_since_s)
            if stuck
            else math.nan
        )
        reasons = [f"{key} closed" for key in newly] + (["request"] if request else [])
        urgent = bool(reasons)
        if hold and time_s - held_since >= self.hold_replan_s:
            counts = self.costmap.mark(counts, seen[in_front])
            reasons.append("held")
        since = self.costmap.since(counts, state.since, time_s)
        obstacles = self.costmap.obstacles(counts)
        why = "held by an obstacle ahead" if hold else ""
        state = dataclasses.replace(
            state,
            counts=counts,
            since=since,
            closed=closed,
            door_streaks=streaks,
            held_since_s=held_since,
            stuck_since_s=stuck_since,
            why=why,
        )
        if state.retreat and not urgent:
            x, y, started, arrived = state.retreat
            there = math.hypot(pose[0] - x, pose[1] - y) <= 0.12
            if math.isnan(arrived) and (there or time_s - started >= self.retreat_timeout_s):
                arrived = time_s
            waited = time_s - arrived  # nan on the way
            early = self.replan_interval_s <= waited < self.retreat_wait_s
            if early and time_s >= state.next_replan_s:
                state = dataclasses.replace(state, next_replan_s=time_s + self.replan_interval_s)
                try:  # the way clear again: go at once
                    route = self.replanner.replan(
                        pose[:2], goal_xy, closed_connectors=closed, obstacles_xy=obstacles
                    )
                except PlanningError:
                    route = None
                if route is not None:
                    state = dataclasses.replace(
                        state,
                        retreat=(),
                        waiting=False,
                        blocked="",
                        replans=state.replans + 1,
                        held_since_s=math.nan,
                        stuck_since_s=math.nan,
                    )
                    return state, Decision(route=route, reasons=("retry",))
            if math.isnan(arrived) or waited < self.retreat_wait_s:
                state = dataclasses.replace(
                    state,
                    retreat=(x, y, started, arrived),
                    held_since_s=math.nan,
                    stuck_since_s=math.nan,
                    why="stepped aside from an obstacle that stayed in the way",
                )
                return state, Decision(hold=hold or not math.isnan(arrived))
            reasons.append("retry")
        state = dataclasses.replace(state, retreat=())
        if stuck and not urgent and time_s - stuck_since >= self.retreat_after_s:
            near = np.hypot(*(seen - pose[:2]).T) <= 1.0
            spot = retreat_point(
                pose,
                seen[in_front] if hold else seen[near],
                self.walls,
                obstacles,
                clearance_m=self.radius_m + self.side_margin_m,
            )
            if spot is not None:
                state = dataclasses.replace(
                    state,
                    retreat=(*spot, time_s, math.nan),
                    held_since_s=math.nan,
                    stuck_since_s=math.nan,
                )
                detour = np.vstack([pose[:2], spot])
                return state, Decision(detour_xy=detour, reasons=("step aside",))
        ahead = np.asarray(ahead_xy, float).reshape(-1, 2)
        persistent = time_s - np.nan_to_num(since, nan=np.inf) >= self.persist_s
        if self.route_blocked(self.costmap.obstacles(counts, persistent), ahead):
            reasons.append("blocked")
        if state.waiting:
            reasons.append("waiting")
        if short_of_goal:
            reasons.append("goal")
        shortcut = (
            not reasons
            and not hold
            and remaining_m > self.shortcut_gain_m
            and time_s >= state.next_shortcut_s
        )
        if shortcut:
            state = dataclasses.replace(state, next_shortcut_s=time_s + self.shortcut_interval_s)
        elif not reasons or not (urgent or time_s >= state.next_replan_s):
            return state, Decision(hold=hold)
        else:
            state = dataclasses.replace(state, next_replan_s=time_s + self.replan_interval_s)
        try:
            route = self.replanner.replan(
                pose[:2], goal_xy, closed_connectors=closed, obstacles_xy=obstacles
            )
        except NoRouteLeft as exc:
            if shortcut:
                return state, Decision(hold=hold)
            state = dataclasses.replace(state, message=str(exc), waiting=False)
            return state, Decision(hold=True, stop=True, reasons=tuple(reasons))
        except RouteBlocked as exc:  # obstacles block every way for now: try again later
            if shortcut:
                return state, Decision(hold=hold)
            state = dataclasses.replace(state, waiting=True, blocked=str(exc))
            retry = "retry" in reasons  # back from stepping aside: head for the way again
            if not (urgent or retry) or exc.route is None:  # keep going: the stop check
                return state, Decision(hold=hold, reasons=tuple(reasons))  # stops the robot
            route = exc.route  # a door closed: head for the way left, obstacles or not
        except PlanningError:  # e.g. the estimate left the plan: keep the route, try again
            if shortcut:
                return state, Decision(hold=hold)
            state = dataclasses.replace(state, waiting=True)
            return state, Decision(hold=hold, reasons=tuple(reasons))
        else:
            if shortcut:
                if route.length_m > self.shortcut_ratio * remaining_m - self.shortcut_gain_m:
                    return state, Decision(hold=hold)
                reasons.append("shorter")
            state = dataclasses.replace(state, waiting=False, blocked="")
        state = dataclasses.replace(state, replans=state.replans + 1, held_since_s=math.nan)
        return state, Decision(hold=hold, route=route, reasons=tuple(reasons))


__all__ = ["Decision", "GuardState", "RouteGuard"]
