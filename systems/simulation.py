"""Run the navigation Diagram to the end of a route: time limit, termination, result in SI units.

The run stops when the route is done, on a collision, at the time limit, or at the wall-clock
limit (checked after every step, and by a SIGALRM timer in the main thread for a step that never
ends, such as an integrator shrinking its step on a non-finite state). Localization error is
measured between the estimate and the true pose of the same odometry tick (the Diagram's
``true_pose_sample`` holds the true pose at the ticks).
"""

from __future__ import annotations

import contextlib
import math
import signal
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from pydrake.geometry import Meshcat
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import EventStatus

from f2n_drake.core.errors import InputError
from f2n_drake.planning.replanning import Replanner
from f2n_drake.systems.diagram import (
    LOG_PERIOD_S,
    WAYPOINT_SPACING_M,
    Correction,
    MakeNavigationDiagram,
    default_start_pose,
    route_waypoints,
)
from f2n_drake.systems.vectors import (
    CollisionStatus,
    NavigationStatus,
    PersonCollisions,
    Pose,
    PoseCorrection,
    Progress,
)
from f2n_drake.systems.viewer import draw_run_paths, write_replay_html
from f2n_drake.world.building import Building


@dataclass
class NavigationResult:
    """Outcome of one simulated run (SI units).

    ``reached``: the estimate finished the route within the time limit AND the true robot ended
    within ``goal_tolerance_m`` of the goal (``goal_distance_m``); ``success`` adds no collision
    (``collided``: walls and furniture; a collision ends the run) and no contact with a person
    (``person_collisions``: contacts counted, the run goes on).
    Errors are |true xy - estimated xy| every ``sample_period_s``, both taken at the same
    odometry tick; ``true_path`` / ``estimated_path`` are those samples. With an unknown start
    the error figures count from the handover (when there was one: before it the estimate is
    in the odometry's own frame), and the ``converged`` fields say how the global localization
    went (``WRONG_CONVERGENCE_M``).
    """

    reached: bool
    collided: bool
    time_s: float
    final_error_m: float
    mean_error_m: float
    max_error_m: float
    true_path: np.ndarray  # (N, 3) [x, y, theta]
    estimated_path: np.ndarray  # (N, 3)
    wall_time_s: float
    realtime_factor: float
    min_clearance_m: float = math.inf
    corrections: int = 0
    goal_distance_m: float = math.inf  # true final xy to the last waypoint
    correction: str = "continuous"
    sample_period_s: float = LOG_PERIOD_S
    route_done: bool = False
    goal_tolerance_m: float = 0.25
    wall_time_limited: bool = False  # stopped by the wall-clock limit
    replans: int = 0  # new routes taken during the run (with a replanner)
    message: str = ""  # why the run ended: route done, collision, time limit, no route left ...
    person_collisions: int = 0  # contacts with people (each run of samples in contact once)
    min_person_clearance_m: float = math.inf
    unknown_start: bool = False  # the robot did not know its start pose
    converged: bool = False  # unknown start: the global localizer handed over
    time_to_converge_s: float = math.nan  # unknown start: simulated time to the handover
    converged_error_m: float = math.nan  # unknown start: |handover xy - true xy| then
    wrong_convergence: bool = False  # unknown start: handed over > 0.5 m from the truth
    collided_before_converged: bool = False  # unknown start: a collision before the handover

    @property
    def success(self) -> bool:
        """Reached the goal (truly) without a collision, with a wall, furniture or a person,
        within the time limit."""
        return self.reached and not self.collided and self.person_collisions == 0


def run_end(
    route_done: bool, collided: bool, wall_time_limited: bool, navigator: str, blocked: str = ""
) -> str:
    """Why a run ended, in a line: "collision", the navigator's message (e.g. "no route left to
    bedroom_1: door_3 is closed"), "route done", "wall-clock limit" or "time limit" (with
    ``blocked``, how obstacles blocked every route at the end, after a colon)."""
    if collided:
        return "collision"
    if navigator:
        return navigator
    if route_done:
        return "route done"
    end = "wall-clock limit" if wall_time_limited else "time limit"
    return f"{end}: {blocked}" if blocked else end


def route_time_limit_s(waypoints: np.ndarray, start_xy: np.ndarray | None = None) -> float:
    """Default time limit [s]: route length at 0.15 m/s, plus 2 s per waypoint, plus 30 s."""
    path = waypoints if start_xy is None else np.vstack([start_xy, waypoints])
    length = float(np.hypot(*np.diff(path, axis=0).T).sum())
    return length / 0.15 + 2.0 * len(waypoints) + 30.0


WRONG_CONVERGENCE_M = 0.5
"""A handover farther than this from the true pose [m] is a wrong convergence."""

LOCALIZATION_TIME_S = 60.0
"""Added to the default time limit of an unknown-start run [s]."""

MAX_WALL_TIME_S = 600.0
"""Longest default wall-clock limit of one simulation [s]."""


