"""How many plans a sheet holds: separate pieces of wall ink of a plan's size.

A plan's walls are one connected piece of ink (``perception.ink.free_marks``). A sheet that shows
several flats or floors side by side has several such pieces of about the same size; the parse
reads them together as one building, so the run tells the user (``plans_on_sheet``).
"""

from __future__ import annotations

import cv2
import numpy as np
from scipy import ndimage

from f2n_drake.perception.ink import binarize

PLAN_MIN_SHARE = 0.25
"""A piece of ink is a plan of its own when its bounding box has at least this share of the
largest plan-like piece's, it encloses rooms (``ENCLOSED_MIN_SHARE``), and its box meets no
other such piece's box (a plan's walls broken at its doors are pieces whose boxes overlap)."""
ENCLOSED_MIN_SHARE = 0.3
"""Paper a plan's walls enclose, as a share of their bounding box."""


def plans_on_sheet(grey: np.ndarray) -> int:
    """Number of separate plans on a drawing: 1 for an ordinary plan (or one whose walls enclose
    nothing the count can see)."""
    lines = binarize(grey)
    n, ink, stats, _ = cv2.connectedComponentsWithStats(lines.astype(np.uint8), connectivity=8)
    x0, y0, w, h, area = (stats[:, i].astype(np.int64) for i in range(5))
    plans = []
    for k in np.argsort(-(w * h))[: min(n, 64)]:
        if k == 0:  # the paper
            continue
        piece = ink[y0[k] : y0[k] + h[k], x0[k] : x0[k] + w[k]] == k
        enclosed = int(ndimage.binary_fill_holes(piece).sum()) - int(area[k])
        if enclosed >= ENCLOSED_MIN_SHARE * w[k] * h[k]:
            plans.append(k)
    if not plans:
        return 1
    box = w * h
    plans = [k for k in plans if box[k] >= PLAN_MIN_SHARE * max(box[plans])]
    x1, y1 = x0 + w, y0 + h
    apart = [
        all(
            x1[i] <= x0[j] or x1[j] <= x0[i] or y1[i] <= y0[j] or y1[j] <= y0[i]
            for j in plans
            if j != i
        )
        for i in plans
    ]
    return max(1, sum(apart))
