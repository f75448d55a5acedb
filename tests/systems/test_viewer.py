"""The plan viewer: the camera an HTML replay holds frames the plan (two sizes and a rotated
plan), and the scene's parts.

A replay's scene is the list of meshcat commands inlined in the HTML as base64 msgpack; the
small reader below decodes them (no msgpack package needed).
"""

from __future__ import annotations

import base64
import re
import struct

import numpy as np
import pytest
import shapely
from shapely import affinity
from shapely.geometry import box

from f2n_drake.core.errors import InputError
from f2n_drake.core.plan import FloorPlan
from f2n_drake.mapping.walls import PlanGeometry
from f2n_drake.systems.plan_texture import render_plan_texture, room_names
from f2n_drake.systems.run_visualizer import beam_segments
from f2n_drake.systems.simulation import simulate_navigation
from f2n_drake.systems.viewer import (
    VIEW_ASPECT,
    RouteDrawing,
    draw_plan,
    draw_route,
    legend_html,
    plan_camera,
    ribbon_mesh,
)

BEDROOM, LIVING, DOOR = box(0, 0, 3, 3), box(3.2, 0, 6.2, 3), box(3.0, 1.2, 3.2, 2.0)
ROUTE = np.array([(1.0, 1.0), (2.5, 1.6), (3.7, 1.6), (5.2, 0.8)])


def two_rooms(angle_deg: float = 0.0) -> FloorPlan:
    """Two 3 x 3 m rooms, 0.2 m walls, joined by a 0.8 m door, turned ``angle_deg``."""
    walls = box(-0.2, -0.2, 6.4, 3.2).difference(shapely.union_all([BEDROOM, LIVING, DOOR]))
    rotate = lambda g: affinity.rotate(g, angle_deg, origin=(0, 0))  # noqa: E731
    polygons = {"bedroom": [BEDROOM], "living": [LIVING], "wall": [walls], "door": [DOOR]}
    return FloorPlan({k: [rotate(g) for g in v] for k, v in polygons.items()}, 0.2, "test")


def rotated_route(angle_deg: float) -> np.ndarray:
    c, s = np.cos(np.radians(angle_deg)), np.sin(np.radians(angle_deg))
    return ROUTE @ np.array([[c, -s], [s, c]]).T


# --- a msgpack reader for the commands in a replay ------------------------------------------

_FIXED = {0xC0: None, 0xC2: False, 0xC3: True}
_NUMBERS = {0xCA: ">f", 0xCB: ">d", 0xCC: ">B", 0xCD: ">H", 0xCE: ">I", 0xCF: ">Q"}
_NUMBERS |= {0xD0: ">b", 0xD1: ">h", 0xD2: ">i", 0xD3: ">q"}
_SIZED = {0xD9: 1, 0xDA: 2, 0xDB: 4, 0xC4: 1, 0xC5: 2, 0xC6: 4}  # str8/16/32, bin8/16/32
_CONTAINERS = {0xDC: (2, "array"), 0xDD: (4, "array"), 0xDE: (2, "map"), 0xDF: (4, "map")}


def _read(b: bytes, i: int):
    t = b[i]
    if t <= 0x7F or t >= 0xE0:
        return (t if t <= 0x7F else t - 0x100), i + 1
    if t in _FIXED:
        return _FIXED[t], i + 1
    if 0xA0 <= t <= 0xBF:
        return b[i + 1 : i + 1 + (t & 0x1F)].decode(), i + 1 + (t & 0x1F)
    if t in _NUMBERS:
        size = struct.calcsize(_NUMBERS[t])
        return struct.unpack(_NUMBERS[t], b[i + 1 : i + 1 + size])[0], i + 1 + size
    if t in _SIZED:
        n, j = int.from_bytes(b[i + 1 : i + 1 + _SIZED[t]], "big"), i + 1 + _SIZED[t]
        return (b[j : j + n].decode() if t >= 0xD9 else b[j : j + n]), j + n
    if 0x80 <= t <= 0x9F or t in _CONTAINERS:
        if t <= 0x9F:
            n, j, kind = t & 0x0F, i + 1, "map" if t <= 0x8F else "array"
        else:
            size, kind = _CONTAINERS[t]
            n, j = int.from_bytes(b[i + 1 : i + 1 + size], "big"), i + 1 + size
        items = []
        for _ in range(2 * n if kind == "map" else n):
            value, j = _read(b, j)
            items.append(value)
        return (dict(zip(items[::2], items[1::2], strict=True)) if kind == "map" else items), j
    if 0xD4 <= t <= 0xD8:  # fixext: typed arrays
        n = 1 << (t - 0xD4)
        return ("ext", b[i + 2 : i + 2 + n]), i + 2 + n
    if t in (0xC7, 0xC8, 0xC9):
        size = {0xC7: 1, 0xC8: 2, 0xC9: 4}[t]
        n, j = int.from_bytes(b[i + 1 : i + 1 + size], "big"), i + 2 + size
        return ("ext", b[j : j + n]), j + n
    raise ValueError(f"msgpack type 0x{t:02x}")


