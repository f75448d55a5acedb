"""Ground truth ``ParsedPlan`` straight from a ``FloorPlan``'s polygons (no perception).

Every polygon of every labelled class becomes its own instance, rasterised in the label-mask draw
order (rooms, balcony, wall, window, door, front door last: later classes overwrite earlier ones).
Where two spaces share a boundary with no wall between them (a kitchen open to the living room),
an ``"opening"`` instance is added: a 2 px strip along the shared boundary, taken from both spaces,
so the connectivity graph sees a connector between them just as it does for a perception cut.
"""

from __future__ import annotations

import logging

import cv2
import numpy as np
import shapely
from shapely.geometry import LineString, Polygon

from f2n_drake.core.classes import CLASS_ID, OPENING, PAINT_ORDER
from f2n_drake.core.parsed import Instance, ParsedPlan
from f2n_drake.core.plan import FloorPlan, polygons_of
from f2n_drake.core.raster import PixelGrid

log = logging.getLogger(__name__)


ROOM_CLASSES: tuple[str, ...] = ("living", "bedroom", "bathroom", "kitchen", "balcony")

_SHIFT = 8  # cv2 sub-pixel bits
_BLOCKERS: tuple[str, ...] = ("wall", "door", "window", "front_door")


def parse_ground_truth(
    plan: FloorPlan,
    grid: PixelGrid | None = None,
    *,
    size_px: int = 512,
    min_opening_m: float = 0.5,
    touch_tol_m: float = 0.03,
) -> ParsedPlan:
    """Rasterise ``plan`` into a ParsedPlan whose instances are its polygons.

    Args:
        plan: the floor plan [m].
        grid: the raster; default ``PixelGrid.fit(plan.bounds, size_px)``.
        size_px: image side when ``grid`` is None [px].
        min_opening_m: shortest wall-less shared boundary recorded as an opening [m].
        touch_tol_m: distance under which two space boundaries count as shared [m].

    Returns:
        A ParsedPlan with ``scale_source="input"``; instance ids count up in draw order, the
        openings last; a polygon entirely painted over by later classes is left out.
    """
    grid = grid or PixelGrid.fit(plan.bounds, size_px)
    shape = grid.shape
    instance_ids = np.zeros(shape, dtype=np.int32)
    labels = np.zeros(shape, dtype=np.uint8)
    drawn: list[tuple[int, str, Polygon]] = []
    next_id = 1
    for name in PAINT_ORDER:
        for poly in plan[name]:
            for part in polygons_of(poly):
                _fill(instance_ids, part, grid, next_id)
                _fill(labels, part, grid, CLASS_ID[name])
                drawn.append((next_id, name, part))
                next_id += 1

    spaces = [(i, p) for i, n, p in drawn if n in ROOM_CLASSES]
    openings = _opening_lines(spaces, plan, min_opening_m, touch_tol_m)
    strip_half_m = 0.75 * grid.metres_per_px  # covers 1-2 pixel centres across the cut
    for line, id_a, id_b in openings:
        strip = line.buffer(strip_half_m, cap_style="flat")
        canvas = np.zeros(shape, dtype=np.uint8)
        for part in polygons_of(strip):
            _fill(canvas, part, grid, 1)
        take = (canvas > 0) & ((instance_ids == id_a) | (instance_ids == id_b))
        if not take.any():
            continue
        instance_ids[take] = next_id  # labels keep the space classes: an opening is no pixel class
        drawn.append((next_id, OPENING, polygons_of(strip)[0]))
        next_id += 1

    instances = _instances(instance_ids, drawn, grid)
    log.debug("ground truth: %d instances (%d openings)", len(instances), len(openings))
    return ParsedPlan(instance_ids, labels, instances, grid, scale_source="input")


def _fill(image: np.ndarray, poly: Polygon, grid: PixelGrid, value: int) -> None:
    """Paint ``poly`` (holes left unpainted) into ``image`` with sub-pixel precision."""
    rings = [poly.exterior, *poly.interiors]
    pts = [
        np.round(grid.to_px(np.asarray(r.coords)[:, :2]) * (1 << _SHIFT)).astype(np.int32)
        for r in rings
    ]
    cv2.fillPoly(image, pts, int(value), lineType=cv2.LINE_8, shift=_SHIFT)


def _opening_lines(
    spaces: list[tuple[int, Polygon]], plan: FloorPlan, min_length_m: float, tol_m: float
) -> list[tuple[LineString, int, int]]:
    """Wall-less shared boundaries of two spaces (instance id, polygon), each at least
    ``min_length_m`` long, as (line, id_a, id_b)."""
    blockers = shapely.union_all([p for n in _BLOCKERS for p in plan[n]])
    blocked = blockers.buffer(tol_m) if not blockers.is_empty else None
    found = []
    for k, (id_a, a) in enumerate(spaces):
        for id_b, b in spaces[k + 1 :]:
            if a.distance(b) > tol_m:
                continue
            shared = a.boundary.intersection(b.buffer(tol_m))
            if blocked is not None:
                shared = shared.difference(blocked)
            lines = [
                g for g in shapely.get_parts(shared) if g.geom_type == "LineString" and g.length
            ]
            if not lines:
                continue
            for line in shapely.get_parts(shapely.line_merge(shapely.MultiLineString(lines))):
                if line.length >= min_length_m:
                    found.append((line, id_a, id_b))
    return found


def _instances(
    instance_ids: np.ndarray, drawn: list[tuple[int, str, Polygon]], grid: PixelGrid
) -> list[Instance]:
    """Pixel statistics of every painted instance; contours from the exact polygons."""
    n = int(instance_ids.max()) + 1
    rows, cols = np.indices(instance_ids.shape)
    flat = instance_ids.ravel()
    area = np.bincount(flat, minlength=n)
    sum_col = np.bincount(flat, weights=cols.ravel(), minlength=n)
    sum_row = np.bincount(flat, weights=rows.ravel(), minlength=n)
    out = []
    for inst_id, name, poly in drawn:
        if inst_id >= n or area[inst_id] == 0:
            continue
        contour = grid.to_px(np.asarray(poly.exterior.coords)[:-1, :2])
        a = area[inst_id]
        centroid = (float(sum_col[inst_id] / a), float(sum_row[inst_id] / a))
        out.append(Instance(inst_id, name, contour, int(area[inst_id]), centroid))
    return out
