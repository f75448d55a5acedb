"""Door swings beside a gap in a wall: a quarter-circle arc or an open leaf hinged at a jamb.

A real drawing tells a door from a plain gap in a wall by its swing: the leaf drawn open (a
straight line from one jamb, as long as the gap is wide, at 30 to 90 degrees to the wall) and
the arc its free end sweeps (a quarter circle about the hinge, from the leaf to the other
jamb). A double door draws two of each, each half as wide. :func:`swing_evidence` looks for
either on the ink around each gap, cheaply: for every gap, its two jambs on each face of the
wall, it samples

- **arcs** of radius ``RADII`` times the gap's width (a single leaf, or one of two) about
  the jamb on the face, over the quarter turn away from the wall, and counts a swing when at
  least ``ARC_COVER`` of the samples lie on ink while the circles ``_OFF_SHARE`` of the radius
  inside and outside it are at least ``ARC_CONTRAST`` emptier (a thin curve, not hatching or a
  fixture's fill);
- **leaves**: rays from the jamb at ``LEAF_ANGLES_DEG`` to the wall, along ``_LEAF_SPAN`` of
  the radius, on ink over at least ``LEAF_COVER`` of their length, the parallel rays
  ``_OFF_SHARE`` of the radius to both sides at least ``ARC_CONTRAST`` emptier, and ending
  there: the ray on beyond the tip (``_PAST_TIP`` of the radius) mostly off the ink (a wall
  running on from the jamb is no leaf). A leaf square to the wall, which a wall's corner beside
  the gap also draws, counts only with ``_ARC_SUPPORT`` of an arc drawn with it.

Samples within a pixel of the ink count as on it. The ink is the drawing's lines and its faint
lines (:func:`~f2n_drake.perception.window_inserts.ink_depth`): swings are often drawn light
grey.

The paper a door's leaf and arc cut off beside its gap (the swing's sector) is floor of the room
beyond the arc: :func:`join_swings` gives it that room's region.
"""

from __future__ import annotations

import cv2
import numpy as np
from scipy import ndimage

RADII: tuple[float, ...] = (1.0, 0.9, 0.5, 0.45)
"""Swing radii tried, as shares of the gap's width: one leaf (its frame eats a little), or one
of two."""
ARC_COVER = 0.6
"""Share of an arc's samples on ink for a swing."""
ARC_CONTRAST = 0.35
"""How much emptier (share of samples) the curves or rays beside a swing must be."""
LEAF_ANGLES_DEG: tuple[float, ...] = (90.0, 75.0, 60.0, 45.0, 30.0)
"""Angles to the wall of the open leaves tried [deg]."""
LEAF_COVER = 0.8
"""Share of a leaf's samples on ink."""
_OFF_SHARE = 0.25  # the curves and rays beside a swing lie this share of its radius off it
_LEAF_SPAN = (0.3, 0.9)  # the part of a leaf sampled, as shares of its length from the hinge
_SQUARE_LEAF_DEG = 85.0  # a leaf this square to the wall needs some of its arc drawn too
_ARC_SUPPORT = 0.3  # share of an arc's samples on ink that supports a square leaf
_PAST_TIP = (1.2, 1.6)  # beyond its tip, a leaf ends (a wall running on from a jamb does not)
_ARC_SPAN_DEG = (12.0, 78.0)  # the part of the quarter turn sampled [deg from the wall]
_SAMPLES = 16  # samples per arc or ray
_MIN_RADIUS_PX = 4.0  # smaller swings are no evidence


