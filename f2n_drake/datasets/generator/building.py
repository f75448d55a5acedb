"""Synthetic buildings: 50-300 rooms along double-loaded corridors (for planning benchmarks).

Layout: ``k`` stacked corridor bands, each with a row of rooms on both sides, all joined by one
cross corridor. The corridors are one "living" space (circulation); every room has a door to
it; front doors sit at corridor ends in the exterior wall; outer-row rooms get windows and some
bedrooms a balcony. About 40-120 m across.
"""

from __future__ import annotations

import math

import numpy as np

from f2n_drake.core.errors import InputError
from f2n_drake.core.plan import FloorPlan
from f2n_drake.datasets.generator.geometry import Opening, balcony_rect, build_plan
from f2n_drake.datasets.generator.layout import Layout, Rect, free_interval
from f2n_drake.datasets.generator.residential import place_windows

ROOM_TYPES = ("bedroom", "bathroom", "kitchen", "living")
ROOM_TYPE_P = (0.62, 0.16, 0.1, 0.12)
WIDTH_CM = {"bathroom": 230, "kitchen": 330, "bedroom": 380, "living": 480}


def generate_building(rng: np.random.Generator, n_rooms: int | None = None) -> FloorPlan:
    """A building with ``n_rooms`` rooms (default: random 50-300) off corridors, in metres.

    Raises:
        InputError: ``n_rooms`` outside 50-300.
    """
    if n_rooms is None:
        n_rooms = int(rng.integers(50, 301))
    if not 50 <= n_rooms <= 300:
        raise InputError(f"n_rooms must be in 50..300, got {n_rooms}")
    t_int = round(float(rng.uniform(0.15, 0.25)), 2)
    t_ext = round(float(rng.uniform(t_int, 0.30)), 2)
    layout = _corridor_layout(rng, n_rooms, t_int, t_ext)
    openings, balconies, n_front = _openings(layout, rng)
    metadata = {
        "kind": "building",
        "outline": "rect",
        "open_kitchen": False,
        "exterior_wall_thickness_m": t_ext,
        "n_front_doors": n_front,
        "n_rooms": n_rooms,
    }
    return build_plan(layout, openings, balconies, metadata=metadata)


def _snap(value_cm: float) -> int:
    return int(round(value_cm / 10)) * 10


def _corridor_layout(rng: np.random.Generator, n_rooms: int, t_int: float, t_ext: float) -> Layout:
    n_bands = int(np.clip(round(math.sqrt(n_rooms / 12)), 1, 6))
    n_rows = 2 * n_bands  # room rows; each is split in two by the cross corridor
    counts = np.full(2 * n_rows, n_rooms // (2 * n_rows))
    counts[rng.permutation(2 * n_rows)[: n_rooms % (2 * n_rows)]] += 1
    types = [list(rng.choice(ROOM_TYPES, size=int(c), p=ROOM_TYPE_P)) for c in counts]
    nominal = [sum(WIDTH_CM[t] for t in ts) for ts in types]
    left_len = _snap(np.mean(nominal[0::2]))
    right_len = _snap(np.mean(nominal[1::2]))
    corridor = _snap(rng.uniform(180, 240))

    rects: list[Rect] = []
    rect_room: list[int] = []
    room_types = ["living"]  # room 0: all corridors
    y = 0
    for band in range(n_bands):
        depths = [_snap(rng.uniform(400, 600)), _snap(rng.uniform(400, 600))]
        rows_y = [
            (y, y + depths[0]),
            (y + depths[0] + corridor, y + depths[0] + corridor + depths[1]),
        ]
        cy0, cy1 = rows_y[0][1], rows_y[1][0]
        rects += [
            (0, cy0, left_len, cy1),
            (left_len + corridor, cy0, left_len + corridor + right_len, cy1),
        ]
        rect_room += [0, 0]
        for r, (y0, y1) in enumerate(rows_y):
            for side, (x0, length) in enumerate(((0, left_len), (left_len + corridor, right_len))):
                row_types = types[2 * (2 * band + r) + side]
                pieces = _split(rng, x0, length, [WIDTH_CM[t] for t in row_types])
                for t, (a, b) in zip(row_types, pieces, strict=True):
                    rects.append((a, y0, b, y1))
                    rect_room.append(len(room_types))
                    room_types.append(str(t))
        y = rows_y[1][1]
    rects.append((left_len, 0, left_len + corridor, y))  # cross corridor, full height
    rect_room.append(0)
    layout = Layout(rects, rect_room, room_types, t_int, t_ext)
    layout.compute_segments()
    return layout


def _split(
    rng: np.random.Generator, x0: int, length: int, nominal: list[int]
) -> list[tuple[int, int]]:
    """Cut [x0, x0+length] [cm] into pieces proportional to jittered ``nominal`` widths."""
    widths = np.asarray(nominal, dtype=float) * rng.uniform(0.85, 1.15, len(nominal))
    edges = np.concatenate([[0], np.cumsum(widths)]) * length / widths.sum()
    cuts = [x0 + _snap(e) for e in edges]
    cuts[-1] = x0 + length
    return list(zip(cuts[:-1], cuts[1:], strict=True))


def _openings(layout: Layout, rng: np.random.Generator) -> tuple[list[Opening], list[tuple], int]:
    segs, types = layout.segments, layout.room_types
    margin = layout.margin_cm()
    openings: list[Opening] = []
    pairs = layout.pair_segments()
    for (a, b), idx in pairs.items():
        if a != 0:
            continue  # only corridor <-> room doors
        seg_i = max(idx, key=lambda i: segs[i].length)
        seg = segs[seg_i]
        width = int(rng.integers(70, 86)) if types[b] == "bathroom" else int(rng.integers(80, 101))
        span = free_interval([], seg.lo + margin, seg.hi - margin, width, 0, rng)
        if span is None:
            raise RuntimeError(f"room {b} too narrow for a door")  # widths make this impossible
        openings.append(Opening("door", seg_i, *span))

    exterior = layout.exterior_segments()
    used: dict[int, list[tuple[int, int]]] = {}
    ends = [i for i in exterior.get(0, []) if segs[i].length >= 120 + 2 * margin]
    n_front = int(rng.integers(1, min(4, len(ends)) + 1))
    for seg_i in rng.choice(ends, size=n_front, replace=False):
        seg = segs[int(seg_i)]
        width = int(rng.integers(90, 121))
        span = free_interval([], seg.lo + margin, seg.hi - margin, width, 0, rng)
        openings.append(Opening("front_door", int(seg_i), *span))
        used[int(seg_i)] = [(seg.lo, seg.hi)]  # no windows beside a front door

    balconies: list[tuple] = []
    for room, seg_ids in exterior.items():
        if types[room] != "bedroom" or rng.random() > 0.2:
            continue
        seg = segs[max(seg_ids, key=lambda i: segs[i].length)]
        seg_i = layout.segments.index(seg)
        if seg.axis != 0 or seg.length < 200 + 2 * margin:
            continue  # balconies only on the long facades
        width = _snap(rng.uniform(200, min(400, seg.length - 2 * margin)))
        span = free_interval([], seg.lo + margin, seg.hi - margin, width, 0, rng)
        depth = _snap(rng.uniform(120, 180))
        balconies.append(balcony_rect(layout, seg, span[0], span[1], depth))
        door = free_interval([], span[0] + 10, span[1] - 10, int(rng.integers(80, 101)), 0, rng)
        openings.append(Opening("door", seg_i, *door))
        used.setdefault(seg_i, []).append(span)
    openings += place_windows(layout, exterior, used, rng)
    return openings, balconies, n_front
