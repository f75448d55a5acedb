"""The navigation Diagram (plan walls, robot, odometry, LiDAR, corrector, controller) and a runner.

Update timing (so a LiDAR correction uses a scan and an estimate of the same instant): odometry
ticks at 0.05 + 0.1 k s, the LiDAR scans at 0.05 + 0.2 k s (with the odometry), the corrector
runs 0.01 s later and its correction takes effect at once; waypoints and the collision monitor
update at 0.1 k s. Localization error is measured between the estimate and the true pose of the
same odometry tick (the true pose is sampled and held at the ticks).
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
from f2n_drake.systems.collision_monitor import CollisionMonitor
from f2n_drake.systems.controller import PurePursuitController
from f2n_drake.systems.lidar import Lidar2D
from f2n_drake.systems.noisy_odometry import NoisyOdometry
from f2n_drake.systems.robot import turtlebot3_burger
from f2n_drake.systems.scene import AddPlanGeometry, PlanGeometry
from f2n_drake.systems.unicycle_plant import UnicyclePlant
from f2n_drake.systems.visualization import (
    add_meshcat_visualizer,
    draw_route,
    save_recording_html,
)
from f2n_drake.systems.waypoint_source import WaypointSource
from pydrake.geometry import Meshcat, SceneGraph
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import Diagram, DiagramBuilder, EventStatus
from pydrake.systems.primitives import Demultiplexer, LogVectorOutput, ZeroOrderHold

from f2n_drake.errors import InputError
from f2n_drake.parsed import ParsedPlan
from f2n_drake.plan import FloorPlan

log = logging.getLogger(__name__)

Correction = Literal["paper", "continuous", "off"]
LOG_PERIOD_S = 0.1
ODOMETRY_PERIOD_S, TICK_OFFSET_S, CORRECTOR_DELAY_S = 0.1, 0.05, 0.01
WAYPOINT_SPACING_M = 0.25
"""Default route resampling [m]: paper mode's "every 5 waypoints" is then every 1.25 m."""


def plan_geometry(plan: Any) -> PlanGeometry:
    """A PlanGeometry from a PlanGeometry, FloorPlan, ParsedPlan or (ParsedPlan, free mask)."""
    if isinstance(plan, PlanGeometry):
        return plan
    if isinstance(plan, FloorPlan):
        return PlanGeometry.from_floorplan(plan)
    if isinstance(plan, ParsedPlan):
        return PlanGeometry.from_parsed(plan)
    if isinstance(plan, tuple) and len(plan) == 2 and isinstance(plan[0], ParsedPlan):
        return PlanGeometry.from_parsed(plan[0], plan[1])
    raise InputError(f"cannot simulate on a {type(plan).__name__}; expected a plan")


def route_waypoints(route: Any) -> np.ndarray:
    """(N, 2) waypoints [m] of an array or of an object with ``.waypoints_m``."""
    waypoints = np.asarray(getattr(route, "waypoints_m", route), dtype=float)
    if waypoints.ndim != 2 or waypoints.shape[1] != 2 or len(waypoints) < 1:
        raise InputError(f"route must be (N, 2) waypoints in metres, got shape {waypoints.shape}")
    return waypoints


def default_start_pose(waypoints: np.ndarray) -> np.ndarray:
    """At the first waypoint, facing the first waypoint more than 1 cm away."""
    far = np.flatnonzero(np.hypot(*(waypoints - waypoints[0]).T) > 0.01)
    d = waypoints[far[0]] - waypoints[0] if len(far) else np.array([1.0, 0.0])
    return np.array([*waypoints[0], math.atan2(d[1], d[0])])


