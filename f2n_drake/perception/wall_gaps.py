"""Gaps in a drawing's walls: paper in a straight wall's line between a run's free end and more
wall, found along rows and columns (the candidates :mod:`~f2n_drake.perception.doorways` closes
as doorways, and the named-room priors close to cut rooms apart). See :func:`collinear_gaps`;
:func:`amid_cells` tells the candidates amid a lattice of ink (a cross-hatched terrace), which are
no gaps in a wall."""

from __future__ import annotations

import cv2
import numpy as np
from scipy import ndimage

from f2n_drake.perception.runs import row_runs, row_spans

CELL_SHARE = 0.1
"""Paper the ink encloses in less than this share of the square of the widest doorway is a
cell: of a cross-hatched floor, a tiled one, a fixture."""
LATTICE_CELLS = 12
"""A gap with only cells beside it and at least this many within a doorway's width around it
lies in a lattice of ink (a cross-hatched terrace), not in a wall."""


def _row_gaps(
    walls: np.ndarray, free_ends: np.ndarray, runs: np.ndarray, max_gap: int
) -> np.ndarray:
    """Paper pixels of each row lying between two ``walls`` pixels at most ``max_gap`` apart
    (exclusive), one in ``free_ends`` and the other in ``runs``."""
    h, w = walls.shape
    row, first, last = row_runs(~walls)  # the runs of paper
    gap = (first > 0) & (last < w - 1) & (last - first < max_gap)  # walls both sides, close
    row, left, right = row[gap], first[gap] - 1, last[gap] + 1  # and the wall pixels ending it
    ended = (free_ends[row, left] & runs[row, right]) | (free_ends[row, right] & runs[row, left])
    return row_spans((h, w), row[ended], left[ended] + 1, right[ended] - 1)


def collinear_gaps(walls: np.ndarray, *, max_gap_px: int, min_run_px: int) -> np.ndarray:
    """(H, W) bool: paper in the gaps of straight wall runs, along rows and columns.

    A gap must end on one side at the free end of a run: a wall pixel in a run at least
    ``min_run_px`` long along the gap's direction, not inside a wall that carries on at least
    half that far to both sides across it; and on the other in a run along either direction
    (a wall, not a door's leaf or a fixture's corner). A run that ends in a wall crossing it
    (the stem of a T) has no free end there, so no gap continues it across the next room; one
    ending in a corner does (a door beside the corner).

    Args:
        walls: (H, W) bool wall evidence.
        max_gap_px: widest gap to fill [px].
        min_run_px: shortest straight run of wall that a gap may end [px].
    """
    along_rows, along_cols = collinear_gaps_by_axis(
        walls, max_gap_px=max_gap_px, min_run_px=min_run_px
    )
    return along_rows | along_cols


