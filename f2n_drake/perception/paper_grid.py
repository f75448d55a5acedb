"""Squared paper: a drawing on a printed grid made plain paper again.

A sketch on graph paper, a plan drawn on an engineering pad or a scan of either carries a grid:
faint lines along the rows and the columns, evenly spaced, from edge to edge of the sheet. Read
as drawn, every grid line is a stroke of ink that crosses every room, so each room falls apart
into squares, and the network, trained on plain paper, reads the squares as walls and windows.
A grid line is told from the drawing's lines by three things at once:

- it is **long and thin**: over at least ``MIN_COVER`` of the sheet's width (height) the row
  (column) is ``DARKER_THAN_PAPER`` darker than the rows a few pixels to both sides, on the
  paper and across rooms' fills alike. The plan's own walls run along a part of it;
- it is **one of many, evenly spaced**: at least ``MIN_LINES`` such rows lie on one spacing
  ``p`` (each within ``SPACING_TOLERANCE_PX`` of ``first + k p``), at least ``MIN_SPACING_PX``
  apart, and those rows are at least ``MIN_LATTICE_SHARE`` of the spacing's places across the
  sheet. A plan's walls and a flight of stairs are neither. Every row at one of the spacing's
  places that is a thin line over ``MIN_PLACE_COVER`` of the width is then a grid line too (one
  along a wall's face shows in the margins only);
- it is **light**: its typical grey (the median over the row) is lighter than half-way
  between the paper and the drawing's ink.

On a grid line, a pixel takes the grey beside the line (the paper, or a room's fill) where the
pixels ``_ACROSS_PX`` beyond the line on one side or the other are lighter than it: a stroke of
the drawing crossing the line is as dark on both sides, and a pixel ``DARKER_THAN_PAPER`` darker
than the line's typical grey (the drawing's lines crossing it or drawn along it) is kept. A
drawing without such a grid comes back unchanged (the same array).
"""

from __future__ import annotations

import numpy as np

from f2n_drake.perception.ink import ink_is_dark

MIN_COVER = 0.6
"""A grid line is a thin line over at least this share of the sheet's width."""
MIN_PLACE_COVER = 0.05
"""Once the spacing is found, a row near one of its places is a grid line when it is a thin
line over this share of the width (the rest hidden by the drawing)."""
MIN_LINES = 6
"""A grid has at least this many lines one way."""
MIN_SPACING_PX = 4
"""Grid lines are at least this far apart [px]."""
SPACING_TOLERANCE_PX = 1.5
"""A grid line lies this close to its place on the spacing [px]."""
MIN_LATTICE_SHARE = 0.5
"""Share of the spacing's places across the sheet on which a grid line is found, at least."""
DARKER_THAN_PAPER = 12
"""A grid line's pixels are at least this many grey levels darker than what lies beside it."""
_ACROSS_PX = 2  # a pixel this far off the line on both sides tells a crossing stroke
_PAPER_SHARE = 0.9  # the paper's grey: this quantile of the drawing's
_INK_SHARE = 0.01  # the ink's grey: this quantile


def without_paper_grid(grey: np.ndarray) -> np.ndarray:
    """``grey`` (uint8) with its printed grid painted paper (see module doc); the same array
    when it has none."""
    grey = np.asarray(grey)
    if grey.ndim != 2 or min(grey.shape) < MIN_LINES * MIN_SPACING_PX or not ink_is_dark(grey):
        return grey
    ink = float(np.quantile(grey, _INK_SHARE))
    (rows, row_grey), (cols, col_grey) = grid_lines(grey, ink), grid_lines(grey.T, ink)
    if not (rows.any() or cols.any()):
        return grey
    out = grey.copy()
    if rows.any():
        _paint_paper(out, rows, keep_below=row_grey - DARKER_THAN_PAPER)
    if cols.any():  # where the rows' lines crossed them is paper now
        _paint_paper(out.T, cols, keep_below=col_grey - DARKER_THAN_PAPER)
    return out


def thin_along_rows(grey: np.ndarray) -> np.ndarray:
    """(H, W) bool: pixels at least ``DARKER_THAN_PAPER`` darker than both pixels
    ``_ACROSS_PX + 1`` rows above and below (the one there is at the sheet's edge): on a line
    along the rows at most ``2 _ACROSS_PX + 1`` px thick, on paper or across a room's fill."""
    reach = _ACROSS_PX + 1
    grey = grey.astype(np.int16)
    padded = np.pad(grey, ((reach, reach), (0, 0)), mode="constant", constant_values=-1)
    above, below = padded[: -2 * reach], padded[2 * reach :]
    beside = np.where(above < 0, below, np.where(below < 0, above, np.minimum(above, below)))
    return grey <= beside - DARKER_THAN_PAPER


