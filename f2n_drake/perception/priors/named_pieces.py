"""A named room cut into pieces by its fixtures is one room: its pieces take the name's class.

A bathroom's tub, basin and toilet, a kitchen's counters, a bedroom's wardrobes are drawn in
thin lines that the parse takes as boundaries: the room becomes a named piece (the one holding
the name) and unnamed pieces around it, which keep whatever the network voted (the inside of a
tub voted living). The room's walls are thicker than its fixtures, or seen by the network:

- the room's extent is the paper under its name bounded only by the walls (the ink ``WALL_PX``
  thick or more, and what the network labels wall, window or door, in no text's box: text is
  never a wall) once their gaps (a
  wide door at most, ``perception.wall_gaps.collinear_gaps``) are closed; none when it reaches the
  image border (the walls leave it open) or holds confident names of another class;
- a room instance lying in it (``INSIDE`` of its pixels) holding no name of a class is one of
  its pieces when less than ``MAX_WALL_SHARE`` of the ink along its outline is wall (fixtures
  bound it, where a room beside it behind a door the closing missed is walled), and when it
  touches the named piece, or a piece that does, across a line thinner than a wall.

:func:`join_named_pieces` gives each such piece the class of the room's names. Without text, or
on drawings whose rooms hold no fixture, the plan comes back unchanged.
"""

from __future__ import annotations

import dataclasses

import cv2
import numpy as np

from f2n_drake.core.classes import CLASS_ID, CONNECTOR_CLASSES, SPACE_CLASSES
from f2n_drake.core.parsed import ParsedPlan
from f2n_drake.perception.doorways import max_gap_px
from f2n_drake.perception.room_names import room_class
from f2n_drake.perception.wall_gaps import collinear_gaps

CONFIDENT = 0.8
"""A name read with at least this confidence gives its room's pieces its class (as it sets the
class of the piece it lies on, ``perception.priors.named_rooms``)."""
INSIDE = 0.8
"""Share of a piece's pixels that must lie in the named room's extent."""
MAX_WALL_SHARE = 0.9
"""A piece with this share of its outline wall or more is a room of its own (a tub in a corner
has half its outline on walls, a room behind a door the closing missed all of it but the door's
swing and leaf)."""
_BOUNDS = [CLASS_ID[c] for c in ("wall", *CONNECTOR_CLASSES)]
_SPECK = np.ones((4, 4), np.uint8)
WALL_PX = 3
"""Ink at least this thick may be a wall; thinner strokes draw fixtures, hatching, railings."""
_WALL = np.ones((WALL_PX, WALL_PX), np.uint8)
_REACH = np.ones((2 * WALL_PX + 1, 2 * WALL_PX + 1), np.uint8)


def wall_ink(lines: np.ndarray, labels: np.ndarray) -> np.ndarray:
    """(H, W) bool walls of a drawing: its ink at least ``WALL_PX`` thick and what the network
    ``labels`` wall, window or door (specks left out)."""
    thick = cv2.morphologyEx(lines.astype(np.uint8), cv2.MORPH_OPEN, _WALL)
    seen = cv2.morphologyEx(np.isin(labels, _BOUNDS).astype(np.uint8), cv2.MORPH_OPEN, _SPECK)
    return (thick > 0) | (seen > 0)


def _names(parsed: ParsedPlan) -> dict[int, set[str]]:
    """Instance id -> the classes of the confident room names placed in it."""
    names: dict[int, set[str]] = {}
    for text in parsed.texts:
        if text.instance_id is None or text.confidence < CONFIDENT:
            continue
        if (cls := room_class(text.text)) in SPACE_CLASSES:
            names.setdefault(text.instance_id, set()).add(cls)
    return names


