"""Doors, front door, balconies and windows of a synthetic apartment layout (sizes in cm).

Every room gets a door on a spanning tree grown from the living room (an open kitchen, sharing
>= 1.5 m of boundary with it, needs none); the front door sits in an exterior wall of the living
room; balconies lie outside exterior walls of living rooms and bedrooms, each reached by a door;
windows go in the exterior walls of the rooms, clear of the other openings. Their widths come
from an :class:`OpeningSizes`: ``TYPICAL_SIZES`` (every test and development plan) or
``VARIED_SIZES``, wider ranges that overlap across room types, for training.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from types import MappingProxyType

import numpy as np

from f2n_drake.datasets.generator.geometry import (
    Opening,
    balcony_rect,
    boxes_overlap,
    outside_box_cm,
)
from f2n_drake.datasets.generator.layout import Layout, free_interval

GRID_CM = 10  # layout grid [cm]: outlines, cells, balconies and windows snap to it


@dataclasses.dataclass(frozen=True)
class OpeningSizes:
    """(min, max) widths [cm] the generator draws doors and windows from.

    Attributes:
        name: what evaluation output and plan metadata call these sizes.
        door: a door into a room (and onto a balcony).
        small_room_door: a door into a bathroom or storeroom.
        front_door: the apartment's entrance.
        window: a window, by the type of the room it lights.
    """

    name: str
    door: tuple[int, int]
    small_room_door: tuple[int, int]
    front_door: tuple[int, int]
    window: Mapping[str, tuple[int, int]]

    def door_for(self, room_type: str) -> tuple[int, int]:
        """The width range of a door into a room of ``room_type``."""
        return self.small_room_door if room_type in ("bathroom", "storage") else self.door


TYPICAL_SIZES = OpeningSizes(
    name="typical",
    door=(80, 100),
    small_room_door=(70, 85),
    front_door=(90, 120),
    window=MappingProxyType(
        {"living": (120, 250), "bedroom": (100, 200), "kitchen": (80, 150), "bathroom": (60, 90)}
    ),
)
"""The sizes every synthetic test and development plan is drawn with: a window's width alone
often tells its room (a 70 cm window is a bathroom's)."""
VARIED_SIZES = OpeningSizes(
    name="varied",
    door=(70, 120),
    small_room_door=(60, 100),
    front_door=(90, 150),
    window=MappingProxyType(
        {"living": (80, 300), "bedroom": (60, 220), "kitchen": (60, 180), "bathroom": (40, 100)}
    ),
)
"""Wider, overlapping ranges, for training: real bedrooms often have 70-90 cm windows and real
doors reach 1.2 m, so a network should not read a room's type off its window's width."""
OPENING_SIZES = {sizes.name: sizes for sizes in (TYPICAL_SIZES, VARIED_SIZES)}
OPEN_KITCHEN_P = 0.4
REJECT_SCORE = 100.0  # door choices this bad (e.g. through a bathroom) discard the layout


def snap_to_grid(value_cm: float) -> int:
    return int(round(value_cm / GRID_CM)) * GRID_CM


def add_openings(
    layout: Layout, rng: np.random.Generator, sizes: OpeningSizes = TYPICAL_SIZES
) -> tuple[list[Opening], list[tuple], bool] | None:
    """Doors (spanning tree from the living room), front door, balconies, windows; or None."""
    types = layout.room_types
    segs = layout.segments
    margin = layout.margin_cm()
    living = types.index("living")
    kitchen = types.index("kitchen")
    pairs = layout.pair_segments()
    exterior = layout.exterior_segments()
    if not _living_connected(layout, living):
        return None

    # open kitchen: kitchen and living share >= 1.5 m of boundary
    open_kitchen = False
    kl = (min(living, kitchen), max(living, kitchen))
    if (
        kl in pairs
        and max(segs[i].length for i in pairs[kl]) >= 150
        and rng.random() < OPEN_KITCHEN_P
    ):
        layout.open_pairs.add(kl)
        open_kitchen = True

    openings: list[Opening] = []
    reached = {living} | ({kitchen} if open_kitchen else set())
    while len(reached) < len(types):
        best = None
        for (a, b), idx in pairs.items():
            if (a in reached) == (b in reached):
                continue
            parent, child = (a, b) if a in reached else (b, a)
            width_lo, width_hi = sizes.door_for(types[child])
            seg_i = max(idx, key=lambda i: segs[i].length)
            if segs[seg_i].length < width_hi + 2 * margin:
                continue
            score = _parent_score(types[parent], types[child])
            if score >= REJECT_SCORE:
                continue
            score += rng.random()
            if best is None or score < best[0]:
                best = (score, child, seg_i, width_lo, width_hi)
        if best is None:
            return None
        _, child, seg_i, width_lo, width_hi = best
        seg = segs[seg_i]
        width = int(rng.integers(width_lo, width_hi + 1))
        # doors sit near a corner more often than in the middle of a wall
        span = seg.length - 2 * margin - width
        offset = (
            int(rng.integers(0, min(span, 40) + 1))
            if rng.random() < 0.7
            else int(rng.integers(0, span + 1))
        )
        lo = seg.lo + margin + offset if rng.random() < 0.5 else seg.hi - margin - offset - width
        openings.append(Opening("door", seg_i, lo, lo + width))
        reached.add(child)

    used: dict[int, list[tuple[int, int]]] = {}
    # front door in an exterior wall of the living room
    fd_width = int(rng.integers(sizes.front_door[0], sizes.front_door[1] + 1))
    candidates = [i for i in exterior.get(living, []) if segs[i].length >= fd_width + 2 * margin]
    if not candidates:
        return None
    seg_i = candidates[int(rng.integers(len(candidates)))]
    span = free_interval([], segs[seg_i].lo + margin, segs[seg_i].hi - margin, fd_width, 0, rng)
    openings.append(Opening("front_door", seg_i, *span))
    used[seg_i] = [span]
    keep_clear = [outside_box_cm(layout, segs[seg_i], span, 120)]

    footprint = [
        (
            x0 - layout.t_ext * 50,
            y0 - layout.t_ext * 50,
            x1 + layout.t_ext * 50,
            y1 + layout.t_ext * 50,
        )
        for x0, y0, x1, y1 in layout.rects
    ]
    balconies: list[tuple] = []
    n_balconies = int(rng.choice([0, 1, 2, 3], p=[0.3, 0.35, 0.25, 0.1]))
    balcony_segs = [
        i
        for r, t in enumerate(types)
        if t in ("living", "bedroom")
        for i in exterior.get(r, [])
        if segs[i].length >= 200 + 2 * margin
    ]
    rng.shuffle(balcony_segs)
    for seg_i in balcony_segs[: n_balconies * 2]:
        if len(balconies) >= n_balconies:
            break
        seg = segs[seg_i]
        width = snap_to_grid(rng.uniform(200, min(500, seg.length - 2 * margin)))
        depth = snap_to_grid(rng.uniform(120, 200))
        span = free_interval(used.get(seg_i, []), seg.lo + margin, seg.hi - margin, width, 30, rng)
        if span is None:
            continue
        box = outside_box_cm(layout, seg, span, depth)
        if any(
            boxes_overlap(box, o)
            for o in footprint + keep_clear + [tuple(v * 100 for v in b) for b in balconies]
        ):
            continue
        balconies.append(balcony_rect(layout, seg, span[0], span[1], depth))
        door_w = int(rng.integers(80, min(121, span[1] - span[0] - 20)))
        door = free_interval([], span[0] + 10, span[1] - 10, door_w, 0, rng)
        openings.append(Opening("door", seg_i, *door))
        used.setdefault(seg_i, []).append(span)

    openings += place_windows(layout, exterior, used, rng, sizes)
    return openings, balconies, open_kitchen


def place_windows(
    layout: Layout,
    exterior: dict[int, list[int]],
    used: dict[int, list[tuple[int, int]]],
    rng: np.random.Generator,
    sizes: OpeningSizes = TYPICAL_SIZES,
) -> list[Opening]:
    """Windows in the exterior walls of rooms, avoiding the ``used`` spans (updated) [cm]."""
    types, segs, margin = layout.room_types, layout.segments, layout.margin_cm()
    openings: list[Opening] = []
    for room, seg_ids in exterior.items():
        kind = types[room]
        if kind not in sizes.window or (kind == "bathroom" and rng.random() < 0.3):
            continue
        n_windows = {"living": 3, "bedroom": 2}.get(kind, 1)
        for seg_i in rng.permutation(seg_ids)[:n_windows]:
            seg = segs[seg_i]
            lo_w, hi_w = sizes.window[kind]
            width = (
                snap_to_grid(rng.uniform(lo_w, hi_w))
                if kind != "bathroom"
                else int(rng.integers(lo_w, hi_w + 1))
            )
            span = free_interval(
                used.get(seg_i, []), seg.lo + margin, seg.hi - margin, width, 30, rng
            )
            if span is None and width > lo_w:
                width = lo_w
                span = free_interval(
                    used.get(seg_i, []), seg.lo + margin, seg.hi - margin, width, 30, rng
                )
            if span is None:
                continue
            openings.append(Opening("window", int(seg_i), *span))
            used.setdefault(int(seg_i), []).append(span)
    return openings


def _living_connected(layout: Layout, living: int) -> bool:
    """Whether all living cells form one room (each touches another by >= 1 m)."""
    cells = [r for r, room in zip(layout.rects, layout.rect_room, strict=True) if room == living]
    if len(cells) == 1:
        return True
    a, b = cells
    overlap_x = min(a[2], b[2]) - max(a[0], b[0])
    overlap_y = min(a[3], b[3]) - max(a[1], b[1])
    return (overlap_x == 0 and overlap_y >= 100) or (overlap_y == 0 and overlap_x >= 100)


def _parent_score(parent: str, child: str) -> float:
    """Lower is better: which room a new room's door should open from."""
    if parent == "living":
        return 0.0
    if parent == "bedroom" and child == "bathroom":
        return 1.0  # en-suite
    if parent == "kitchen" and child == "storage":
        return 1.0  # pantry
    if parent == "kitchen" and child != "bedroom":
        return 3.0
    if parent == "bedroom" and child != "kitchen":
        return 5.0  # a walk-through room: allowed but rare
    return REJECT_SCORE
