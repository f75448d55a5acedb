"""Windows drawn in a wall's line: thin parallel lines spanning a gap in a thick wall.

Real drawings draw a wall as a thick stroke (or a solid black band) and a window as an insert in
its line: the thick ink stops, two or three thin lines (the glass, the sill, the wall's faces
carried on) run along the wall across the opening, and the thick ink starts again. The thin lines
are often light grey and lost when the drawing is binarised, so the window reads as a plain gap
and the room behind it leaks to the outside. This module finds those inserts on the ink:

1. **Thick walls**: ink whose stroke width (the shorter of its row and column run,
   :func:`stroke_widths_px`) is at least ``2 w + 1`` for the drawing's thin-line width ``w``
   (the most common width of the ink the network labels no wall, thinner than half the
   walls it labels): wall
   bands, not lines. A drawing whose walls are no thicker than that has no inserts.
2. **Gaps in a wall's line**: along each row (column), the pixels between two thick pixels at
   most ``max_span_px`` apart, where at least one of the two is the end of a wall running along
   the row (a band at most ``_BAND_SHARE`` times the wall thickness across). The gap's pixels,
   4-connected, are a piece; a piece is a span of a wall's line when it is a rectangle about as
   thick as the wall.
3. **Thin lines along it**: the faint ink (the binarised lines, or grey at least
   ``FAINT_DEPTH`` darker than the local paper) covering at least ``_LINE_COVER`` of the span's
   length, on at least two separate rows (columns) of it: parallel lines spanning the wall.

Each such span is a window insert: a window instance, a boundary for the ground robot's rooms as
a wall is, and a connector for the drone.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
from scipy import ndimage

from f2n_drake.core.classes import CLASS_ID

_WALL = CLASS_ID["wall"]
MAX_WINDOW_M = 3.0
"""Longest window insert when the scale is known [m]."""
MAX_WINDOW_SHARE = 0.4
"""Longest window insert when the scale is unknown, as a share of the wall ink's extent."""
_BAND_SHARE = 2.0  # a wall's end is a band at most this many wall thicknesses across
_END_SHARE = 0.75  # and runs on along the line at least this many wall thicknesses
_ALIGN_SHARE = 0.25  # a gap's two ends are one wall's line: edges this share of its thickness apart
_THICK_SLACK = 1.5  # a gap is at most this many times its ends' thickness across, plus 2 px
_FILL_SHARE = 0.7  # and fills at least this share of its bounding box (a rectangle)
_VALLEY_SHARE = 0.6  # two lines part where the darkness between them falls to this share
FAINT_DEPTH = 12
"""Grey levels below the local paper that make faint ink."""
_PAPER_WINDOW_PX = 9  # window of the local paper level (a closing of the grey image) [px]
_MIN_THICK_PX = 3  # the thinnest stroke that can be a thick wall [px]
_MIN_SPAN_PX = 3  # shorter gaps are a wall's ragged edge
_FACE_PX = 2  # a window's lines on the wall's faces lie at most this far beyond its gap [px]


def stroke_widths_px(ink: np.ndarray) -> np.ndarray:
    """(H, W) int32: per ink pixel, the shorter of the lengths of its row run and its column run
    of ink [px] (a horizontal wall t px thick gives t); 0 off the ink."""
    ink = np.asarray(ink, bool)
    return np.minimum(_run_lengths(ink), _run_lengths(ink.T).T)


def _run_lengths(ink: np.ndarray) -> np.ndarray:
    """(H, W) int32: per ink pixel, the length of the run of ink along its row."""
    h, w = ink.shape
    steps = np.diff(np.pad(ink.astype(np.int8), ((0, 0), (1, 1))), axis=1).ravel()
    starts, ends = np.flatnonzero(steps == 1), np.flatnonzero(steps == -1)
    marks = np.zeros(h * (w + 1) + 1, np.int32)
    marks[starts] += ends - starts
    marks[ends] -= ends - starts
    return np.cumsum(marks)[:-1].reshape(h, w + 1)[:, :w]


