"""Turn a ``Layout`` plus chosen openings and balconies into a ``FloorPlan`` (metres).

Walls are centred on the cell boundaries: each walled segment becomes a rectangle of its wall
thickness, extended by half a thickness at both ends so corners and junctions close. Rooms are
their cells minus the walls (so they end at the inner wall faces); doors and windows are the
rectangles cut out of the walls, so each exactly fills its gap.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import shapely
from shapely.geometry import Polygon

from f2n_drake.core.plan import FloorPlan, polygons_of
from f2n_drake.datasets.generator.layout import Layout, Segment


@dataclass(frozen=True)
class Opening:
    """A door, window or front door cut into segment ``seg`` over [lo, hi] [cm]."""

    kind: str
    seg: int
    lo: int
    hi: int


class GeometryError(RuntimeError):
    """A layout produced a degenerate room; the caller retries with another layout."""


def balcony_rect(layout: Layout, seg: Segment, lo: int, hi: int, depth: int) -> tuple:
    """(x0, y0, x1, y1) [m] of a balcony against the outer face of exterior segment ``seg``."""
    half = layout.t_ext / 2
    if seg.outward < 0:
        face = seg.c / 100 - half
        a, b = face - depth / 100, face
    else:
        face = seg.c / 100 + half
        a, b = face, face + depth / 100
    if seg.axis == 0:
        return (lo / 100, a, hi / 100, b)
    return (a, lo / 100, b, hi / 100)


def outside_box_cm(layout: Layout, seg: Segment, span: tuple[int, int], depth: int) -> tuple:
    """Box [cm] of ``depth`` cm outside the outer face of exterior ``seg`` over ``span``."""
    half = layout.t_ext * 50
    if seg.outward < 0:
        a, b = seg.c - half - depth, seg.c - half
    else:
        a, b = seg.c + half, seg.c + half + depth
    if seg.axis == 0:
        return (span[0], a, span[1], b)
    return (a, span[0], b, span[1])


def boxes_overlap(a: tuple, b: tuple, eps: float = 1e-6) -> bool:
    return min(a[2], b[2]) - max(a[0], b[0]) > eps and min(a[3], b[3]) - max(a[1], b[1]) > eps


def _segment_box(seg: Segment, lo: float, hi: float, half: float) -> tuple:
    """Box [m] around the centre line of ``seg`` over [lo, hi] [m], half-thickness ``half``."""
    c = seg.c / 100
    if seg.axis == 0:
        return (lo, c - half, hi, c + half)
    return (c - half, lo, c + half, hi)


def build_plan(
    layout: Layout,
    openings: list[Opening],
    balconies: list[tuple],
    *,
    metadata: dict[str, Any],
) -> FloorPlan:
    """The FloorPlan of a layout; raises GeometryError if a room comes out in pieces."""
    wall_boxes = []
    for seg in layout.segments:
        pair = (min(seg.low, seg.high), max(seg.low, seg.high))
        if pair in layout.open_pairs:
            continue
        half = layout.thickness(seg) / 2
        wall_boxes.append(_segment_box(seg, seg.lo / 100 - half, seg.hi / 100 + half, half))
    walls = shapely.box(*np.asarray(wall_boxes, dtype=float).T)

    open_boxes = []
    for op in openings:
        seg = layout.segments[op.seg]
        open_boxes.append(_segment_box(seg, op.lo / 100, op.hi / 100, layout.thickness(seg) / 2))
    open_polys = shapely.box(*np.asarray(open_boxes, dtype=float).T) if open_boxes else []

    cells = shapely.box(*(np.asarray(layout.rects, dtype=float).T / 100))
    room_cells: dict[int, list] = {}
    for cell, room in zip(cells, layout.rect_room, strict=True):
        room_cells.setdefault(room, []).append(cell)
    tree = shapely.STRtree(walls)
    polygons: dict[str, list[Polygon]] = {}
    for room, parts in room_cells.items():
        area = parts[0] if len(parts) == 1 else shapely.union_all(parts)
        near = walls[tree.query(area)]
        pieces = polygons_of(shapely.difference(area, shapely.union_all(near)))
        pieces = [p for p in pieces if p.area > 1e-6]
        if len(pieces) != 1:
            raise GeometryError(f"room {room} splits into {len(pieces)} pieces")
        poly = shapely.simplify(pieces[0], 0.0)
        polygons.setdefault(layout.room_types[room], []).append(poly)

    wall_union = shapely.union_all(walls)
    if len(open_polys):
        wall_union = shapely.difference(wall_union, shapely.union_all(open_polys))
    polygons["wall"] = [shapely.simplify(p, 0.0) for p in polygons_of(wall_union)]
    for op, poly in zip(openings, open_polys, strict=True):
        polygons.setdefault(op.kind, []).append(poly)
    polygons["balcony"] = [shapely.box(*b) for b in balconies]
    return FloorPlan(polygons, layout.t_int, "synthetic", metadata)
