"""Synthetic apartments: an L/T/U/rect outline split into rooms, then doors, windows, balconies.

Recipe: pick the rooms and their target areas, pick an outline (a chain of 1-3 rectangles on a
10 cm grid) of about that area, deal the rooms out to the outline's rectangles in an order that
puts the living room (sometimes two cells, merged into a non-rectangular room) and the kitchen in
the middle, split each rectangle treemap-style, then connect every room to the living room by a
spanning tree of doors (an open kitchen needs none), and add the front door, balconies and
windows in the exterior walls. A layout that breaks a size rule is discarded and redrawn.
The openings are placed by :mod:`f2n_drake.datasets.generator.openings` (its names are re-exported
here).
"""

from __future__ import annotations

import math

import numpy as np

from f2n_drake.core.plan import FloorPlan
from f2n_drake.datasets.generator.geometry import GeometryError, build_plan
from f2n_drake.datasets.generator.layout import Layout, Rect
from f2n_drake.datasets.generator.openings import (
    GRID_CM,
    OPEN_KITCHEN_P,
    OPENING_SIZES,
    REJECT_SCORE,
    TYPICAL_SIZES,
    VARIED_SIZES,
    OpeningSizes,
    add_openings,
    place_windows,
    snap_to_grid,
)

# (min short side [cm], max aspect ratio) of a cell of each type
CELL_RULES = {
    "living": (220, 5.0),
    "kitchen": (200, 3.0),
    "bedroom": (260, 2.6),
    "bathroom": (150, 2.6),
    "storage": (160, 2.5),
}
MAX_ATTEMPTS = 500


def generate_residential(
    rng: np.random.Generator, sizes: OpeningSizes = TYPICAL_SIZES
) -> FloorPlan:
    """One synthetic apartment (8-20 m across, 1-4 bedrooms, 1-3 bathrooms), in metres, its
    doors and windows as wide as ``sizes`` says."""
    outline = str(rng.choice(["rect", "L", "T", "U"], p=[0.25, 0.3, 0.2, 0.25]))
    for _ in range(MAX_ATTEMPTS):
        layout, shape = _sample_layout(rng, outline)
        if layout is None:
            continue
        result = add_openings(layout, rng, sizes)
        if result is None:
            continue
        openings, balconies, open_kitchen = result
        metadata = {
            "kind": "residential",
            "outline": shape,
            "open_kitchen": open_kitchen,
            "exterior_wall_thickness_m": layout.t_ext,
            "n_front_doors": 1,
            "opening_sizes": sizes.name,
        }
        try:
            return build_plan(layout, openings, balconies, metadata=metadata)
        except GeometryError:
            continue
    raise RuntimeError("no valid residential layout found")  # practically unreachable


def _sample_rooms(rng: np.random.Generator) -> list[tuple[str, float]]:
    """Room types with target areas [m²], in deal-out order (living and kitchen central)."""
    n_bed = int(rng.choice([1, 2, 3, 4], p=[0.2, 0.35, 0.3, 0.15]))
    n_bath = 1 + int(n_bed >= 2 and rng.random() < 0.6) + int(n_bed >= 3 and rng.random() < 0.4)
    others = [("bedroom", rng.uniform(10, 17)) for _ in range(n_bed)]
    others += [("bathroom", rng.uniform(3.5, 6.5)) for _ in range(n_bath)]
    if rng.random() < 0.3:
        others.append(("storage", rng.uniform(3.0, 5.0)))
    rng.shuffle(others)
    core = [("living", rng.uniform(18, 30))]
    if rng.random() < 0.5:  # a second living cell, merged later: non-rectangular living room
        core.append(("living", rng.uniform(5, 12)))
    kitchen = ("kitchen", rng.uniform(7, 13))
    core = [kitchen, *core] if rng.random() < 0.5 else [*core, kitchen]
    k = int(rng.integers(0, len(others) + 1))
    return others[:k] + core + others[k:]