def replay_commands(html: str) -> list[dict]:
    """The meshcat commands a static HTML replay sends to its viewer, decoded."""
    found = re.findall(r'base64,([A-Za-z0-9+/=]+)"\)', html)
    return [_read(base64.b64decode(data), 0)[0] for data in found]


def replay_camera(html: str) -> tuple[dict, np.ndarray, np.ndarray]:
    """(orthographic camera, camera position [m], target [m]) a replay holds, in Drake's z-up
    world frame (meshcat's three.js frame is y-up: (x, z, -y))."""
    commands = replay_commands(html)
    (camera,) = [
        c["object"]["object"]
        for c in commands
        if c["type"] == "set_object" and c["path"] == "/Cameras/default/rotated"
    ]
    (position,) = [
        c["value"]
        for c in commands
        if c["type"] == "set_property" and c["path"] == "/Cameras/default/rotated/<object>"
    ]
    (target,) = [c["value"] for c in commands if c["type"] == "set_target"]
    to_drake = lambda v: np.array([v[0], -v[2], v[1]])  # noqa: E731
    return camera, to_drake(position), to_drake(target)


# --- the camera -------------------------------------------------------------------------------


def _scene_html(geometry: PlanGeometry, monkeypatch) -> str:
    monkeypatch.setenv("DRAKE_ALLOW_NETWORK", "meshcat")
    from pydrake.geometry import Meshcat

    meshcat = Meshcat()
    draw_plan(meshcat, geometry)
    return meshcat.StaticHtml()


@pytest.mark.parametrize(
    "name, geometry",
    [
        ("6.6 m two rooms", PlanGeometry.from_floorplan(two_rooms())),
        ("40 m, scaled 6x", None),
        ("rotated 30 deg", PlanGeometry.from_floorplan(two_rooms(30.0))),
    ],
)
def test_replay_camera_frames_the_whole_plan_from_above(name, geometry, monkeypatch):
    if geometry is None:
        small = PlanGeometry.from_floorplan(two_rooms())
        scale = lambda g: affinity.scale(g, 6.0, 6.0, origin=(10.0, -5.0))  # noqa: E731
        geometry = PlanGeometry(
            [scale(w) for w in small.walls],
            [(n, scale(f)) for n, f in small.floors],
            [(n, scale(c)) for n, c in small.connectors],
        )
    camera, position, target = replay_camera(_scene_html(geometry, monkeypatch))
    assert camera["type"] == "OrthographicCamera", name
    xy = np.vstack([np.asarray(w.exterior.coords) for w in geometry.walls])
    # Looking straight down on the plan's centre, from above everything.
    centre = (xy.min(axis=0) + xy.max(axis=0)) / 2
    np.testing.assert_allclose(target[:2], centre, atol=1e-6)
    assert target[2] == 0.0 and position[2] > 10.0
    tilt = np.hypot(*(position[:2] - target[:2])) / (position[2] - target[2])
    assert tilt < 0.01 and position[1] < target[1]  # a hair south: north is up
    # The view holds every wall corner, and the plan fills it in its tighter direction.
    half_w = (camera["right"] - camera["left"]) / 2
    half_h = (camera["top"] - camera["bottom"]) / 2
    assert half_w / half_h == pytest.approx(VIEW_ASPECT)
    assert np.all(np.abs(xy[:, 0] - target[0]) <= half_w)
    assert np.all(np.abs(xy[:, 1] - target[1]) <= half_h)
    extent = xy.max(axis=0) - xy.min(axis=0)
    assert max(extent[0] / (2 * half_w), extent[1] / (2 * half_h)) > 0.9


