"""The walls and floors of a plan in metres, for the simulation and the figures.

A :class:`PlanGeometry` holds the walls (obstacles) and floors (room class, polygon) as plain
shapely data; it is made from a ground-truth :class:`~f2n_drake.core.plan.FloorPlan` or from a
perceived :class:`~f2n_drake.core.parsed.ParsedPlan` (cut from its occupancy map, so the simulated
walls are the ones the route was planned around). Collision geometry takes boxes, so each wall
polygon is cut into rectangles (:func:`decompose_rectangles`), exactly for rectilinear walls in
any orientation.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import cv2
import numpy as np
import shapely
from shapely import affinity
from shapely.geometry import Polygon

from f2n_drake.core.classes import CONNECTOR_CLASSES, SPACE_CLASSES
from f2n_drake.core.errors import InputError
from f2n_drake.core.parsed import ParsedPlan
from f2n_drake.core.plan import FloorPlan, polygons_of
from f2n_drake.mapping.occupancy import occupancy_map
from f2n_drake.mapping.robots import GROUND

Rectangle = tuple[float, float, float, float, float]
"""(centre x [m], centre y [m], length along yaw [m], width [m], yaw [rad])."""


MAX_CELLS_PER_SIDE = 2000
"""Most cells along a side of a non-rectilinear polygon cut into rectangles."""


@dataclass
class PlanGeometry:
    """Walls (obstacles), floors (room class, polygon) and connectors (door, window or
    front_door, polygon) of a plan, in metres. Connectors are drawn by the viewer only."""

    walls: list[Polygon]
    floors: list[tuple[str, Polygon]] = field(default_factory=list)
    connectors: list[tuple[str, Polygon]] = field(default_factory=list)

    @classmethod
    def from_floorplan(cls, plan: FloorPlan) -> PlanGeometry:
        """Obstacles are ``plan["wall"]`` and the windows (glazed wall: the ground robot cannot
        pass and the LiDAR sees them), merged; doors and front doors are gaps."""
        walls = polygons_of(shapely.union_all(plan["wall"] + plan["window"]))
        if not walls:
            raise InputError("floor plan has no wall polygons")
        connectors = [(n, p) for n in CONNECTOR_CLASSES for p in plan[n]]
        return cls(walls, list(plan.spaces()), connectors)

    @classmethod
    def from_parsed(
        cls, parsed: ParsedPlan, free: np.ndarray | None = None, *, band_m: float = 0.5
    ) -> PlanGeometry:
        """Walls are the occupied pixels (not ``free``) within ``band_m`` of free space.

        The pixel outlines are simplified by 1 px and, where every edge is within 10 degrees of
        the dominant directions, squared up (:func:`simplify_rectilinear`).

        Args:
            parsed: instances with a known ``grid``.
            free: (H, W) bool free-space mask; by default the ground robot's occupancy map
                (``occupancy.occupancy_map``: spaces, doors, front doors and openings, the drawn
                outlines between them bridged as far as the planner bridges them).
            band_m: occupied pixels farther than this from free space (the outside of the
                building) are dropped [m].
        Raises:
            InputError: no grid (unknown scale), wrong mask shape, or no free space.
        """
        grid = parsed.grid
        if grid is None:
            raise InputError("parsed plan has no pixel grid (unknown scale)")
        if free is None:
            free = occupancy_map(parsed, GROUND.traversable)
        free = np.asarray(free, dtype=bool)
        if free.shape != parsed.instance_ids.shape:
            raise InputError(f"free mask shape {free.shape} != plan {parsed.instance_ids.shape}")
        if not free.any():
            raise InputError("parsed plan has no free space")
        band_px = max(1, int(round(grid.length_px(band_m))))
        near = cv2.dilate(free.astype(np.uint8), np.ones((2 * band_px + 1,) * 2, np.uint8)) > 0
        occupied = (near & ~free).astype(np.uint8)
        tolerance_m = grid.metres_per_px
        walls = [
            p
            for raw in _mask_polygons_m(occupied, grid)
            for p in polygons_of(simplify_rectilinear(raw, tolerance_m))
        ]
        floors, connectors = [], []
        for inst in parsed.instances:
            if inst.class_name in SPACE_CLASSES:
                simple = inst.polygon_m(grid).simplify(tolerance_m)
                floors += [(inst.class_name, p) for p in polygons_of(simple)]
            elif inst.class_name in CONNECTOR_CLASSES:
                connectors.append((inst.class_name, inst.polygon_m(grid)))
        return cls(walls, floors, connectors)

    def bounds(self) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax) [m] of the walls and floors."""
        b = np.array([p.bounds for p in (*self.walls, *(f for _, f in self.floors))])
        return (*b[:, :2].min(axis=0), *b[:, 2:].max(axis=0))

    def wall_segments(self) -> np.ndarray:
        """(N, 4) array [x0, y0, x1, y1] [m] of every wall polygon edge (holes included)."""
        segments = []
        for poly in self.walls:
            for ring in (poly.exterior, *poly.interiors):
                xy = np.asarray(ring.coords)[:, :2]
                segments.append(np.hstack([xy[:-1], xy[1:]]))
        return np.vstack(segments) if segments else np.zeros((0, 4))


