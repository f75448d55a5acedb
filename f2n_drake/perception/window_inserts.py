"""Windows drawn in a wall's line: thin parallel lines spanning a gap in a thick wall.

Real drawings draw a wall as a thick stroke (or a solid black band) and a window as an insert in
its line: the thick ink stops, two or three thin lines (the glass, the sill, the wall's faces
carried on) run along the wall across the opening, and the thick ink starts again. The thin lines
are often light grey and lost when the drawing is binarised, so the window reads as a plain gap
and the room behind it leaks to the outside. This module finds those inserts on the ink
(:func:`find_wall_inserts`):

1. **Wall bands** (:func:`wall_bands`): the ink at least half as dark as the drawing's ink; the
   walls' thickness ``t`` is the median stroke width (the shorter of a pixel's row and column
   run, :func:`~f2n_drake.perception.runs.stroke_widths_px`) of that ink where the network
   labels wall. Thick walls are the ink a square ``t / 2`` wide fits in, wall bands the ink a
   ``_MIN_THICK_PX`` square fits in (thin walls too; thin lines are neither).
2. **Gaps in a wall's line** (:func:`wall_line_gaps`): along each row (column), the paper
   between two runs of band at most ``max_span_px`` apart, both the end of a wall running along
   the row (at most ``_BAND_SHARE`` walls thick across, at least ``_END_SHARE`` of one long),
   their edges across the row in line to ``_ALIGN_SHARE`` of a wall, and a row beside it with
   the same span (a wall's ragged edge runs on to another wall's); the gap's pixels,
   4-connected, a rectangle about as thick as the wall.
3. **Thin lines along it**: in a gap of the thick walls, the darkness profile across the wall
   (the median depth below the local paper, :func:`ink_depth`, of each row of the gap, with the
   lines on the wall's faces touching it) crosses at least two separate lines
   (:func:`count_lines`): parallel lines spanning the wall.

4. **Or the network's word for it**: a gap of the thick walls the network labels door, window or
   front door on at least ``_SEEN_SHARE`` of its pixels (ink or paper), window the most: a
   window drawn as a grey fill, or with lines the binarisation merged. A gap it sees as a door
   stays a door's place, whose swing the doorways find.

Each such span is a window insert: a connector instance the size of the wall's opening (the
strip between the wall's two faces across the gap, its lines included; a line crossing it from
face to face, a mullion, parts two lights, each its own window when both are a wall thick long;
mullions are looked for on the drawing's darkness, as a thin window's lines binarise to one band),
a boundary for the ground robot's rooms as a wall is, and a connector for the drone; or, where
the network labels it door or front door more than window, a door (a box in a thick wall: its
two long sides are two lines too; their thickness, the pen of the door's jambs, is
``WallInserts.door_face_px``, for the scale: :func:`~f2n_drake.perception.scale.jamb_line_px`).
The other gaps of both kinds of band at most ``max_door_px`` long are a door's place
(``WallInserts.gaps``), tried by :func:`~f2n_drake.perception.doorways.find_doorways`; given
``max_wide_door_px``, those longer, up to it, and a pixel off the others, are a wide door's place
(``WallInserts.wide_gaps``: a double door, a closet's front).

Walls drawn at an angle (a bay window's cheeks, a facade set at 45 degrees) are scanned too: for
each direction of straight thick wall off the rows and columns
(:func:`~f2n_drake.perception.wall_angles.oblique_wall_angles`), the drawing is turned until
those walls run along its rows, the same steps find their window inserts, and these are turned
back onto the drawing (grown a pixel to meet their walls again). Only windows come back that
way; a door's place in such a wall is left to the doorways step and the network.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
from scipy import ndimage

from f2n_drake.core.classes import CLASS_ID
from f2n_drake.perception.runs import row_runs, row_spans, stroke_widths_px
from f2n_drake.perception.wall_angles import oblique_wall_angles, turned, turned_back

_WALL = CLASS_ID["wall"]
_INSERT_IDS = np.array([CLASS_ID[name] for name in ("window", "door", "front_door")])
_WINDOW = CLASS_ID["window"]
MAX_WINDOW_M = 3.0
"""Longest window insert when the scale is known [m]."""
MAX_WINDOW_SHARE = 0.4
"""Longest window insert when the scale is unknown, as a share of the wall ink's extent."""
_BAND_SHARE = 2.0  # a wall's end is a band at most this many wall thicknesses across
_END_SHARE = 0.75  # and runs on along the line at least this many wall thicknesses
_ALIGN_SHARE = 0.25  # a gap's two ends are one wall's line: edges this share of its thickness apart
_MULLION_SHARE = 0.9  # a line across a window insert on this share of its depth parts two lights
_THICK_SLACK = 1.5  # a gap is at most this many times its ends' thickness across, plus 2 px
_FILL_SHARE = 0.7  # and fills at least this share of its bounding box (a rectangle)
_SEEN_SHARE = 0.5  # a gap the network labels a connector on this share of its pixels is one
_VALLEY_SHARE = 0.6  # two lines part where the darkness between them falls to this share
FAINT_DEPTH = 12
"""Grey levels below the local paper that make faint ink."""
_PAPER_WINDOW_PX = 9  # window of the local paper level (a closing of the grey image) [px]
_MIN_THICK_PX = 3  # the thinnest stroke that can be a wall [px]
_MIN_SPAN_PX = 3  # shorter gaps are a wall's ragged edge
_FACE_PX = 2  # a window's lines on the wall's faces lie at most this far beyond its gap [px]
_SEAL = np.ones((3, 3), np.uint8)  # a turned-back window is grown this much to meet its walls


