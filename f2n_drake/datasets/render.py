"""Rasterise a ``FloorPlan`` into a drawing (the pipeline's input) and its label mask.

The drawing follows ResPlan's look (see TEAM_RULES): black outlines on white of the wall, door,
window, front-door, balcony and extra (storage, stair, ...) polygons, never of room polygons, so
rooms are the white regions the wall and door lines enclose. A :class:`DrawingStyle` varies line
width, filled walls, door-swing arcs, a small rotation, blur, noise, JPEG artefacts and grey ink
for training augmentation. The label mask gives each pixel the class of the polygon covering it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np
from shapely.geometry import Polygon

from f2n_drake.core.classes import CLASS_ID, NUM_CLASSES, PAINT_ORDER, PALETTE
from f2n_drake.core.errors import InputError
from f2n_drake.core.plan import FloorPlan
from f2n_drake.core.raster import PixelGrid

SHIFT = 4
"""Fractional bits of the fixed-point coordinates handed to OpenCV (1/16 px accuracy)."""
_SCALE = 1 << SHIFT


OUTLINED_CLASSES: tuple[str, ...] = ("balcony", "wall", "window", "door", "front_door")
DRAWN_EXTRA_KEYS: tuple[str, ...] = ("storage", "stair", "garden", "pool", "parking", "veranda")
"""Extra plan keys whose outlines appear in the drawing (labelled background)."""

ROOM_LABELS = np.array([CLASS_ID[n] for n in ("living", "bedroom", "bathroom", "kitchen")])
MAX_SIDE_PX = 16384


@dataclass(frozen=True)
class DrawingStyle:
    """How a plan is drawn. The default is a clean ResPlan-like drawing.

    Attributes:
        line_width_px: outline thickness, 1..3 [px].
        filled_walls: walls filled with ink instead of outlined.
        door_arcs: draw each door's swing (leaf line + quarter arc) into a room beside it.
        rotation_deg: rotation of image and labels about the image centre [deg], |θ| ≤ 5.
        blur_sigma_px: Gaussian blur sigma [px], 0 for none.
        noise_std: std of additive Gaussian noise [grey levels], 0 for none.
        jpeg_quality: JPEG re-encoding quality 30..95, or None for none.
        antialias: antialiased lines (else 4-connected aliased lines).
        grey_lines: ink intensity, 0 (black) .. 120.
    """

    line_width_px: int = 1
    filled_walls: bool = False
    door_arcs: bool = False
    rotation_deg: float = 0.0
    blur_sigma_px: float = 0.0
    noise_std: float = 0.0
    jpeg_quality: int | None = None
    antialias: bool = False
    grey_lines: int = 0

    def __post_init__(self) -> None:
        if not 1 <= self.line_width_px <= 3:
            raise ValueError(f"line_width_px must be 1..3, got {self.line_width_px}")
        if abs(self.rotation_deg) > 5:
            raise ValueError(f"|rotation_deg| must be ≤ 5, got {self.rotation_deg}")
        if self.blur_sigma_px < 0 or self.noise_std < 0:
            raise ValueError("blur_sigma_px and noise_std must be ≥ 0")
        if self.jpeg_quality is not None and not 30 <= self.jpeg_quality <= 95:
            raise ValueError(f"jpeg_quality must be None or 30..95, got {self.jpeg_quality}")
        if not 0 <= self.grey_lines <= 120:
            raise ValueError(f"grey_lines must be 0..120, got {self.grey_lines}")

    @classmethod
    def random(cls, rng: np.random.Generator) -> DrawingStyle:
        """A random realistic style for augmentation: mostly clean-ish, about 15 % heavy."""
        heavy = rng.random() < 0.15
        p = 0.8 if heavy else 0.3  # probability of each degradation
        return cls(
            line_width_px=int(rng.choice([1, 1, 1, 2, 2, 3])),
            filled_walls=bool(rng.random() < 0.25),
            door_arcs=bool(rng.random() < 0.3),
            rotation_deg=float(rng.uniform(-3, 3)) if rng.random() < p else 0.0,
            blur_sigma_px=float(rng.uniform(0.3, 1.5 if heavy else 0.9))
            if rng.random() < p
            else 0.0,
            noise_std=float(rng.uniform(2, 20 if heavy else 8)) if rng.random() < p else 0.0,
            jpeg_quality=int(rng.integers(30 if heavy else 60, 96)) if rng.random() < p else None,
            antialias=bool(rng.random() < 0.5),
            grey_lines=int(rng.integers(0, 121)) if rng.random() < p else 0,
        )


@dataclass
class RenderedPlan:
    """A drawing and its labels.

    Attributes:
        image: (H, W) uint8 grey drawing, 255 = paper.
        labels: (H, W) uint8 class ids (``CLASS_NAMES``).
        grid: metres <-> pixels. Exact when ``style.rotation_deg == 0``; otherwise pixels are
            ``grid.to_px`` rotated by ``rotation_deg`` (counter-clockwise as seen) about the image
            centre.
        style: the style used.
    """

    image: np.ndarray
    labels: np.ndarray
    grid: PixelGrid
    style: DrawingStyle


class _Projector:
    """Metres -> fixed-point OpenCV pixel coordinates, with the style's rotation."""

    def __init__(self, grid: PixelGrid, rotation_deg: float = 0.0) -> None:
        self.grid = grid
        t = math.radians(rotation_deg)
        # Image rows point down, so a counter-clockwise turn as seen is (c, s; -s, c) in (col, row).
        self.rot = np.array([[math.cos(t), math.sin(t)], [-math.sin(t), math.cos(t)]])
        self.centre = np.array([(grid.shape[1] - 1) / 2, (grid.shape[0] - 1) / 2])
        self.rotate = rotation_deg != 0.0

    def px(self, xy_m: np.ndarray) -> np.ndarray:
        """(N, 2) metres -> (N, 2) float pixel-centre coordinates (col, row)."""
        p = self.grid.to_px(xy_m)
        if self.rotate:
            p = (p - self.centre) @ self.rot.T + self.centre
        return p

    def fixed(self, xy_m: np.ndarray) -> np.ndarray:
        return np.round(self.px(xy_m) * _SCALE).astype(np.int32)

    def rings(self, poly: Polygon) -> list[np.ndarray]:
        """Exterior then holes of ``poly`` as fixed-point int32 (N, 2) arrays."""
        rings = [poly.exterior, *poly.interiors]
        return [self.fixed(np.asarray(r.coords)[:-1]) for r in rings]


