"""A drawing scanned or drawn a little off square, turned upright.

A page laid on a scanner's glass a degree or two askew draws every wall a little off the rows
and columns. The steps that close a wall's gaps and find its windows scan rows and columns
(walls drawn well off them, :mod:`~f2n_drake.perception.wall_angles`, from 8 degrees, are
scanned turned): two degrees make a 600 px wall drift 20 px across the rows, and most of its
doors and windows are lost.

:func:`skew_deg` measures the drawing's own direction. Its straight lines (a probabilistic Hough
transform on the outlines of its ink, runs at least ``MIN_RUN_SHARE`` of the long side) must
mostly (``MIN_SQUARE_SHARE`` of their length) lie within ``MAX_SKEW_DEG`` of the rows or
columns: a round plan, or one of wings at many angles, is left as drawn. The skew is then the
turn that makes the sums of the ink's rows sharpest (largest sum of squares: a line along the
rows puts all its ink in one row), searched in ``_COARSE_DEG`` and then ``_FINE_DEG`` steps (the
Hough runs of a slightly slanted line break into level steps and would measure it too small),
and the same turn must make its columns sharpest, within ``_AGREE_DEG``: a page laid askew turns
every wall alike, while a plan whose facade alone is drawn at an angle sharpens its rows and its
columns at different turns, and is left as drawn. A drawing is askew from ``MIN_SKEW_DEG``.
:func:`upright` turns it by that much, on a canvas holding all of it (white paper added at the
corners), bicubically: every later step and every output lie on the upright drawing.
"""

from __future__ import annotations

import cv2
import numpy as np

from f2n_drake.perception.ink import as_grey, binarize
from f2n_drake.perception.wall_angles import turn_matrix

MIN_SKEW_DEG = 0.5
"""Least skew undone [deg]: turning costs a resampling, which blurs thin lines."""
MAX_SKEW_DEG = 8.0
"""Most skew undone [deg]; walls farther off the rows are scanned turned where they are
(``perception.wall_angles``)."""
MIN_SQUARE_SHARE = 0.6
"""Least share of the straight runs' length within ``MAX_SKEW_DEG`` of the rows or columns."""
MIN_RUN_SHARE = 0.05
"""Shortest straight run that votes, as a share of the drawing's long side."""
_COARSE_DEG = 0.25  # first search step [deg]
_FINE_DEG = 0.05  # the refined skew's resolution [deg]
_AGREE_DEG = 0.3  # the rows' and the columns' lines turned this alike are one skew [deg]
_MAX_SIDE_PX = 1600  # drawings larger than this are measured shrunk to it


def skew_deg(image: np.ndarray) -> float:
    """How far the drawing's walls run off its rows [deg, counter-clockwise as shown, rows growing
    down the page]; 0 when it is square to them, or not clearly askew (module doc)."""
    grey = as_grey(image)
    scale = min(1.0, _MAX_SIDE_PX / max(grey.shape))
    if scale < 1.0:
        grey = cv2.resize(grey, None, fx=scale, fy=scale, interpolation=cv2.INTER_AREA)
    ink = binarize(grey)
    min_len = max(12, int(MIN_RUN_SHARE * max(ink.shape)))
    edges = cv2.Canny(ink.astype(np.uint8) * 255, 50, 150)
    segments = cv2.HoughLinesP(edges, 1, np.pi / 720, min_len, minLineLength=min_len, maxLineGap=2)
    if segments is None:
        return 0.0
    x0, y0, x1, y1 = segments.reshape(-1, 4).T.astype(float)
    length = np.hypot(x1 - x0, y1 - y0)
    angle = (np.degrees(np.arctan2(y0 - y1, x1 - x0)) + 45.0) % 90.0 - 45.0  # -45 .. 45
    if length[np.abs(angle) <= MAX_SKEW_DEG].sum() < MIN_SQUARE_SHARE * length.sum():
        return 0.0  # a round plan, or one of wings at many angles
    points = _centred_points(ink)
    turns = []
    for axis in (0, 1):  # the rows' lines, the columns' lines
        turn = _sharpest_turn(points, axis, 0.0, MAX_SKEW_DEG, _COARSE_DEG)
        turns.append(_sharpest_turn(points, axis, turn, _COARSE_DEG, _FINE_DEG))
    if abs(turns[0] - turns[1]) > _AGREE_DEG:
        return 0.0  # the walls along the rows and those along the columns are not turned alike
    skew = (turns[0] + turns[1]) / 2
    return skew if MIN_SKEW_DEG <= abs(skew) <= MAX_SKEW_DEG else 0.0


def _sharpest_turn(points: np.ndarray, axis: int, near: float, within: float, step: float) -> float:
    """The skew within ``within`` of ``near`` [deg], in ``step`` degree steps, whose undoing
    makes the sums of the ink's rows (``axis`` 0) or columns (1) sharpest."""
    skews = np.arange(near - within, near + within + step / 2, step)
    scores = [_sharpness(points, float(skew), axis) for skew in skews]
    return float(skews[int(np.argmax(scores))])


def _centred_points(ink: np.ndarray) -> np.ndarray:
    """(N, 2) x, y of the ink's pixels about their mean."""
    points = np.argwhere(ink)[:, ::-1].astype(float)
    return points - points.mean(axis=0)


def _sharpness(points: np.ndarray, skew: float, axis: int) -> float:
    """Sum of squares of the row (``axis`` 0) or column (1) sums of the ``points`` turned
    ``skew`` degrees clockwise (rows grow down the page)."""
    t = np.radians(skew)
    if axis == 0:
        along = points[:, 1] * np.cos(t) + points[:, 0] * np.sin(t)
    else:
        along = points[:, 0] * np.cos(t) - points[:, 1] * np.sin(t)
    sums = np.bincount(np.round(along - along.min()).astype(int))
    return float(sums @ sums)


def upright(image: np.ndarray, skew: float) -> np.ndarray:
    """``image`` (grey, or BGR/BGRA) turned ``skew`` degrees clockwise, so that walls ``skew``
    degrees off its rows run along them, on a canvas holding all of it
    (:func:`~f2n_drake.perception.wall_angles.turn_matrix`), the corners white paper (bicubic).
    The same array when ``skew`` is 0."""
    if skew == 0.0:
        return image
    matrix, size = turn_matrix(image.shape[:2], skew)
    paper = (255,) * (image.shape[2] if image.ndim == 3 else 1)
    return cv2.warpAffine(image, matrix, size, flags=cv2.INTER_CUBIC, borderValue=paper)
