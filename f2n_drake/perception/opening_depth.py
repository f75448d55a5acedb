"""Openings as deep as their wall: a door or window fills the gap between the wall's two ends.

A connector instance comes from whatever closed the gap in the wall: the doorway step's strip,
a window insert between the wall's faces, or the thin paper left between a threshold or sill
line and the wall's face. Where the drawing draws a line across the gap (a threshold, a sill,
the outer face carried on), the connector can end up a thin strip on one side of that line,
and the paper between the line and the other face of the wall is taken by the room (or the
outside) beyond it. The opening in the wall is the whole gap: between the two wall ends, as
thick as they are (as R3D paints doors and windows, and as a robot has to drive through it).

:func:`fill_wall_depth` grows each connector to that rectangle. A connector's wall ends are
found along its two axes: the wall bands
(:func:`~f2n_drake.perception.window_inserts.wall_bands`) within ``_END_REACH_PX`` beyond each
end of its extent, the run of band across the axis nearest the connector's middle. An axis
counts when both ends are wall at most ``_END_WALLS`` walls thick (a wall's end, not a crossing
wall or a corner) and their common span across overlaps the connector; only a connector with
exactly one such axis is grown, and only when most of it (``_INSIDE_SHARE``) lies within that
span (a bay window's curve or a label joined to a front door is no strip across a wall). The
rectangle between the ends takes the pixels of rooms and of no instance that are no wall band;
a room giving up more than ``_MAX_ROOM_SHARE`` of itself keeps its pixels (the rectangle is then
no gap in a wall). A window's rectangle also takes the reveal beside it, where the wall steps
back round the window on the room's or the street's side (R3D paints the opening across the
wall's whole thickness): rows with no band across the window's extent but band within half a
wall beyond both its ends, up to a wall's thickness in all. A door's gap does not (grown so too,
doors beside a corner took the room's paper round it: fewer R3D openings matched, not more).

A line drawn along the wall through an opening (a sill, the glazing, a reveal's step) can also
part it lengthwise into two connectors of one class side by side across the wall's depth, each
a strip along the same span. :func:`join_depth_pieces` makes them one: two connectors of one
class whose shared edge runs along the length of both and at least ``_SAME_SPAN_SHARE`` of the
longer one's. Panes end to end along the wall (parted at a mullion or a pier) share only their
ends and stay apart.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from f2n_drake.core.classes import CONNECTOR_CLASSES, SPACE_CLASSES
from f2n_drake.core.parsed import ParsedPlan, instance_from_mask, joined_instances
from f2n_drake.perception.ink import as_grey
from f2n_drake.perception.window_inserts import wall_bands

_END_REACH_PX = 3  # a wall's end lies at most this far beyond the connector's extent [px]
_END_WALLS = 2.5  # and is at most this many walls thick across (no crossing wall)
_INSIDE_SHARE = 0.5  # at least this share of a grown connector lies between its wall's faces
_MAX_ROOM_SHARE = 0.2  # a room gives up at most this share of its pixels to one connector
_REVEAL_REACH = 0.5  # a window's reveal is walled within this many walls beyond its ends
_SAME_SPAN_SHARE = 0.85  # side-by-side pieces of one opening share this much of the longer's length


def fill_wall_depth(
    parsed: ParsedPlan,
    grey: np.ndarray,
    lines: np.ndarray,
    probabilities: np.ndarray | None = None,
    *,
    walls: tuple[np.ndarray, np.ndarray, int] | None = None,
) -> ParsedPlan:
    """``parsed`` with each connector grown to its gap in the wall (module doc); the same plan
    when none grows.

    Args:
        parsed: the instances of a drawing.
        grey: (H, W) uint8 grey drawing, dark lines on light paper (or BGR/BGRA, made grey).
        lines: (H, W) bool, its walls' ink.
        probabilities: (NUM_CLASSES, H, W) class probabilities, for the changed instances'
            scores.
        walls: ``wall_bands(grey, lines, parsed.labels)`` when already computed.
    """
    _, bands, wall_px = walls or wall_bands(as_grey(grey), lines, parsed.labels)
    if wall_px == 0:
        return parsed
    ids = parsed.instance_ids.copy()
    room_ids = [inst.id for inst in parsed.instances if inst.class_name in SPACE_CLASSES]
    areas = np.bincount(ids.ravel(), minlength=max(room_ids, default=0) + 1)  # may hold no pixel
    rooms = np.zeros(areas.size, bool)
    rooms[room_ids] = True
    boxes = parsed.boxes()
    changed: set[int] = set()
    for inst in parsed.instances:
        box = boxes[inst.id - 1] if inst.id <= len(boxes) else None
        if inst.class_name not in CONNECTOR_CLASSES or box is None:
            continue
        rows, cols = np.nonzero(parsed.instance_ids[box] == inst.id)
        rows, cols = rows + box[0].start, cols + box[1].start
        reveal = inst.class_name == "window"
        gaps = [
            gap
            for gap in (
                _gap_across(bands, rows, cols, wall_px, reveal),  # a wall along the rows
                _transposed(_gap_across(bands.T, cols, rows, wall_px, reveal)),  # the columns
            )
            if gap is not None
        ]
        if len(gaps) != 1:
            continue
        rect = gaps[0]
        inside = ids[rect]
        take = rooms[inside] | ((inside == 0) & ~bands[rect])
        given = np.bincount(inside[take], minlength=areas.size)
        if not take.any() or np.any(given[rooms] > _MAX_ROOM_SHARE * areas[rooms]):
            continue
        changed.update(np.flatnonzero(given).tolist())
        changed.add(inst.id)
        inside[take] = inst.id  # a view: writes the rectangle of ids
    changed.discard(0)
    if not changed:
        return parsed
    instances = []
    for inst in parsed.instances:
        if inst.id in changed:
            mask = ids == inst.id
            if not mask.any():
                continue
            grown = instance_from_mask(inst.id, inst.class_name, mask, parsed.labels, probabilities)
            inst = dataclasses.replace(grown, name=inst.name)
        instances.append(inst)
    return dataclasses.replace(parsed, instance_ids=ids, instances=instances)


def join_depth_pieces(parsed: ParsedPlan, probabilities: np.ndarray | None = None) -> ParsedPlan:
    """``parsed`` with connectors of one class lying side by side across the wall's depth along
    the same span one instance (module doc), instance ids renumbered 1..K in their order; the
    same plan when none join.

    Args:
        parsed: the instances of a drawing.
        probabilities: (NUM_CLASSES, H, W) class probabilities, for the joined instances' scores.
    """
    ids = parsed.instance_ids
    largest = max([int(ids.max()), *(i.id for i in parsed.instances)])
    connector = np.zeros(largest + 1, bool)
    connector[[i.id for i in parsed.instances if i.class_name in CONNECTOR_CLASSES]] = True
    if connector.sum() < 2:
        return parsed
    boxes = parsed.boxes()
    by_id = parsed.by_id()
    size = connector.size
    root = np.arange(size)

    def find(k: int) -> int:
        while root[k] != k:
            root[k] = root[root[k]]
            k = int(root[k])
        return k

    # pixel pairs across a horizontal edge (rows r, r + 1), then across a vertical one
    for first, second, along_rows in ((ids[:-1], ids[1:], True), (ids[:, :-1], ids[:, 1:], False)):
        touching = connector[first] & connector[second] & (first != second)
        low = np.minimum(first[touching], second[touching]).astype(np.int64)
        high = np.maximum(first[touching], second[touching]).astype(np.int64)
        pairs, shared = np.unique(low * size + high, return_counts=True)
        for pair, edge in zip(pairs.tolist(), shared.tolist(), strict=True):
            a, b = divmod(pair, size)
            if by_id[a].class_name != by_id[b].class_name:
                continue
            lengths = [_length(boxes[k - 1], along_rows) for k in (a, b)]
            if any(length is None for length in lengths):  # one of them runs across the edge
                continue
            if edge >= _SAME_SPAN_SHARE * max(lengths):
                root[find(b)] = find(a)
    joined = {int(k): find(k) for k in np.flatnonzero(connector) if find(k) != k}
    if not joined:
        return parsed
    return joined_instances(parsed, joined, lambda inst, _: inst.class_name, probabilities)


def _length(box: tuple[slice, slice], along_rows: bool) -> int | None:
    """The length of a connector whose box is ``box`` when it runs along the rows
    (``along_rows``) or the columns, None when it runs the other way (longer across)."""
    width, height = box[1].stop - box[1].start, box[0].stop - box[0].start
    long, short = (width, height) if along_rows else (height, width)
    return long if long >= short else None


def _gap_across(
    bands: np.ndarray, rows: np.ndarray, cols: np.ndarray, wall_px: int, reveal: bool = False
) -> tuple[slice, slice] | None:
    """The rectangle (rows, columns) between the two ends of a wall running along the rows
    that the connector of pixels ``rows``, ``cols`` lies in, or None (module doc); with
    ``reveal``, carried on across the reveal beside it (:func:`_across_reveal`)."""
    top, bottom, left, right = rows.min(), rows.max(), cols.min(), cols.max()
    if left - _END_REACH_PX < 0 or right + _END_REACH_PX >= bands.shape[1]:
        return None
    ends = [
        _run_near(bands[:, left - _END_REACH_PX : left].any(axis=1), top, bottom),
        _run_near(bands[:, right + 1 : right + 1 + _END_REACH_PX].any(axis=1), top, bottom),
    ]
    if any(end is None or end[1] - end[0] + 1 > _END_WALLS * wall_px for end in ends):
        return None
    first, last = max(ends[0][0], ends[1][0]), min(ends[0][1], ends[1][1])
    if last - first + 1 < 2 or first > bottom or last < top:
        return None
    if np.mean((rows >= first) & (rows <= last)) < _INSIDE_SHARE:
        return None
    if reveal:
        first, last = _across_reveal(bands, first, last, left, right, wall_px)
    return slice(first, last + 1), slice(left, right + 1)


def _across_reveal(
    bands: np.ndarray, first: int, last: int, left: int, right: int, wall_px: int
) -> tuple[int, int]:
    """Rows ``first..last`` carried on, on both sides, over the rows where the wall steps back
    round the gap (a window's reveal): rows with no band between columns ``left`` and ``right``
    and band within ``_REVEAL_REACH`` walls beyond both, as long as the rectangle stays at most
    a wall (and 2 px) thick."""
    reach = max(_END_REACH_PX, int(_REVEAL_REACH * wall_px))
    deepest = wall_px + 2

    def stepped_back(row: int) -> bool:
        return (
            0 <= row < bands.shape[0]
            and not bands[row, left : right + 1].any()
            and bands[row, max(0, left - reach) : left].any()
            and bands[row, right + 1 : right + 1 + reach].any()
        )

    while last - first + 1 < deepest and stepped_back(last + 1):
        last += 1
    while last - first + 1 < deepest and stepped_back(first - 1):
        first -= 1
    return first, last


def _transposed(rect: tuple[slice, slice] | None) -> tuple[slice, slice] | None:
    return None if rect is None else (rect[1], rect[0])


def _run_near(column: np.ndarray, top: int, bottom: int) -> tuple[int, int] | None:
    """(first, last) index of the run of True in ``column`` through the hit in ``top..bottom``
    nearest their middle; None when that stretch holds none."""
    hits = top + np.flatnonzero(column[top : bottom + 1])
    if hits.size == 0:
        return None
    at = int(hits[np.argmin(np.abs(hits - (top + bottom) / 2))])
    first, last = at, at
    while first > 0 and column[first - 1]:
        first -= 1
    while last < column.size - 1 and column[last + 1]:
        last += 1
    return first, last