def MakeNavigationDiagram(
    plan: Any,
    route: Any,
    *,
    correction: Correction = "continuous",
    seed: int = 0,
    meshcat: Meshcat | None = None,
    odometry_sigma_m: float = 0.02,
    start_pose: np.ndarray | None = None,
    record: bool = False,
    waypoint_spacing_m: float | None = WAYPOINT_SPACING_M,
) -> Diagram:
    """The closed-loop navigation Diagram of a TurtleBot3 Burger following ``route`` in ``plan``.

    Args:
        plan: FloorPlan, ParsedPlan, (ParsedPlan, free mask) or PlanGeometry.
        route: (N, 2) waypoints [m] or an object with ``.waypoints_m``.
        correction: LiDAR pose correction: ``"paper"`` (every 5 waypoints, axis-aligned lines),
            ``"continuous"`` (ICP on every scan) or ``"off"`` (no corrector).
        seed: seeds odometry and LiDAR noise (same seed, same run).
        meshcat: if given, a MeshcatVisualizer (named ``"meshcat_visualizer"``) and the route.
        odometry_sigma_m: odometry x/y noise per 0.1 s step [m].
        start_pose: true and initial estimated pose [x, y, theta]; default
            :func:`default_start_pose`.
        record: add loggers ``"true_pose_log"`` and ``"estimated_pose_log"`` (every 0.1 s); the
            true pose is logged through ``"true_pose_sample"``, a ZeroOrderHold at the odometry
            ticks (its state starts at zero: set it to the start pose, see
            :func:`simulate_navigation`).
        waypoint_spacing_m: the route is resampled to this spacing [m] (``None``: as given)
            without changing its shape; paper mode corrects every 5 of these waypoints.

    Exported outputs: ``true_pose``, ``estimated_pose`` [x, y, theta]; ``collision``
    [collided, min_clearance_m, count]; ``progress`` [waypoint index, done]; ``scan`` (360 m);
    and ``pose_correction`` [count, x, y, theta] when a corrector is present.
    """
    if correction not in ("paper", "continuous", "off"):
        raise InputError(f"correction must be paper, continuous or off, got {correction!r}")
    geometry = plan_geometry(plan)
    waypoints = route_waypoints(route)
    x0 = default_start_pose(waypoints) if start_pose is None else np.asarray(start_pose, float)
    robot = turtlebot3_burger()

    builder = DiagramBuilder()
    scene_graph = builder.AddNamedSystem("scene_graph", SceneGraph())
    AddPlanGeometry(scene_graph, geometry)
    plant = UnicyclePlant.AddToBuilder(builder, scene_graph, x0, name="plant")
    odometry = builder.AddNamedSystem(
        "odometry",
        NoisyOdometry(
            x0,
            seed,
            period_s=ODOMETRY_PERIOD_S,
            xy_sigma_m=odometry_sigma_m,
            offset_s=TICK_OFFSET_S,
        ),
    )
    lidar = builder.AddNamedSystem(
        "lidar",
        Lidar2D(
            seed,
            robot.lidar_num_beams,
            robot.lidar_min_range_m,
            robot.lidar_max_range_m,
            period_s=1.0 / robot.lidar_rate_hz,
            offset_s=TICK_OFFSET_S,
        ),
    )
    source = builder.AddNamedSystem(
        "waypoints",
        WaypointSource(
            waypoints, tolerance_m=0.1, spacing_m=waypoint_spacing_m, corner_tolerance_m=0.04
        ),
    )
    controller = builder.AddNamedSystem(
        "controller",
        PurePursuitController(
            len(source.waypoints_m),
            v_max=robot.v_max_mps,
            omega_max=robot.omega_max_radps,
            corners=np.flatnonzero(source.corners),
        ),
    )
    monitor = builder.AddNamedSystem("collision_monitor", CollisionMonitor(robot.radius_m))

    query = scene_graph.get_query_output_port()
    true_pose = plant.GetOutputPort("state")
    estimated_pose = odometry.GetOutputPort("estimated_pose")
    builder.Connect(query, lidar.GetInputPort("geometry_query"))
    builder.Connect(query, monitor.GetInputPort("geometry_query"))
    builder.Connect(true_pose, odometry.GetInputPort("true_pose"))
    builder.Connect(true_pose, lidar.GetInputPort("true_pose"))
    builder.Connect(estimated_pose, source.GetInputPort("estimated_pose"))
    builder.Connect(estimated_pose, controller.GetInputPort("estimated_pose"))
    builder.Connect(source.GetOutputPort("segment"), controller.GetInputPort("segment"))
    builder.Connect(source.GetOutputPort("progress"), controller.GetInputPort("progress"))
    builder.Connect(controller.GetOutputPort("command"), plant.GetInputPort("command"))

    if correction != "off":
        from f2n_drake.systems.lidar_corrector import LidarCorrector  # noqa: PLC0415

        corrector = builder.AddNamedSystem(
            "corrector",
            LidarCorrector(
                geometry.wall_segments(),
                correction,
                num_beams=robot.lidar_num_beams,
                min_range_m=robot.lidar_min_range_m,
                max_range_m=robot.lidar_max_range_m,
                period_s=1.0 / robot.lidar_rate_hz,
                offset_s=TICK_OFFSET_S + CORRECTOR_DELAY_S,
            ),
        )
        index = builder.AddNamedSystem("progress_index", Demultiplexer(2, 1))
        builder.Connect(source.GetOutputPort("progress"), index.get_input_port(0))
        builder.Connect(index.get_output_port(0), corrector.GetInputPort("waypoint_index"))
        builder.Connect(lidar.GetOutputPort("scan"), corrector.GetInputPort("scan"))
        builder.Connect(estimated_pose, corrector.GetInputPort("estimated_pose"))
        builder.Connect(
            corrector.GetOutputPort("pose_correction"), odometry.GetInputPort("pose_correction")
        )
        builder.ExportOutput(corrector.GetOutputPort("pose_correction"), "pose_correction")

    builder.ExportOutput(true_pose, "true_pose")
    builder.ExportOutput(estimated_pose, "estimated_pose")
    builder.ExportOutput(monitor.GetOutputPort("collision"), "collision")
    builder.ExportOutput(source.GetOutputPort("progress"), "progress")
    builder.ExportOutput(lidar.GetOutputPort("scan"), "scan")
    if record:
        sample = builder.AddNamedSystem(
            "true_pose_sample", ZeroOrderHold(ODOMETRY_PERIOD_S, 3, TICK_OFFSET_S)
        )
        builder.Connect(true_pose, sample.get_input_port())
        LogVectorOutput(sample.get_output_port(), builder, LOG_PERIOD_S).set_name("true_pose_log")
        LogVectorOutput(estimated_pose, builder, LOG_PERIOD_S).set_name("estimated_pose_log")
    if meshcat is not None:
        add_meshcat_visualizer(builder, scene_graph, meshcat)
        draw_route(meshcat, waypoints)
    diagram = builder.Build()
    diagram.set_name("navigation")
    return diagram