def thick_walls(
    grey: np.ndarray, lines: np.ndarray, labels: np.ndarray, side_px: int | None = None
) -> tuple[np.ndarray, int]:
    """The thick-wall ink of a drawing and the walls' typical thickness [px] (see module doc);
    ``(no pixels, 0)`` when there are none.

    The ink is the ``lines`` at least half as dark as the drawing's ink is from its paper (light
    grey glazing lines the binarisation joined into a band part again); the walls' thickness is
    the median stroke width (:func:`stroke_widths_px`) of that ink where the network labels
    wall, and the thick walls are the ink a square half that wide (at least ``_MIN_THICK_PX``)
    fits in.
    """
    lines = np.asarray(lines, bool)
    none = np.zeros(lines.shape, bool), 0
    if not lines.any() or lines.all():
        return none
    paper, ink = float(np.median(grey[~lines])), float(np.median(grey[lines]))
    dark = lines & (grey <= (paper + ink) / 2)
    widths = stroke_widths_px(dark)
    on_walls = widths[dark & (labels == _WALL)]
    if on_walls.size == 0:
        return none
    wall_px = int(np.median(on_walls))
    side = max(int(np.ceil(wall_px / 2)), _MIN_THICK_PX) if side_px is None else side_px
    if wall_px < side:
        return none
    kernel = np.ones((side, side), np.uint8)
    return cv2.morphologyEx(dark.astype(np.uint8), cv2.MORPH_OPEN, kernel) > 0, wall_px


def ink_depth(grey: np.ndarray) -> np.ndarray:
    """(H, W) int16: how much darker than the local paper each pixel is [grey levels]; the paper
    is the grey image closed over ``_PAPER_WINDOW_PX``, so a thin line is as deep as it is dark
    whatever ink lies near it."""
    kernel = np.ones((_PAPER_WINDOW_PX, _PAPER_WINDOW_PX), np.uint8)
    return cv2.morphologyEx(grey, cv2.MORPH_CLOSE, kernel).astype(np.int16) - grey


def max_window_px(walls: np.ndarray, metres_per_px: float | None = None) -> int:
    """Longest insert [px]: ``MAX_WINDOW_M`` at a known scale, else ``MAX_WINDOW_SHARE`` of the
    extent of the ``walls`` ink (0 when there is none)."""
    if metres_per_px:
        return int(round(MAX_WINDOW_M / metres_per_px))
    rows, cols = np.nonzero(walls)
    if rows.size == 0:
        return 0
    extent = max(rows.max() - rows.min(), cols.max() - cols.min()) + 1
    return int(round(MAX_WINDOW_SHARE * extent))


