"""Floors drawn with a texture (planks, tiles, a carpet's grain) made plain fills again.

A rendered listing paints its floors: planks as light lines a few pixels apart, tiles as a grid,
wood or carpet as grain. Read as drawn, every plank line is a stroke of ink (the binarisation
takes thin strokes from 12 % of the ink's contrast below the local paper), so each room falls
apart into strips, and the network, trained on plain paper, reads the stripes as windows and
walls. A texture's stroke is told from the drawing's by three things at once:

- it lies on a **floor fill**: the drawing's light level under its thin strokes (a grey closing,
  seen through a 3 px blur so that a halftone grey is a plain fill) is at least
  ``FILL_BELOW_PAPER`` levels darker than the paper, lighter than half-way to the ink, and
  ``FLOOR_SHARE`` of the long side wide (no word, no wall's edge). Textures on white paper are
  left: a hatched wall's lines look the same there;
- it is **faint and long**: at least ``MIN_STROKE_DEPTH`` levels darker than the fill, at most
  ``TEXTURE_CONTRAST`` of the fill's contrast to the darkest ink (the drawing's walls, doors
  and text lie dark on top of a floor), in a piece as long as a floor is wide (not a JPEG
  ripple);
- it **repeats**: a row or a column through it, ``WINDOW_SHARE`` of the drawing's long side
  long (at least ``MIN_WINDOW_PX``), crosses at least ``MIN_CROSSINGS`` such strokes. A door's
  arc or a sofa's outline across a floor crosses one. The faint long strokes as near those as
  a floor is wide (the planks beside a wall) are the texture's too.

The strokes take their fill's grey when they cover at least ``MIN_TEXTURE_SHARE`` of the box
round the dark ink: a textured floor is a drawing's style, and a patterned terrace alone (R3D's
own convention, which the network learned) is left. The fringe of the drawing's dark lines
(one pixel) is left as drawn. A drawing with no such floor comes back unchanged (the same
array), as does a negative.
"""

from __future__ import annotations

import cv2
import numpy as np

from f2n_drake.perception.ink import ink_is_dark

FILL_BELOW_PAPER = 20
"""A floor at least this many grey levels darker than the paper is filled."""
TEXTURE_CONTRAST = 0.4
"""A texture's strokes are at most this share of the fill-to-ink contrast darker than the fill."""
WINDOW_SHARE = 0.08
"""Length of the row and column looked along for repeated strokes, as a share of the long side."""
MIN_WINDOW_PX = 41
FLOOR_SHARE = 0.025
"""A floor is at least this share of the long side wide, a texture's stroke at least this long,
and the strokes this near a repeated one are the texture's too (the planks beside a wall)."""
MIN_FLOOR_PX = 15
MIN_CROSSINGS = 3
"""Strokes a row or column through a texture crosses within the window, at least."""
MIN_STROKE_DEPTH = 6
"""A texture's strokes are at least this many grey levels darker than their fill (seen through a
3 px blur: a halftone finer than that is a plain grey; JPEG's ripples are shallower)."""
MIN_TEXTURE_SHARE = 0.05
"""Textured floors are a drawing's style: their strokes cover at least this share of the box
round its dark ink, or the drawing is left as drawn (a few strokes found are likelier a
window's lines or a word than a floor)."""
_MIN_CLOSING_PX = 5  # the closing that reads the fill under strokes up to 4 px wide
_CLOSING_SHARE = 1 / 150  # grows with the drawing (its strokes do)
_PAPER_SHARE = 0.99  # the paper's grey: this share of the pixels is as dark or darker
_INK_SHARE = 0.001  # the drawing's darkest ink


def without_floor_textures(grey: np.ndarray) -> np.ndarray:
    """``grey`` (uint8) with its floors' textures painted their fill's grey (see module doc);
    the same array when it has none."""
    grey = np.asarray(grey)
    if grey.size == 0 or not ink_is_dark(grey):
        return grey
    texture, fill = texture_strokes(grey)
    if not texture.any():
        return grey
    out = grey.copy()
    out[texture] = fill[texture]
    return out


