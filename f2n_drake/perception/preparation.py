"""A drawing as the network learned to see drawings: grey, dark ink on white paper, no marks,
cropped to the plan, strokes wide enough to survive shrinking, hatched walls filled solid.

:class:`~f2n_drake.segmenter.inference.Segmenter` applies these before the network; each is
measured in docs/perception.md (*Drawings as they come*).
"""

from __future__ import annotations

import math

import cv2
import numpy as np

from f2n_drake.core.errors import InputError
from f2n_drake.perception.hatching import hatched_walls
from f2n_drake.perception.ink import as_grey, binarize, free_marks, ink_is_dark

MIN_SIDE_PX = 8
CONTENT_MIN_SHARE = 0.8
"""A drawing whose ink spans less than this share of its long side is cropped to the ink (plus
``CONTENT_MARGIN``) before it is letterboxed or tiled: the training drawings fill 92-97 %."""
CONTENT_MARGIN = 0.03
"""Paper kept round the ink of a cropped drawing, as a share of the ink's long side."""
TINTED_PAPER_GREY = 240
TINTED_PAPER_SHARE = 0.1
"""Paper darker than this grey, over more than this share of it, is tinted (room fills) and is
made white before the network sees it."""
LIGHT_INK_GREY = 170
"""A drawing whose darkest tenth of its own lines (no names nor furniture) is lighter than this
grey is drawn in light lines (a CAD export's grey hairlines, 190-230): R3D's listings' darkest
tenth is under 40, and the palest training style (black hairlines blurred, with noise, saved as
JPEG) about 150."""
DARK_INK_GREY = 128
"""Pixels up to this grey are dark ink (a light-lined drawing's black names, say)."""
LIGHT_TO_DARK = 3.0
"""A drawing in light lines also has at least this many light grey pixels (``DARK_INK_GREY`` to
230) for each dark one (R3D's listings: at most 2.3, their median 0.5)."""
MIN_STROKE_INPUT_PX = 0.5
"""Narrowest stroke [px of the network input] a drawing shrunk to the input keeps: training
drawings of up to 1024 px were shrunk to 512 px, so their 1 px lines arrived at least half as
dark as drawn; a 2560 px drawing's would arrive at a fifth."""


def to_grey(image: np.ndarray) -> np.ndarray:
    """(H,W), (H,W,1), (H,W,3) or (H,W,4) uint8 -> (H,W) uint8 grey, colour read as BGR (as
    OpenCV loads it) by :func:`~f2n_drake.perception.ink.as_grey`, so the network and the instance
    extraction see the same grey.

    Raises:
        InputError: wrong dtype, shape or a side shorter than 8 px.
    """
    if not isinstance(image, np.ndarray) or image.dtype != np.uint8:
        raise InputError(f"image must be a uint8 numpy array, got {getattr(image, 'dtype', image)}")
    if image.ndim == 3 and image.shape[2] in (1, 3, 4):
        image = as_grey(np.ascontiguousarray(image))
    if image.ndim != 2:
        raise InputError(f"image must be (H,W) grey or (H,W,3) colour, got shape {image.shape}")
    if min(image.shape) < MIN_SIDE_PX:
        raise InputError(f"image is too small: {image.shape[1]}x{image.shape[0]} px")
    return np.ascontiguousarray(image)


def on_white_paper(grey: np.ndarray, lines: np.ndarray | None = None) -> np.ndarray:
    """``grey`` as the network was trained to see drawings: dark ink on white paper.

    A drawing of dark lines on light paper comes back as drawn (anti-aliasing, noise and all, as
    in training) unless more than ``TINTED_PAPER_SHARE`` of its paper is tinted (darker than
    ``TINTED_PAPER_GREY`` after a 5 px median filter: coloured or grey room fills, a yellowed
    scan); then every pixel :func:`~f2n_drake.perception.ink.binarize` reads as paper becomes white
    and
    the ink keeps its grey level. A drawing of light lines on dark paper (a negative, a blueprint)
    is inverted and its paper made white the same way. ``lines``: ``binarize(grey)``, if known.
    """
    lines = binarize(grey) if lines is None else lines
    if not lines.any():
        return grey
    if ink_is_dark(grey):
        paper = ~lines
        tinted = paper & (cv2.medianBlur(grey, 5) < TINTED_PAPER_GREY)
        if tinted.sum() <= TINTED_PAPER_SHARE * paper.sum():
            return grey
        ink = grey
    else:
        ink = 255 - grey
    return np.where(lines, ink, np.uint8(255))


def _light_lines(grey: np.ndarray) -> np.ndarray | None:
    """The ink of a drawing's own lines when they are light (:func:`drawn_in_light_lines`),
    else None."""
    levels = np.bincount(grey.ravel(), minlength=256)
    dark, light = levels[: DARK_INK_GREY + 1].sum(), levels[DARK_INK_GREY + 1 : 231].sum()
    if light < LIGHT_TO_DARK * dark:  # mostly dark ink (and its anti-aliasing): no marks sought
        return None
    lines = binarize(grey, faint=True)
    own = lines & ~free_marks(lines).ink
    if not own.any() or np.percentile(grey[own], 10) <= LIGHT_INK_GREY:
        return None
    return own


