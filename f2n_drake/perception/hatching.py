"""Hatched walls: architects hatch cut walls with diagonal lines, the training drawings never.

Hatching changes the grey across its lines, not along them, while walls drawn along the rows
and columns change alike along both diagonals, whatever their style. :func:`hatched_walls` finds
a drawing's hatched wall bands at the network's scale (``DETECTION_SIDE_PX``), where hatching
6-10 cm apart is a few pixels apart. Two consumers: :func:`~f2n_drake.perception.ink.binarize` makes
the paper between the hatching's lines ink (:func:`with_hatch_cells`), so that a large drawing's
walls do not become thousands of tiny instances, and the segmenter shows the network the walls
filled solid (``perception.preparation.solid_hatching``). ``python -m f2n_drake.evaluate
hatching`` measures where hatching is found.
"""

from __future__ import annotations

from collections.abc import Callable

import cv2
import numpy as np

MIN_ASYMMETRY = 0.15
"""Wall bands whose grey changes this much more (a share of both) along one diagonal than along
the other are hatched."""
DETECTION_SIDE_PX = 512
"""Hatching is looked for with the drawing's long side at most this many pixels (the network's
input), where its lines are 1.5-6 px apart."""
BAND_CLOSING_PX = 5
"""Ink closed by this square, then opened by 3x3, is a wall band: outlined, filled or hatched."""
MIN_CELL_SHARE = 0.5
"""Paper at least this share of which lies on hatched walls is a cell of their hatching if it
fills at most ``MAX_CELL_FILL`` of its bounding box (cut by diagonal lines) or its bounding box
is at most ``MAX_CELL_ASPECT`` times as long as wide (a dot between close lines). The inside of
a window's or a door's box is neither: a rectangle as wide as the opening, a few times longer
than the wall is thick."""
MAX_CELL_FILL = 0.75
MAX_CELL_ASPECT = 2.0


def wall_bands(ink: np.ndarray) -> np.ndarray:
    """A drawing's wall bands, outlined, filled or hatched: its ``ink`` closed by
    ``BAND_CLOSING_PX`` and opened by 3x3 (single outlines are thinner)."""
    square = np.ones((BAND_CLOSING_PX, BAND_CLOSING_PX), np.uint8)
    bands = cv2.morphologyEx(ink.astype(np.uint8), cv2.MORPH_CLOSE, square)
    return cv2.morphologyEx(bands, cv2.MORPH_OPEN, np.ones((3, 3), np.uint8)).astype(bool)


def diagonal_asymmetry(grey: np.ndarray, region: np.ndarray) -> float:
    """|a - b| / (a + b), with a and b the summed grey change [levels] between each pixel of
    ``region`` and its neighbour down-right (a) and down-left (b); 0 for an empty region."""
    inside = region[:-1, 1:-1]
    g = grey.astype(np.int16)
    down_right = int(np.abs(g[:-1, 1:-1] - g[1:, 2:])[inside].sum())
    down_left = int(np.abs(g[:-1, 1:-1] - g[1:, :-2])[inside].sum())
    return abs(down_right - down_left) / max(down_right + down_left, 1)


def hatched_walls(grey: np.ndarray, ink: np.ndarray) -> np.ndarray | None:
    """The wall bands (:func:`wall_bands`) of ``grey`` (dark ink on light paper, ``ink`` its
    ink) if their :func:`diagonal_asymmetry` is at least ``MIN_ASYMMETRY``, else None."""
    bands = wall_bands(ink)
    return bands if diagonal_asymmetry(grey, bands) >= MIN_ASYMMETRY else None


def detection_scale(shape: tuple[int, ...]) -> float:
    """The factor that shrinks a drawing of ``shape`` to ``DETECTION_SIDE_PX`` (at most 1)."""
    return min(1.0, DETECTION_SIDE_PX / max(shape[:2]))


def with_hatch_cells(
    grey: np.ndarray, ink: np.ndarray, ink_of: Callable[[np.ndarray], np.ndarray]
) -> np.ndarray:
    """``ink`` with the paper between the lines of hatched walls made ink too.

    Args:
        grey: (H, W) uint8 drawing, dark ink on light paper.
        ink: its ink (bool), as ``ink_of(grey)`` finds it.
        ink_of: the binarisation, applied to ``grey`` shrunk to ``DETECTION_SIDE_PX`` when larger.

    Returns:
        ``ink`` itself when the drawing has no hatched walls; otherwise a copy in which every
        cell of the hatching (see ``MIN_CELL_SHARE``) is ink.
    """
    scale = detection_scale(grey.shape)
    if scale < 1:
        size = (max(1, round(grey.shape[1] * scale)), max(1, round(grey.shape[0] * scale)))
        small = cv2.resize(grey, size, interpolation=cv2.INTER_AREA)
        walls = hatched_walls(small, ink_of(small))
        if walls is None:
            return ink
        walls = cv2.resize(
            walls.astype(np.uint8), grey.shape[::-1], interpolation=cv2.INTER_NEAREST
        ).astype(bool)
    else:
        walls = hatched_walls(grey, ink)
        if walls is None:
            return ink
    n, cells, stats, _ = cv2.connectedComponentsWithStats((~ink).astype(np.uint8), connectivity=4)
    area = stats[:, cv2.CC_STAT_AREA]
    width, height = stats[:, cv2.CC_STAT_WIDTH], stats[:, cv2.CC_STAT_HEIGHT]
    on_walls = np.bincount(cells[walls], minlength=n) >= MIN_CELL_SHARE * area
    cut = area <= MAX_CELL_FILL * width * height
    dot = np.maximum(width, height) <= MAX_CELL_ASPECT * np.minimum(width, height)
    is_cell = on_walls & (cut | dot)
    is_cell[0] = False  # label 0 is the ink
    return ink | is_cell[cells]