def collinear_gaps_by_axis(
    walls: np.ndarray, *, max_gap_px: int, min_run_px: int
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`collinear_gaps` apart: the gaps found along rows (in walls running along the
    rows) and those found along columns, two (H, W) bool images."""
    walls = np.asarray(walls, bool)
    if max_gap_px < 1 or not walls.any():
        return np.zeros(walls.shape, bool), np.zeros(walls.shape, bool)
    wall_u8 = walls.astype(np.uint8)
    run = min_run_px | 1  # an odd kernel opens symmetrically: runs keep both their ends
    along_rows = cv2.morphologyEx(wall_u8, cv2.MORPH_OPEN, np.ones((1, run), np.uint8)) > 0
    along_cols = cv2.morphologyEx(wall_u8, cv2.MORPH_OPEN, np.ones((run, 1), np.uint8)) > 0
    runs = along_rows | along_cols
    free_ends = along_rows & ~_through(wall_u8, min_run_px // 2, 0)
    row_gaps = _row_gaps(walls, free_ends, runs, max_gap_px)
    free_ends = along_cols & ~_through(wall_u8, min_run_px // 2, 1)
    return row_gaps, _row_gaps(walls.T, free_ends.T, runs.T, max_gap_px).T


def _through(walls: np.ndarray, reach_px: int, axis: int) -> np.ndarray:
    """(H, W) bool: wall pixels from which wall runs on ``reach_px`` px or more to both sides
    along ``axis`` (0: up and down; 1: left and right), inside a wall that carries on past."""
    shape = (reach_px, 1) if axis == 0 else (1, reach_px)
    kernel = np.ones(shape, np.uint8)
    last = (0, reach_px - 1) if axis == 0 else (reach_px - 1, 0)  # anchor (x, y)
    before = cv2.erode(walls, kernel, anchor=last, borderValue=0) > 0
    after = cv2.erode(walls, kernel, anchor=(0, 0), borderValue=0) > 0
    return before & after


def gap_pieces(
    walls: np.ndarray,
    ink: np.ndarray,
    max_gap_px: int,
    min_run_px: int,
    wall_gaps: np.ndarray | None,
    wide_wall_gaps: np.ndarray | None = None,
) -> tuple[int, np.ndarray, int, np.ndarray]:
    """The candidate gaps, one piece per gap: (count + 1, (H, W) int32 labels, 0 none, the
    first row piece's label: pieces below it run along columns, and per label whether the
    piece is a wide gap).

    The collinear gaps of ``walls`` and the ``wall_gaps`` (a 4-connected piece of them runs
    along its bounding box's longer side) are pieces apart along rows and along columns,
    4-connected, so that two gaps meeting at a corner, or a door's gap and the gap beside its
    leaf, are two candidates, each a strip across one wall; a pixel in both takes the column's.
    The ``wide_wall_gaps`` (longer than a doorway) are pieces too, wide gaps, kept a pixel apart
    from the others so that no gap a doorway wide grows into a wide one.
    """
    along_rows, along_cols = collinear_gaps_by_axis(
        walls, max_gap_px=max_gap_px, min_run_px=min_run_px
    )
    line_rows, line_cols = _by_axis(wall_gaps, ink)
    narrow = ((along_rows | line_rows) & ~ink, (along_cols | line_cols) & ~ink)
    near = cv2.dilate((narrow[0] | narrow[1]).astype(np.uint8), np.ones((3, 3), np.uint8)) > 0
    wide = _by_axis(wide_wall_gaps, ink | near)
    pieces = np.zeros(ink.shape, np.int32)
    is_wide = [False]
    n_cols = 1
    for axis in (1, 0):  # columns first; a pixel in both is the column's
        for gaps, flag in ((narrow[axis], False), (wide[axis], True)):
            if axis == 0:
                gaps = gaps & ~narrow[1] & ~wide[1]
            n, labels = cv2.connectedComponents(gaps.astype(np.uint8), connectivity=4)
            pieces = np.where(labels > 0, labels + len(is_wide) - 1, pieces).astype(np.int32)
            is_wide += [flag] * (n - 1)
        if axis == 1:
            n_cols = len(is_wide)
    return len(is_wide), pieces, n_cols, np.array(is_wide)


def _by_axis(line_gaps: np.ndarray | None, ink: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The paper of ``line_gaps`` off the ``ink``, each 4-connected piece along rows or along
    columns as its bounding box is wide or tall: two (H, W) bool images."""
    rows, cols = np.zeros(ink.shape, bool), np.zeros(ink.shape, bool)
    if line_gaps is None or not line_gaps.any():
        return rows, cols
    n, line_pieces = cv2.connectedComponents((line_gaps & ~ink).astype(np.uint8), 4)
    boxes = ndimage.find_objects(line_pieces)
    lying = np.array([False] + [b[1].stop - b[1].start >= b[0].stop - b[0].start for b in boxes])
    rows = (line_pieces > 0) & lying[line_pieces]
    cols = (line_pieces > 0) & ~lying[line_pieces]
    return rows, cols


def amid_cells(
    pieces: np.ndarray,
    group: np.ndarray,
    before: np.ndarray,
    ink: np.ndarray,
    boxes: list[tuple[slice, slice]],
    max_gap_px: int,
) -> np.ndarray:
    """Per piece, True when it and the pieces grouped with it have only cells (paper regions of
    ``before``, the ink's own, under ``CELL_SHARE`` of ``max_gap_px`` squared) beside them, and
    ``LATTICE_CELLS`` cells lie within ``max_gap_px`` of its centre: a gap in the lattice of a
    cross-hatched floor. A door's box or a window's lines enclose a cell or two, a tiled room's
    grid many, but a doorway into it has the paper of the room beyond on its other side.

    Args:
        pieces: (H, W) int32 candidate gap pieces (:func:`gap_pieces`, more labels after them
            allowed), 0 elsewhere.
        group: per label of ``pieces``, the label of the group it is judged with.
        before: (H, W) int32 the paper regions the ink alone leaves (4-connected), 0 on the ink.
        ink: (H, W) bool, the drawing's lines.
        boxes: bounding box of each label of ``pieces`` (label k at index k - 1).
        max_gap_px: widest gap closed as a doorway [px].
    """
    area = np.bincount(before.ravel())
    min_room = CELL_SHARE * max_gap_px**2
    near = ndimage.grey_dilation(pieces, size=(3, 3))
    ring = (near > 0) & (pieces == 0) & ~ink
    largest_beside = np.zeros(group.size, np.int64)
    np.maximum.at(largest_beside, near[ring], area[before[ring]])
    largest_in_group = np.zeros(group.size, np.int64)
    np.maximum.at(largest_in_group, group, largest_beside)
    amid = largest_in_group[group] < min_room
    amid[0] = False
    if not amid.any():
        return amid
    cells = np.flatnonzero(area < min_room)
    cells = cells[cells > 0]  # label 0 is the ink
    rows, cols = np.indices(ink.shape, sparse=True)
    labels = before.ravel()
    centre_rows = np.bincount(labels, np.broadcast_to(rows, ink.shape).ravel())[cells] / area[cells]
    centre_cols = np.bincount(labels, np.broadcast_to(cols, ink.shape).ravel())[cells] / area[cells]
    seeds = np.zeros(ink.shape, np.float32)
    np.add.at(seeds, (centre_rows.astype(int), centre_cols.astype(int)), 1.0)
    side = max(3, max_gap_px) | 1
    count = cv2.boxFilter(seeds, -1, (side, side), normalize=False)
    for k in np.flatnonzero(amid):
        box = boxes[k - 1]
        centre = ((box[0].start + box[0].stop) // 2, (box[1].start + box[1].stop) // 2)
        amid[k] = count[centre] >= LATTICE_CELLS
    return amid