def _mask_polygons_m(mask: np.ndarray, grid) -> list[Polygon]:
    """Polygons [m] of a binary mask following the pixel edges (holes kept)."""
    # Upsample 2x so the contour through pixel-corner points traces the pixel boundary.
    big = cv2.resize(mask, None, fx=2, fy=2, interpolation=cv2.INTER_NEAREST)
    contours, hierarchy = cv2.findContours(big, cv2.RETR_CCOMP, cv2.CHAIN_APPROX_SIMPLE)
    if hierarchy is None:
        return []
    rings = [c.reshape(-1, 2).astype(float) / 2.0 for c in contours]  # ~pixel corner (col,row)
    polygons = []
    for k, (_, _, child, parent) in enumerate(hierarchy[0]):
        if parent != -1 or len(rings[k]) < 3:
            continue
        holes, c = [], child
        while c != -1:
            if len(rings[c]) >= 3:
                holes.append(grid.to_m(rings[c] - 0.25))
            c = hierarchy[0][c][0]
        # The rings join boundary-pixel points 1/4 px inside the mask: grow back by 1/4 px.
        poly = Polygon(grid.to_m(rings[k] - 0.25), holes).buffer(
            0.25 * grid.metres_per_px, join_style="mitre"
        )
        polygons += [p for p in polygons_of(poly) if p.area > 0]
    return polygons


def dominant_angle(poly: Polygon) -> float:
    """Length-weighted orientation of a polygon's edges modulo 90 deg [rad, in (-pi/4, pi/4]]."""
    d = np.diff(np.asarray(poly.exterior.coords)[:, :2], axis=0)
    for ring in poly.interiors:
        d = np.vstack([d, np.diff(np.asarray(ring.coords)[:, :2], axis=0)])
    w = np.hypot(d[:, 0], d[:, 1])
    a = 4.0 * np.arctan2(d[:, 1], d[:, 0])
    return 0.25 * math.atan2(float(w @ np.sin(a)), float(w @ np.cos(a)))


def _orthogonal_ring(xy: np.ndarray, max_deviation_rad: float) -> np.ndarray | None:
    """Corners of a closed ring whose edges are all near-axis-aligned, snapped to the axes
    (each run of parallel edges to its length-weighted mean line); None if an edge is diagonal."""
    pts = xy[:-1]
    d = np.roll(pts, -1, axis=0) - pts  # edge i: pts[i] -> pts[i + 1]
    length = np.hypot(d[:, 0], d[:, 1])
    angle = np.arctan2(np.abs(d[:, 1]), np.abs(d[:, 0]))
    horizontal = angle <= max_deviation_rad
    if (
        np.any(~horizontal & (angle < np.pi / 2 - max_deviation_rad))
        or horizontal.all()
        or (not horizontal.any())
    ):
        return None
    start = int(np.flatnonzero(horizontal != np.roll(horizontal, 1))[0])  # a run starts here
    order = np.roll(np.arange(len(pts)), -start)
    runs: list[tuple[bool, float]] = []  # (horizontal, snapped coordinate)
    i = 0
    while i < len(order):
        j = i
        while j + 1 < len(order) and horizontal[order[j + 1]] == horizontal[order[i]]:
            j += 1
        edges = order[i : j + 1]
        axis = 1 if horizontal[order[i]] else 0
        mid = (pts[edges, axis] + np.roll(pts, -1, axis=0)[edges, axis]) / 2
        runs.append((bool(horizontal[order[i]]), float(mid @ length[edges] / length[edges].sum())))
        i = j + 1
    corners = []
    for k, (is_h, value) in enumerate(runs):  # corner between run k - 1 and run k
        _, previous = runs[k - 1]
        corners.append((previous, value) if is_h else (value, previous))
    return np.array(corners + corners[:1])


