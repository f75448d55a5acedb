"""The plans on a sheet: what surrounds them (legends, title blocks, compass roses, scale bars,
notes) is left out before the drawing is parsed.

A plan is a structure of walls on the sheet: its ink, less the annotations
(:func:`~f2n_drake.perception.ink.free_marks`: words, numbers, symbols, a sheet's frame), is
grouped into pieces that touch or nearly touch (``JOIN_SHARE`` of the ink's extent: a balcony
or an annex drawn beside the walls stays with them). Each group is scored by its walls: its ink
in straight runs (``RUN_SHARE`` of the extent long at least), less solid areas (a title bar),
less the annotation ink within its box (a legend's words). The best group is the plan; its box
grows by the groups reaching into it. Other groups scoring at least ``OTHER_PLAN_SHARE`` of the
best one, lying apart from it and with walls inside their outline (``INNER_WALL_SHARE``), are
further plans on the same sheet (the floors of a house drawn side by side): the box grows to
hold them too, so every plan is parsed, and they are counted, so the user is told. The box is
widened by ``MARGIN_SHARE``; the ink lying wholly outside it, or round it on every side (a
frame), is painted over in the paper's grey. A drawing with nothing outside its plans comes back
unchanged.
"""

from __future__ import annotations

import dataclasses
import logging
from dataclasses import dataclass

import cv2
import numpy as np
from scipy import ndimage

from f2n_drake.perception.ink import free_marks

log = logging.getLogger(__name__)

JOIN_SHARE = 0.05
"""Ink pieces this close (share of the ink's extent) are one group."""
MARGIN_SHARE = 0.03
"""Paper kept round the plan's box, as a share of its long side."""
RUN_SHARE = 0.03
"""Wall ink lies in straight runs at least this long (share of the ink's extent)."""
OTHER_PLAN_SHARE = 0.3
"""A group with at least this share of the plan's wall ink, apart from it, is another plan ..."""
INNER_WALL_SHARE = 0.15
"""... when at least this share of its wall ink lies inside its outline (a frame round a legend
or a box of notes has none there; the floors of R3D's listings 0.3-0.65)."""
RIM_SHARE = 0.05
"""Width of an outline's rim, as a share of its box's short side."""


@dataclass(frozen=True)
class PlanOnSheet:
    """Where the plan lies on its sheet (:func:`find_plan`).

    Attributes:
        box: (row0, row1, col0, col1) of the plan with its margin [px].
        plans: how many plans the sheet holds (1 when only one was found); ``box`` holds them
            all.
        left_out: whether ink outside ``box`` was left out.
    """

    box: tuple[int, int, int, int]
    plans: int = 1
    left_out: bool = False

    def describe(self) -> str:
        """One line for the user: which part of the sheet was parsed."""
        r0, r1, c0, c1 = self.box
        where = f"rows {r0}-{r1}, columns {c0}-{c1}"
        if self.plans > 1:
            return (
                f"the sheet holds {self.plans} plans, parsed together ({where}); rooms on one "
                "cannot be reached from another"
            )
        if self.left_out:
            return f"parsed the plan at {where}; what lies outside it (legends, notes) was left out"
        return f"parsed the whole drawing ({where})"


def _wall_ink(structure: np.ndarray, run_px: int) -> np.ndarray:
    """The ink of ``structure`` in straight runs at least ``run_px`` long, along rows or columns,
    less solid areas (a title bar, a filled panel: as wide as a run both ways)."""
    ink = structure.astype(np.uint8)
    runs = cv2.morphologyEx(ink, cv2.MORPH_OPEN, np.ones((1, run_px), np.uint8))
    runs |= cv2.morphologyEx(ink, cv2.MORPH_OPEN, np.ones((run_px, 1), np.uint8))
    solid = cv2.morphologyEx(ink, cv2.MORPH_OPEN, np.ones((run_px, run_px), np.uint8))
    return (runs > 0) & ~(solid > 0)


def find_plan(lines: np.ndarray) -> PlanOnSheet:
    """The plan on a binarised sheet (see module doc); the whole sheet when it has no ink."""
    lines = np.asarray(lines, bool)
    height, width = lines.shape
    whole = PlanOnSheet((0, height, 0, width))
    rows, cols = np.nonzero(lines)
    if rows.size == 0:
        return whole
    marks = free_marks(lines)
    structure = lines & ~marks.annotation
    if not structure.any():
        return whole
    extent = max(rows.max() - rows.min(), cols.max() - cols.min()) + 1
    join = max(3, int(round(JOIN_SHARE * extent)))
    grouped = cv2.dilate(structure.astype(np.uint8), np.ones((join, join), np.uint8))
    n, groups = cv2.connectedComponents(grouped, connectivity=8)
    boxes = ndimage.find_objects(groups)
    walls = _wall_ink(structure, max(3, int(round(RUN_SHARE * extent))))
    scores = np.bincount(groups[walls], minlength=n)
    for k, box in enumerate(boxes, start=1):  # a legend's or a title block's words count against
        scores[k] -= np.count_nonzero(marks.annotation[box])
    scores[0] = 0
    best = int(np.argmax(scores))
    if scores[best] == 0:
        return whole
    rs, cs = boxes[best - 1]
    pad = max(4, int(round(MARGIN_SHARE * max(rs.stop - rs.start, cs.stop - cs.start))))
    box = (rs.start, rs.stop, cs.start, cs.stop)
    member = np.zeros(n, bool)
    member[best] = True
    while True:  # groups reaching into the plan's box are parts of it (a broken outline)
        r0, r1, c0, c1 = box[0] - pad, box[1] + pad, box[2] - pad, box[3] + pad
        reach = np.array(
            [False]
            + [
                b[0].start < r1 and b[0].stop > r0 and b[1].start < c1 and b[1].stop > c0
                for b in boxes
            ]
        )
        grown = member | reach
        if np.array_equal(grown, member):
            break
        member = grown
        ks = np.flatnonzero(member)
        box = (
            min(boxes[k - 1][0].start for k in ks),
            max(boxes[k - 1][0].stop for k in ks),
            min(boxes[k - 1][1].start for k in ks),
            max(boxes[k - 1][1].stop for k in ks),
        )
    others = [
        k
        for k in np.flatnonzero(~member[1:]) + 1
        if scores[k] >= OTHER_PLAN_SHARE * scores[best]
        and _inner_share(walls[boxes[k - 1]] & (groups[boxes[k - 1]] == k)) >= INNER_WALL_SHARE
    ]
    for k in others:  # every plan on the sheet is parsed: the box holds them all
        rs, cs = boxes[k - 1]
        box = (
            min(box[0], rs.start),
            max(box[1], rs.stop),
            min(box[2], cs.start),
            max(box[3], cs.stop),
        )
    box = _with_pieces_reaching_in(lines, box)
    box = (
        max(box[0] - pad, 0),
        min(box[1] + pad, height),
        max(box[2] - pad, 0),
        min(box[3] + pad, width),
    )
    r0, r1, c0, c1 = box
    inside = np.zeros(lines.shape, bool)
    inside[r0:r1, c0:c1] = True
    return PlanOnSheet(box, 1 + len(others), bool((lines & ~inside).any()))