def texture_strokes(grey: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(H, W) bool, the strokes of ``grey``'s floor textures (see module doc; none when they
    cover less than ``MIN_TEXTURE_SHARE`` of the box round the dark ink), and (H, W) uint8, the
    fill under them."""
    cumulative = np.cumsum(np.bincount(grey.ravel(), minlength=256)) / grey.size
    ink, paper = (float(np.searchsorted(cumulative, q)) for q in (_INK_SHARE, _PAPER_SHARE))
    min_px = MIN_TEXTURE_SHARE * _box_px(grey < (ink + paper) / 2)
    none = np.zeros(grey.shape, bool)
    smooth = cv2.blur(grey, (3, 3))  # a halftone grey finer than 3 px is a plain fill
    fill = floor_fill(smooth)
    window = _share_px(grey.shape, WINDOW_SHARE, MIN_WINDOW_PX)
    reach = _share_px(grey.shape, FLOOR_SHARE, MIN_FLOOR_PX)
    floor = np.ones((reach, reach), np.uint8)  # a floor is wide: no word, no wall's edge
    filled = (fill <= paper - FILL_BELOW_PAPER) & (fill >= (paper + ink) / 2)
    filled = cv2.morphologyEx(filled.astype(np.uint8), cv2.MORPH_OPEN, floor) > 0
    if np.count_nonzero(filled) < min_px:
        return none, fill
    depth = fill.astype(np.int16) - smooth
    faint_limit = np.maximum(TEXTURE_CONTRAST * (fill.astype(np.float32) - ink), 1.0)
    strong = fill.astype(np.int16) - grey > faint_limit  # the drawing's lines, as drawn
    fringe = cv2.dilate(strong.astype(np.uint8), np.ones((3, 3), np.uint8)) > 0
    faint = _long_strokes(filled & (depth >= MIN_STROKE_DEPTH) & ~fringe, reach)
    textured = cv2.dilate((faint & repeated(faint, window)).astype(np.uint8), floor) > 0
    texture = faint & textured  # a floor's strokes beside the walls cross fewer of the others
    texture = (cv2.dilate(texture.astype(np.uint8), np.ones((3, 3), np.uint8)) > 0) & ~fringe
    if np.count_nonzero(texture) < min_px:
        return none, fill
    return texture, fill


def floor_fill(grey: np.ndarray) -> np.ndarray:
    """(H, W) uint8: the light level under ``grey``'s thin dark strokes (a grey closing as wide
    as the drawing's strokes may be)."""
    side = max(_MIN_CLOSING_PX, int(round(max(grey.shape) * _CLOSING_SHARE)) | 1)
    return cv2.morphologyEx(grey, cv2.MORPH_CLOSE, np.ones((side, side), np.uint8))


def repeated(strokes: np.ndarray, window_px: int) -> np.ndarray:
    """(H, W) bool: pixels whose row or column, ``window_px`` long and centred on them,
    crosses at least ``MIN_CROSSINGS`` separate runs of ``strokes``."""
    s = strokes.astype(np.uint8)
    starts_x = s & ~np.pad(s, ((0, 0), (1, 0)))[:, :-1] & 1
    starts_y = s & ~np.pad(s, ((1, 0), (0, 0)))[:-1, :] & 1
    count_x = cv2.boxFilter(starts_x.astype(np.float32), -1, (window_px, 1), normalize=False)
    count_y = cv2.boxFilter(starts_y.astype(np.float32), -1, (1, window_px), normalize=False)
    return np.maximum(count_x, count_y) >= MIN_CROSSINGS - 0.5


def _long_strokes(strokes: np.ndarray, min_px: int) -> np.ndarray:
    """The 8-connected pieces of ``strokes`` at least ``min_px`` long (a plank's edge, a tile's
    joint; not a ripple of JPEG's or a speck of grain)."""
    _, pieces, stats, _ = cv2.connectedComponentsWithStats(strokes.astype(np.uint8), connectivity=8)
    long = np.maximum(stats[:, cv2.CC_STAT_WIDTH], stats[:, cv2.CC_STAT_HEIGHT]) >= min_px
    long[0] = False
    return long[pieces]


def _box_px(mask: np.ndarray) -> int:
    """Pixels of the box round ``mask`` (0 when it is empty)."""
    rows, cols = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
    return int((rows[-1] - rows[0] + 1) * (cols[-1] - cols[0] + 1)) if rows.size else 0


def _share_px(shape: tuple[int, int], share: float, least: int) -> int:
    """``share`` of the long side of ``shape``, odd, at least ``least`` [px]."""
    return max(least, int(round(share * max(shape))) | 1)
