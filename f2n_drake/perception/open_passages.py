"""Open-passage split: one white region holding two rooms -> room parts and opening strips.

Open passages (beyond FloorPlan2Nav): a kitchen open to the living room is one white region of the
drawing. When the partner class of a space region (``SplitOptions.open_pairs``: living and kitchen)
holds a substantial (``SplitOptions.min_fraction`` of the region or ``min_area_m2``) and compact
(survives a majority smoothing and an opening; solidity >= ``min_solidity``) part of it, the region
is split along the network's own semantic boundary: seeds are those smoothed compact components of
each class, every pixel of the region takes the class of its nearest seed, and each connected part
becomes an instance. The 2 px strip where two parts touch (one pixel row from each side) becomes an
instance of class ``"opening"``, the connector between the two spaces. Scattered noise never
survives the smoothing, so it never splits a room.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from f2n_drake.core.classes import CLASS_ID, CLASS_NAMES, NUM_CLASSES, SPACE_CLASSES


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
        open_pairs: the pairs of space classes a region may be split into: by default only a
            kitchen open to the living room (the only open passage in the training data and
            the usual one in real flats; a bedroom the network half calls kitchen stays whole).
    """

    min_fraction: float = 0.15
    min_area_m2: float = 3.0
    min_part_px: int = 64
    open_px: int = 5
    min_solidity: float = 0.6
    min_cut_px: int = 3
    open_pairs: tuple[tuple[str, str], ...] = (("living", "kitchen"),)

    def __post_init__(self) -> None:
        for pair in self.open_pairs:
            if len(pair) != 2 or not set(pair) <= set(SPACE_CLASSES) or pair[0] == pair[1]:
                raise ValueError(f"open_pairs holds {pair!r}: need two different space classes")

    def partners(self, class_id: int) -> np.ndarray:
        """Space class ids a region of ``class_id`` may be split off into."""
        name = CLASS_NAMES[class_id]
        others = {b if a == name else a for a, b in self.open_pairs if name in (a, b)}
        return np.array([CLASS_ID[o] for o in sorted(others)], dtype=np.int64)


DEFAULT_SPLIT = SplitOptions()


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
    for cls in (main_cls, *opt.partners(main_cls)):
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