def _grid_for(
    plan: FloorPlan, size_px: int, margin_px: int, metres_per_px: float | None, rotation_deg: float
) -> PixelGrid:
    xmin, ymin, xmax, ymax = plan.bounds
    if rotation_deg:  # grow the bounds so the rotated plan still fits inside the margin
        t = math.radians(abs(rotation_deg))
        w, h = xmax - xmin, ymax - ymin
        rw, rh = w * math.cos(t) + h * math.sin(t), w * math.sin(t) + h * math.cos(t)
        cx, cy = (xmin + xmax) / 2, (ymin + ymax) / 2
        xmin, xmax, ymin, ymax = cx - rw / 2, cx + rw / 2, cy - rh / 2, cy + rh / 2
    if metres_per_px is None:
        return PixelGrid.fit((xmin, ymin, xmax, ymax), size_px, margin_px)
    if not metres_per_px > 0:
        raise InputError(f"metres_per_px must be positive, got {metres_per_px}")
    cols = math.ceil((xmax - xmin) / metres_per_px) + 2 * margin_px
    rows = math.ceil((ymax - ymin) / metres_per_px) + 2 * margin_px
    if max(rows, cols) > MAX_SIDE_PX:
        raise InputError(
            f"plan needs a {cols}x{rows} px image at {metres_per_px} m/px "
            f"(limit {MAX_SIDE_PX} px); use a coarser scale"
        )
    origin = (xmin - margin_px * metres_per_px, ymax + margin_px * metres_per_px)
    return PixelGrid(metres_per_px, origin, (rows, cols))


def render_labels(plan: FloorPlan, grid: PixelGrid, *, rotation_deg: float = 0.0) -> np.ndarray:
    """(H, W) uint8 label mask: each pixel gets the class of the last polygon covering its centre
    in ``PAINT_ORDER``; holes keep what lies under them; extras stay background (0)."""
    return _render_labels(plan, _Projector(grid, rotation_deg))


def _render_labels(plan: FloorPlan, proj: _Projector) -> np.ndarray:
    labels = np.zeros(proj.grid.shape, np.uint8)
    for name in PAINT_ORDER:
        for poly in plan[name]:
            # One call per polygon: OpenCV's even-odd fill leaves the holes as they were.
            cv2.fillPoly(labels, proj.rings(poly), CLASS_ID[name], cv2.LINE_8, SHIFT)
    return labels


def render_drawing(
    plan: FloorPlan,
    grid: PixelGrid,
    style: DrawingStyle | None = None,
    *,
    rng: np.random.Generator | None = None,
) -> np.ndarray:
    """(H, W) uint8 drawing of ``plan`` on ``grid`` (rotation, noise etc. as in ``style``)."""
    style = style or DrawingStyle()
    rng = rng if rng is not None else np.random.default_rng(0)
    proj = _Projector(grid, style.rotation_deg)
    labels = _render_labels(plan, proj) if style.door_arcs else None
    return _render_drawing(plan, proj, style, rng, labels)