def drawn_in_light_lines(grey: np.ndarray) -> bool:
    """Whether a drawing (dark ink on white paper) is drawn in light lines: a CAD export's grey
    hairlines, often beside black names. Its light grey pixels (``DARK_INK_GREY`` to 230) are at
    least ``LIGHT_TO_DARK`` times its dark ones, and the darkest tenth of its own lines (its faint
    strokes read as ink, names and furniture left out: :func:`~f2n_drake.perception.ink.free_marks`)
    is lighter than ``LIGHT_INK_GREY``."""
    return _light_lines(grey) is not None


def with_dark_ink(grey: np.ndarray) -> np.ndarray:
    """``grey`` (dark ink on white paper) with light lines made dark: a drawing
    :func:`drawn_in_light_lines` has its tones stretched so that white stays white and the median
    tone of its own lines becomes black, as the network was trained to see lines. Shown light grey
    hairlines as drawn, the network reads the faint floor as one room; any other drawing comes
    back unchanged (the same array)."""
    own = _light_lines(grey)
    if own is None:
        return grey
    ink_grey = min(float(np.median(grey[own])), 254.0)
    darkness = (255.0 - grey) * (255.0 / (255.0 - ink_grey))
    return (255.0 - np.minimum(darkness, 255.0)).astype(np.uint8)


def without_marks(grey: np.ndarray, lines: np.ndarray, marks: np.ndarray) -> np.ndarray:
    """``grey`` with its ``marks`` (the ink of :func:`~f2n_drake.perception.ink.free_marks` of its
    ``lines``: room names, dimensions, furniture) painted over in the paper's grey, one pixel
    around them too (their anti-aliased fringe). The plan's own ink is untouched. The network
    never saw text or furniture in training: a room name can make it misread the room, or a
    window beside it."""
    if not marks.any():
        return grey
    erase = cv2.dilate(marks.astype(np.uint8), np.ones((3, 3), np.uint8)).astype(bool)
    erase &= ~(lines & ~marks)
    paper = np.uint8(np.median(grey[~lines]))
    return np.where(erase, paper, grey)


def visible_strokes(grey: np.ndarray, stroke_px: int, scale: float) -> np.ndarray:
    """``grey`` with its ink grown (a grey-level erosion) until strokes ``stroke_px`` wide are at
    least ``MIN_STROKE_INPUT_PX`` wide once the drawing is shrunk by ``scale``; unchanged when
    they already are (every drawing of up to twice the input size)."""
    need = math.ceil(MIN_STROKE_INPUT_PX / scale - 1e-9)
    if need <= max(stroke_px, 1):
        return grey
    grow = need - max(stroke_px, 1) + 1
    return cv2.erode(grey, np.ones((grow, grow), np.uint8))


def content_box(lines: np.ndarray) -> tuple[int, int, int, int]:
    """(row0, row1, col0, col1) of the part of a drawing the network should see, given its ink
    (``binarize``): the whole drawing, or, when the ink spans less than ``CONTENT_MIN_SHARE`` of
    the long side (a small plan on a big sheet), the ink's bounding box widened by
    ``CONTENT_MARGIN`` of its long side."""
    h, w = lines.shape
    rows, cols = np.nonzero(lines)
    if rows.size == 0:
        return 0, h, 0, w
    r0, r1, c0, c1 = rows.min(), rows.max() + 1, cols.min(), cols.max() + 1
    span = max(r1 - r0, c1 - c0)
    if span >= CONTENT_MIN_SHARE * max(h, w):
        return 0, h, 0, w
    pad = max(4, round(CONTENT_MARGIN * span))
    return max(0, r0 - pad), min(h, r1 + pad), max(0, c0 - pad), min(w, c1 + pad)


def solid_hatching(grey: np.ndarray) -> np.ndarray:
    """``grey`` (dark ink on white paper, at the network's scale) with hatched walls filled solid.

    Architects hatch cut walls with diagonal lines; shrunk to the network's input they become a
    band of grey stripes that the network never saw in training, while walls filled solid it
    did.
    When the walls are hatched (:func:`~f2n_drake.perception.hatching.hatched_walls`), the thick
    ink (the
    binarised lines, the hatching's cells included, opened by 3x3: outlines, window frames and
    door leaves are thinner) takes the grey of its darkest 5 %. Any other drawing comes back
    unchanged (the same array), as does one with no thick ink: a thin-lined drawing whose few
    wall bands (door arcs meeting a corner) change more along one diagonal than the other.
    """
    lines = binarize(grey)
    if hatched_walls(grey, lines) is None:
        return grey
    thick = cv2.morphologyEx(lines.astype(np.uint8), cv2.MORPH_OPEN, np.ones((3, 3), np.uint8))
    thick = thick.astype(bool)
    if not thick.any():
        return grey
    ink = np.uint8(np.percentile(grey[thick], 5))
    return np.where(thick, ink, grey)