def wall_bands(
    grey: np.ndarray, lines: np.ndarray, labels: np.ndarray
) -> tuple[np.ndarray, np.ndarray, int]:
    """The thick walls and every wall band of a drawing, and the walls' typical thickness [px]
    (see module doc); no pixels and 0 when the network labels no wall on the ink.

    The ink is the ``lines`` at least half as dark as the drawing's ink is from its paper (light
    grey glazing lines the binarisation joined into a band part again); the walls' thickness is
    the median stroke width (:func:`~f2n_drake.perception.runs.stroke_widths_px`) of that ink
    where the network labels wall. The thick walls are the ink a square half that wide (at least
    ``_MIN_THICK_PX``) fits in, the bands the ink a ``_MIN_THICK_PX`` square fits in (thin walls
    too, no lines).
    """
    lines = np.asarray(lines, bool)
    none = np.zeros(lines.shape, bool)
    if not lines.any() or lines.all():
        return none, none, 0
    paper, ink = float(np.median(grey[~lines])), float(np.median(grey[lines]))
    dark = (lines & (grey <= (paper + ink) / 2)).astype(np.uint8)
    on_walls = stroke_widths_px(dark > 0)[(dark > 0) & (labels == _WALL)]
    if on_walls.size == 0:
        return none, none, 0
    wall_px = int(np.median(on_walls))
    side = max(int(np.ceil(wall_px / 2)), _MIN_THICK_PX) | 1  # odd: opens in place
    if wall_px < side:
        return none, none, 0
    thick = cv2.morphologyEx(dark, cv2.MORPH_OPEN, np.ones((side, side), np.uint8)) > 0
    square = np.ones((_MIN_THICK_PX, _MIN_THICK_PX), np.uint8)
    return thick, cv2.morphologyEx(dark, cv2.MORPH_OPEN, square) > 0, wall_px


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


