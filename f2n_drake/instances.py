"""Drawing + per-pixel labels -> instances: enclosed regions, majority vote, open-passage split.

An instance is a connected region of non-line pixels (4-connectivity, so an 8-connected line of
ink always separates two regions) that does not touch the image border. Its class is the majority
of the predicted labels inside it, which corrects scattered errors of the network. Regions voted
``background`` (storage, stairs, ... render as background) are dropped: their pixels get instance
id 0, like line pixels and the outside. Regions of one space class separated only by ink the
network also calls that class (a door swing's leaf and arc drawn inside a room) are one instance.
A door or window drawn with no white interior (thick outlines in a thin wall) becomes an instance
made of its ink pixels the network labels as that connector, so the rooms stay connected.

Open passages (beyond FloorPlan2Nav): a kitchen open to the living room is one white region of the
drawing. When a second space class holds a substantial (``SplitOptions.min_fraction`` of the region
or ``min_area_m2``) and compact (survives a majority smoothing and an opening; solidity >=
``min_solidity``) part of a space region, the region is split along the network's own semantic
boundary: seeds are those smoothed compact components of each space class, every pixel of the
region takes the class of its nearest seed, and each connected part becomes an instance. The 2 px
strip where two parts touch (one pixel row from each side) becomes an instance of class
``"opening"``, the connector between the two spaces. Scattered noise never survives the smoothing,
so it never splits a room.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import cv2
import numpy as np

from f2n_drake.classes import (
    CLASS_ID,
    CLASS_NAMES,
    CONNECTOR_CLASSES,
    NUM_CLASSES,
    OPENING,
    SPACE_CLASSES,
)
from f2n_drake.errors import InputError
from f2n_drake.parsed import Instance, ParsedPlan
from f2n_drake.raster import PixelGrid

_SPACE_IDS = np.array([CLASS_ID[name] for name in SPACE_CLASSES])
_CONNECTOR_IDS = np.array([CLASS_ID[name] for name in CONNECTOR_CLASSES])
_MIN_CONTRAST = 40  # grey levels between ink and paper below which an image has no lines
_MAX_SPECK_PX = 3  # isolated dark specks up to this size are noise, not lines
_BLACKHAT_PX = 13  # window [px] giving the local paper level around thin strokes
_MIN_STROKE_CONTRAST = 20  # grey levels below local paper that make a thin stroke ink
_MIN_INK_CONNECTOR_M2 = 0.1  # smallest connector made of ink alone (with a known scale) [m^2]
_MIN_INK_CONNECTOR_PX = 100  # the same without a scale [px]
_CONNECTOR_REACH_PX = 3  # an ink-only connector must have two non-wall regions this close
_MIN_STROKE_PX = 20  # thin strokes found by local contrast must have this many pixels
_NOISE_MARGIN_SIGMAS = 4  # and be darker than paper by this many paper-noise sigmas


@dataclass(frozen=True)
class SplitOptions:
    """When and how a merged space region is split into open-passage parts.

    Attributes:
        min_fraction: a second space class must hold at least this fraction of the region...
        min_area_m2: ...or at least this area [m^2] (used only when the grid is known).
        min_part_px: and never fewer pixels than this.
        open_px: noise scale [px]: seeds are the pixels where the class holds over half of the
            region in a ``2 * open_px + 1`` window, opened with an ``open_px`` square.
        min_solidity: a seed component's area over its convex-hull area must reach this.
        min_cut_px: cut strips with fewer pixels are not recorded as openings.
    """

    min_fraction: float = 0.15
    min_area_m2: float = 3.0
    min_part_px: int = 64
    open_px: int = 5
    min_solidity: float = 0.6
    min_cut_px: int = 3


DEFAULT_SPLIT = SplitOptions()


def as_grey(image: np.ndarray) -> np.ndarray:
    """(H, W) uint8 grey from a grey, BGR or BGRA uint8 image (alpha composited on white)."""
    image = np.asarray(image)
    if image.dtype != np.uint8:
        raise InputError(f"image must be uint8, got {image.dtype}")
    if image.ndim == 2:
        return image
    if image.ndim == 3 and image.shape[2] == 4:
        alpha = image[..., 3:4].astype(np.float32) / 255.0
        bgr = image[..., :3].astype(np.float32) * alpha + 255.0 * (1.0 - alpha)
        return cv2.cvtColor(bgr.round().astype(np.uint8), cv2.COLOR_BGR2GRAY)
    if image.ndim == 3 and image.shape[2] == 3:
        return cv2.cvtColor(image, cv2.COLOR_BGR2GRAY)
    if image.ndim == 3 and image.shape[2] == 1:
        return image[..., 0]
    raise InputError(f"image must be (H, W) or (H, W, 3|4), got shape {image.shape}")


def _ridge(grey: np.ndarray, depth: float, reach: int = 2) -> np.ndarray:
    """Pixels at least ``depth`` darker than both pixels ``reach`` px away along some axis or
    diagonal: the middle of a thin dark stroke, not the paper between two close strokes."""
    g = np.pad(grey.astype(np.int16), reach, mode="edge")
    h, w = grey.shape
    centre = g[reach : reach + h, reach : reach + w]
    out = np.zeros((h, w), dtype=bool)
    for dr, dc in ((0, reach), (reach, 0), (reach, reach), (reach, -reach)):
        ahead = g[reach + dr : reach + dr + h, reach + dc : reach + dc + w]
        behind = g[reach - dr : reach - dr + h, reach - dc : reach - dc + w]
        out |= (ahead - centre > depth) & (behind - centre > depth)
    return out


def binarize(image: np.ndarray) -> np.ndarray:
    """(H, W) bool mask of line (ink) pixels.

    Ink is, OR-ed: raw or lightly blurred grey at most the Otsu cut (moved to the middle of an
    empty grey range, clamped to the middle 60 % between ink and paper), or a thin stroke at
    least 12 % of the ink-paper contrast darker than the local paper (13 px black-hat). Isolated
    dark specks of <= 3 px are dropped, then a 3x3 closing seals hairline anti-aliasing gaps.
    Ink is the minority tone: a mostly dark image is read as light lines on dark paper. A uniform
    image (contrast < 40 grey levels) has no lines.
    """
    grey = as_grey(image)
    if grey.size == 0:
        return np.zeros(grey.shape, dtype=bool)
    cumulative = np.cumsum(np.bincount(grey.ravel(), minlength=256)) / grey.size
    lo, median, hi = (int(np.searchsorted(cumulative, q)) for q in (0.001, 0.5, 0.999))
    if hi - lo < _MIN_CONTRAST:
        return np.zeros(grey.shape, dtype=bool)
    if median < (lo + hi) / 2:  # light lines on dark paper
        grey, lo, hi = 255 - grey, 255 - hi, 255 - lo
    # Otsu splits at <= t vs > t; move the cut to the middle of any empty grey range above t.
    otsu, _ = cv2.threshold(grey, 0, 255, cv2.THRESH_BINARY + cv2.THRESH_OTSU)
    above = np.flatnonzero(np.bincount(grey.ravel(), minlength=256)[int(otsu) + 1 :])
    cut = (otsu + (otsu + 1 + above[0])) / 2 if above.size else otsu
    threshold = float(np.clip(cut, lo + 0.2 * (hi - lo), lo + 0.8 * (hi - lo)))
    blurred = cv2.GaussianBlur(grey, (3, 3), 0.7)
    ink = (grey <= threshold) | (blurred <= threshold)
    # Faint thin strokes (grey, blurred) next to heavy filled walls fall above a global cut:
    # catch them by their contrast to the local paper level (black-hat transform).
    # Noise makes short clusters there: only strokes of >= _MIN_STROKE_PX pixels count, and the
    # contrast margin grows with the noise level (robust sigma of the blurred paper texture).
    paper = cv2.morphologyEx(
        blurred, cv2.MORPH_CLOSE, np.ones((_BLACKHAT_PX, _BLACKHAT_PX), np.uint8)
    ).astype(np.int16)
    texture = (blurred.astype(np.int16) - cv2.blur(blurred, (5, 5)))[::3, ::3]
    sigma = 1.4826 * float(np.median(np.abs(texture[grey[::3, ::3] > threshold])))
    margin = max(_MIN_STROKE_CONTRAST, 0.12 * (hi - lo), _NOISE_MARGIN_SIGMAS * sigma)
    strokes = (paper - blurred > margin) & (paper - grey > margin / 2)
    strokes = (strokes & _ridge(blurred, margin / 2)).astype(np.uint8)
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


def _contour(mask: np.ndarray, offset: tuple[int, int]) -> np.ndarray:
    """(N, 2) float outer contour (col, row) of the largest blob of a bool crop."""
    contours, _ = cv2.findContours(
        np.pad(mask, 1).astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE
    )
    if not contours:
        return np.zeros((0, 2))
    best = max(contours, key=lambda c: (cv2.contourArea(c), len(c)))
    return best.reshape(-1, 2).astype(float) + (offset[0] - 1, offset[1] - 1)


def _instance(
    iid: int, class_name: str, mask: np.ndarray, labels: np.ndarray, offset: tuple[int, int]
) -> Instance:
    """An Instance from a bool crop ``mask`` whose top-left pixel is ``offset`` (col, row)."""
    rows, cols = np.nonzero(mask)
    votes = np.bincount(labels[mask], minlength=NUM_CLASSES)
    return Instance(
        id=iid,
        class_name=class_name,
        contour_px=_contour(mask, offset),
        area_px=int(rows.size),
        centroid_px=(float(cols.mean() + offset[0]), float(rows.mean() + offset[1])),
        votes={int(c): int(v) for c, v in enumerate(votes) if v},
    )


def _seeds(
    region: np.ndarray,
    labels: np.ndarray,
    cls: int,
    min_px: int,
    opt: SplitOptions,
    need_compact: bool,
) -> np.ndarray | None:
    """Union of the large (and compact) smoothed components of class ``cls`` in a region crop.

    Smoothing: a pixel is in the class when the class holds over half of the region pixels in
    the ``2 * open_px + 1`` window around it (removes scattered votes, fills pin-holes), then an
    ``open_px`` opening removes thin strokes.
    """
    size = (2 * opt.open_px + 1,) * 2
    in_region = cv2.boxFilter(region.astype(np.float32), -1, size, normalize=True)
    in_class = cv2.boxFilter(
        (region & (labels == cls)).astype(np.float32), -1, size, normalize=True
    )
    mask = (region & (in_class > 0.5 * in_region)).astype(np.uint8)
    kernel = np.ones((opt.open_px, opt.open_px), np.uint8)
    opened = cv2.morphologyEx(mask, cv2.MORPH_OPEN, kernel)
    n, cc, stats, _ = cv2.connectedComponentsWithStats(opened, connectivity=4)
    seed = np.zeros(region.shape, dtype=bool)
    for k in range(1, n):
        if stats[k, cv2.CC_STAT_AREA] < min_px:
            continue
        if need_compact:
            pts = cv2.findNonZero((cc == k).astype(np.uint8))
            hull_area = cv2.contourArea(cv2.convexHull(pts))
            if stats[k, cv2.CC_STAT_AREA] < opt.min_solidity * max(hull_area, 1.0):
                continue
        seed |= cc == k
    return seed if seed.any() else None


def split_region(
    region: np.ndarray, labels: np.ndarray, main_cls: int, min_px: int, opt: SplitOptions
) -> tuple[list[tuple[int, np.ndarray]], list[np.ndarray]] | None:
    """Parts ``[(class_id, bool crop)]`` and opening strips ``[bool crop]`` of one region crop, or
    None when it holds no second substantial, compact space class."""
    seeds: dict[int, np.ndarray] = {}
    votes = np.bincount(labels[region], minlength=NUM_CLASSES)
    for cls in _SPACE_IDS:
        if cls != main_cls and votes[cls] < min_px:
            continue
        seed = _seeds(region, labels, int(cls), min_px, opt, need_compact=cls != main_cls)
        if seed is not None:
            seeds[int(cls)] = seed
    if main_cls not in seeds or len(seeds) < 2:
        return None
    classes = np.array(list(seeds))
    dist = np.stack(
        [cv2.distanceTransform((~seed).astype(np.uint8), cv2.DIST_L2, 3) for seed in seeds.values()]
    )
    assign = np.where(region, classes[np.argmin(dist, axis=0)], -1)
    seed_any = np.zeros(region.shape, dtype=bool)
    for seed in seeds.values():
        seed_any |= seed
    # Pieces cut off from every seed (non-convex regions) join the class they touch most.
    parts: list[tuple[int, np.ndarray]] = []
    part_index = np.zeros(region.shape, dtype=np.int32)
    for cls in classes:
        n, cc = cv2.connectedComponents((assign == cls).astype(np.uint8), connectivity=4)
        for k in range(1, n):
            piece = cc == k
            if (piece & seed_any).any():
                parts.append((int(cls), piece))
                part_index[piece] = len(parts)
    orphans = region & (part_index == 0)
    if orphans.any():
        n, cc = cv2.connectedComponents(orphans.astype(np.uint8), connectivity=4)
        for k in range(1, n):
            piece = cc == k
            ring = cv2.dilate(piece.astype(np.uint8), np.ones((3, 3), np.uint8)).astype(bool)
            touching = part_index[ring & ~piece]
            touching = touching[touching > 0]
            if touching.size:
                p = int(np.bincount(touching).argmax())
                parts[p - 1][1][piece] = True
                part_index[piece] = p
    if len(parts) < 2:
        return None
    # Cut strips: pixels of a part 4-adjacent to another part, from both sides.
    cut_pair = np.zeros(region.shape, dtype=np.int64)
    n_parts = len(parts) + 1
    for a, b, sa, sb in (
        (part_index[:, :-1], part_index[:, 1:], np.s_[:, :-1], np.s_[:, 1:]),
        (part_index[:-1, :], part_index[1:, :], np.s_[:-1, :], np.s_[1:, :]),
    ):
        edge = (a > 0) & (b > 0) & (a != b)
        code = np.minimum(a, b) * n_parts + np.maximum(a, b)
        for s in (sa, sb):
            view = cut_pair[s]
            view[edge & (view == 0)] = code[edge & (view == 0)]
    cuts: list[np.ndarray] = []
    for code in np.unique(cut_pair[cut_pair > 0]):
        n, cc = cv2.connectedComponents((cut_pair == code).astype(np.uint8), connectivity=8)
        for k in range(1, n):
            strip = cc == k
            if strip.sum() >= opt.min_cut_px:
                cuts.append(strip)
    for strip in cuts:
        for _, piece in parts:
            piece &= ~strip
    return parts, cuts


def _regions(
    cc: np.ndarray,
    stats: np.ndarray,
    keep: np.ndarray,
    winner: np.ndarray,
    labels: np.ndarray,
    lines: np.ndarray,
    bridge_px: int = 5,
) -> Iterator[tuple[int, tuple[int, int, int, int], np.ndarray]]:
    """Yield ``(class id, (x0, y0, x1, y1), bool crop)`` per region to turn into instances.

    Kept components of one space class that ink predicted as that same class separates (a door
    swing's arc and leaf drawn inside a room) are one region: a ``bridge_px`` closing of their
    union, limited to those components and that ink, joins them, bridging ink included.
    """
    kernel = np.ones((bridge_px, bridge_px), np.uint8)
    merged = np.zeros(len(keep), dtype=bool)
    groups: list[tuple[int, np.ndarray]] = []
    for cls in _SPACE_IDS:
        members = keep & (winner == cls)
        if members.sum() < 2:
            continue
        union = members[cc]
        allowed = union | (lines & (labels == cls))
        closed = cv2.morphologyEx(union.astype(np.uint8), cv2.MORPH_CLOSE, kernel).astype(bool)
        n, group = cv2.connectedComponents((closed & allowed).astype(np.uint8), connectivity=4)
        ids = np.flatnonzero(members)
        group_of = np.zeros(len(keep), dtype=np.int32)
        group_of[cc[union]] = group[union]  # a component lies inside one group
        anchor = group_of[ids]
        for g in np.unique(anchor):
            together = ids[anchor == g]
            if together.size > 1:
                merged[together] = True
                groups.append((int(cls), group == g))
    for k in np.flatnonzero(keep & ~merged):
        x0, y0 = stats[k, cv2.CC_STAT_LEFT], stats[k, cv2.CC_STAT_TOP]
        x1, y1 = x0 + stats[k, cv2.CC_STAT_WIDTH], y0 + stats[k, cv2.CC_STAT_HEIGHT]
        yield int(winner[k]), (x0, y0, x1, y1), cc[y0:y1, x0:x1] == k
    for cls, mask in groups:
        x0, y0, w, h = cv2.boundingRect(mask.astype(np.uint8))
        yield cls, (x0, y0, x0 + w, y0 + h), mask[y0 : y0 + h, x0 : x0 + w]


def _add_ink_connectors(
    lines: np.ndarray,
    labels: np.ndarray,
    regions: tuple[np.ndarray, np.ndarray],
    instance_ids: np.ndarray,
    instances: list[Instance],
    min_area_px: int,
) -> None:
    """Add connectors drawn with no white interior (thick outlines in a thin wall fill the whole
    door rectangle): an 8-connected blob of ink the network labels door/window/front door
    becomes an instance of its majority connector class when it has ``min_area_px`` pixels
    (0.1 m^2, or 100 px without a scale: smaller blobs are mostly misread wall),
    touches no connector instance, and joins two regions that are not walls (two rooms, or a
    room and the outside). ``regions`` is (component image, winner class per component).
    Edits ``instance_ids`` and ``instances`` in place."""
    ink_conn = lines & np.isin(labels, _CONNECTOR_IDS)
    if not ink_conn.any():
        return
    cc_regions, winner = regions
    square = np.ones((3, 3), np.uint8)
    conn_ids = [i.id for i in instances if i.class_name in CONNECTOR_CLASSES]
    near = cv2.dilate(np.isin(instance_ids, conn_ids).astype(np.uint8), square).astype(bool)
    n, cc, stats, _ = cv2.connectedComponentsWithStats(ink_conn.astype(np.uint8), connectivity=8)
    touched = np.zeros(n, dtype=bool)
    touched[cc[near]] = True
    height, width = lines.shape
    for k in range(1, n):
        if touched[k] or stats[k, cv2.CC_STAT_AREA] < min_area_px:
            continue
        x, y, w, h = (int(v) for v in stats[k, :4])
        r = _CONNECTOR_REACH_PX
        x0, y0, x1, y1 = max(x - r, 0), max(y - r, 0), min(x + w + r, width), min(y + h + r, height)
        blob = cc[y0:y1, x0:x1] == k
        reach = np.ones((2 * r + 1, 2 * r + 1), np.uint8)
        ring = cv2.dilate(blob.astype(np.uint8), reach).astype(bool) & ~lines[y0:y1, x0:x1]
        sides = np.unique(cc_regions[y0:y1, x0:x1][ring])
        if np.count_nonzero(winner[sides] != CLASS_ID["wall"]) < 2:
            continue
        crop_labels = labels[y0:y1, x0:x1]
        votes = np.bincount(crop_labels[blob], minlength=NUM_CLASSES)
        cls = int(_CONNECTOR_IDS[np.argmax(votes[_CONNECTOR_IDS])])
        iid = len(instances) + 1
        instance_ids[y0:y1, x0:x1][blob] = iid
        instances.append(_instance(iid, CLASS_NAMES[cls], blob, crop_labels, (x0, y0)))


def extract_instances(
    image: np.ndarray,
    labels: np.ndarray,
    *,
    grid: PixelGrid | None = None,
    min_area_px: int = 12,
    split: SplitOptions | None = DEFAULT_SPLIT,
    lines: np.ndarray | None = None,
    scale_source: str | None = None,
) -> ParsedPlan:
    """Instances of a drawing, each classed by the majority of ``labels`` inside it.

    Line pixels get instance id 0, except connectors with no white interior (see module doc).

    Args:
        image: (H, W) uint8 grey drawing (or BGR/BGRA), dark lines on light paper.
        labels: (H, W) uint8 per-pixel class ids (network prediction or ground truth).
        grid: pixel <-> metre mapping, if known (enables ``split.min_area_m2``).
        min_area_px: regions smaller than this [px] are specks and dropped.
        split: open-passage split options; None disables the split.
        lines: precomputed ``binarize(image)``.
        scale_source: recorded in the result; default "argument" with a grid, else "unknown".

    Returns:
        ParsedPlan with ``labels`` the given labels (unchanged) and instance ids 1..K.

    Raises:
        InputError: shapes differ or labels hold ids >= NUM_CLASSES.
    """
    labels = np.asarray(labels)
    if labels.shape != np.shape(image)[:2]:
        raise InputError(f"labels {labels.shape} and image {np.shape(image)[:2]} differ in size")
    if labels.size and int(labels.max()) >= NUM_CLASSES:
        raise InputError(f"label id {int(labels.max())} is not a class (< {NUM_CLASSES})")
    labels = labels.astype(np.uint8, copy=False)
    if lines is None:
        lines = binarize(image)
    height, width = labels.shape
    n, cc, stats, centroids = cv2.connectedComponentsWithStats(
        (~lines).astype(np.uint8), connectivity=4, ltype=cv2.CV_32S
    )
    x, y, w, h, area = (stats[:, i] for i in range(5))
    keep = (area >= min_area_px) & (x > 0) & (y > 0) & (x + w < width) & (y + h < height)
    keep[0] = False  # component 0 is the line pixels
    votes = np.bincount((cc * NUM_CLASSES + labels).ravel(), minlength=n * NUM_CLASSES)
    votes = votes.reshape(n, NUM_CLASSES)
    winner = votes.argmax(axis=1)
    keep &= winner != 0

    min_part_floor = split.min_part_px if split else 0
    abs_px = grid.length_px(1.0) ** 2 * split.min_area_m2 if (split and grid) else np.inf
    instance_ids = np.zeros((height, width), dtype=np.int32)
    instances: list[Instance] = []
    for cls, (x0, y0, x1, y1), crop in _regions(cc, stats, keep, winner, labels, lines):
        crop_labels = labels[y0:y1, x0:x1]
        result = None
        if split and cls in _SPACE_IDS:
            region_votes = np.bincount(crop_labels[crop], minlength=NUM_CLASSES)
            min_px = int(max(min_part_floor, min(split.min_fraction * crop.sum(), abs_px)))
            others = region_votes[_SPACE_IDS].copy()
            others[_SPACE_IDS == cls] = 0
            if others.max() >= min_px:
                result = split_region(crop, crop_labels, cls, min_px, split)
        ids_view = instance_ids[y0:y1, x0:x1]
        if result is None:
            iid = len(instances) + 1
            ids_view[crop] = iid
            instances.append(_instance(iid, CLASS_NAMES[cls], crop, crop_labels, (x0, y0)))
            continue
        parts, cuts = result
        for part_cls, piece in parts:
            iid = len(instances) + 1
            ids_view[piece] = iid
            instances.append(_instance(iid, CLASS_NAMES[part_cls], piece, crop_labels, (x0, y0)))
        for strip in cuts:
            iid = len(instances) + 1
            ids_view[strip] = iid
            instances.append(_instance(iid, OPENING, strip, crop_labels, (x0, y0)))
    min_ink_px = grid.length_px(1.0) ** 2 * _MIN_INK_CONNECTOR_M2 if grid else _MIN_INK_CONNECTOR_PX
    _add_ink_connectors(
        lines, labels, (cc, winner), instance_ids, instances, max(min_area_px, min_ink_px)
    )
    if scale_source is None:
        scale_source = "argument" if grid is not None else "unknown"
    return ParsedPlan(instance_ids, labels, instances, grid, scale_source)


def vote_corrected_labels(parsed: ParsedPlan) -> np.ndarray:
    """(H, W) uint8 labels after the vote: every instance's pixels take its class.

    Pixels of no instance (lines, outside, dropped background regions) and of ``opening``
    strips keep the network's label.
    """
    if not parsed.instances:
        return parsed.labels.copy()
    lut = np.full(max(inst.id for inst in parsed.instances) + 1, -1, dtype=np.int16)
    for inst in parsed.instances:
        if inst.class_name in CLASS_ID:
            lut[inst.id] = CLASS_ID[inst.class_name]
    voted = lut[parsed.instance_ids]
    return np.where(voted >= 0, voted, parsed.labels).astype(np.uint8)