def _run_bounds(ink: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(H, W) int32 first and last column of the run of ink along its row, per ink pixel."""
    h, w = ink.shape
    col = np.broadcast_to(np.arange(w, dtype=np.int32), (h, w))
    before = np.pad(ink, ((0, 0), (1, 0)))[:, :-1]
    after = np.pad(ink, ((0, 0), (0, 1)))[:, 1:]
    first = np.maximum.accumulate(np.where(ink & ~before, col, -1), axis=1)
    last = np.minimum.accumulate(np.where(ink & ~after, col, w)[:, ::-1], axis=1)[:, ::-1]
    return first, last


def wall_line_gaps(
    thick: np.ndarray, wall_px: int, max_span_px: int, end_px: float | None = None
) -> np.ndarray:
    """(H, W) bool: the gaps in the rows of ``thick`` walls that continue a wall's line (see
    module doc, step 2); columns are the rows of the transpose.

    A gap pixel lies between two thick pixels at most ``max_span_px`` apart along its row, each
    in a band at most ``_BAND_SHARE`` wall thicknesses across that runs on along the row at
    least ``_END_SHARE`` of one, and the two bands are one line: their edges across the row
    agree to ``_ALIGN_SHARE`` of the thickness (a wall's two ends, not a wall and a fixture, a
    curved wall or a crossing wall). The gap pixels, 4-connected, are a rectangle about as thick
    as the wall across the row (within a factor ``_THICK_SLACK``).
    """
    band = np.asarray(thick, bool)
    h, w = band.shape
    top, bottom = (x.T for x in _run_bounds(band.T))
    along = np.zeros((h, w), np.int32)
    first, last = _run_bounds(band)
    along[band] = (last - first + 1)[band]
    across = np.where(band, bottom - top + 1, 0)
    end_px = _END_SHARE * wall_px if end_px is None else end_px
    wall_end = band & (across <= _BAND_SHARE * wall_px) & (along >= end_px)
    col = np.broadcast_to(np.arange(w, dtype=np.int32), (h, w))
    left = np.maximum.accumulate(np.where(band, col, -1), axis=1)
    right = np.minimum.accumulate(np.where(band, col, w)[:, ::-1], axis=1)[:, ::-1]
    span = right - left - 1
    inside = ~band & (left >= 0) & (right < w) & (span >= _MIN_SPAN_PX) & (span <= max_span_px)
    rows = np.broadcast_to(np.arange(h)[:, None], (h, w))[inside]
    a, b = left[inside], right[inside]
    tolerance = max(2.0, _ALIGN_SHARE * wall_px)
    aligned = (np.abs(top[rows, a] - top[rows, b]) <= tolerance) & (
        np.abs(bottom[rows, a] - bottom[rows, b]) <= tolerance
    )
    gap = np.zeros((h, w), bool)
    gap[inside] = wall_end[rows, a] & wall_end[rows, b] & aligned
    n, pieces = cv2.connectedComponents(gap.astype(np.uint8), connectivity=4)
    if n <= 1:
        return gap
    thickness, thickest = np.zeros(n), np.zeros(n)
    t_a, t_b, kept = across[rows, a], across[rows, b], gap[inside]
    np.maximum.at(thickness, pieces[gap], np.minimum(t_a, t_b)[kept])
    np.maximum.at(thickest, pieces[gap], np.maximum(t_a, t_b)[kept])
    boxes = ndimage.find_objects(pieces)
    height = np.array([0] + [box[0].stop - box[0].start for box in boxes])
    box_px = np.array([0] + [box[0].stop - box[0].start for box in boxes]) * np.array(
        [0] + [box[1].stop - box[1].start for box in boxes]
    )
    area = np.bincount(pieces.ravel(), minlength=n)
    # a rectangle as thick as the wall: the span of one wall's line, not a strip of a room
    keep = (height <= _THICK_SLACK * thickness + 2) & (height >= thickest / _THICK_SLACK - 1)
    keep &= area >= _FILL_SHARE * box_px
    keep[0] = False
    return keep[pieces]


def count_lines(profile: np.ndarray) -> int:
    """How many separate lines a darkness profile across a wall crosses [grey levels per px]:
    rises to at least ``FAINT_DEPTH``, a rise counting as a new line when the profile fell
    between it and the last line's peak to at most ``_VALLEY_SHARE`` of the shallower of the two
    (blurred lines a pixel apart still part)."""
    lines, peak, valley = 0, 0.0, 0.0
    for depth in map(float, profile):
        if depth >= FAINT_DEPTH and (lines == 0 or valley <= _VALLEY_SHARE * min(peak, depth)):
            lines, peak, valley = lines + 1, depth, depth
        elif depth > peak:
            peak = valley = depth
        else:
            valley = min(valley, depth)
    return lines


def _lined(pieces: np.ndarray, depth: np.ndarray) -> np.ndarray:
    """(H, W) bool: the pieces of ``pieces`` (gaps along rows) across which at least two
    separate lines run along the row (:func:`count_lines` of the median ``depth`` of each row
    over the piece's columns), the rows of lines on the wall's faces (up to ``_FACE_PX`` beyond
    the piece) with them."""
    out = np.zeros(pieces.shape, bool)
    h = pieces.shape[0]
    for k, box in enumerate(ndimage.find_objects(pieces), start=1):
        if box is None:
            continue
        r0, r1 = max(box[0].start - _FACE_PX, 0), min(box[0].stop + _FACE_PX, h)
        profile = np.median(depth[r0:r1, box[1]], axis=1)
        if count_lines(profile) < 2:
            continue
        out[box] |= pieces[box] == k
        rows = np.flatnonzero(profile >= FAINT_DEPTH) + r0
        face = rows[(rows < box[0].start) | (rows >= box[0].stop)]
        out[face, box[1]] = True
    return out


@dataclass(frozen=True)
class WallInserts:
    """What fills the gaps in a drawing's wall lines (:func:`find_wall_inserts`).

    Attributes:
        windows: (H, W) int32, 0 or ``k + 1`` on the k-th window insert.
        gaps: (H, W) bool, the other gaps at most a doorway long: paper (or a leaf, a threshold)
            between two ends of one wall's line, a door's place.
    """

    windows: np.ndarray
    gaps: np.ndarray


def find_wall_inserts(
    grey: np.ndarray,
    lines: np.ndarray,
    labels: np.ndarray,
    *,
    max_window_px: int,
    max_door_px: int,
) -> WallInserts:
    """The window inserts and door-wide gaps in a drawing's thick walls (module doc).

    Args:
        grey: (H, W) uint8 grey drawing, dark lines on light paper.
        lines: (H, W) bool, its walls' ink (furniture left out).
        labels: (H, W) the network's class ids (its walls give their thickness).
        max_window_px: longest window [px] (:func:`max_window_px`).
        max_door_px: longest gap kept as a door's place [px].
    """
    lines = np.asarray(lines, bool)
    windows = np.zeros(lines.shape, bool)
    gaps = np.zeros(lines.shape, bool)
    thick, wall_px = thick_walls(grey, lines, labels)
    max_span_px = max(max_window_px, max_door_px)
    if wall_px == 0 or max_span_px < _MIN_SPAN_PX:
        return WallInserts(windows.astype(np.int32), gaps)
    depth = ink_depth(grey)
    for transpose in (False, True):
        band = thick.T if transpose else thick
        along_line = wall_line_gaps(band, wall_px, max_span_px)
        pieces = cv2.connectedComponents(along_line.astype(np.uint8), connectivity=4)[1]
        lined = _lined(pieces, depth.T if transpose else depth)
        lengths = np.zeros(int(pieces.max()) + 1, int)
        for k, box in enumerate(ndimage.find_objects(pieces), start=1):
            lengths[k] = box[1].stop - box[1].start
        windows_here = lined & (lengths <= max_window_px)[pieces]
        door_wide = along_line & ~lined & (lengths <= max_door_px)[pieces]
        windows |= windows_here.T if transpose else windows_here
        gaps |= door_wide.T if transpose else door_wide
    thin, _ = thick_walls(grey, lines, labels, side_px=3)
    for transpose in (False, True):
        band = thin.T if transpose else thin
        along_line = wall_line_gaps(band, wall_px, max_door_px, end_px=3)
        gaps |= along_line.T if transpose else along_line
    windows_ids = cv2.connectedComponents(windows.astype(np.uint8), connectivity=4)[1]
    return WallInserts(windows_ids, gaps & ~windows)


def wall_piers(marks: np.ndarray, windows: np.ndarray) -> np.ndarray:
    """(H, W) bool: the pieces of free-standing ink ``marks`` (8-connected) touching a window of
    ``windows`` (labels): a piece of wall between two windows whose glazing the binarisation
    lost stands free, but it is wall."""
    marks = np.asarray(marks, bool)
    if not marks.any() or not windows.any():
        return np.zeros(marks.shape, bool)
    _, pieces = cv2.connectedComponents(marks.astype(np.uint8), connectivity=8)
    near = cv2.dilate((windows > 0).astype(np.uint8), np.ones((3, 3), np.uint8)) > 0
    touching = np.zeros(int(pieces.max()) + 1, bool)
    touching[pieces[near]] = True
    touching[0] = False
    return touching[pieces]