def wall_line_gaps(
    thick: np.ndarray, wall_px: int, max_span_px: int, end_px: float | None = None
) -> np.ndarray:
    """(H, W) bool: the gaps in the rows of ``thick`` walls that continue a wall's line (see
    module doc, step 2); columns are the rows of the transpose.

    A gap is the paper of a row between two runs of thick wall at most ``max_span_px`` apart,
    each in a band at most ``_BAND_SHARE`` wall thicknesses across and at least ``end_px``
    long (default ``_END_SHARE`` of a wall thickness), the two bands one line: their edges
    across the row agree to ``_ALIGN_SHARE`` of the thickness (a wall's two ends, not a wall
    and a fixture, a curved wall or a crossing wall). The gap pixels, 4-connected, are a
    rectangle about as thick as the wall across the row (within a factor ``_THICK_SLACK``).
    Computed on the runs of the rows and columns, not per pixel.
    """
    band = np.asarray(thick, bool)
    h, w = band.shape
    gap = np.zeros((h, w), bool)
    row, first, last = row_runs(band)
    pair = np.flatnonzero(row[1:] == row[:-1])  # run k and run k + 1 share a row
    r, a, b = row[pair], last[pair], first[pair + 1]
    span = b - a - 1
    end_px = _END_SHARE * wall_px if end_px is None else end_px
    ok = (span >= _MIN_SPAN_PX) & (span <= max_span_px)
    ok &= (last[pair] - first[pair] + 1 >= end_px) & (
        last[pair + 1] - first[pair + 1] + 1 >= end_px
    )
    r, a, b = r[ok], a[ok], b[ok]
    if r.size == 0:
        return gap
    col, top, bottom = row_runs(np.ascontiguousarray(band.T))  # the columns' runs
    keys = col * h + top
    top_a, bottom_a = (x[np.searchsorted(keys, a * h + r, "right") - 1] for x in (top, bottom))
    top_b, bottom_b = (x[np.searchsorted(keys, b * h + r, "right") - 1] for x in (top, bottom))
    t_a, t_b = bottom_a - top_a + 1, bottom_b - top_b + 1
    tolerance = max(2.0, _ALIGN_SHARE * wall_px)
    ok = np.maximum(t_a, t_b) <= _BAND_SHARE * wall_px
    ok &= (np.abs(top_a - top_b) <= tolerance) & (np.abs(bottom_a - bottom_b) <= tolerance)
    r, a, b, t_a, t_b = r[ok], a[ok], b[ok], t_a[ok], t_b[ok]
    # a row whose span the rows beside it do not share (a wall's ragged edge reaching on to
    # the next wall's) would join the gap to a strip of another
    ok = _shared_with_a_neighbour(r, a, b, w, tolerance)
    r, a, b, t_a, t_b = r[ok], a[ok], b[ok], t_a[ok], t_b[ok]
    if r.size == 0:
        return gap
    gap = row_spans((h, w), r, a + 1, b - 1)
    n, pieces = cv2.connectedComponents(gap.astype(np.uint8), connectivity=4)
    piece = pieces[r, a + 1]
    thickness, thickest = np.zeros(n), np.zeros(n)
    np.maximum.at(thickness, piece, np.minimum(t_a, t_b))
    np.maximum.at(thickest, piece, np.maximum(t_a, t_b))
    lo, hi = np.full(n, h), np.zeros(n, int)
    left, right = np.full(n, w), np.zeros(n, int)
    np.minimum.at(lo, piece, r)
    np.maximum.at(hi, piece, r)
    np.minimum.at(left, piece, a + 1)
    np.maximum.at(right, piece, b - 1)
    area = np.bincount(piece, weights=b - a - 1, minlength=n)
    height = hi - lo + 1
    box_px = height * (right - left + 1)
    # a rectangle as thick as the wall: the span of one wall's line, not a strip of a room
    keep = (height <= _THICK_SLACK * thickness + 2) & (height >= thickest / _THICK_SLACK - 1)
    keep &= area >= _FILL_SHARE * box_px
    keep[0] = False
    return keep[pieces]