def _inner_share(walls: np.ndarray) -> float:
    """Share of ``walls`` (one group's wall ink) lying off the rim of its box, farther than
    ``RIM_SHARE`` of the box's short side (at least 3 px) from its edges: a plan's inner walls."""
    rows, cols = np.nonzero(walls)
    if rows.size == 0:
        return 0.0
    r0, r1, c0, c1 = rows.min(), rows.max() + 1, cols.min(), cols.max() + 1
    rim = max(3, int(round(RIM_SHARE * min(r1 - r0, c1 - c0))))
    inner = walls[r0 + rim : r1 - rim, c0 + rim : c1 - rim]
    return float(np.count_nonzero(inner)) / rows.size


def _with_pieces_reaching_in(
    lines: np.ndarray, box: tuple[int, int, int, int]
) -> tuple[int, int, int, int]:
    """``box`` grown by the boxes of the 8-connected ink pieces reaching into it from outside
    (a part of the plan that :func:`~f2n_drake.perception.ink.free_marks` took for a legend),
    until none does; a piece round it on every side (a frame) does not count."""
    _, _, stats, _ = cv2.connectedComponentsWithStats(lines.astype(np.uint8), connectivity=8)
    x0, y0 = stats[1:, 0].astype(np.int64), stats[1:, 1].astype(np.int64)
    x1, y1 = x0 + stats[1:, 2], y0 + stats[1:, 3]
    r0, r1, c0, c1 = box
    while True:
        overlaps = (y0 < r1) & (y1 > r0) & (x0 < c1) & (x1 > c0)
        around = (y0 < r0) & (y1 > r1) & (x0 < c0) & (x1 > c1)
        reach = overlaps & ~around
        grown = (
            min(r0, int(y0[reach].min(initial=r0))),
            max(r1, int(y1[reach].max(initial=r1))),
            min(c0, int(x0[reach].min(initial=c0))),
            max(c1, int(x1[reach].max(initial=c1))),
        )
        if grown == (r0, r1, c0, c1):
            return grown
        r0, r1, c0, c1 = grown


def _outside(lines: np.ndarray, box: tuple[int, int, int, int]) -> np.ndarray:
    """(H, W) bool: the ink of the 8-connected pieces of ``lines`` lying wholly outside ``box``
    or round it on every side (a sheet's frame); a piece reaching into it from one side (a
    terrace drawn against the walls) stays."""
    r0, r1, c0, c1 = box
    n, pieces, stats, _ = cv2.connectedComponentsWithStats(lines.astype(np.uint8), connectivity=8)
    x, y, w, h = (stats[:, i] for i in range(4))
    apart = (y >= r1) | (y + h <= r0) | (x >= c1) | (x + w <= c0)
    around = (y < r0) & (y + h > r1) & (x < c0) & (x + w > c1)  # a sheet's frame, a border
    apart |= around
    apart[0] = False
    return apart[pieces]


def only_the_plan(grey: np.ndarray, lines: np.ndarray) -> tuple[np.ndarray, PlanOnSheet]:
    """``grey`` with the ink lying wholly outside its plan's box painted over in the paper's grey,
    and with it whatever else lies outside the box and is no ink (a grey frame, a title bar,
    tinted panels), unchanged (the same array) when there is none; and where the plan is."""
    plan = find_plan(lines)
    if not plan.left_out:
        return grey, plan
    outside = _outside(lines, plan.box)
    if not outside.any():
        return grey, dataclasses.replace(plan, left_out=False)
    paper = np.uint8(np.median(grey[~lines])) if (~lines).any() else np.uint8(255)
    fringe = cv2.dilate(outside.astype(np.uint8), np.ones((3, 3), np.uint8)) > 0
    r0, r1, c0, c1 = plan.box
    beyond = np.ones(lines.shape, bool)
    beyond[r0:r1, c0:c1] = False
    log.info("%s", plan.describe())
    return np.where((fringe | beyond) & ~(lines & ~outside), paper, grey), plan
