"""A drawing lit unevenly (a photographed page, a scan with the lid up) lit evenly again.

A phone photo dims the paper towards a side or a corner; the darker side's lines then lie below
the binarisation's single cut together with its paper, or its paper with them. The paper's light
changes slowly across a page, the drawing quickly, so the light is a smooth surface under the
paper:

- the drawing is cut into cells (``CELLS`` along its long side); a cell's paper is its
  ``PAPER_PERCENTILE`` grey (its lines are darker and fewer);
- a quadratic surface in x and y is fitted to the cells' paper by least squares, and refitted
  ``_ROUNDS`` times without the cells more than ``DARKER_GREYS`` darker than the surface (a solid
  wall, a filled room, a title bar: no paper in them);
- when the drawing is dark lines on light paper, at least ``MIN_PAPER_SHARE`` of the cells are
  paper and the surface's darkest point is below ``MAX_DIMMING`` of its brightest, the drawing
  is divided by it, so its paper is white again. Any other drawing comes back unchanged (the
  same array): an evenly lit page, a negative, or one whose light the surface does not follow
  (most of it filled or dark).
"""

from __future__ import annotations

import cv2
import numpy as np

from f2n_drake.perception.ink import ink_is_dark

CELLS = 24
"""Cells along the drawing's long side."""
PAPER_PERCENTILE = 90
"""A cell's paper grey: this percentile of its pixels."""
DARKER_GREYS = 12
"""A cell this many grey levels darker than the fitted light is no paper (a fill, a solid wall)."""
MIN_PAPER_SHARE = 0.5
"""Share of the cells that must be paper for the fitted light to be trusted."""
MAX_DIMMING = 0.85
"""The light is corrected when its darkest point is below this share of its brightest."""
_ROUNDS = 4
_SAMPLED_PX = 480  # the cells are read on the drawing shrunk to at most this long side


def evenly_lit(grey: np.ndarray) -> np.ndarray:
    """``grey`` (dark lines on light paper, uint8) divided by its paper's light when that is
    uneven (see module doc); the same array otherwise."""
    light = paper_light(grey)
    if light is None:
        return grey
    lit = grey.astype(np.float32) * (255.0 / light)
    return np.clip(lit, 0, 255).round().astype(np.uint8)


def paper_light(grey: np.ndarray) -> np.ndarray | None:
    """(H, W) float32 grey of the paper's light, fitted as in the module doc, or None when the
    page is evenly lit or its light cannot be told from its drawing."""
    if not ink_is_dark(grey):  # a negative's paper is dark: nothing to light
        return None
    h, w = grey.shape
    shrink = min(1.0, _SAMPLED_PX / max(h, w))
    sample = (
        grey
        if shrink == 1.0
        else cv2.resize(grey, None, fx=shrink, fy=shrink, interpolation=cv2.INTER_AREA)
    )
    sh, sw = sample.shape
    step = max(1, int(np.ceil(max(sh, sw) / CELLS)))
    rows, cols = sh // step, sw // step
    if rows < 3 or cols < 3:
        return None
    cells = sample[: rows * step, : cols * step].reshape(rows, step, cols, step)
    cells = cells.transpose(0, 2, 1, 3).reshape(rows, cols, step * step)
    paper = np.percentile(cells, PAPER_PERCENTILE, axis=2).ravel()
    ys, xs = np.mgrid[0:rows, 0:cols]
    y = ((ys + 0.5) * step / sh - 0.5).ravel()
    x = ((xs + 0.5) * step / sw - 0.5).ravel()
    design = _quadratic(x, y)
    kept = np.ones(paper.size, dtype=bool)
    for _ in range(_ROUNDS):
        coefficients, *_ = np.linalg.lstsq(design[kept], paper[kept], rcond=None)
        kept = paper >= design @ coefficients - DARKER_GREYS
    if kept.mean() < MIN_PAPER_SHARE:
        return None
    coefficients, *_ = np.linalg.lstsq(design[kept], paper[kept], rcond=None)
    c0, cx, cy, cxx, cxy, cyy = coefficients.astype(np.float32)
    x = (np.arange(w, dtype=np.float32) + 0.5) / w - 0.5
    y = ((np.arange(h, dtype=np.float32) + 0.5) / h - 0.5)[:, None]
    light = c0 + cx * x + cy * y + cxx * x * x + cxy * x * y + cyy * y * y
    brightest = float(light.max())
    if brightest <= 0 or float(light.min()) >= MAX_DIMMING * brightest:
        return None
    return np.maximum(light, 1.0).astype(np.float32)


def _quadratic(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """(N, 6) design matrix 1, x, y, x², xy, y² of N coordinates."""
    return np.stack([np.ones_like(x), x, y, x * x, x * y, y * y], axis=1)
