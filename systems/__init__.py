"""Drake LeafSystems, the navigation Diagram and its runner (installed as f2n_drake.systems).

The plan's walls (``f2n_drake.mapping.walls``) and the robot (``f2n_drake.mapping.robots``,
``models/turtlebot3_burger.yaml``) are plain data read from the library; only Drake types live
here.
"""

from f2n_drake.systems.collision_monitor import CollisionMonitor
from f2n_drake.systems.controller import PurePursuitController, pure_pursuit_command
from f2n_drake.systems.diagram import MakeNavigationDiagram, plan_geometry
from f2n_drake.systems.lidar import Lidar2D, wall_segments_from_query
from f2n_drake.systems.navigator import Navigator
from f2n_drake.systems.noisy_odometry import NoisyOdometry
from f2n_drake.systems.scene import AddPlanGeometry
from f2n_drake.systems.simulation import NavigationResult, simulate_navigation
from f2n_drake.systems.unicycle_plant import UnicyclePlant
from f2n_drake.systems.vectors import (
    CollisionStatus,
    Command,
    FitQuality,
    NavigationStatus,
    Pose,
    PoseCorrection,
    Progress,
    Segment,
)
from f2n_drake.systems.viewer import (
    TopDownCamera,
    draw_plan,
    draw_route,
    draw_run_paths,
    frame_plan,
    plan_camera,
    write_replay_html,
)
from f2n_drake.systems.visualization import (
    add_meshcat_visualizer,
    draw_lidar_hits,
    draw_polyline,
    save_recording_html,
)
from f2n_drake.systems.waypoint_source import WaypointSource, densify_route

__all__ = [
    "AddPlanGeometry",
    "CollisionStatus",
    "Command",
    "FitQuality",
    "NavigationStatus",
    "Pose",
    "PoseCorrection",
    "Progress",
    "Segment",
    "CollisionMonitor",
    "Lidar2D",
    "MakeNavigationDiagram",
    "NavigationResult",
    "NavigationStatus",
    "Navigator",
    "NoisyOdometry",
    "PurePursuitController",
    "TopDownCamera",
    "UnicyclePlant",
    "WaypointSource",
    "add_meshcat_visualizer",
    "densify_route",
    "draw_lidar_hits",
    "draw_polyline",
    "draw_plan",
    "draw_route",
    "draw_run_paths",
    "frame_plan",
    "plan_camera",
    "plan_geometry",
    "pure_pursuit_command",
    "save_recording_html",
    "simulate_navigation",
    "wall_segments_from_query",
    "write_replay_html",
]
