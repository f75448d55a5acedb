"""The navigation Diagram (plan walls, robot, odometry, LiDAR, corrector, controller).

Update timing (so a LiDAR correction uses a scan and an estimate of the same instant): odometry
ticks at 0.05 + 0.1 k s, the LiDAR scans at 0.05 + 0.2 k s (with the odometry), the corrector
runs 0.01 s later and its correction takes effect at once; waypoints and the collision monitor
update at 0.1 k s, and a navigator (with a replanner) reads each scan at 0.1 + 0.2 k s.
Localization error is measured between the estimate and the true pose of the same odometry tick
(the true pose is sampled and held at the ticks).

The runner (:func:`simulate_navigation`, :class:`NavigationResult`, :func:`route_time_limit_s`)
lives in :mod:`f2n_drake.systems.simulation` and is re-exported here.
"""

from __future__ import annotations

import logging
import math
from typing import Any, Literal

import numpy as np
from pydrake.geometry import Meshcat, SceneGraph
from pydrake.systems.framework import Diagram, DiagramBuilder
from pydrake.systems.primitives import Demultiplexer, LogVectorOutput, ZeroOrderHold

from f2n_drake.core.errors import InputError
from f2n_drake.core.parsed import ParsedPlan
from f2n_drake.core.plan import FloorPlan
from f2n_drake.mapping.robots import shipped_robot
from f2n_drake.mapping.walls import PlanGeometry
from f2n_drake.planning.replanning import Replanner
from f2n_drake.systems.collision_monitor import CollisionMonitor
from f2n_drake.systems.controller import PurePursuitController
from f2n_drake.systems.lidar import Lidar2D
from f2n_drake.systems.navigator import Navigator
from f2n_drake.systems.noisy_odometry import NoisyOdometry
from f2n_drake.systems.people import People
from f2n_drake.systems.run_visualizer import RunVisualizer
from f2n_drake.systems.scene import AddFurniture, AddPlanGeometry
from f2n_drake.systems.unicycle_plant import UnicyclePlant
from f2n_drake.systems.unknown_start import AddGlobalLocalization
from f2n_drake.systems.viewer import RouteDrawing, draw_plan, draw_route, run_path
from f2n_drake.systems.visualization import add_meshcat_visualizer
from f2n_drake.systems.waypoint_source import WaypointSource
from f2n_drake.world.building import Building

log = logging.getLogger(__name__)

Correction = Literal["paper", "continuous", "off"]
LOG_PERIOD_S = 0.1
ODOMETRY_PERIOD_S, TICK_OFFSET_S, CORRECTOR_DELAY_S = 0.1, 0.05, 0.01
NAVIGATOR_OFFSET_S = 0.1
"""The navigator reads each scan at 0.1 + 0.2 k s: with the waypoint updates (no extra
integration step) and before the next odometry tick, so the estimate is still the scan's."""
WAYPOINT_SPACING_M = 0.025
"""Default route resampling [m]: about one planning-grid cell (generated plans are planned at
1.9-3.0 cm per cell), so the waypoints are spaced like the A* path cells FloorPlan2Nav's
waypoints come from, and paper mode's "every 5 waypoints" is every 0.125 m."""


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