def simplify_rectilinear(
    poly: Polygon, tolerance_m: float, max_deviation_deg: float = 10.0
) -> Polygon:
    """``poly`` simplified by ``tolerance_m`` [m], then made exactly rectilinear in its dominant
    direction when every edge is within ``max_deviation_deg`` of it (else just simplified)."""
    simple = poly.simplify(tolerance_m, preserve_topology=True)
    theta = dominant_angle(simple)
    local = affinity.rotate(simple, -theta, origin=(0, 0), use_radians=True)
    rings = [
        _orthogonal_ring(np.asarray(r.coords)[:, :2], math.radians(max_deviation_deg))
        for r in (local.exterior, *local.interiors)
    ]
    if any(r is None for r in rings):
        return simple
    square = Polygon(rings[0], [r for r in rings[1:] if len(r) >= 4]).buffer(0)
    square = affinity.rotate(square, theta, origin=(0, 0), use_radians=True)
    if square.symmetric_difference(poly).area > 2 * tolerance_m * poly.length:
        return simple
    return square


def _breaks(values: np.ndarray, snap_m: float, max_gap_m: float | None) -> np.ndarray:
    """Sorted cuts: ``values`` clustered within ``snap_m``, gaps split to at most ``max_gap_m``."""
    v = np.unique(values)
    v = v[np.concatenate([[True], np.diff(v) > snap_m])]
    if max_gap_m is None:
        return v
    out = [v[:1]]
    for a, b in zip(v[:-1], v[1:], strict=True):
        n = int(math.ceil((b - a) / max_gap_m))
        out.append(np.linspace(a, b, n + 1)[1:])
    return np.concatenate(out)


def decompose_rectangles(poly: Polygon, resolution_m: float = 0.02) -> list[Rectangle]:
    """Cover a polygon with non-overlapping rectangles aligned with its dominant direction.

    Exact (to 0.1 mm) for rectilinear polygons in any orientation; other shapes are approximated
    on cells no larger than ``resolution_m`` [m] (a cell is kept when its centre is inside), or
    than a ``MAX_CELLS_PER_SIDE``-th of the polygon's extent when that is coarser (a campus-sized
    polygon stays a few million cells).
    """
    theta = dominant_angle(poly)
    local = affinity.rotate(poly, -theta, origin=(0, 0), use_radians=True)
    coords = np.vstack([np.asarray(r.coords)[:, :2] for r in (local.exterior, *local.interiors)])
    d = np.abs(np.diff(coords, axis=0))
    rectilinear = bool(np.all(np.minimum(d[:, 0], d[:, 1]) < 1e-6))
    extent = float(np.ptp(coords, axis=0).max())
    gap = None if rectilinear else max(resolution_m, extent / MAX_CELLS_PER_SIDE)
    xs = _breaks(coords[:, 0], 1e-4, gap)
    ys = _breaks(coords[:, 1], 1e-4, gap)
    cx, cy = np.meshgrid((xs[:-1] + xs[1:]) / 2, (ys[:-1] + ys[1:]) / 2)
    shapely.prepare(local)
    inside = shapely.contains_xy(local, cx, cy)  # (rows along y, cols along x)
    boxes: list[tuple[int, int, int, int]] = []  # (c0, c1, r0, r1) cell index ranges
    active: dict[tuple[int, int], int] = {}
    for r in range(inside.shape[0] + 1):
        runs: dict[tuple[int, int], int] = {}
        if r < inside.shape[0]:
            row = np.concatenate([[False], inside[r], [False]]).astype(np.int8)
            edges = np.flatnonzero(np.diff(row))
            for c0, c1 in zip(edges[0::2], edges[1::2], strict=True):
                runs[(int(c0), int(c1))] = active.pop((int(c0), int(c1)), r)
        boxes += [(c0, c1, r0, r) for (c0, c1), r0 in active.items()]
        active = runs
    c, s = math.cos(theta), math.sin(theta)
    rects = []
    for c0, c1, r0, r1 in boxes:
        x0, x1, y0, y1 = xs[c0], xs[c1], ys[r0], ys[r1]
        mx, my = (x0 + x1) / 2, (y0 + y1) / 2
        rects.append((c * mx - s * my, s * mx + c * my, x1 - x0, y1 - y0, theta))
    return rects