class WallClockExceeded(Exception):
    """The simulation ran past its wall-clock limit inside one step."""


@contextlib.contextmanager
def wall_clock_alarm(seconds: float) -> Iterator[None]:
    """Raise ``WallClockExceeded`` in the block after ``seconds`` of wall time (a SIGALRM
    timer; in other threads than the main one, nothing)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def expire(signum, frame):
        raise WallClockExceeded()

    previous = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def simulate_navigation(
    plan: Any,
    route: Any,
    *,
    correction: Correction = "continuous",
    seed: int = 0,
    time_limit_s: float | None = None,
    meshcat: Meshcat | None = None,
    html_path: str | Path | None = None,
    odometry_sigma_m: float = 0.02,
    start_pose: np.ndarray | None = None,
    goal_tolerance_m: float = 0.25,
    waypoint_spacing_m: float | None = WAYPOINT_SPACING_M,
    run_name: str | None = None,
    wall_time_limit_s: float | None = None,
    building: Building | None = None,
    unknown_start: bool = False,
    replanner: Replanner | None = None,
    guard_options: dict[str, Any] | None = None,
) -> NavigationResult:
    """Run :func:`MakeNavigationDiagram` until the route is done, a collision, or the time limit.

    The default time limit is :func:`route_time_limit_s`; the default wall-clock limit
    ``wall_time_limit_s`` is as many seconds, at least 60 and at most ``MAX_WALL_TIME_S`` (a run
    slower than real time has gone wrong). With ``meshcat`` the run is shown in the plan viewer
    (under ``runs/<run_name>``, default the correction) and its true and estimated paths are
    drawn when it ends; it goes into meshcat's recording when meshcat records. With
    ``html_path`` the run is recorded (in a new ``Meshcat()`` if none is given) and saved as a
    standalone HTML. A collision or the wall-clock limit ends the run and is reported in the
    result, not raised. ``building``: the building as it is (default: exactly the plan), see
    :func:`MakeNavigationDiagram`; so are ``replanner`` (avoid obstacles, replan past closed
    doors; the run also ends when no route is left) and ``guard_options``. ``unknown_start``:
    the robot does not know ``start_pose`` and localizes itself first
    (:func:`MakeNavigationDiagram`); the default time limit grows by ``LOCALIZATION_TIME_S``.

    Raises:
        InputError: a non-finite or negative noise, tolerance or limit.
    """
    for name, value in (
        ("odometry_sigma_m", odometry_sigma_m),
        ("goal_tolerance_m", goal_tolerance_m),
        ("time_limit_s", time_limit_s),
        ("wall_time_limit_s", wall_time_limit_s),
    ):
        if value is not None and not (math.isfinite(value) and value >= 0):
            raise InputError(f"{name} must be a finite number >= 0, got {value}")
    waypoints = route_waypoints(route)
    x0 = default_start_pose(waypoints) if start_pose is None else np.asarray(start_pose, float)
    if time_limit_s is None:
        time_limit_s = route_time_limit_s(waypoints, x0[:2])
        time_limit_s += LOCALIZATION_TIME_S if unknown_start else 0.0
    if wall_time_limit_s is None:
        wall_time_limit_s = min(max(60.0, time_limit_s), MAX_WALL_TIME_S)
    if html_path is not None and meshcat is None:
        meshcat = Meshcat()
    diagram = MakeNavigationDiagram(
        plan,
        waypoints,
        correction=correction,
        seed=seed,
        meshcat=meshcat,
        odometry_sigma_m=odometry_sigma_m,
        start_pose=x0,
        record=True,
        waypoint_spacing_m=waypoint_spacing_m,
        run_name=run_name,
        building=building,
        unknown_start=unknown_start,
        replanner=replanner,
        guard_options=guard_options,
    )
    simulator = Simulator(diagram)
    context = simulator.get_mutable_context()
    sample = diagram.GetSubsystemByName("true_pose_sample")
    sample.SetVectorState(sample.GetMyMutableContextFromRoot(context), x0)
    progress_port = diagram.GetOutputPort("progress")
    collision_port = diagram.GetOutputPort("collision")
    status_port = (
        diagram.GetOutputPort("navigation_status")
        if diagram.HasOutputPort("navigation_status")
        else None
    )

    def monitor(root_context) -> EventStatus:
        if time.perf_counter() - wall_start > wall_time_limit_s:
            return EventStatus.ReachedTermination(diagram, "wall-clock limit")
        if Progress(progress_port.Eval(root_context)).done > 0:
            return EventStatus.ReachedTermination(diagram, "route done")
        if CollisionStatus(collision_port.Eval(root_context)).count > 0:
            return EventStatus.ReachedTermination(diagram, "collision")
        if status_port is not None and NavigationStatus(status_port.Eval(root_context)).no_route:
            return EventStatus.ReachedTermination(diagram, "no route left")
        return EventStatus.Succeeded()

    simulator.set_monitor(monitor)
    visualizer = diagram.GetSubsystemByName("meshcat_visualizer") if meshcat else None
    if html_path is not None:
        visualizer.StartRecording()
    wall_start = time.perf_counter()
    try:
        with wall_clock_alarm(wall_time_limit_s + 5.0):
            simulator.AdvanceTo(time_limit_s)
    except WallClockExceeded:
        pass
    wall_time_s = time.perf_counter() - wall_start
    wall_time_limited = wall_time_s > wall_time_limit_s
    true_log = diagram.GetSubsystemByName("true_pose_log").FindLog(context)
    estimated_log = diagram.GetSubsystemByName("estimated_pose_log").FindLog(context)
    true_path, estimated_path = true_log.data().T.copy(), estimated_log.data().T.copy()
    handover_s = float(diagram.GetOutputPort("handover").Eval(context)[0]) if unknown_start else 0
    known = first_sample_after(true_log.sample_times(), handover_s)  # the estimate is on the plan
    if meshcat is not None:
        name = correction if run_name is None else run_name
        draw_run_paths(meshcat, name, true_path[:, :2], estimated_path[known:, :2])
    if html_path is not None:
        write_replay_html(meshcat, html_path)
    true_now = Pose(diagram.GetOutputPort("true_pose").Eval(context))
    estimated_now = Pose(diagram.GetOutputPort("estimated_pose").Eval(context))
    errors = np.hypot(*(true_path[:, :2] - estimated_path[:, :2]).T)
    collision = CollisionStatus(collision_port.Eval(context))
    person = PersonCollisions(diagram.GetOutputPort("person_collision").Eval(context))
    localization = {}
    if unknown_start:
        localization, errors = global_localization_outcome(
            handover_s, errors, known, collision.count > 0
        )
    corrections = (
        int(PoseCorrection(diagram.GetOutputPort("pose_correction").Eval(context)).count)
        if diagram.HasOutputPort("pose_correction")
        else 0
    )
    sim_time = context.get_time()
    route_done = bool(Progress(progress_port.Eval(context)).done > 0)
    replans, message, blocked = 0, "", ""
    if status_port is not None:
        navigator = diagram.GetSubsystemByName("navigator")
        own = navigator.GetMyContextFromRoot(context)
        replans = int(NavigationStatus(status_port.Eval(context)).replans)
        message, blocked = navigator.message(own), navigator.blocked(own)
    message = run_end(route_done, bool(collision.count > 0), wall_time_limited, message, blocked)
    goal_distance = float(np.hypot(true_now.x - waypoints[-1][0], true_now.y - waypoints[-1][1]))
    return NavigationResult(
        reached=route_done and goal_distance <= goal_tolerance_m,
        collided=bool(collision.count > 0),
        time_s=sim_time,
        final_error_m=float(np.hypot(true_now.x - estimated_now.x, true_now.y - estimated_now.y)),
        mean_error_m=float(errors.mean()) if len(errors) else 0.0,
        max_error_m=float(errors.max()) if len(errors) else 0.0,
        true_path=true_path,
        estimated_path=estimated_path,
        wall_time_s=wall_time_s,
        realtime_factor=sim_time / max(wall_time_s, 1e-9),
        min_clearance_m=float(collision.min_clearance_m),
        corrections=corrections,
        goal_distance_m=goal_distance,
        correction=correction,
        sample_period_s=LOG_PERIOD_S,
        route_done=route_done,
        goal_tolerance_m=goal_tolerance_m,
        wall_time_limited=wall_time_limited,
        replans=replans,
        message=message,
        person_collisions=int(person.contacts),
        min_person_clearance_m=float(person.min_clearance_m),
        unknown_start=unknown_start,
        **localization,
    )


def first_sample_after(sample_times: np.ndarray, time_s: float) -> int:
    """Index of the first sample at or after ``time_s`` (a handover; negative: none, past the
    end). Before a handover the estimate is in the odometry's own frame."""
    if time_s < 0:
        return len(sample_times)
    return int(np.searchsorted(sample_times, time_s - 1e-9))


def global_localization_outcome(
    handover_s: float, errors: np.ndarray, first: int, collided: bool
) -> tuple[dict, np.ndarray]:
    """The unknown-start fields of a :class:`NavigationResult` and the errors [m] counted from
    the handover at ``handover_s`` (negative: none; then all the errors), whose first sample is
    ``first``: it pairs the handover pose with the true pose of the same odometry tick."""
    if handover_s < 0:
        return dict(converged=False, collided_before_converged=bool(collided)), errors
    after = errors[first:]
    error = float(after[0]) if len(after) else math.nan
    return (
        dict(
            converged=True,
            time_to_converge_s=handover_s,
            converged_error_m=error,
            wrong_convergence=bool(error > WRONG_CONVERGENCE_M),
            collided_before_converged=False,  # a collision ends the run
        ),
        after if len(after) else errors,
    )