def _shared_with_a_neighbour(
    r: np.ndarray, a: np.ndarray, b: np.ndarray, w: int, tolerance: float
) -> np.ndarray:
    """Per span (row ``r``, ends ``a`` < ``b``; sorted by row, then column; rows ``w`` wide),
    whether the row above or below has a span with both ends within ``tolerance`` of its own."""
    keys = r.astype(np.int64) * w + a
    shared = np.zeros(r.size, bool)
    if r.size == 0:
        return shared
    for step in (-1, 1):
        j = np.searchsorted(keys, (r.astype(np.int64) + step) * w + a - tolerance)
        j = np.minimum(j, r.size - 1)
        near = (r[j] == r + step) & (np.abs(a[j] - a) <= tolerance)
        shared |= near & (np.abs(b[j] - b) <= tolerance)
    return shared


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


def _lined(pieces: np.ndarray, depth: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(H, W) bool: the pieces of ``pieces`` (gaps along rows) across which at least two
    separate lines run along the row (:func:`count_lines` of the median ``depth`` of each row
    over the piece's columns), with the lines on the wall's faces (rows of ink touching the
    piece, up to ``_FACE_PX`` beyond it); and the length of each piece along the row [px]."""
    out = np.zeros(pieces.shape, bool)
    boxes = ndimage.find_objects(pieces)
    lengths = np.array([0] + [box[1].stop - box[1].start for box in boxes], int)
    h = pieces.shape[0]
    for k, box in enumerate(boxes, start=1):
        r0, r1 = max(box[0].start - _FACE_PX, 0), min(box[0].stop + _FACE_PX, h)
        profile = np.median(depth[r0:r1, box[1]], axis=1)
        deep = profile >= FAINT_DEPTH
        top, bottom = box[0].start - r0, box[0].stop - r0  # the piece's rows in the profile
        while top > 0 and deep[top - 1]:  # lines on the wall's faces, touching the piece
            top -= 1
        while bottom < deep.size and deep[bottom]:
            bottom += 1
        if count_lines(profile[top:bottom]) < 2:
            continue
        out[box] |= pieces[box] == k
        out[r0 + top : box[0].start, box[1]] = True
        out[box[0].stop : r0 + bottom, box[1]] = True
    return out, lengths


@dataclass(frozen=True)
class WallInserts:
    """What fills the gaps in a drawing's wall lines (:func:`find_wall_inserts`).

    Attributes:
        windows: (H, W) int32, 0 or ``k + 1`` on the k-th window insert.
        classes: (K,) class id of each insert: window, or door or front door where the network
            labels it that more than window.
        gaps: (H, W) bool, the other gaps at most a doorway long: paper (or a leaf, a threshold)
            between two ends of one wall's line, a door's place.
        wide_gaps: (H, W) bool, such gaps longer than a doorway, up to ``max_wide_door_px``
            (a double door's or a closet front's place, if a door is drawn there).
        wall_px: the walls' typical thickness [px] (:func:`wall_bands`; 0: no walls found).
        door_face_px: the median thickness of the lines along the sides of the door inserts
            (:func:`face_lines_px`; 0: none), drawn with the pen of their jambs.
    """

    windows: np.ndarray
    classes: np.ndarray
    gaps: np.ndarray
    wall_px: int = 0
    door_face_px: float = 0.0
    wide_gaps: np.ndarray | None = None


def find_wall_inserts(
    grey: np.ndarray,
    lines: np.ndarray,
    labels: np.ndarray,
    *,
    max_window_px: int,
    max_door_px: int,
    max_wide_door_px: int = 0,
) -> WallInserts:
    """The window inserts and door-wide gaps in a drawing's thick walls (module doc).

    Args:
        grey: (H, W) uint8 grey drawing, dark lines on light paper.
        lines: (H, W) bool, its walls' ink (furniture left out).
        labels: (H, W) the network's class ids (its walls give their thickness).
        max_window_px: longest window [px] (:func:`max_window_px`).
        max_door_px: longest gap kept as a door's place [px].
        max_wide_door_px: longest gap kept as a wide door's place [px] (0: none).
    """
    lines = np.asarray(lines, bool)
    windows = np.zeros(lines.shape, bool)
    gaps = np.zeros(lines.shape, bool)
    thick, bands, wall_px = wall_bands(grey, lines, labels)
    max_span_px = max(max_window_px, max_door_px)
    if wall_px == 0 or max_span_px < _MIN_SPAN_PX:
        return WallInserts(windows.astype(np.int32), np.zeros(0, int), gaps)
    depth = ink_depth(grey)
    spans = (wall_px, max_window_px, max_door_px)
    windows, gaps = _inserts_along_axes(thick, bands, depth, labels, *spans)
    wide_gaps = None
    if max_wide_door_px > max_door_px:
        wide_spans = (wall_px, max_window_px, max_wide_door_px)
        _, wide_gaps = _inserts_along_axes(thick, bands, depth, labels, *wide_spans)
        near = cv2.dilate((gaps | windows).astype(np.uint8), np.ones((3, 3), np.uint8)) > 0
        wide_gaps &= ~near
    for angle in oblique_wall_angles(thick, wall_px):  # walls drawn at an angle: turned
        turned_arrays = [turned(image, angle) for image in (thick, bands, depth, labels)]
        more, _ = _inserts_along_axes(*turned_arrays, *spans)
        more = cv2.dilate(turned_back(more, angle, lines.shape).astype(np.uint8), _SEAL) > 0
        windows |= more & ~thick & ~windows & ~gaps
    windows_ids = cv2.connectedComponents(windows.astype(np.uint8), connectivity=4)[1]
    lit = _insert_classes(windows_ids, labels) == _WINDOW
    # mullions on the drawing's darkness: a thin window's lines binarise to one band of ink
    windows_ids = _split_at_mullions(windows_ids, lit, depth >= FAINT_DEPTH, wall_px)
    classes = _insert_classes(windows_ids, labels)
    faces = [
        face_lines_px(windows_ids[box] == k, lines[box])
        for k, box in enumerate(ndimage.find_objects(windows_ids), start=1)
        if box is not None and classes[k - 1] != _INSERT_IDS[0]
    ]
    faces = [f for f in faces if f > 0]
    face_px = float(np.median(faces)) if faces else 0.0
    return WallInserts(windows_ids, classes, gaps & ~windows, wall_px, face_px, wide_gaps)


def _inserts_along_axes(
    thick: np.ndarray,
    bands: np.ndarray,
    depth: np.ndarray,
    labels: np.ndarray,
    wall_px: int,
    max_window_px: int,
    max_door_px: int,
) -> tuple[np.ndarray, np.ndarray]:
    """(windows, gaps): the window inserts and door-wide gaps of the walls running along the
    rows and the columns (bool, no insert told from the next)."""
    windows = np.zeros(thick.shape, bool)
    gaps = np.zeros(thick.shape, bool)
    max_span_px = max(max_window_px, max_door_px)
    for transpose in (False, True):
        flip = np.transpose if transpose else np.asarray
        along_line = wall_line_gaps(np.ascontiguousarray(flip(thick)), wall_px, max_span_px)
        pieces = cv2.connectedComponents(along_line.astype(np.uint8), connectivity=4)[1]
        lined, lengths = _lined(pieces, np.ascontiguousarray(flip(depth)))
        seen = _seen_window(pieces, np.ascontiguousarray(flip(labels)))
        windows |= flip((lined | seen) & (lengths <= max_window_px)[pieces])
        gaps |= flip(along_line & ~lined & ~seen & (lengths <= max_door_px)[pieces])
        # gaps in thin walls too (no windows: too thin to hold lines apart)
        thin_gaps = wall_line_gaps(
            np.ascontiguousarray(flip(bands)), wall_px, max_door_px, end_px=_MIN_THICK_PX
        )
        gaps |= flip(thin_gaps)
    return windows, gaps


def _insert_classes(windows_ids: np.ndarray, labels: np.ndarray) -> np.ndarray:
    """Class id per insert of ``windows_ids`` (0 or ``k + 1``): the network's majority among
    window, door and front door on it (ties: the window)."""
    n = int(windows_ids.max()) + 1
    votes = np.stack([np.bincount(windows_ids[labels == c], minlength=n) for c in _INSERT_IDS])
    return _INSERT_IDS[np.argmax(votes[:, 1:], axis=0)]


def _split_at_mullions(
    windows_ids: np.ndarray, windows: np.ndarray, lines: np.ndarray, wall_px: int
) -> np.ndarray:
    """``windows_ids`` (0 or ``k + 1`` per insert) with each insert ``windows[k]`` marks a
    window cut where a line of ``lines`` (the drawing's ink, down to its faint lines) crosses it
    from one face of the wall to the other (a mullion between two lights), when every part is at
    least a wall thick long."""
    out = np.zeros_like(windows_ids)
    count = 0
    for k, box in enumerate(ndimage.find_objects(windows_ids), start=1):
        if box is None:
            continue
        mask = windows_ids[box] == k
        ink = lines[box]
        along_rows = mask.shape[1] >= mask.shape[0]  # the insert runs along the rows
        m, i = (mask, ink) if along_rows else (mask.T, ink.T)
        depth = m.sum(axis=0)
        crossing = (depth > 0) & ((m & i).sum(axis=0) >= np.maximum(depth, 1) * _MULLION_SHARE)
        cut = m & ~crossing[None, :]
        n, parts = cv2.connectedComponents(cut.astype(np.uint8), connectivity=4)
        lengths = [np.flatnonzero((parts == j).any(axis=0)).size for j in range(1, n)]
        if not windows[k - 1] or n <= 2 or min(lengths) < wall_px:
            parts, n = m.astype(np.int32), 2  # one light, or lights too short to be windows
        else:
            # a mullion's own columns go to the light before it (the first light: after it)
            light = parts.max(axis=0)
            seen = np.flatnonzero(light)
            before = seen[
                np.clip(np.searchsorted(seen, np.arange(light.size), "right") - 1, 0, None)
            ]
            parts = np.where(m, light[before][None, :], 0)
        parts = parts if along_rows else parts.T
        sub = out[box]
        sub[parts > 0] = parts[parts > 0] + count
        count += n - 1
    return out


def _seen_window(pieces: np.ndarray, labels: np.ndarray) -> np.ndarray:
    """(H, W) bool: the pieces of ``pieces`` (labels, 0 none) the network labels door, window
    or front door on at least ``_SEEN_SHARE`` of their pixels, ink or paper, window the most (a
    window drawn as a grey fill, or with lines the binarisation merged). A gap it sees as a door
    stays a door's place: the doorways take its swing too."""
    n = int(pieces.max()) + 1
    size = np.bincount(pieces.ravel(), minlength=n)
    votes = np.stack([np.bincount(pieces[labels == c], minlength=n) for c in _INSERT_IDS])
    seen = votes.sum(axis=0) >= _SEEN_SHARE * np.maximum(size, 1)
    seen &= votes[0] >= votes[1:].sum(axis=0)
    seen[0] = False
    return seen[pieces]


def face_lines_px(insert: np.ndarray, ink: np.ndarray) -> float:
    """Thickness of the lines along the two long sides of an insert [px] (``insert``, a crop of
    one insert; ``ink``, the crop's ink): the mean count of its rows (columns, when it is taller
    than wide) from either side inwards in which at least half its pixels are ink; 0 when a side
    has none, or the ink fills it (no paper between the lines)."""
    if insert.shape[0] > insert.shape[1]:
        insert, ink = insert.T, ink.T
    size = insert.sum(axis=1)
    inked = ((insert & ink).sum(axis=1) >= 0.5 * size) & (size > 0)
    rows = np.flatnonzero(size > 0)
    inked = inked[rows[0] : rows[-1] + 1]
    if inked.all():
        return 0.0
    first, last = int(np.argmin(inked)), int(np.argmin(inked[::-1]))
    return (first + last) / 2 if first and last else 0.0


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