def _sample_outline(rng: np.random.Generator, area_m2: float, kind: str) -> tuple[str, list[Rect]]:
    """Outline rectangles [cm] of the given kind, ordered so consecutive ones touch; the kind
    falls back to "rect" when the size leaves no room for a notch."""
    notch = {
        "rect": 0.0,
        "L": rng.uniform(0.12, 0.3),
        "T": rng.uniform(0.2, 0.35),
        "U": rng.uniform(0.1, 0.22),
    }[kind]
    bbox = area_m2 / (1 - notch)
    aspect = rng.uniform(1.0, 1.6)
    w = float(np.clip(math.sqrt(bbox * aspect), 8, 20))
    h = float(np.clip(bbox / w, 8, 20))
    W, H = snap_to_grid(w * 100), snap_to_grid(h * 100)
    if kind == "L":
        fx = rng.uniform(0.3, 0.6)
        nx, ny = snap_to_grid(W * fx), snap_to_grid(H * min(0.6, notch / fx))
        parts = [(0, H - ny, W - nx, H), (0, 0, W, H - ny)]
    elif kind == "T":
        hb = snap_to_grid(H * rng.uniform(0.4, 0.6))
        sw = snap_to_grid(W * rng.uniform(0.45, 0.7))
        sx = snap_to_grid(rng.uniform(0.15, 0.85) * (W - sw))
        parts = [(sx, 0, sx + sw, H - hb), (0, H - hb, W, H)]
    elif kind == "U":
        hb = snap_to_grid(H * rng.uniform(0.4, 0.6))
        ax = max(300, snap_to_grid(W * rng.uniform(0.3, 0.4)))
        bx = max(300, snap_to_grid(W * rng.uniform(0.3, 0.4)))
        if W - ax - bx < 200:
            return "rect", [(0, 0, W, H)]
        parts = [(0, hb, ax, H), (0, 0, W, hb), (W - bx, hb, W, H)]
    else:
        parts = [(0, 0, W, H)]
    if any(min(x1 - x0, y1 - y0) < 300 for x0, y0, x1, y1 in parts):
        kind, parts = "rect", [(0, 0, W, H)]
    if rng.random() < 0.5:  # mirror x
        parts = [(W - x1, y0, W - x0, y1) for x0, y0, x1, y1 in parts]
    if rng.random() < 0.5:  # mirror y
        parts = [(x0, H - y1, x1, H - y0) for x0, y0, x1, y1 in parts]
    if rng.random() < 0.5:  # transpose
        parts = [(y0, x0, y1, x1) for x0, y0, x1, y1 in parts]
    return kind, parts


def _deal(
    items: list[tuple[str, float]], parts: list[Rect]
) -> list[list[tuple[str, float]]] | None:
    """Split ``items`` into contiguous chunks, one per part, matching the parts' areas."""
    part_area = np.array([(x1 - x0) * (y1 - y0) for x0, y0, x1, y1 in parts], dtype=float)
    cum_part = np.cumsum(part_area) / part_area.sum()
    cum_item = np.cumsum([a for _, a in items]) / sum(a for _, a in items)
    cuts, prev = [], 0
    for j in range(len(parts) - 1):
        best = int(np.argmin(np.abs(cum_item - cum_part[j]))) + 1
        best = max(best, prev + 1)
        if best > len(items) - (len(parts) - 1 - j):
            return None
        cuts.append(best)
        prev = best
    bounds = [0, *cuts, len(items)]
    return [items[a:b] for a, b in zip(bounds[:-1], bounds[1:], strict=True)]