def test_plan_camera_fits_wide_and_tall_plans_and_rejects_empty_bounds():
    wide = plan_camera((0.0, 0.0, 30.0, 2.0), aspect=1.5, margin=0.0)
    assert (wide.width_m, wide.height_m) == pytest.approx((30.0, 20.0))
    tall = plan_camera((-1.0, -10.0, 1.0, 10.0), aspect=1.5, margin=0.1)
    assert tall.height_m == pytest.approx(20.0 / 0.8) and tall.target_m == (0.0, 0.0)
    xmin, ymin, xmax, ymax = tall.bounds_m
    assert xmin < -1.0 and xmax > 1.0 and ymin < -10.0 and ymax > 10.0
    for bad in [(0.0, 0.0, 0.0, 1.0), (0.0, 0.0, np.inf, 1.0)]:
        with pytest.raises(InputError):
            plan_camera(bad)


def test_replay_of_a_run_holds_the_camera_the_run_and_a_legend(tmp_path, monkeypatch):
    monkeypatch.setenv("DRAKE_ALLOW_NETWORK", "meshcat")
    html = tmp_path / "run.html"
    plan = two_rooms(30.0)
    simulate_navigation(
        plan, rotated_route(30.0), correction="off", seed=0, time_limit_s=1.0, html_path=html
    )
    text = html.read_text()
    camera, _, target = replay_camera(text)
    bounds = PlanGeometry.from_floorplan(plan).bounds()
    np.testing.assert_allclose(
        target[:2], [(bounds[0] + bounds[2]) / 2, (bounds[1] + bounds[3]) / 2]
    )
    paths = {c.get("path", "") for c in replay_commands(text)}
    for part in ("plan/floor", "route", "runs/off/true_path", "runs/off/estimated_path"):
        assert f"/drake/{part}" in paths, part
    assert any(p.startswith("/drake/runs/off/lidar/") for p in paths)
    assert any(p.startswith("/drake/runs/off/robot/") for p in paths)
    assert 'id="f2n-legend"' in text and "estimated path" in text


# --- scene parts ------------------------------------------------------------------------------


def test_plan_texture_is_the_plan_with_room_names():
    geometry = PlanGeometry.from_floorplan(two_rooms())
    image = render_plan_texture(geometry, geometry.bounds())
    assert image.dtype == np.uint8 and image.shape[1] == 2048
    assert image.shape[0] == pytest.approx(2048 * 3.4 / 6.6, abs=2)
    assert room_names(geometry) == ["living_0", "bedroom_0"]
    assert len(geometry.connectors) == 1 and geometry.connectors[0][0] == "door"


def test_ribbon_and_beams():
    vertices, faces = ribbon_mesh(
        np.array([(0.0, 0.0), (1.0, 0.0), (1.0, 0.0), (1.0, 2.0)]), 0.1, 0.02
    )
    assert vertices.shape == (3, 8) and faces.shape == (3, 4)  # the repeated point is skipped
    assert np.all(vertices[2] == 0.02) and np.ptp(vertices[1, :4]) == pytest.approx(0.1)
    scan = np.full(8, np.inf)
    scan[0], scan[2] = 1.0, 2.0
    starts, ends = beam_segments(np.array([1.0, 1.0, np.pi / 2]), scan)
    np.testing.assert_allclose(starts[:2].T, [[1.0, 1.0]] * 2)
    np.testing.assert_allclose(ends[:2].T, [[1.0, 2.0], [-1.0, 1.0]], atol=1e-12)


def test_legend_names_every_colour():
    text = legend_html()
    for label in (
        "route",
        "true path",
        "estimated path",
        "LiDAR beams",
        "robot",
        "window",
        "kitchen",
    ):
        assert label in text


def test_a_replanned_route_is_drawn_and_replaces_the_one_before(monkeypatch):
    from pydrake.geometry import Meshcat

    monkeypatch.setenv("DRAKE_ALLOW_NETWORK", "meshcat")
    meshcat = Meshcat()
    draw_route(meshcat, np.array([[0.0, 0.0], [1.0, 0.0]]))
    drawing = RouteDrawing(meshcat)
    drawing(np.array([[0.0, 0.0], [0.5, 0.5], [1.0, 0.0]]), 2.0)
    drawing(np.array([[0.5, 0.5], [1.0, 0.0]]), 4.0)
    assert drawing.count == 2
    assert meshcat.HasPath("replanned/1") and meshcat.HasPath("replanned/2")
