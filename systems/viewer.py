"""The plan viewer in meshcat: a top-down camera framed on the plan, the plan, the route and runs.

One scene serves the live viewer (``--meshcat``) and the HTML replay (``--html``); everything is
under meshcat's ``/drake`` folder, so each part has a checkbox in the controls:

- ``plan``: the floor picture (:mod:`f2n_drake.systems.plan_texture`: rooms tinted by class with
  their names, doors and windows marked), walls as low dark boxes, windows as cyan boxes on them;
- ``route``: the planned route (blue ribbon);
- ``runs/<correction>``: one simulated run: the robot, its LiDAR scan (``lidar``, beams of the
  current scan, red), its estimated pose (``estimate``, an orange disc under the robot), and once
  it is over the true path (green) and the estimated path (orange) it drove.

The camera (:func:`plan_camera`, :func:`frame_plan`) is orthographic and looks straight down on
the plan's bounds, north up; the user can still orbit, pan and zoom.
"""

from __future__ import annotations

import math
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pydrake.geometry import Box, Mesh, Meshcat, Rgba
from pydrake.math import RigidTransform, RotationMatrix

from f2n_drake.core.classes import SPACE_CLASSES
from f2n_drake.core.errors import InputError
from f2n_drake.mapping.walls import PlanGeometry, decompose_rectangles
from f2n_drake.systems.plan_texture import class_rgb, plan_floor_mesh, room_rgb

VIEW_ASPECT = 1.5  # width / height of the window the camera is framed for (1200 x 800)
VIEW_MARGIN = 0.04  # empty border around the plan, as a fraction of the view
VIEW_WALL_HEIGHT_M = 0.3  # walls in the viewer are low, so an orbiting camera sees into rooms
PLAN_PATH, ROUTE_PATH, RUNS_PATH = "plan", "route", "runs"
POINT_LIGHTS = ("/Lights/PointLightNegativeX", "/Lights/PointLightPositiveX")
AMBIENT_LIGHT = 2.5  # meshcat's default is 0.6, with two point lights near the origin

WALL_RGBA = Rgba(0.25, 0.25, 0.28, 1.0)
WINDOW_RGBA = Rgba(0.0, 0.86, 0.9, 1.0)
ROUTE_RGBA = Rgba(0.55, 0.68, 1.0, 1.0)  # opaque: overlapping translucent quads show
TRUE_PATH_RGBA = Rgba(0.1, 0.65, 0.15, 1.0)
ESTIMATED_PATH_RGBA = Rgba(1.0, 0.5, 0.0, 1.0)
LIDAR_RGBA = Rgba(0.9, 0.05, 0.05, 0.6)
ESTIMATE_RGBA = Rgba(1.0, 0.5, 0.0, 0.7)

# (width [m], height above the floor [m]) of the ribbons, widest lowest.
ROUTE_RIBBON = (0.16, 0.02)
TRUE_RIBBON = (0.06, 0.03)
ESTIMATED_RIBBON = (0.03, 0.04)