def grid_lines(grey: np.ndarray, ink: float) -> tuple[np.ndarray, float]:
    """(rows,) bool, the rows of ``grey`` that are lines of a printed grid (module doc; pass
    the transpose for its columns), and the lines' typical grey (the paper's when there are
    none). ``ink`` is the drawing's darkest grey."""
    n = grey.shape[0]
    paper = float(np.quantile(grey, _PAPER_SHARE))
    found = np.zeros(n, bool), paper
    thin = thin_along_rows(grey)
    long = thin.mean(axis=1) >= MIN_COVER
    if np.count_nonzero(long) < MIN_LINES:
        return found
    centres = np.array([(start + stop - 1) / 2.0 for start, stop in _runs(long)])  # 2 px lines
    spacing = _spacing(centres)
    if spacing is None:
        return found
    offsets = np.mod(centres - centres[0] + SPACING_TOLERANCE_PX, spacing)
    on = centres[offsets <= 2 * SPACING_TOLERANCE_PX]
    # the spacing's best phase: the one most centres keep to
    phase = float(np.median(np.mod(on, spacing)))
    places = np.arange(phase, n, spacing)
    hit = (np.abs(on[:, None] - places[None, :]) <= SPACING_TOLERANCE_PX).any(axis=0)
    if hit.sum() < MIN_LINES or hit.mean() < MIN_LATTICE_SHARE:
        return found
    # every place of the spacing holds a line, also where the drawing hides most of it (a
    # line along a wall's face): the row nearest the place that is thinnest over most of it
    cover = thin.mean(axis=1)
    rows = []
    for place in places:
        near = np.arange(
            int(np.ceil(place - SPACING_TOLERANCE_PX)), int(place + SPACING_TOLERANCE_PX) + 1
        )
        near = near[(near >= 0) & (near < n)]
        run = near[cover[near] >= MIN_PLACE_COVER]
        rows.extend(run.tolist())
    rows = np.array(sorted(set(rows)), int)
    if rows.size == 0:
        return found
    level = float(np.median(grey[rows][thin[rows]]))
    if level <= (paper + ink) / 2:  # as dark as the drawing: ruled lines of the drawing itself
        return found
    lines = np.zeros(n, bool)
    lines[rows] = True
    return lines, level


def _spacing(centres: np.ndarray) -> float | None:
    """The grid's spacing [px]: the median of the gaps between neighbouring centres near their
    most common value, when at least ``MIN_LINES - 1`` gaps agree; else None."""
    gaps = np.diff(centres)
    gaps = gaps[gaps >= MIN_SPACING_PX]
    if gaps.size < MIN_LINES - 1:
        return None
    counts = np.array([np.count_nonzero(np.abs(gaps - g) <= SPACING_TOLERANCE_PX) for g in gaps])
    best = gaps[np.argmax(counts)]
    agreeing = gaps[np.abs(gaps - best) <= SPACING_TOLERANCE_PX]
    if agreeing.size < MIN_LINES - 1:
        return None
    return float(np.median(agreeing))


def _paint_paper(grey: np.ndarray, rows: np.ndarray, keep_below: float) -> None:
    """Paint the pixels of the grid ``rows`` of ``grey`` (a view, edited in place) with the
    lighter of the greys ``_ACROSS_PX`` beyond the line's run on either side (the paper, or the
    fill of a room the line crosses; the one side inside the sheet at its edge), where it is at
    least ``DARKER_THAN_PAPER / 2`` lighter than the pixel (a stroke of the drawing crossing the
    line is as dark on both sides) and the pixel is no darker than ``keep_below`` (the
    drawing's own ink)."""
    n = grey.shape[0]
    for start, stop in _runs(rows):
        sides = [
            grey[r].astype(np.int16)
            for r in (start - 1 - _ACROSS_PX, stop + _ACROSS_PX)
            if 0 <= r < n
        ]
        if not sides:
            continue
        beside = np.maximum.reduce(sides)
        band = grey[start:stop]
        line = (band >= keep_below) & (band.astype(np.int16) <= beside - DARKER_THAN_PAPER // 2)
        band[line] = np.broadcast_to(beside, band.shape)[line].astype(np.uint8)


def _runs(rows: np.ndarray) -> list[tuple[int, int]]:
    """(start, stop) of each run of True in ``rows``."""
    padded = np.concatenate([[False], rows, [False]]).astype(np.int8)
    edges = np.flatnonzero(np.diff(padded))
    return list(zip(edges[::2].tolist(), edges[1::2].tolist(), strict=True))
