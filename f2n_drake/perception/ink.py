"""Drawing -> line (ink) pixels: grey conversion and binarisation robust to faint thin strokes."""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial

import cv2
import numpy as np

from f2n_drake.core.errors import InputError
from f2n_drake.perception.hatching import with_hatch_cells

_MIN_CONTRAST = 40  # grey levels between ink and paper below which an image has no lines
_THICK_PX = 7  # a tone's shapes this wide are paper or margins, not lines
_MAX_SPECK_PX = 3  # isolated dark specks up to this size are noise, not lines
_BLACKHAT_PX = 13  # window [px] giving the local paper level around thin strokes
_MIN_STROKE_CONTRAST = 20  # grey levels below local paper that make a thin stroke ink
_STROKE_CONTRAST_SHARE = 0.12  # and darker by this share of the ink-paper contrast
_FAINT_STROKE_CONTRAST = 10  # grey levels below local paper that make a stroke ink, read faint
_MIN_STROKE_PX = 20  # thin strokes found by local contrast must have this many pixels
_NOISE_MARGIN_SIGMAS = 4  # and be darker than paper by this many paper-noise sigmas
_MAX_INK_SHARE = 0.15  # a cut making more of the image ink may have split the paper's tones
_MIN_FILL_CONTRAST = 60  # grey levels between ink and room fills
_MARK_MAX_SHARE = 0.04  # free-standing ink at most this share of the ink's extent across is text
_FURNITURE_MAX_SHARE = 0.1  # furniture covers at most this share of the plan's bounding box
_FRAME_MIN_MARGIN = 0.08  # a frame round the plan this far from it (share of its extent): a border
_MARK_MIN_CHROMA = 64  # max - min of B, G, R: a coloured mark (escape route, extinguisher, fill)
_LINE_MIN_PX = 4  # a line the marks cut is rejoined when it runs on this far on both sides
_SHEET_MIN_GAP = 0.05  # ink this far beside the plan (share of its extent) is on the sheet
_SHEET_MAX_INK = 0.5  # and holds less than this share of the plan's ink (more: part of the plan)


def as_grey(image: np.ndarray) -> np.ndarray:
    """(H, W) uint8 grey from a grey, BGR or BGRA uint8 image (alpha composited on white);
    strongly coloured marks on a colour drawing become paper (:func:`without_colour_marks`)."""
    image = np.asarray(image)
    if image.dtype != np.uint8:
        raise InputError(f"image must be uint8, got {image.dtype}")
    if image.ndim == 2:
        return image
    if image.ndim == 3 and image.shape[2] == 4:
        alpha = image[..., 3:4].astype(np.float32) / 255.0
        bgr = image[..., :3].astype(np.float32) * alpha + 255.0 * (1.0 - alpha)
        return without_colour_marks(bgr.round().astype(np.uint8))
    if image.ndim == 3 and image.shape[2] == 3:
        return without_colour_marks(image)
    if image.ndim == 3 and image.shape[2] == 1:
        return image[..., 0]
    raise InputError(f"image must be (H, W) or (H, W, 3|4), got shape {image.shape}")