def _treemap(
    rect: Rect,
    items: list[tuple[str, float]],
    out: list[tuple[str, Rect]],
    rng: np.random.Generator,
) -> bool:
    """Split ``rect`` into one cell per item (areas proportional, order kept, cuts chosen to keep
    cells well shaped); False if no cut leaves both sides at least 1.3 m wide."""
    if len(items) == 1:
        out.append((items[0][0], rect))
        return True
    cum = np.cumsum([a for _, a in items])
    x0, y0, x1, y1 = rect
    best = None
    for k in range(1, len(items)):
        frac = cum[k - 1] / cum[-1]
        for vertical in (True, False):
            if vertical:
                cut = _clamp_cut(x0 + snap_to_grid((x1 - x0) * frac), x0, x1, items, k)
                first, second = (x0, y0, cut, y1), (cut, y0, x1, y1)
            else:
                cut = _clamp_cut(y0 + snap_to_grid((y1 - y0) * frac), y0, y1, items, k)
                first, second = (x0, y0, x1, cut), (x0, cut, x1, y1)
            if min(_short(first), _short(second)) < 130:
                continue
            score = _shape_penalty(first, items[:k]) + _shape_penalty(second, items[k:])
            score += 0.3 * rng.random()
            if best is None or score < best[0]:
                best = (score, k, first, second)
    if best is None:
        return False
    _, k, first, second = best
    return _treemap(first, items[:k], out, rng) and _treemap(second, items[k:], out, rng)


def _clamp_cut(cut: int, lo: int, hi: int, items: list[tuple[str, float]], k: int) -> int:
    """Move a cut so a single-room side gets at least its room type's minimum width."""
    need_lo = CELL_RULES[items[0][0]][0] if k == 1 else 130
    need_hi = CELL_RULES[items[-1][0]][0] if k == len(items) - 1 else 130
    return min(max(cut, lo + need_lo), hi - need_hi)


def _short(rect: Rect) -> int:
    return min(rect[2] - rect[0], rect[3] - rect[1])


def _shape_penalty(rect: Rect, items: list[tuple[str, float]]) -> float:
    """How badly ``rect`` suits ``items``: cell rules for one item, elongation for several."""
    short, long_ = sorted((rect[2] - rect[0], rect[3] - rect[1]))
    aspect = long_ / short
    if len(items) == 1:
        min_short, max_aspect = CELL_RULES[items[0][0]]
        return 10.0 * (short < min_short) + 3.0 * max(0.0, aspect - max_aspect) + 0.2 * aspect
    return 0.5 * max(0.0, aspect - len(items))


def _sample_layout(rng: np.random.Generator, kind: str) -> tuple[Layout | None, str]:
    items = _sample_rooms(rng)
    kind, parts = _sample_outline(rng, sum(a for _, a in items), kind)
    chunks = _deal(items, parts)
    if chunks is None:
        return None, kind
    cells: list[tuple[str, Rect]] = []
    for part, chunk in zip(parts, chunks, strict=True):
        if not _treemap(part, chunk, cells, rng):
            return None, kind
    for name, (x0, y0, x1, y1) in cells:
        short, long_ = sorted((x1 - x0, y1 - y0))
        min_short, max_aspect = CELL_RULES[name]
        if short < min_short or long_ > max_aspect * short:
            return None, kind
    room_types: list[str] = []
    rect_room: list[int] = []
    living = -1
    for name, _ in cells:
        if name == "living" and living >= 0:
            rect_room.append(living)
            continue
        if name == "living":
            living = len(room_types)
        rect_room.append(len(room_types))
        room_types.append(name)
    t_int = round(float(rng.uniform(0.15, 0.25)), 2)
    t_ext = t_int if rng.random() < 0.5 else round(float(rng.uniform(t_int, 0.30)), 2)
    layout = Layout([r for _, r in cells], rect_room, room_types, t_int, t_ext)
    layout.compute_segments()
    return layout, kind


__all__ = [
    "CELL_RULES",
    "GRID_CM",
    "MAX_ATTEMPTS",
    "OPENING_SIZES",
    "OPEN_KITCHEN_P",
    "REJECT_SCORE",
    "TYPICAL_SIZES",
    "VARIED_SIZES",
    "OpeningSizes",
    "generate_residential",
    "place_windows",
]
