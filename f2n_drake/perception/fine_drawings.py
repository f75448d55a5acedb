"""Fine drawings read shrunk: a plan drawn over many pixels, parsed at the size the parse suits.

The parse's geometry counts in pixels made for plans about 600-1000 px across: a 3x3 closing
seals the gaps anti-aliasing leaves in a line, a thin stroke is the middle of a few pixels darker
than both sides, a speck is a few pixels. On a plan drawn over 2000 px a dashed glazing line's
gaps stay open and its dashes are taken for marks, a grey line's middle is no darker than its
sides, and rooms leak. A plan whose box on the sheet (``perception.sheet``: a legend or a title
block beside it does not count) is longer than ``FINE_PLAN_PX`` is therefore shrunk (by area) so
that box is ``READ_PLAN_PX`` long, never so far that its lines (their stroke width) come under
``MIN_STROKE_PX`` nor its rooms (``perception.room_width``) under ``MIN_ROOM_PX``, a large
building's small rooms kept as drawn; the parse is brought back onto the drawing's own grid
(:func:`on_drawing_grid`), so its labels and instances lie on the pixels the user handed over.
"""

from __future__ import annotations

import dataclasses

import cv2
import numpy as np

from f2n_drake.core.parsed import ParsedPlan
from f2n_drake.core.raster import PixelGrid
from f2n_drake.perception.ink import stroke_width_px
from f2n_drake.perception.room_width import room_width_px

FINE_PLAN_PX = 1280
"""A plan whose box is longer than this [px] is parsed shrunk."""
READ_PLAN_PX = 1024
"""The length [px] a fine plan's box is shrunk to."""
MIN_STROKE_PX = 1.0
"""Lines are never shrunk thinner than this [px]."""
MIN_ROOM_PX = 40.0
"""Rooms are never shrunk narrower than this [px]: a large building's stay as drawn (R3D's
listings, letterboxed to the network's 512 px, measure 21 to 190 px, 71 at the median)."""
_LEAST_REDUCTION = 1.1
"""A reduction under this is not worth a resampling."""


def reduction(lines: np.ndarray, box: tuple[int, int, int, int]) -> float:
    """How many times the drawing of ink ``lines`` is parsed smaller (1: as drawn), its plan in
    ``box`` (row0, row1, col0, col1)."""
    r0, r1, c0, c1 = box
    side = max(r1 - r0, c1 - c0)
    if side <= FINE_PLAN_PX:
        return 1.0
    plan = lines[r0:r1, c0:c1]
    factor = min(side / READ_PLAN_PX, stroke_width_px(plan) / MIN_STROKE_PX)
    if factor >= _LEAST_REDUCTION:
        rooms = room_width_px(plan)
        factor = min(factor, rooms / MIN_ROOM_PX) if rooms is not None else 1.0
    return factor if factor >= _LEAST_REDUCTION else 1.0


def shrunk(grey: np.ndarray, factor: float) -> np.ndarray:
    """``grey`` ``factor`` times smaller (by area)."""
    height, width = grey.shape
    shape = (max(1, round(width / factor)), max(1, round(height / factor)))
    return cv2.resize(grey, shape, interpolation=cv2.INTER_AREA)


def on_drawing_grid(parsed: ParsedPlan, shape: tuple[int, int]) -> ParsedPlan:
    """A plan parsed on its drawing shrunk, brought back onto the drawing's grid of ``shape``
    (rows, cols): every pixel takes the instance and label of the pixel it shrank into; outlines,
    areas, centroids, votes, words' boxes and lengths in pixels grow with it."""
    height, width = shape
    small_h, small_w = parsed.instance_ids.shape
    if (small_h, small_w) == (height, width):
        return parsed
    sx, sy = width / small_w, height / small_h
    ids = cv2.resize(parsed.instance_ids, (width, height), interpolation=cv2.INTER_NEAREST)
    labels = cv2.resize(parsed.labels, (width, height), interpolation=cv2.INTER_NEAREST)
    n = max(int(ids.max()), max((i.id for i in parsed.instances), default=0)) + 1
    area = np.bincount(ids.ravel(), minlength=n)
    rows, cols = np.indices(ids.shape)
    sum_r = np.bincount(ids.ravel(), weights=rows.ravel(), minlength=n)
    sum_c = np.bincount(ids.ravel(), weights=cols.ravel(), minlength=n)
    instances = []
    for inst in parsed.instances:
        if area[inst.id] == 0:
            continue
        grown = area[inst.id] / max(inst.area_px, 1)
        instances.append(
            dataclasses.replace(
                inst,
                contour_px=(np.asarray(inst.contour_px, float) + 0.5) * (sx, sy) - 0.5,
                area_px=int(area[inst.id]),
                centroid_px=(sum_c[inst.id] / area[inst.id], sum_r[inst.id] / area[inst.id]),
                votes={k: int(round(v * grown)) for k, v in inst.votes.items()},
            )
        )
    grid = parsed.grid
    if grid is not None:
        grid = PixelGrid(grid.metres_per_px / sx, grid.origin_m, (height, width))
    return dataclasses.replace(
        parsed,
        instance_ids=ids,
        labels=labels,
        instances=instances,
        grid=grid,
        texts=[text.scaled(1 / sx) for text in parsed.texts],
        door_outline_px=parsed.door_outline_px * sx,
    )