def _on(ink: np.ndarray, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """``ink`` at the (rounded) points, False off the image; same shape as ``rows``."""
    r, c = np.rint(rows).astype(np.int64), np.rint(cols).astype(np.int64)
    inside = (r >= 0) & (r < ink.shape[0]) & (c >= 0) & (c < ink.shape[1])
    out = np.zeros(r.shape, bool)
    out[inside] = ink[r[inside], c[inside]]
    return out


def _hinges(boxes: list[tuple[slice, slice]]) -> tuple[np.ndarray, ...]:
    """Per gap (bounding box) and jamb-face corner (4 each): hinge row and column [px], the
    unit vector along the wall into the gap and the unit normal away from the wall, and the
    gap's width [px]. A box wider than high is a gap in a horizontal wall."""
    rows, cols, along, normal, width = [], [], [], [], []
    for box in boxes:
        r0, r1 = box[0].start - 0.5, box[0].stop - 0.5
        c0, c1 = box[1].start - 0.5, box[1].stop - 0.5
        horizontal = (c1 - c0) >= (r1 - r0)
        if horizontal:
            corners = [(r0, c0, (0, 1), (-1, 0)), (r0, c1, (0, -1), (-1, 0))]
            corners += [(r1, c0, (0, 1), (1, 0)), (r1, c1, (0, -1), (1, 0))]
            w = c1 - c0
        else:
            corners = [(r0, c0, (1, 0), (0, -1)), (r1, c0, (-1, 0), (0, -1))]
            corners += [(r0, c1, (1, 0), (0, 1)), (r1, c1, (-1, 0), (0, 1))]
            w = r1 - r0
        for r, c, a, n in corners:
            rows.append(r)
            cols.append(c)
            along.append(a)
            normal.append(n)
            width.append(w)
    return (
        np.array(rows, float),
        np.array(cols, float),
        np.array(along, float).reshape(-1, 2),
        np.array(normal, float).reshape(-1, 2),
        np.array(width, float),
    )


def _arc_cover(ink, rows, cols, along, normal, radius) -> np.ndarray:
    """(N,) share of the samples of each arc on ink: radius ``radius`` about (rows, cols), from
    the wall (``along``) to the normal."""
    theta = np.deg2rad(np.linspace(*_ARC_SPAN_DEG, _SAMPLES))
    cos, sin = np.cos(theta)[None, :], np.sin(theta)[None, :]
    dr = along[:, :1] * cos + normal[:, :1] * sin
    dc = along[:, 1:] * cos + normal[:, 1:] * sin
    r = rows[:, None] + radius[:, None] * dr
    c = cols[:, None] + radius[:, None] * dc
    return _on(ink, r, c).mean(axis=1)


def _ray_cover(
    ink, rows, cols, along, normal, length, angle, offset, span=_LEAF_SPAN
) -> np.ndarray:
    """(N,) share of the samples of each ray on ink: from (rows, cols) at ``angle`` [rad] from
    the wall, over ``span`` of ``length``, shifted ``offset`` px sideways."""
    t = np.linspace(*span, _SAMPLES)[None, :] * length[:, None]
    direction = along * np.cos(angle) + normal * np.sin(angle)
    side = along * np.sin(angle) - normal * np.cos(angle)
    r = rows[:, None] + t * direction[:, :1] + offset[:, None] * side[:, :1]
    c = cols[:, None] + t * direction[:, 1:] + offset[:, None] * side[:, 1:]
    return _on(ink, r, c).mean(axis=1)


def swing_evidence(pieces: np.ndarray, ink: np.ndarray, candidates: np.ndarray) -> np.ndarray:
    """(n,) bool per label of ``pieces`` (0 and those not ``candidates`` False): whether a door's
    swing (arc or open leaf, see module doc) is drawn at the gap.

    Args:
        pieces: (H, W) int labels of the gaps.
        ink: (H, W) bool, the drawing's lines and faint lines.
        candidates: (n,) bool per label, the gaps to test.
    """
    n = len(candidates)
    found = np.zeros(n, bool)
    labels = np.flatnonzero(candidates[1:]) + 1
    boxes = ndimage.find_objects(pieces, max_label=n - 1)
    labels = np.array([k for k in labels if boxes[k - 1] is not None], int)
    if labels.size == 0:
        return found
    rows, cols, along, normal, width = _hinges([boxes[k - 1] for k in labels])
    ink = cv2.dilate(np.asarray(ink, np.uint8), np.ones((3, 3), np.uint8)) > 0  # 1 px slack
    owner = np.repeat(labels, 4)
    swung = np.zeros(owner.size, bool)
    some_arc = np.zeros(owner.size)
    for share in RADII:
        radius = share * width
        cover = _arc_cover(ink, rows, cols, along, normal, radius)
        some_arc = np.maximum(some_arc, cover)
        beside = np.maximum(
            _arc_cover(ink, rows, cols, along, normal, radius * (1 - _OFF_SHARE)),
            _arc_cover(ink, rows, cols, along, normal, radius * (1 + _OFF_SHARE)),
        )
        swung |= (cover >= ARC_COVER) & (cover - beside >= ARC_CONTRAST)
    length = width
    offset = _OFF_SHARE * length
    for angle in np.deg2rad(LEAF_ANGLES_DEG):
        cover = _ray_cover(ink, rows, cols, along, normal, length, angle, np.zeros_like(length))
        beside = np.maximum(
            _ray_cover(ink, rows, cols, along, normal, length, angle, offset),
            _ray_cover(ink, rows, cols, along, normal, length, angle, -offset),
        )
        past = _ray_cover(ink, rows, cols, along, normal, length, angle, 0 * length, _PAST_TIP)
        leaf = (cover >= LEAF_COVER) & (cover - beside >= ARC_CONTRAST)
        if angle >= np.deg2rad(_SQUARE_LEAF_DEG):  # square to the wall: a wall's corner too
            leaf &= some_arc >= _ARC_SUPPORT
        swung |= leaf & (past <= 1 - LEAF_COVER)
    swung &= width >= _MIN_RADIUS_PX
    found[owner[swung]] = True
    return found


def swing_rooms(
    regions: np.ndarray, swings: np.ndarray, connectors: np.ndarray, reach_px: int
) -> dict[int, int]:
    """The room each swing sector belongs to: per label of ``regions`` (4-connected paper, the
    doorways closed) lying in ``swings`` (the sectors a door's leaf and arc cut off,
    ``Doorways.swings``), the label of the region beyond the sector's arc and leaf: of the other
    regions within ``reach_px`` of it without crossing a ``connectors`` pixel, the one along most
    of its edge. A sector with none beyond keeps its own."""
    if swings is None or not swings.any():
        return {}
    joined = {}
    step = np.ones((3, 3), np.uint8)
    open_ground = (connectors == 0).astype(np.uint8)
    sectors = np.unique(regions[swings > 0])
    boxes = ndimage.find_objects(regions)
    for r in sectors[sectors > 0]:
        box = tuple(
            slice(max(s.start - reach_px, 0), min(s.stop + reach_px, size))
            for s, size in zip(boxes[r - 1], regions.shape, strict=True)
        )
        near = (regions[box] == r).astype(np.uint8)
        for _ in range(reach_px):
            near = cv2.dilate(near, step) & open_ground[box]
        beyond = regions[box][near > 0]
        beyond = beyond[(beyond > 0) & (beyond != r)]
        if beyond.size:
            joined[int(r)] = int(np.argmax(np.bincount(beyond)))
    return joined


def join_swings(
    regions: np.ndarray,
    stats: np.ndarray,
    swings: np.ndarray | None,
    connectors: np.ndarray,
    reach_px: int,
) -> None:
    """Relabel each swing sector of ``regions`` (labels; ``stats``: their
    ``cv2.connectedComponentsWithStats`` rows) as the room beyond its arc (:func:`swing_rooms`),
    followed on while that one joins another (a loop ends at its largest region); the room's
    stats grow to hold it and a joined region's area becomes 0. Edits in place."""
    joined = swing_rooms(regions, swings, connectors, reach_px)
    if not joined:
        return
    lut = np.arange(len(stats))
    for k in joined:
        chain = [k]
        while chain[-1] in joined and joined[chain[-1]] not in chain:
            chain.append(joined[chain[-1]])
        if chain[-1] in joined:  # a loop: its largest region holds the rest
            chain.append(max(chain, key=lambda r: stats[r, cv2.CC_STAT_AREA]))
        lut[k] = chain[-1]
    for k in joined:
        into = lut[k]
        if into == k:
            continue
        x0 = min(stats[k, cv2.CC_STAT_LEFT], stats[into, cv2.CC_STAT_LEFT])
        y0 = min(stats[k, cv2.CC_STAT_TOP], stats[into, cv2.CC_STAT_TOP])
        x1 = max(stats[k, 0] + stats[k, 2], stats[into, 0] + stats[into, 2])
        y1 = max(stats[k, 1] + stats[k, 3], stats[into, 1] + stats[into, 3])
        stats[into, :4] = (x0, y0, x1 - x0, y1 - y0)
    area = np.bincount(lut, weights=stats[:, cv2.CC_STAT_AREA], minlength=len(stats))
    stats[:, cv2.CC_STAT_AREA] = area.astype(stats.dtype)
    regions[:] = lut[regions]