def add_navigator(
    builder: DiagramBuilder,
    waypoints: np.ndarray,
    replanner: Replanner,
    geometry: PlanGeometry,
    waypoint_spacing_m: float | None,
    guard_options: dict[str, Any] | None = None,
    meshcat: Meshcat | None = None,
) -> tuple[Navigator, PurePursuitController]:
    """A ``"navigator"`` and a guided ``"controller"`` in ``builder`` (connect the scan); with
    ``meshcat``, each route it takes after the first is drawn there (``RouteDrawing``)."""
    robot = shipped_robot("ground")
    lidar_spec, limits = robot.lidar, robot.limits
    navigator = builder.AddNamedSystem(
        "navigator",
        Navigator(
            waypoints,
            replanner,
            geometry.wall_segments(),
            num_beams=lidar_spec.num_beams,
            tolerance_m=0.1,
            corner_tolerance_m=0.04,
            spacing_m=waypoint_spacing_m,
            scan_period_s=1.0 / lidar_spec.rate_hz,
            scan_offset_s=NAVIGATOR_OFFSET_S,
            guard_options=guard_options,
            on_route=None if meshcat is None else RouteDrawing(meshcat),
        ),
    )
    controller = builder.AddNamedSystem(
        "controller",
        PurePursuitController(
            1,
            v_max=limits.max_linear_velocity_mps,
            omega_max=limits.max_angular_velocity_radps,
            guided=True,
        ),
    )
    builder.Connect(navigator.GetOutputPort("guidance"), controller.GetInputPort("guidance"))
    return navigator, controller


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
    run_name: str | None = None,
    building: Building | None = None,
    unknown_start: bool = False,
    replanner: Replanner | None = None,
    guard_options: dict[str, Any] | None = None,
) -> Diagram:
    """The closed-loop navigation Diagram of a TurtleBot3 Burger following ``route`` in ``plan``.

    Args:
        plan: FloorPlan, ParsedPlan, (ParsedPlan, free mask) or PlanGeometry.
        route: (N, 2) waypoints [m] or an object with ``.waypoints_m``.
        correction: LiDAR pose correction: ``"paper"`` (every 5 waypoints, axis-aligned lines),
            ``"continuous"`` (ICP on every scan) or ``"off"`` (no corrector).
        seed: seeds odometry and LiDAR noise (same seed, same run).
        meshcat: if given, the plan viewer (:mod:`f2n_drake.systems.viewer`): the plan, the
            route and a camera framed on them, a MeshcatVisualizer of the robot (named
            ``"meshcat_visualizer"``) and a ``"run_visualizer"`` of the scan and estimate, both
            under ``runs/<run_name>``.
        odometry_sigma_m: odometry x/y noise per 0.1 s step [m].
        start_pose: true and initial estimated pose [x, y, theta]; default
            :func:`default_start_pose`.
        record: add loggers ``"true_pose_log"`` and ``"estimated_pose_log"`` (every 0.1 s); the
            true pose is logged through ``"true_pose_sample"``, a ZeroOrderHold at the odometry
            ticks (its state starts at zero: set it to the start pose, see
            :func:`simulate_navigation`).
        waypoint_spacing_m: the route is resampled to this spacing [m] (``None``: as given)
            without changing its shape; paper mode corrects every 5 of these waypoints.
        run_name: the run's meshcat folder name [default: ``correction``].
        building: the building as it is (what the LiDAR and the collision check see): its
            walls, its furniture (:func:`AddFurniture`) and, when it has people, a ``"people"``
            system (:class:`~f2n_drake.systems.people.People`) walking them; the robot's
            planner and corrector know only ``plan`` [default: the plan itself].
        unknown_start: the robot does not know ``start_pose``: the odometry starts at the
            origin of its own frame, a ``"global_localizer"`` (Monte Carlo localization on the
            plan) and an ``"explorer"`` (slow, safe motion from the scan) run until the
            localizer converges, then it corrects the odometry once and hands over to the
            route and the tracking corrector (:mod:`f2n_drake.systems.unknown_start`); with
            meshcat the particle cloud is drawn under ``runs/<run_name>/particles``.
        replanner: the plan's :class:`~f2n_drake.planning.replanning.Replanner`; with it a
            ``"navigator"`` (:class:`~f2n_drake.systems.navigator.Navigator`) follows the route
            instead of ``"waypoints"``: it avoids what the LiDAR sees and the plan lacks,
            replans past closed doors, and replans when its ``replan_request`` input rises;
            ``navigation_status`` is exported. Without it the route is followed as planned.
        guard_options: keyword arguments of
            :class:`~f2n_drake.planning.route_guard.RouteGuard` (with ``replanner``).

    Exported outputs: ``true_pose``, ``estimated_pose`` [x, y, theta]; ``collision``
    [collided, min_clearance_m, count] (walls and furniture); ``person_collision``
    [in_contact, min_clearance_m, contacts]; ``progress`` [waypoint index, done]; ``scan``
    (360 m); ``pose_correction`` [count, x, y, theta] when a corrector is present; and
    ``navigation_status`` [replans, no route left, closed doors, hold] with a ``replanner``.
    With ``unknown_start`` also ``localized`` [converged, handovers] and ``handover`` [time_s,
    x, y, theta], and ``pose_correction`` is what the odometry receives (the handover, then the
    tracking corrections).
    """
    if correction not in ("paper", "continuous", "off"):
        raise InputError(f"correction must be paper, continuous or off, got {correction!r}")
    geometry = plan_geometry(plan)
    waypoints = route_waypoints(route)
    x0 = default_start_pose(waypoints) if start_pose is None else np.asarray(start_pose, float)
    robot = shipped_robot("ground")  # models/turtlebot3_burger.yaml
    lidar_spec, limits = robot.lidar, robot.limits

    builder = DiagramBuilder()
    scene_graph = builder.AddNamedSystem("scene_graph", SceneGraph())
    world = geometry
    if building is not None:
        world = PlanGeometry(list(building.walls), geometry.floors, geometry.connectors)
    AddPlanGeometry(scene_graph, world, illustration=meshcat is None)
    if building is not None:
        AddFurniture(scene_graph, building)
    plant = UnicyclePlant.AddToBuilder(builder, scene_graph, x0, name="plant")
    if building is not None and building.people:  # after the anchored geometry it filters
        people = People.AddToBuilder(
            builder, scene_graph, building.people, robot_radius_m=robot.body.radius_m
        )
        builder.Connect(plant.GetOutputPort("state"), people.GetInputPort("true_pose"))
    odometry = builder.AddNamedSystem(
        "odometry",
        NoisyOdometry(
            x0,
            seed,
            period_s=ODOMETRY_PERIOD_S,
            xy_sigma_m=odometry_sigma_m,
            offset_s=TICK_OFFSET_S,
            initial_estimate=np.zeros(3) if unknown_start else None,
        ),
    )
    lidar = builder.AddNamedSystem(
        "lidar",
        Lidar2D(
            seed,
            lidar_spec.num_beams,
            lidar_spec.min_range_m,
            lidar_spec.max_range_m,
            period_s=1.0 / lidar_spec.rate_hz,
            offset_s=TICK_OFFSET_S,
        ),
    )
    if replanner is None:
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
                v_max=limits.max_linear_velocity_mps,
                omega_max=limits.max_angular_velocity_radps,
                corners=np.flatnonzero(source.corners),
                leg_ends=source.leg_ends,
            ),
        )
    else:
        source, controller = add_navigator(
            builder, waypoints, replanner, geometry, waypoint_spacing_m, guard_options, meshcat
        )
        builder.Connect(lidar.GetOutputPort("scan"), source.GetInputPort("scan"))
        builder.ExportOutput(source.GetOutputPort("navigation_status"), "navigation_status")
    monitor = builder.AddNamedSystem("collision_monitor", CollisionMonitor(robot.body.radius_m))

    query = scene_graph.get_query_output_port()
    true_pose = plant.GetOutputPort("state")
    estimated_pose = odometry.GetOutputPort("estimated_pose")
    builder.Connect(query, lidar.GetInputPort("geometry_query"))
    builder.Connect(query, monitor.GetInputPort("geometry_query"))
    builder.Connect(true_pose, odometry.GetInputPort("true_pose"))
    builder.Connect(true_pose, lidar.GetInputPort("true_pose"))
    route_pose, command = estimated_pose, controller.GetOutputPort("command")
    localization = None
    if unknown_start:
        localization = AddGlobalLocalization(
            builder,
            geometry,
            seed=seed,
            scan=lidar.GetOutputPort("scan"),
            odometry_pose=estimated_pose,
            lidar=lidar_spec,
            robot_radius_m=robot.body.radius_m,
            period_s=1.0 / lidar_spec.rate_hz,
            offset_s=TICK_OFFSET_S + CORRECTOR_DELAY_S,
            meshcat=meshcat,
            particles_path=f"{run_path(correction if run_name is None else run_name)}/particles",
        )
        route_pose = localization.gate.GetOutputPort("route_pose")
        builder.Connect(command, localization.switch.GetInputPort("route_command"))
        command = localization.switch.GetOutputPort("command")
    builder.Connect(route_pose, source.GetInputPort("estimated_pose"))
    builder.Connect(route_pose, controller.GetInputPort("estimated_pose"))
    builder.Connect(source.GetOutputPort("segment"), controller.GetInputPort("segment"))
    builder.Connect(source.GetOutputPort("progress"), controller.GetInputPort("progress"))
    builder.Connect(command, plant.GetInputPort("command"))
    odometry_correction = None

    if correction != "off":
        from f2n_drake.systems.lidar_corrector import LidarCorrector  # noqa: PLC0415

        corrector = builder.AddNamedSystem(
            "corrector",
            LidarCorrector(
                geometry.wall_segments(),
                correction,
                num_beams=lidar_spec.num_beams,
                min_range_m=lidar_spec.min_range_m,
                max_range_m=lidar_spec.max_range_m,
                period_s=1.0 / lidar_spec.rate_hz,
                offset_s=TICK_OFFSET_S + CORRECTOR_DELAY_S,
            ),
        )
        index = builder.AddNamedSystem("progress_index", Demultiplexer(2, 1))
        builder.Connect(source.GetOutputPort("progress"), index.get_input_port(0))
        builder.Connect(index.get_output_port(0), corrector.GetInputPort("waypoint_index"))
        builder.Connect(lidar.GetOutputPort("scan"), corrector.GetInputPort("scan"))
        builder.Connect(estimated_pose, corrector.GetInputPort("estimated_pose"))
        odometry_correction = corrector.GetOutputPort("pose_correction")
    if localization is not None:
        if odometry_correction is not None:
            tracking = localization.localizer.GetInputPort("tracking_correction")
            builder.Connect(odometry_correction, tracking)
        odometry_correction = localization.localizer.GetOutputPort("pose_correction")
        builder.ExportOutput(localization.localizer.GetOutputPort("localized"), "localized")
        builder.ExportOutput(localization.localizer.GetOutputPort("handover"), "handover")
        if replanner is not None:  # localized at last: a route from where the robot now is
            handovers = builder.AddNamedSystem("handover_count", Demultiplexer([1, 1]))
            builder.Connect(
                localization.localizer.GetOutputPort("localized"), handovers.get_input_port(0)
            )
            builder.Connect(handovers.get_output_port(1), source.GetInputPort("replan_request"))
    if odometry_correction is not None:
        builder.Connect(odometry_correction, odometry.GetInputPort("pose_correction"))
        builder.ExportOutput(odometry_correction, "pose_correction")

    builder.ExportOutput(true_pose, "true_pose")
    builder.ExportOutput(estimated_pose, "estimated_pose")
    builder.ExportOutput(monitor.GetOutputPort("collision"), "collision")
    builder.ExportOutput(monitor.GetOutputPort("person_collision"), "person_collision")
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
        folder = run_path(correction if run_name is None else run_name)
        draw_plan(meshcat, geometry)
        draw_route(meshcat, waypoints)
        add_meshcat_visualizer(builder, scene_graph, meshcat, prefix=f"{folder}/robot")
        viewer = builder.AddNamedSystem(
            "run_visualizer",
            RunVisualizer(
                meshcat,
                folder,
                num_beams=lidar_spec.num_beams,
                period_s=1.0 / lidar_spec.rate_hz,
                offset_s=TICK_OFFSET_S,
            ),
        )
        builder.Connect(true_pose, viewer.GetInputPort("true_pose"))
        shown = estimated_pose if localization is None else localization.shown.get_output_port()
        builder.Connect(shown, viewer.GetInputPort("estimated_pose"))
        builder.Connect(lidar.GetOutputPort("scan"), viewer.GetInputPort("scan"))
    diagram = builder.Build()
    diagram.set_name("navigation")
    return diagram


__all__ = [
    "CORRECTOR_DELAY_S",
    "LOG_PERIOD_S",
    "NAVIGATOR_OFFSET_S",
    "ODOMETRY_PERIOD_S",
    "TICK_OFFSET_S",
    "WAYPOINT_SPACING_M",
    "Correction",
    "MakeNavigationDiagram",
    "add_navigator",
    "default_start_pose",
    "plan_geometry",
    "route_waypoints",
]