@dataclass(frozen=True)
class TopDownCamera:
    """An orthographic camera above ``target_m`` looking straight down, north (+y) up.

    The view spans ``width_m`` x ``height_m`` [m] for a window of ``width_m / height_m`` aspect;
    meshcat keeps the height and the left edge when the window has another aspect.
    """

    target_m: tuple[float, float]
    width_m: float
    height_m: float

    @property
    def position_m(self) -> np.ndarray:
        """Camera position [m]: high above the target, a hair south of it so north is up."""
        height = 2.0 * max(self.width_m, self.height_m) + 10.0
        return np.array([self.target_m[0], self.target_m[1] - 1e-3 * height, height])

    @property
    def bounds_m(self) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax) [m] of the floor in view."""
        x, y = self.target_m
        return (
            x - self.width_m / 2,
            y - self.height_m / 2,
            x + self.width_m / 2,
            y + self.height_m / 2,
        )


def plan_camera(
    bounds_m: tuple[float, float, float, float],
    *,
    aspect: float = VIEW_ASPECT,
    margin: float = VIEW_MARGIN,
) -> TopDownCamera:
    """The top-down camera that shows all of ``bounds_m`` (xmin, ymin, xmax, ymax) [m] in a
    window of ``aspect`` (width / height), centred, with ``margin`` of the view to spare.

    Raises:
        InputError: bounds that are not finite or not positive in size, or aspect <= 0.
    """
    xmin, ymin, xmax, ymax = (float(v) for v in bounds_m)
    if not all(map(math.isfinite, (xmin, ymin, xmax, ymax))) or xmax <= xmin or ymax <= ymin:
        raise InputError(f"plan bounds must be finite with xmax > xmin, ymax > ymin: {bounds_m}")
    if not aspect > 0:
        raise InputError(f"aspect must be positive, got {aspect}")
    height = max(ymax - ymin, (xmax - xmin) / aspect) / (1.0 - 2.0 * margin)
    return TopDownCamera(((xmin + xmax) / 2, (ymin + ymax) / 2), height * aspect, height)


def frame_plan(meshcat: Meshcat, camera: TopDownCamera) -> None:
    """Set meshcat's camera to ``camera``, hide the grid, axes and background (white) and light
    the scene evenly (ambient light only: meshcat's point lights fade within 10 m of the
    origin), so colours read the same over the whole plan."""
    ortho = Meshcat.OrthographicCamera()
    ortho.left, ortho.right = -camera.width_m / 2, camera.width_m / 2
    ortho.top, ortho.bottom = camera.height_m / 2, -camera.height_m / 2
    ortho.near, ortho.far = -1000.0, 1000.0
    meshcat.SetCamera(ortho)
    meshcat.SetCameraPose(camera.position_m, np.array([*camera.target_m, 0.0]))
    for path in ("/Grid", "/Axes", "/Background", *POINT_LIGHTS):
        meshcat.SetProperty(path, "visible", False)
    meshcat.SetProperty("/Lights/AmbientLight/<object>", "intensity", AMBIENT_LIGHT)


def _boxes(meshcat: Meshcat, path: str, polygons, height_m: float, rgba: Rgba) -> None:
    for i, poly in enumerate(polygons):
        for j, (x, y, length, width, yaw) in enumerate(decompose_rectangles(poly)):
            meshcat.SetObject(f"{path}/{i}_{j}", Box(length, width, height_m), rgba)
            X_WB = RigidTransform(RotationMatrix.MakeZRotation(yaw), [x, y, height_m / 2])
            meshcat.SetTransform(f"{path}/{i}_{j}", X_WB)


def draw_plan(meshcat: Meshcat, geometry: PlanGeometry) -> TopDownCamera:
    """Draw the plan at ``plan`` (floor picture, walls, windows), frame the camera on it and
    return that camera."""
    bounds = geometry.bounds()
    meshcat.Delete(PLAN_PATH)
    with tempfile.TemporaryDirectory(prefix="f2n_plan_") as folder:
        meshcat.SetObject(
            f"{PLAN_PATH}/floor", Mesh(str(plan_floor_mesh(geometry, bounds, Path(folder))))
        )
    _boxes(meshcat, f"{PLAN_PATH}/walls", geometry.walls, VIEW_WALL_HEIGHT_M, WALL_RGBA)
    windows = [p for name, p in geometry.connectors if name == "window"]
    _boxes(meshcat, f"{PLAN_PATH}/windows", windows, VIEW_WALL_HEIGHT_M + 0.01, WINDOW_RGBA)
    camera = plan_camera(bounds)
    frame_plan(meshcat, camera)
    return camera


def ribbon_mesh(xy_m: np.ndarray, width_m: float, z_m: float) -> tuple[np.ndarray, np.ndarray]:
    """A flat strip ``width_m`` wide along the (N, 2) polyline ``xy_m`` [m] at height ``z_m``:
    (3, 4K) vertices and (3, 2K) triangles, one quad per segment longer than 0.1 mm."""
    xy = np.asarray(xy_m, dtype=float).reshape(-1, 2)
    d = np.diff(xy, axis=0)
    length = np.hypot(d[:, 0], d[:, 1])
    keep = length > 1e-4
    a, d, length = xy[:-1][keep], d[keep], length[keep]
    if len(a) == 0:
        return np.zeros((3, 0)), np.zeros((3, 0), dtype=np.int32)
    side = np.stack([-d[:, 1], d[:, 0]], axis=1) / length[:, None] * (width_m / 2)
    along = d / length[:, None] * (width_m / 2)  # overlap the joints by half a width
    b = a + d + along
    a = a - along
    corners = np.stack([a - side, a + side, b + side, b - side], axis=1).reshape(-1, 2)
    vertices = np.vstack([corners.T, np.full(len(corners), z_m)])
    k = 4 * np.arange(len(a))
    faces = np.concatenate([np.stack([k, k + 3, k + 2]), np.stack([k, k + 2, k + 1])], axis=1)
    return vertices, faces.astype(np.int32)


def draw_ribbon(
    meshcat: Meshcat, path: str, xy_m: np.ndarray, rgba: Rgba, ribbon: tuple[float, float]
) -> None:
    """The (N, 2) polyline ``xy_m`` [m] as a ribbon (width [m], height [m]) at ``path``."""
    vertices, faces = ribbon_mesh(xy_m, *ribbon)
    if faces.shape[1]:
        meshcat.SetTriangleMesh(path, vertices, faces, rgba)


def draw_route(meshcat: Meshcat, waypoints_m: np.ndarray) -> None:
    """The planned route at ``route``."""
    draw_ribbon(meshcat, ROUTE_PATH, waypoints_m, ROUTE_RGBA, ROUTE_RIBBON)


REPLANNED_PATH = "replanned"


def draw_replanned_route(
    meshcat: Meshcat, waypoints_m: np.ndarray, index: int, time_s: float
) -> None:
    """Route ``index`` (1, 2, ...: the routes taken after the planned one) at
    ``replanned/<index>``, taken at ``time_s`` [s]: live, it replaces the route shown; in a
    recording, it shows from ``time_s`` on and the one before it hides then."""
    path = f"{REPLANNED_PATH}/{index}"
    previous = ROUTE_PATH if index <= 1 else f"{REPLANNED_PATH}/{index - 1}"
    draw_ribbon(meshcat, path, waypoints_m, ROUTE_RGBA, ROUTE_RIBBON)
    meshcat.SetProperty(previous, "visible", False)
    meshcat.SetProperty(previous, "visible", False, time_s)
    meshcat.SetProperty(path, "visible", False, 0.0)
    meshcat.SetProperty(path, "visible", True, time_s)


class RouteDrawing:
    """Draws each route a navigator takes (its ``on_route``), numbered in the order taken."""

    def __init__(self, meshcat: Meshcat) -> None:
        self.meshcat, self.count = meshcat, 0

    def __call__(self, waypoints_m: np.ndarray, time_s: float) -> None:
        self.count += 1
        draw_replanned_route(self.meshcat, waypoints_m, self.count, time_s)


def run_path(name: str) -> str:
    """The meshcat folder of the run ``name`` (a correction mode)."""
    return f"{RUNS_PATH}/{name}"


def draw_run_paths(
    meshcat: Meshcat, name: str, true_xy_m: np.ndarray, estimated_xy_m: np.ndarray
) -> None:
    """The true (green) and estimated (orange) paths [m] of run ``name``."""
    draw_ribbon(meshcat, f"{run_path(name)}/true_path", true_xy_m, TRUE_PATH_RGBA, TRUE_RIBBON)
    draw_ribbon(
        meshcat,
        f"{run_path(name)}/estimated_path",
        estimated_xy_m,
        ESTIMATED_PATH_RGBA,
        ESTIMATED_RIBBON,
    )


def show_only_run(meshcat: Meshcat, names: list[str], shown: str) -> None:
    """Tick the run ``shown`` in meshcat's controls and untick the others ``names``."""
    for name in names:
        meshcat.SetProperty(run_path(name), "visible", name == shown)


