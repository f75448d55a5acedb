"""A flight of stairs drawn in a room: its treads, and the room it makes circulation.

A stair is drawn as its treads: parallel straight lines across the flight, evenly spaced, each as
long as the flight is wide. Seen by the network they are a pattern of tiles, and a hall holding
a stair is often voted a bathroom (or a bedroom). A room holding a flight is where people walk
through: :func:`stairs_are_circulation` gives a bedroom or a bathroom that holds one the class
of circulation, living (f2n_drake's class for halls).

:func:`holds_flight` looks for a flight in a room's ink, along rows and along columns: a tread is
a run of ink across the room's paper at least ``MIN_TREAD_SHARE`` of the room's width across it
(the box's side along the run) and ``MIN_TREAD_PX`` long; a flight is at least ``MIN_TREADS``
treads in a row, each spaced from the next within ``SPACING_SPREAD`` of their median spacing,
spanning the same stretch (their ends within ``END_SPREAD`` of a tread's length), with a spacing
of at least ``MIN_STEP_PX``. Tiles are lines both ways: where more than ``MAX_LINES_ALONG`` long
lines run across the treads (a flight's two sides), the pattern is no flight.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from scipy import ndimage

from f2n_drake.core.parsed import ParsedPlan
from f2n_drake.perception.ink import as_grey
from f2n_drake.perception.runs import row_runs
from f2n_drake.perception.window_inserts import FAINT_DEPTH, ink_depth

MIN_TREADS = 5
"""Fewest treads of a flight."""
MIN_TREAD_SHARE = 0.25
"""A tread spans at least this share of the room's box across it."""
MIN_TREAD_PX = 8
"""A tread is at least this long [px]."""
MIN_STEP_PX = 3
"""Treads are at least this far apart [px], centre to centre."""
SPACING_SPREAD = 0.3
"""Each spacing lies within this share of the flight's median spacing."""
END_SPREAD = 0.2
"""The treads' ends lie within this share of a tread's length of the flight's median ends."""
MAX_LINES_ALONG = 2
"""Most long lines along a flight (its two sides): more are tiles, drawn both ways."""
_EDGE_PX = 4  # the rows of a room's box its walls' inner faces lie on (the box grown by 2 px)
CIRCULATION = "living"
"""The class of a room holding a flight (halls, landings and corridors are living)."""
NOT_CIRCULATION: tuple[str, ...] = ("bedroom", "bathroom")
"""Room classes a flight of stairs is never in."""


def holds_flight(room: np.ndarray, ink: np.ndarray) -> bool:
    """Whether the ink inside a room (bool crops of one size: the room's paper, the drawing's
    ink) draws a flight of stairs (module doc): treads along rows or along columns, and no more
    than ``MAX_LINES_ALONG`` long lines across them."""
    inside = ink & ndimage.binary_fill_holes(room | ink & ndimage.binary_dilation(room))
    inside &= ~room
    for treads, across in ((inside, inside.T), (inside.T, inside)):
        if _flight(treads) and _long_lines(across) <= MAX_LINES_ALONG:
            return True
    return False


def _long_lines(ink: np.ndarray) -> int:
    """How many lines of ink run along the rows of ``ink`` as long as a tread would be, leaving
    out those on the box's first and last ``_EDGE_PX`` rows (the room's walls)."""
    starts, ends = _longest_runs(ink)
    long = (ends - starts) >= max(MIN_TREAD_PX, MIN_TREAD_SHARE * ink.shape[1])
    long[:_EDGE_PX] = long[-_EDGE_PX:] = False
    return ndimage.label(long)[1]


def _flight(ink: np.ndarray) -> bool:
    """Whether the rows of ``ink`` hold a flight: treads are the longest run of ink of a row."""
    if ink.shape[0] < MIN_TREADS or not ink.any():
        return False
    min_len = max(MIN_TREAD_PX, MIN_TREAD_SHARE * ink.shape[1])
    starts, ends = _longest_runs(ink)
    tread = (ends - starts) >= min_len
    rows, count = ndimage.label(tread)
    if count < MIN_TREADS:
        return False
    centres = np.array(ndimage.mean(np.arange(len(tread)), rows, range(1, count + 1)))
    first = np.array(ndimage.median(starts, rows, range(1, count + 1)))
    last = np.array(ndimage.median(ends, rows, range(1, count + 1)))
    # the longest chain of treads evenly spaced, spanning one stretch
    best = 1
    for i in range(count):
        chain = [i]
        for j in range(i + 1, count):
            step = centres[j] - centres[chain[-1]]
            if step < MIN_STEP_PX:
                continue
            spacing = np.diff(centres[[*chain, j]])
            same_step = np.abs(spacing - np.median(spacing)) <= SPACING_SPREAD * np.median(spacing)
            length = np.median(last[chain] - first[chain])
            same_ends = (
                abs(first[j] - np.median(first[chain])) <= END_SPREAD * length
                and abs(last[j] - np.median(last[chain])) <= END_SPREAD * length
            )
            if same_step.all() and same_ends:
                chain.append(j)
            elif len(chain) > 1:
                break
        best = max(best, len(chain))
    return best >= MIN_TREADS


def _longest_runs(ink: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per row, the start and end (exclusive) of its longest run of ink (the first of equals;
    0, 0 for none)."""
    starts = np.zeros(ink.shape[0], int)
    ends = np.zeros(ink.shape[0], int)
    rows, first, last = row_runs(ink)
    order = np.lexsort((first, first - last, rows))  # per row: the longest, then the leftmost
    best = order[np.r_[True, rows[order][1:] != rows[order][:-1]]] if rows.size else order
    starts[rows[best]] = first[best]
    ends[rows[best]] = last[best] + 1
    return starts, ends


def stairs_are_circulation(parsed: ParsedPlan, lines: np.ndarray, grey: np.ndarray) -> ParsedPlan:
    """``parsed`` with each bedroom or bathroom holding a flight of stairs re-classed
    ``CIRCULATION``; the same plan when none. The flight is looked for in the drawing's ink
    (``lines``, without its words) and its faint lines (``grey``, or the colour drawing, at least
    ``window_inserts.FAINT_DEPTH`` darker than the local paper: treads are often drawn light)."""
    ink = lines | (ink_depth(as_grey(grey)) >= FAINT_DEPTH)
    ids = parsed.instance_ids
    boxes = parsed.boxes()
    changed = False
    instances = []
    for inst in parsed.instances:
        box = boxes[inst.id - 1] if inst.id <= len(boxes) else None
        if inst.class_name in NOT_CIRCULATION and box is not None:
            grown = tuple(slice(max(s.start - 2, 0), s.stop + 2) for s in box)
            if holds_flight((ids[grown] == inst.id) & ~ink[grown], ink[grown]):
                inst = dataclasses.replace(inst, class_name=CIRCULATION)
                changed = True
        instances.append(inst)
    return dataclasses.replace(parsed, instances=instances) if changed else parsed