def without_colour_marks(bgr: np.ndarray) -> np.ndarray:
    """(H, W) uint8 grey of a BGR drawing whose strongly coloured pixels are painted paper.

    Plans are drawn in black or grey; what a sign or a listing adds in colour is drawn on the
    plan, not built: escape routes, exits, extinguishers, "you are here", coloured room fills.
    Pixels of chroma (max - min of B, G, R) at least ``_MARK_MIN_CHROMA``, and their tinted
    fringe (2 px, chroma at least an eighth of that), take the paper's grey (the median of the
    others). Where a mark crossed a line (a route drawn over a door's outline) the line is
    joined again under it: where a row (column) of ink at least ``_LINE_MIN_PX`` long stops at
    painted pixels and goes on beyond them, less than five times the marks' stroke width
    further along, the painted pixels between are inked. Nothing is painted when the colour is
    the drawing itself: over half the image (coloured paper, a blueprint), or coloured ink
    (darker than grey 200) at least as plentiful as the neutral ink (a plan drawn in colour).
    """
    grey = cv2.cvtColor(bgr, cv2.COLOR_BGR2GRAY)
    chroma = bgr.max(axis=2).astype(np.int16) - bgr.min(axis=2)
    coloured = chroma >= _MARK_MIN_CHROMA
    n_coloured = int(np.count_nonzero(coloured))
    if n_coloured == 0 or n_coloured > coloured.size // 2:
        return grey
    neutral_ink = ~coloured & (grey < 128)
    if np.count_nonzero(coloured & (grey < 200)) >= np.count_nonzero(neutral_ink):
        return grey
    ring = cv2.dilate(coloured.astype(np.uint8), np.ones((5, 5), np.uint8)) > 0
    painted = coloured | (ring & (chroma >= _MARK_MIN_CHROMA // 8))
    out = grey.copy()
    out[painted] = int(np.median(grey[~painted]))
    gap = 5 * max(stroke_width_px(coloured), 1) + 3
    ink = (out < 128).astype(np.uint8)
    joined = np.zeros(ink.shape, bool)
    for line, across in (((1, _LINE_MIN_PX), (1, gap)), ((_LINE_MIN_PX, 1), (gap, 1))):
        along = cv2.morphologyEx(ink, cv2.MORPH_OPEN, np.ones(line, np.uint8))
        joined |= cv2.morphologyEx(along, cv2.MORPH_CLOSE, np.ones(across, np.uint8)) > 0
    out[painted & joined & (ink == 0)] = int(np.median(grey[neutral_ink]))
    return out


def _ridge(grey: np.ndarray, depth: float, reach: int = 2) -> np.ndarray:
    """Pixels at least ``depth`` (>= 0) darker than both pixels ``reach`` px away along some
    axis or diagonal: the middle of a thin dark stroke, not the paper between two close strokes.
    ``grey`` is uint8: a neighbour darker than the pixel differs by 0 (saturated), never more
    than ``depth``."""
    g = cv2.copyMakeBorder(grey, reach, reach, reach, reach, cv2.BORDER_REPLICATE)
    h, w = grey.shape
    centre = g[reach : reach + h, reach : reach + w]
    out = np.zeros((h, w), dtype=bool)
    for dr, dc in ((0, reach), (reach, 0), (reach, reach), (reach, -reach)):
        ahead = g[reach + dr : reach + dr + h, reach + dc : reach + dc + w]
        behind = g[reach - dr : reach - dr + h, reach - dc : reach - dc + w]
        out |= (cv2.subtract(ahead, centre) > depth) & (cv2.subtract(behind, centre) > depth)
    return out


def _grey_levels(grey: np.ndarray) -> tuple[int, int, int]:
    """The 0.1 %, 50 % and 99.9 % grey levels of an image."""
    cumulative = np.cumsum(np.bincount(grey.ravel(), minlength=256)) / grey.size
    lo, median, hi = (int(np.searchsorted(cumulative, q)) for q in (0.001, 0.5, 0.999))
    return lo, median, hi


def _ink_is_dark(grey: np.ndarray, lo: int, median: int, hi: int) -> bool:
    """Ink is the minority tone: dark unless most of the image is darker than mid-grey. Then
    the paper is the median tone, and the ink is dark still when what is darker than the paper
    draws thinner shapes than what is lighter (grey paper with white margins, a scan of a
    photocopy), light when it is the other way round (a negative, a blueprint)."""
    if median >= (lo + hi) / 2:
        return True
    darker = grey < median - _MIN_CONTRAST // 2
    lighter = grey > median + _MIN_CONTRAST // 2
    return _thin_share(darker) > _thin_share(lighter)


def _thin_share(mask: np.ndarray) -> float:
    """Share of ``mask``'s pixels in strokes thinner than ``_THICK_PX`` (gone after an opening
    that wide): near 1 for lines, near 0 for paper and margins."""
    count = np.count_nonzero(mask)
    if not count:
        return 0.0
    kernel = np.ones((_THICK_PX, _THICK_PX), np.uint8)
    thick = cv2.morphologyEx(mask.astype(np.uint8), cv2.MORPH_OPEN, kernel)
    return 1.0 - np.count_nonzero(thick) / count


def _with_paper_white(grey: np.ndarray, median: int) -> np.ndarray:
    """``grey`` lightened so that its paper, the median tone, is white (lighter tones too)."""
    scaled = grey.astype(np.float32) * (255.0 / max(median, 1))
    return np.clip(scaled, 0, 255).astype(np.uint8)


def ink_is_dark(image: np.ndarray) -> bool:
    """Whether a drawing has dark lines on light paper (False: light lines on dark paper, as a
    negative or a blueprint)."""
    grey = as_grey(image)
    return grey.size == 0 or _ink_is_dark(grey, *_grey_levels(grey))


def dark_on_light(grey: np.ndarray) -> np.ndarray:
    """``grey`` with dark ink on light paper: a negative or a blueprint inverted, any other
    drawing as it is (the same array). The word reader, like the network, was trained on dark
    letters on light paper."""
    return grey if ink_is_dark(grey) else 255 - grey


def _below_fills(grey: np.ndarray, threshold: float) -> float:
    """``threshold``, or a cut below it when it made too much of the drawing ink.

    Ink (lines, filled walls) is a minority of a drawing, at most about a fifth of it. A cut
    leaving more than ``_MAX_INK_SHARE`` of the pixels darker may have split the paper's own tones
    (rooms filled with greys or colours, white elsewhere): while the pixels below the cut are two
    tones at least ``_MIN_FILL_CONTRAST`` apart, the Otsu cut between them moves the cut down, so
    it ends below the lightest fills that are darker than the paper, at the ink. Noisy black ink
    is one tone and keeps the first cut.
    """
    if np.count_nonzero(grey <= threshold) <= _MAX_INK_SHARE * grey.size:
        return threshold
    dark = grey[grey <= threshold]
    while dark.size:
        sub, _ = cv2.threshold(dark.reshape(-1, 1), 0, 255, cv2.THRESH_BINARY + cv2.THRESH_OTSU)
        darker, lighter = dark[dark <= sub], dark[dark > sub]
        if darker.size == 0 or lighter.size == 0:
            break
        if float(lighter.mean()) - float(darker.mean()) < _MIN_FILL_CONTRAST:
            break
        threshold, dark = float(sub), darker
    return threshold


def binarize(image: np.ndarray, *, faint: bool = False) -> np.ndarray:
    """(H, W) bool mask of line (ink) pixels.

    Ink is, OR-ed: raw or lightly blurred grey at most the Otsu cut (moved to the middle of an
    empty grey range, clamped to the middle 60 % between ink and paper, then below any grey room
    fills, see ``_below_fills``), or a thin stroke at
    least 12 % of the ink-paper contrast darker than the local paper (13 px black-hat). Isolated
    dark specks of <= 3 px are dropped, then a 3x3 closing seals hairline anti-aliasing gaps.
    Ink is the minority tone: a mostly dark image is read as light lines on dark paper, unless
    its darker tones draw the thinner shapes (dark lines on grey paper: the paper is made white
    first, :func:`_ink_is_dark`). A uniform
    image (contrast < 40 grey levels) has no lines. The paper between the lines of hatched walls
    is ink too (:func:`~f2n_drake.perception.hatching.with_hatch_cells`).

    ``faint``: a thin stroke is ink from 10 grey levels below the local paper (more on noisy
    paper), whatever the ink-paper contrast: for drawings whose lines are far lighter than their
    text (a CAD export's light-grey hairlines, shrunk or saved as JPEG), which the default cut
    leaves with no closed outline. It reads grey furniture and dimension lines as ink too.
    """
    grey = as_grey(image)
    if grey.size == 0:
        return np.zeros(grey.shape, dtype=bool)
    lo, median, hi = _grey_levels(grey)
    if hi - lo < _MIN_CONTRAST:
        return np.zeros(grey.shape, dtype=bool)
    if not _ink_is_dark(grey, lo, median, hi):  # light lines on dark paper
        grey, lo, hi = 255 - grey, 255 - hi, 255 - lo
    elif median < (lo + hi) / 2:  # dark lines on grey paper
        grey = _with_paper_white(grey, median)
        lo, _, hi = _grey_levels(grey)
    return with_hatch_cells(
        grey, _dark_ink(grey, lo, hi, faint), partial(_ink_of_dark_drawing, faint=faint)
    )


def _ink_of_dark_drawing(grey: np.ndarray, faint: bool = False) -> np.ndarray:
    """The ink of a drawing known to have dark lines on light paper (hatched walls left open)."""
    lo, _, hi = _grey_levels(grey)
    if hi - lo < _MIN_CONTRAST:
        return np.zeros(grey.shape, dtype=bool)
    return _dark_ink(grey, lo, hi, faint)


def _dark_ink(grey: np.ndarray, lo: int, hi: int, faint: bool = False) -> np.ndarray:
    """:func:`binarize` of dark lines on light paper whose 0.1 % and 99.9 % grey levels are
    ``lo`` and ``hi``, before hatched walls are closed."""
    # Otsu splits at <= t vs > t; move the cut to the middle of any empty grey range above t.
    otsu, _ = cv2.threshold(grey, 0, 255, cv2.THRESH_BINARY + cv2.THRESH_OTSU)
    above = np.flatnonzero(np.bincount(grey.ravel(), minlength=256)[int(otsu) + 1 :])
    cut = (otsu + (otsu + 1 + above[0])) / 2 if above.size else otsu
    threshold = float(np.clip(cut, lo + 0.2 * (hi - lo), lo + 0.8 * (hi - lo)))
    threshold = _below_fills(grey, threshold)
    blurred = cv2.GaussianBlur(grey, (3, 3), 0.7)
    ink = (grey <= threshold) | (blurred <= threshold)
    # Faint thin strokes (grey, blurred) next to heavy filled walls fall above a global cut:
    # catch them by their contrast to the local paper level (black-hat transform).
    # Noise makes short clusters there: only strokes of >= _MIN_STROKE_PX pixels count, and the
    # contrast margin grows with the noise level (robust sigma of the blurred paper texture).
    paper = cv2.morphologyEx(
        blurred, cv2.MORPH_CLOSE, np.ones((_BLACKHAT_PX, _BLACKHAT_PX), np.uint8)
    )
    texture = (blurred.astype(np.int16) - cv2.blur(blurred, (5, 5)))[::3, ::3]
    sigma = 1.4826 * float(np.median(np.abs(texture[grey[::3, ::3] > threshold])))
    contrast = (
        _FAINT_STROKE_CONTRAST
        if faint
        else max(_MIN_STROKE_CONTRAST, _STROKE_CONTRAST_SHARE * (hi - lo))
    )
    margin = max(contrast, _NOISE_MARGIN_SIGMAS * sigma)
    # how much darker than the paper [grey levels]; lighter is 0 (saturated), as margin > 0
    below_paper, grey_below_paper = cv2.subtract(paper, blurred), cv2.subtract(paper, grey)
    strokes = (below_paper > margin) & (grey_below_paper > margin / 2)
    strokes &= _ridge(blurred, margin / 2)
    # A one-pixel hairline loses half its contrast to the blur: take it on the raw grey.
    strokes |= (grey_below_paper > margin) & _ridge(grey, margin / 2, reach=1)
    strokes = strokes.astype(np.uint8)
    n, cc, stats, _ = cv2.connectedComponentsWithStats(strokes, connectivity=8)
    long_stroke = stats[:, cv2.CC_STAT_AREA] >= _MIN_STROKE_PX
    long_stroke[0] = False
    ink |= long_stroke[cc]
    ink = ink.astype(np.uint8)
    n, cc, stats, _ = cv2.connectedComponentsWithStats(ink, connectivity=8)
    small = stats[:, cv2.CC_STAT_AREA] <= _MAX_SPECK_PX
    small[0] = False
    if small.any():
        ink[small[cc]] = 0
    kernel = np.ones((3, 3), np.uint8)
    return cv2.morphologyEx(ink, cv2.MORPH_CLOSE, kernel).astype(bool)


def stroke_width_px(lines: np.ndarray, longest_px: int = 16) -> int:
    """Outline thickness of a binarised drawing [px]: the most common length of the ink runs
    across rows and columns (a vertical stroke w px wide gives row runs of w), counting runs
    shorter than ``longest_px``; 0 when there is no such run."""
    counts = np.zeros(longest_px, dtype=np.int64)
    for ink in (lines, lines.T):
        steps = np.diff(np.pad(ink.astype(np.int8), ((0, 0), (1, 1))), axis=1)
        starts = np.flatnonzero(steps.ravel() == 1)
        ends = np.flatnonzero(steps.ravel() == -1)  # run k ends where run k started, row-major
        runs = ends - starts
        counts += np.bincount(runs[runs < longest_px], minlength=longest_px)
    counts[0] = 0
    return int(np.argmax(counts)) if counts.any() else 0


@dataclass(frozen=True)
class Marks:
    """The free-standing ink of a drawing (:func:`free_marks`), (H, W) bool masks.

    Attributes:
        annotation: what is drawn on the plan, not built: words and numbers (room names, areas,
            dimensions), symbols, a frame round the sheet. No obstacle: the paper it stands on
            and encloses belongs to the room (or the outside) around it.
        furniture: larger marks within the plan: beds, sofas, tables. Obstacles: the paper they
            enclose is no room.
    """

    annotation: np.ndarray
    furniture: np.ndarray

    @property
    def ink(self) -> np.ndarray:
        """Every mark's ink."""
        return self.annotation | self.furniture


def free_marks(lines: np.ndarray, max_share: float = _MARK_MAX_SHARE) -> Marks:
    """The marks of a binarised drawing: room names, dimensions, furniture standing in rooms.

    A plan's walls, doors and windows are one connected piece of ink, the largest; a door swing
    or a window's panes touch it. A mark is any other connected piece of ink (8-connected). One
    at most ``max_share`` of the drawing's ink extent across is an annotation (a word or number:
    anti-aliased letters run together; a north arrow), wherever it is, and so is a frame round
    all the other ink at least ``_FRAME_MIN_MARGIN`` of its extent away from it on every side
    (a sheet's border, never the plan), and so is a piece holding words beside the plan (neither
    within it nor round it), at least ``_SHEET_MIN_GAP`` of the plan's extent away from its ink
    and with less than ``_SHEET_MAX_INK`` of its ink: a title block, a legend. A larger piece
    within the plan whose bounding box covers at most ``_FURNITURE_MAX_SHARE`` of the plan's is
    furniture. Other pieces are structure: an annex or a detached balcony built against the
    plan, either line of double walls drawn with no openings joining the two, the plan's other
    half. Marks are no walls and no connectors.
    """
    lines = np.asarray(lines, bool)
    none = np.zeros(lines.shape, bool)
    n, ink, stats, _ = cv2.connectedComponentsWithStats(lines.astype(np.uint8), connectivity=8)
    if n <= 2:
        return Marks(none, none)
    x, y, w, h, area = (stats[:, i].astype(np.int64) for i in range(5))  # 0: the paper
    frame = _frames(ink, stats)
    extent = max((x + w)[1:].max() - x[1:].min(), (y + h)[1:].max() - y[1:].min())
    structure = int(np.argmax(np.where(frame, -1, area)[1:])) + 1
    small = np.minimum(w, h) <= max_share * extent
    piece = w * h <= _FURNITURE_MAX_SHARE * w[structure] * h[structure]  # not a wall's outline
    within = np.zeros(n, bool)
    within[ink[enclosed_by(ink == structure) & lines]] = True
    annotation = small | frame
    annotation[[0, structure]] = within[[0, structure]] = False
    round_it = (x <= x[structure]) & (y <= y[structure])
    round_it &= (x + w >= x[structure] + w[structure]) & (y + h >= y[structure] + h[structure])
    beside = np.flatnonzero(~(annotation | within | round_it))
    if beside.size:
        gap = cv2.distanceTransform((ink != structure).astype(np.uint8), cv2.DIST_L2, 3)
        nearest = np.full(n, np.inf, np.float32)  # per piece, its least distance to the plan
        np.minimum.at(nearest, ink[lines], gap[lines])  # over ink pixels only: fast on a sheet
        nearest = nearest[beside]
        far = beside[nearest >= _SHEET_MIN_GAP * max(w[structure], h[structure])]
        far = far[area[far] < _SHEET_MAX_INK * area[structure]]  # not the plan's other half
        annotation[[k for k in far if _holds_words(ink, stats[k], k, small)]] = True
    return Marks(annotation[ink], (within & piece & ~annotation)[ink])


def _holds_words(ink: np.ndarray, box: np.ndarray, k: int, words: np.ndarray) -> bool:
    """Whether component ``k`` of ``ink`` (labels; ``box``: its stats row) encloses ink of the
    components ``words`` marks (bool per label), as a title block or a legend holds its text."""
    x, y, w, h = (int(v) for v in box[:4])
    crop = ink[y : y + h, x : x + w]
    return bool(words[crop[enclosed_by(crop == k)]].any())


def _frames(ink: np.ndarray, stats: np.ndarray) -> np.ndarray:
    """(n,) bool: the components of ``ink`` (labels; 0 is the paper) that frame the drawing: an
    outline (no ink of its own beyond ``_FRAME_MIN_MARGIN`` of its box from the box's sides)
    whose box holds every other component's, with that margin of their extent to spare on all
    sides, around content at least a third as wide as itself."""
    n = len(stats)
    frame = np.zeros(n, bool)
    x0, y0, w, h = (stats[:, i].astype(np.int64) for i in range(4))
    x1, y1 = x0 + w, y0 + h
    for k in range(1, n):
        others = np.ones(n, bool)
        others[[0, k]] = False
        if not others.any():
            continue
        ox0, oy0, ox1, oy1 = x0[others].min(), y0[others].min(), x1[others].max(), y1[others].max()
        extent = max(ox1 - ox0, oy1 - oy0)
        margin = _FRAME_MIN_MARGIN * extent
        if not (
            x0[k] <= ox0 - margin
            and y0[k] <= oy0 - margin
            and x1[k] >= ox1 + margin
            and y1[k] >= oy1 + margin
            and extent >= max(w[k], h[k]) / 3
        ):
            continue
        mx, my = int(np.ceil(_FRAME_MIN_MARGIN * w[k])), int(np.ceil(_FRAME_MIN_MARGIN * h[k]))
        inner = ink[y0[k] + my : y1[k] - my, x0[k] + mx : x1[k] - mx]
        frame[k] = not (inner == k).any()
    return frame


def enclosed_by(ink: np.ndarray) -> np.ndarray:
    """(H, W) bool: the paper ``ink`` alone encloses (4-connected regions of not-``ink`` that
    do not touch the image border)."""
    n, regions = cv2.connectedComponents((~np.asarray(ink, bool)).astype(np.uint8), connectivity=4)
    enclosed = np.ones(n, bool)
    enclosed[0] = False  # the ink itself
    enclosed[np.concatenate([regions[0], regions[-1], regions[:, 0], regions[:, -1]])] = False
    return enclosed[regions]