def join_named_pieces(parsed: ParsedPlan, lines: np.ndarray) -> ParsedPlan:
    """``parsed`` with the unnamed pieces of each named room (see module doc) re-classed to the
    room's named class; the same plan when there is none. ``lines`` is the drawing's ink without
    its words."""
    names = _names(parsed)
    by_id = parsed.by_id()
    named = {i: next(iter(c)) for i, c in names.items() if len(c) == 1}
    named = {i: c for i, c in named.items() if by_id[i].class_name == c}
    if not named:
        return parsed
    walls = wall_ink(lines, parsed.labels) & ~_text_boxes(parsed, lines.shape)
    widest = max_gap_px(walls)
    gaps = collinear_gaps(walls, max_gap_px=widest, min_run_px=max(3, widest // 2)) & ~walls
    n, paper = cv2.connectedComponents((~(walls | gaps)).astype(np.uint8), connectivity=4)
    outside = np.unique(np.concatenate([paper[0], paper[-1], paper[:, 0], paper[:, -1]]))
    ids = parsed.instance_ids
    # region of each instance: the paper component holding most of its pixels, and how many
    pairs = ids.astype(np.int64) * n + paper
    counts = np.bincount(pairs.ravel(), minlength=(int(ids.max()) + 1) * n).reshape(-1, n)
    counts[:, 0] = 0
    region_of = counts.argmax(axis=1)
    share = counts.max(axis=1) / np.maximum(np.bincount(ids.ravel(), minlength=len(counts)), 1)
    classes_in: dict[int, set[str]] = {}
    for iid, cls in names.items():
        classes_in.setdefault(int(region_of[iid]), set()).update(cls)
    room_of = {}
    for iid, cls in named.items():
        region = int(region_of[iid])
        if region and region not in outside and classes_in[region] == {cls}:
            room_of[region] = cls
    pieces: dict[int, list[int]] = {}
    for inst in parsed.instances:
        region = int(region_of[inst.id])
        if (
            region in room_of
            and inst.id not in names
            and inst.class_name in SPACE_CLASSES
            and inst.class_name != room_of[region]
            and share[inst.id] >= INSIDE
            and _bounded_by_fixtures(ids == inst.id, lines, walls)
        ):
            pieces.setdefault(region, []).append(inst.id)
    changed = {}
    for region, candidates in pieces.items():
        room = np.isin(ids, [i for i in named if region_of[i] == region])
        for iid in _touching(ids, room, candidates):
            changed[iid] = room_of[region]
    if not changed:
        return parsed
    instances = [
        dataclasses.replace(i, class_name=changed[i.id]) if i.id in changed else i
        for i in parsed.instances
    ]
    return dataclasses.replace(parsed, instances=instances)


def _text_boxes(parsed: ParsedPlan, shape: tuple[int, int]) -> np.ndarray:
    """(H, W) bool: the boxes of every text read; what is left of its ink there (strokes running
    out of the box, the network's labels on them) is no wall."""
    boxes = np.zeros(shape, bool)
    for text in parsed.texts:
        c0, r0, c1, r1 = text.box_px
        boxes[r0:r1, c0:c1] = True
    return boxes


def _touching(ids: np.ndarray, room: np.ndarray, candidates: list[int]) -> list[int]:
    """The ``candidates`` (instance ids) that touch the named ``room`` across a line thinner
    than a wall (``WALL_PX`` reach), or touch one that does, and so on."""
    room = room.copy()
    joined: list[int] = []
    grew = True
    while grew:
        grew = False
        for iid in candidates:
            if iid in joined:
                continue
            rows, cols = np.nonzero(ids == iid)
            r0, r1 = max(rows.min() - WALL_PX, 0), rows.max() + WALL_PX + 1
            c0, c1 = max(cols.min() - WALL_PX, 0), cols.max() + WALL_PX + 1
            piece = (ids[r0:r1, c0:c1] == iid).astype(np.uint8)
            if (cv2.dilate(piece, _REACH).astype(bool) & room[r0:r1, c0:c1]).any():
                joined.append(iid)
                room[r0:r1, c0:c1] |= piece.astype(bool)
                grew = True
    return joined


def _bounded_by_fixtures(piece: np.ndarray, lines: np.ndarray, walls: np.ndarray) -> bool:
    """Whether less than ``MAX_WALL_SHARE`` of the ink along ``piece``'s outline (the pixels
    next to it) is wall."""
    rows, cols = np.nonzero(piece)
    r0, r1 = max(rows.min() - 2, 0), rows.max() + 3
    c0, c1 = max(cols.min() - 2, 0), cols.max() + 3
    box = piece[r0:r1, c0:c1].astype(np.uint8)
    ring = (cv2.dilate(box, np.ones((3, 3), np.uint8)) > 0) & ~box.astype(bool)
    ink = ring & (lines[r0:r1, c0:c1] | walls[r0:r1, c0:c1])
    if not ink.any():
        return False
    return np.count_nonzero(ink & walls[r0:r1, c0:c1]) < MAX_WALL_SHARE * np.count_nonzero(ink)