@dataclass
class NavigationResult:
    """Outcome of one simulated run (SI units).

    ``reached``: the estimate finished the route within the time limit AND the true robot ended
    within ``goal_tolerance_m`` of the goal (``goal_distance_m``); ``success`` adds no collision.
    Errors are |true xy - estimated xy| every ``sample_period_s``, both taken at the same
    odometry tick; ``true_path`` / ``estimated_path`` are those samples.
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

    @property
    def success(self) -> bool:
        """Reached the goal (truly) without a collision within the time limit."""
        return self.reached and not self.collided


def route_time_limit_s(waypoints: np.ndarray, start_xy: np.ndarray | None = None) -> float:
    """Default time limit [s]: route length at 0.15 m/s, plus 2 s per waypoint, plus 30 s."""
    path = waypoints if start_xy is None else np.vstack([start_xy, waypoints])
    length = float(np.hypot(*np.diff(path, axis=0).T).sum())
    return length / 0.15 + 2.0 * len(waypoints) + 30.0


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
) -> NavigationResult:
    """Run :func:`MakeNavigationDiagram` until the route is done, a collision, or the time limit.

    The default time limit is :func:`route_time_limit_s`. With ``html_path`` the run is
    recorded in meshcat (a new ``Meshcat()`` if none is given) and saved as a standalone HTML.
    A collision ends the run and is reported in the result, not raised.
    """
    waypoints = route_waypoints(route)
    x0 = default_start_pose(waypoints) if start_pose is None else np.asarray(start_pose, float)
    if time_limit_s is None:
        time_limit_s = route_time_limit_s(waypoints, x0[:2])
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
    )
    simulator = Simulator(diagram)
    context = simulator.get_mutable_context()
    sample = diagram.GetSubsystemByName("true_pose_sample")
    sample.SetVectorState(sample.GetMyMutableContextFromRoot(context), x0)
    progress_port = diagram.GetOutputPort("progress")
    collision_port = diagram.GetOutputPort("collision")

    def monitor(root_context) -> EventStatus:
        if progress_port.Eval(root_context)[1] > 0:
            return EventStatus.ReachedTermination(diagram, "route done")
        if collision_port.Eval(root_context)[2] > 0:
            return EventStatus.ReachedTermination(diagram, "collision")
        return EventStatus.Succeeded()

    simulator.set_monitor(monitor)
    visualizer = diagram.GetSubsystemByName("meshcat_visualizer") if meshcat else None
    if html_path is not None:
        visualizer.StartRecording()
    wall_start = time.perf_counter()
    simulator.AdvanceTo(time_limit_s)
    wall_time_s = time.perf_counter() - wall_start
    if html_path is not None:
        save_recording_html(meshcat, visualizer, html_path)

    true_log = diagram.GetSubsystemByName("true_pose_log").FindLog(context)
    estimated_log = diagram.GetSubsystemByName("estimated_pose_log").FindLog(context)
    true_path, estimated_path = true_log.data().T.copy(), estimated_log.data().T.copy()
    true_now = diagram.GetOutputPort("true_pose").Eval(context)
    estimated_now = diagram.GetOutputPort("estimated_pose").Eval(context)
    errors = np.hypot(*(true_path[:, :2] - estimated_path[:, :2]).T)
    collision = collision_port.Eval(context)
    corrections = (
        int(diagram.GetOutputPort("pose_correction").Eval(context)[0])
        if diagram.HasOutputPort("pose_correction")
        else 0
    )
    sim_time = context.get_time()
    route_done = bool(progress_port.Eval(context)[1] > 0)
    goal_distance = float(np.hypot(*(true_now[:2] - waypoints[-1])))
    return NavigationResult(
        reached=route_done and goal_distance <= goal_tolerance_m,
        collided=bool(collision[2] > 0),
        time_s=sim_time,
        final_error_m=float(np.hypot(*(true_now[:2] - estimated_now[:2]))),
        mean_error_m=float(errors.mean()) if len(errors) else 0.0,
        max_error_m=float(errors.max()) if len(errors) else 0.0,
        true_path=true_path,
        estimated_path=estimated_path,
        wall_time_s=wall_time_s,
        realtime_factor=sim_time / max(wall_time_s, 1e-9),
        min_clearance_m=float(collision[1]),
        corrections=corrections,
        goal_distance_m=goal_distance,
        correction=correction,
        sample_period_s=LOG_PERIOD_S,
        route_done=route_done,
        goal_tolerance_m=goal_tolerance_m,
    )