def _css(rgb) -> str:
    return "rgb({},{},{})".format(*(round(255 * float(c)) for c in rgb))


def legend_html() -> str:
    """A one-line legend of the viewer's colours, fixed at the bottom of the replay page."""
    marks = [
        ("route", ROUTE_RGBA, "bar"),
        ("true path", TRUE_PATH_RGBA, "bar"),
        ("estimated path", ESTIMATED_PATH_RGBA, "bar"),
        ("LiDAR beams", LIDAR_RGBA, "bar"),
        ("robot", Rgba(0.15, 0.15, 0.15, 1.0), "dot"),
        ("estimate", ESTIMATE_RGBA, "dot"),
        ("wall", WALL_RGBA, "box"),
        ("window", WINDOW_RGBA, "box"),
        *((name, room_rgb(name), "box") for name in SPACE_CLASSES),
        *((name.replace("_", " "), class_rgb(name), "box") for name in ("door", "front_door")),
    ]
    shapes = {
        "bar": "width:18px;height:4px",
        "dot": "width:10px;height:10px;border-radius:50%",
        "box": "width:12px;height:12px",
    }
    items = "".join(
        f'<span style="margin-right:12px;white-space:nowrap"><span style="display:inline-block;'
        f"{shapes[shape]};background:"
        f"{_css(rgba.rgba[:3] if isinstance(rgba, Rgba) else rgba)};margin-right:4px;"
        f'vertical-align:middle"></span>{label}</span>'
        for label, rgba, shape in marks
    )
    return (
        '<div id="f2n-legend" style="position:fixed;left:0;right:0;bottom:0;padding:3px 8px;'
        "font:12px sans-serif;color:#222;background:rgba(255,255,255,0.85);"
        f'pointer-events:none;z-index:10">{items}</div>'
    )


def write_replay_html(meshcat: Meshcat, html_path: str | Path, *, legend: bool = True) -> Path:
    """Stop and publish meshcat's recording and write ``meshcat.StaticHtml()`` to a file, with
    :func:`legend_html` at the bottom of the page unless ``legend`` is False."""
    meshcat.StopRecording()
    meshcat.PublishRecording()
    html = meshcat.StaticHtml()
    if legend:
        at = html.rfind("</body>")
        html = html[:at] + legend_html() + "\n" + html[at:] if at >= 0 else html
    path = Path(html_path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text(html)
    tmp.replace(path)
    return path


__all__ = [
    "ESTIMATED_PATH_RGBA",
    "LIDAR_RGBA",
    "ROUTE_RGBA",
    "TRUE_PATH_RGBA",
    "TopDownCamera",
    "draw_plan",
    "draw_ribbon",
    "RouteDrawing",
    "draw_replanned_route",
    "draw_route",
    "draw_run_paths",
    "frame_plan",
    "legend_html",
    "plan_camera",
    "ribbon_mesh",
    "run_path",
    "show_only_run",
    "write_replay_html",
]