def _render_drawing(
    plan: FloorPlan,
    proj: _Projector,
    style: DrawingStyle,
    rng: np.random.Generator,
    labels: np.ndarray | None,
) -> np.ndarray:
    image = np.full(proj.grid.shape, 255, np.uint8)
    ink = int(style.grey_lines)
    line_type = cv2.LINE_AA if style.antialias else cv2.LINE_4
    width = int(style.line_width_px)
    outlined = [n for n in DRAWN_EXTRA_KEYS if n in plan.polygons] + list(OUTLINED_CLASSES)
    if style.filled_walls:
        for poly in plan["wall"]:
            cv2.fillPoly(image, proj.rings(poly), ink, line_type, SHIFT)
    rings = [r for name in outlined for poly in plan[name] for r in proj.rings(poly)]
    if rings:
        cv2.polylines(image, rings, True, ink, width, line_type, SHIFT)
    if style.door_arcs and labels is not None:
        arcs = [
            a
            for n in ("door", "front_door")
            for p in plan[n]
            for a in _door_swing(p, proj, labels, rng)
        ]
        if arcs:
            cv2.polylines(image, arcs, False, ink, 1, line_type, SHIFT)
    return _degrade(image, style, rng)


def _door_swing(
    door: Polygon, proj: _Projector, labels: np.ndarray, rng: np.random.Generator
) -> list[np.ndarray]:
    """Leaf line and quarter arc of a door swinging into a room beside it ([] if none found)."""
    rect = np.asarray(door.minimum_rotated_rectangle.exterior.coords)[:4]
    edges = np.roll(rect, -1, axis=0) - rect
    lengths = np.linalg.norm(edges, axis=1)
    i = int(np.argmax(lengths))
    width = lengths[i]
    if width < 1e-6:
        return []
    along = edges[i] / width
    normal = np.array([-along[1], along[0]])
    centre = rect.mean(axis=0)
    depth = lengths[(i + 1) % 4]
    sides = []
    for sign in (1.0, -1.0):  # keep the sides whose probe point lies in a room
        col, row = np.round(proj.px((centre + sign * normal * (depth / 2 + 0.5 * width))[None])[0])
        r, c = int(row), int(col)
        if 0 <= r < labels.shape[0] and 0 <= c < labels.shape[1] and labels[r, c] in ROOM_LABELS:
            sides.append(sign)
    if not sides:
        return []
    sign = sides[int(rng.integers(len(sides)))]
    hinge_side = 1.0 if rng.random() < 0.5 else -1.0
    face = centre + sign * normal * depth / 2
    hinge = face + hinge_side * along * width / 2
    leaf_end = hinge + sign * normal * width
    angles = np.linspace(0.0, math.pi / 2, 13)
    towards = -hinge_side * along  # from hinge to the opposite jamb
    arc = hinge + width * (
        np.cos(angles)[:, None] * (sign * normal) + np.sin(angles)[:, None] * towards
    )
    return [proj.fixed(np.stack([hinge, leaf_end])), proj.fixed(arc)]


def _degrade(image: np.ndarray, style: DrawingStyle, rng: np.random.Generator) -> np.ndarray:
    if style.blur_sigma_px > 0:
        image = cv2.GaussianBlur(image, (0, 0), style.blur_sigma_px)
    if style.noise_std > 0:
        noise = rng.standard_normal(image.shape, dtype=np.float32) * np.float32(style.noise_std)
        image = np.clip(image + noise, 0, 255).astype(np.uint8)
    if style.jpeg_quality is not None:
        ok, buf = cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_QUALITY, int(style.jpeg_quality)])
        image = cv2.imdecode(buf, cv2.IMREAD_GRAYSCALE)
    return image


def render(
    plan: FloorPlan,
    size_px: int = 512,
    *,
    style: DrawingStyle | None = None,
    rng: np.random.Generator | None = None,
    margin_px: int = 16,
    metres_per_px: float | None = None,
) -> RenderedPlan:
    """Draw ``plan`` and its label mask.

    Args:
        plan: the plan [m].
        size_px: side of the square image when ``metres_per_px`` is None [px].
        style: drawing style (default: clean 1 px black lines).
        rng: randomness for noise and door-swing sides (default: seeded 0, deterministic).
        margin_px: free border on every side [px].
        metres_per_px: fixed scale [m/px]; the image is then sized to fit the plan.

    Raises:
        InputError: the plan has no geometry, or the image would exceed ``MAX_SIDE_PX`` a side.
    """
    style = style or DrawingStyle()
    if metres_per_px is None and size_px <= 2 * margin_px:
        raise InputError(f"size_px {size_px} leaves no room inside a {margin_px} px margin")
    if metres_per_px is None and size_px > MAX_SIDE_PX:
        raise InputError(f"a {size_px} px drawing is above the {MAX_SIDE_PX} px limit")
    rng = rng if rng is not None else np.random.default_rng(0)
    grid = _grid_for(plan, size_px, margin_px, metres_per_px, style.rotation_deg)
    proj = _Projector(grid, style.rotation_deg)
    labels = _render_labels(plan, proj)
    image = _render_drawing(plan, proj, style, rng, labels)
    return RenderedPlan(image, labels, grid, style)


def colorize(labels: np.ndarray) -> np.ndarray:
    """(H, W) label ids -> (H, W, 3) uint8 RGB using ``PALETTE``."""
    palette = np.array(PALETTE, np.uint8)
    if labels.size and int(labels.max()) >= NUM_CLASSES:
        raise ValueError(f"label id {int(labels.max())} out of range 0..{NUM_CLASSES - 1}")
    return palette[labels]
