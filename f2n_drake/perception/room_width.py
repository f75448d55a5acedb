"""How wide a drawing's rooms are [px], whatever its resolution, stroke width or wall style: the
segmenter's choice between one letterboxed pass (a flat) and tiles (a large building)."""

from __future__ import annotations

import cv2
import numpy as np

_GAP_CLOSINGS = (0.0, 0.004, 0.008, 0.016, 0.03, 0.06)  # closings measuring rooms (share of side)
_ROOMS_MIN_SHARE = 0.4  # the rooms measured cover at least this share of the plan


def _enclosed_widths(lines: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Inscribed diameters [px] and areas [px] of the paper regions of ``lines`` not touching
    the image border (the outside)."""
    paper = (~lines).astype(np.uint8)
    n, regions = cv2.connectedComponents(paper, connectivity=4)
    depth = cv2.distanceTransform(paper, cv2.DIST_L2, cv2.DIST_MASK_PRECISE)
    peak = np.zeros(n, np.float32)
    np.maximum.at(peak, regions.ravel(), depth.ravel())
    area = np.bincount(regions.ravel(), minlength=n)
    edge = np.concatenate([regions[0], regions[-1], regions[:, 0], regions[:, -1]])
    inside = np.ones(n, bool)
    inside[np.unique(edge)] = False
    inside[0] = False  # the ink
    return 2.0 * peak[inside], area[inside]


def _closed(lines: np.ndarray, size: int) -> np.ndarray:
    """``lines`` with gaps narrower than ``size`` [px] closed (a square closing)."""
    if size < 2:
        return lines
    kernel = np.ones((size, size), np.uint8)
    return cv2.morphologyEx(lines.astype(np.uint8), cv2.MORPH_CLOSE, kernel).astype(bool)


def room_width_px(lines: np.ndarray) -> float | None:
    """Typical room width of a binarised drawing [px], None when nothing is enclosed.

    The median inscribed diameter (twice the largest distance to ink) of the enclosed paper
    regions at least a quarter as wide as the widest one: the rooms, not the wall interiors,
    door boxes or specks. Regions touching the image border (the outside) do not count. It tells
    how big the drawing's rooms are whatever its resolution, stroke width or wall style.

    Real drawings draw doors as gaps, so their rooms join the outside and the ink alone encloses
    letters and door boxes. The gaps are closed by closings of growing size
    (``_GAP_CLOSINGS``, up to a flat's doorway and short of its rooms) until the regions counted
    cover ``_ROOMS_MIN_SHARE`` of the plan (the ink and paper the largest closing parts from the
    outside); when none does, the closing whose regions cover most of it is taken.
    """
    lines = np.asarray(lines, bool)
    side = max(lines.shape)
    widest = _closed(lines, round(_GAP_CLOSINGS[-1] * side))
    plan_area = max(1.0, float(widest.sum() + _enclosed_widths(widest)[1].sum()))
    best = (-1.0, None)
    for share_of_side in _GAP_CLOSINGS:
        widths, areas = _enclosed_widths(_closed(lines, round(share_of_side * side)))
        if widths.size == 0:
            continue
        rooms = widths >= 0.25 * widths.max()
        covered = float(areas[rooms].sum()) / plan_area
        width = float(np.median(widths[rooms]))
        if covered >= _ROOMS_MIN_SHARE:
            return width
        best = max(best, (covered, width))
    return best[1]
