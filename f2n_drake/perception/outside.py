"""The outside of a plan: paper that reaches the sheet's border through more than a doorway.

A region of paper touching the image border is the outside and no instance. But a room whose
outer wall the drawing leaves open where the doorway step found no door (an entrance drawn as a
plain gap, glazing drawn dashed, a wall lost in a faint scan) joins the outside through that gap
and would be lost with it. The outside is therefore the paper the border reaches through gaps
wider than ``gap_px`` (the widest doorway): paper farther than half of it from any line, grown
from a margin round the image, and grown back to the lines. What a border region holds beyond
that, if at least a square ``gap_px`` wide and voted a room, is a region of its own (an
instance candidate), and the seam where it meets the outside, grown ``_MOUTH_PX`` along the
paper, is its mouth: the room's doorway. The disc reaches into the gap, so the seam is an arc;
the mouth is moved to the gap it spans, between the ends of the two lines it touches, and the
room takes the paper on its side of it.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
from scipy import ndimage

from f2n_drake.core.classes import CLASS_ID, NUM_CLASSES, SPACE_CLASSES

_SPACE_IDS = np.array([CLASS_ID[name] for name in SPACE_CLASSES])
_MOUTH_PX = 2
"""A mouth reaches this far along the paper on either side of the cut between a room and the
outside [px]."""
_SEAM_SHARE = 1.5
"""A seam whose ends lie farther apart than this many widest doorways spans more than one gap."""


@dataclass(frozen=True)
class Parted:
    """A drawing's paper with its rooms parted from the outside (:func:`part_from_outside`).

    Attributes:
        components: (H, W) int32 4-connected paper components, 0 on the lines and mouths.
        stats: their ``cv2.connectedComponentsWithStats`` rows.
        rooms: ids of the components parted from the outside: enclosed, though a wall drawn
            on the image's edge may leave them touching it.
        mouths: (H, W) int32, 0 or ``k + 1`` on the k-th gap a parted room opens to the
            outside through: the paper along the cut between them (a doorway).
    """

    components: np.ndarray
    stats: np.ndarray
    rooms: np.ndarray
    mouths: np.ndarray


def part_from_outside(
    barrier: np.ndarray,
    components: np.ndarray,
    stats: np.ndarray,
    gap_px: int,
    labels: np.ndarray | None = None,
) -> Parted:
    """``components`` (4-connected paper of ``~barrier``, 0 on it; ``stats`` theirs) with the
    paper of each border-touching component that gaps at most ``gap_px`` wide part from the
    outside made components of their own, and those gaps mouths (module doc). Given the
    network's ``labels``, only parts it votes a room (a space class) are parted."""
    unchanged = Parted(components, stats, np.zeros(0, int), np.zeros(components.shape, np.int32))
    border = np.concatenate([components[0], components[-1], components[:, 0], components[:, -1]])
    touching = np.setdiff1d(np.unique(border), [0])
    half = gap_px / 2.0
    if touching.size == 0 or half < 1:
        return unchanged
    # the outside's core: paper a disc wider than the widest doorway passes, from a margin of
    # paper round the image (a plan drawn to the image's edge has no outside paper of its own)
    pad = int(np.ceil(half)) + 2
    paper = np.pad((~barrier).astype(np.uint8), pad, constant_values=1)
    clear = (cv2.distanceTransform(paper, cv2.DIST_L2, 5) > half).astype(np.uint8)
    _, flood = cv2.connectedComponents(clear, connectivity=4)
    core = (flood == flood[0, 0]).astype(np.uint8)
    inside = (slice(pad, -pad), slice(pad, -pad))
    near_core = (cv2.distanceTransform(1 - core, cv2.DIST_L2, 5) <= half + 1)[inside]
    inner = np.isin(components, touching) & ~near_core
    n_inner, parts, part_stats, _ = cv2.connectedComponentsWithStats(
        inner.astype(np.uint8), connectivity=4
    )
    # a room at least as large as a square the widest doorway wide: not the paper a disc that
    # wide leaves in a corner of the outside, nor a recess of the facade
    outside = part_stats[:, cv2.CC_STAT_AREA] < gap_px**2
    if labels is not None:  # and a room: what the network votes background stays outside
        votes = np.bincount(
            (parts.astype(np.int64) * NUM_CLASSES + labels).ravel(),
            minlength=n_inner * NUM_CLASSES,
        ).reshape(n_inner, NUM_CLASSES)
        outside |= ~np.isin(votes.argmax(axis=1), _SPACE_IDS)
    outside[0] = True
    parts[outside[parts]] = 0
    if not parts.any():
        return unchanged
    # its mouths: the seam where its paper meets the outside's, grown along the paper
    room = (parts > 0).astype(np.uint8)
    rest = (np.isin(components, touching) & near_core).astype(np.uint8)
    cross = cv2.getStructuringElement(cv2.MORPH_CROSS, (3, 3))
    seam = (cv2.dilate(room, cross) & rest) | (cv2.dilate(rest, cross) & room)
    for _ in range(_MOUTH_PX):
        seam = cv2.dilate(seam, cross) & (room | rest)
    _, mouths = cv2.connectedComponents(seam, connectivity=4)
    mouths = mouths.astype(np.int32)
    moved = _across_gaps(mouths, barrier, parts, rest > 0, core[inside] > 0, gap_px)
    if moved is not None:
        mouths, parts = moved
    parts[mouths > 0] = 0
    _, parts = np.unique(parts, return_inverse=True)
    parts = parts.reshape(components.shape).astype(np.int32)
    first = int(components.max()) + 1
    relabelled = components.copy()
    relabelled[parts > 0] = parts[parts > 0] + first - 1
    relabelled[mouths > 0] = 0
    rooms = np.arange(first, first + int(parts.max()))
    return Parted(relabelled, _stats(relabelled), rooms, mouths)


def _across_gaps(
    mouths: np.ndarray,
    barrier: np.ndarray,
    parts: np.ndarray,
    rest: np.ndarray,
    core: np.ndarray,
    gap_px: int,
) -> tuple[np.ndarray, np.ndarray] | None:
    """The ``mouths`` moved from their seams to the gaps they span, and ``parts`` (the rooms)
    grown by the outside's paper (``rest``) that the gaps cut off from its ``core``; None when a
    gap does not part its room from the outside, or joins two rooms.

    The disc that finds the outside reaches into a doorway, and past a thin wall into the room, so
    the seam is an arc. A mouth's gap is the paper between the two ends of the lines the seam
    spans: in the convex hull of the line pixels within a wall's thickness of the two contact
    pixels farthest apart, the wall's gap through its whole thickness, with the ink mostly inside
    it. A seam whose ends lie farther apart than ``_SEAM_SHARE`` times ``gap_px`` (a doorway;
    the arc a disc that wide leaves on a thin wall's inner face is a little longer) spans no one
    gap and stays the mouth."""
    paper = ~barrier
    gaps = np.zeros_like(mouths)
    ones = np.ones((3, 3), np.uint8)
    thickness = cv2.distanceTransform(barrier.astype(np.uint8), cv2.DIST_L2, 3)
    for k, box in enumerate(ndimage.find_objects(mouths), start=1):  # labels 1..n, none empty
        pad = 8 + int(max(box[0].stop - box[0].start, box[1].stop - box[1].start))
        window = tuple(
            slice(max(s.start - pad, 0), min(s.stop + pad, n))
            for s, n in zip(box, mouths.shape, strict=True)
        )
        mouth = (mouths[window] == k).astype(np.uint8)
        contact = np.argwhere(cv2.dilate(mouth, ones).astype(bool) & barrier[window])[:, ::-1]
        if len(contact) < 2:
            return None
        hull = cv2.convexHull(contact.astype(np.int32))[:, 0]
        far_apart = np.linalg.norm(hull[:, None] - hull[None], axis=2)
        i, j = np.unravel_index(far_apart.argmax(), far_apart.shape)
        if far_apart[i, j] > _SEAM_SHARE * gap_px:
            gaps[window][mouth.astype(bool) & (gaps[window] == 0)] = k
            continue
        ends = np.zeros(mouth.shape, np.uint8)
        local = thickness[window]
        for x, y in (hull[i], hull[j]):
            reach = int(np.ceil(2 * local[max(y - 3, 0) : y + 4, max(x - 3, 0) : x + 4].max())) + 1
            cv2.circle(ends, (int(x), int(y)), reach, 1, -1)
        lines = np.argwhere(ends.astype(bool) & barrier[window])[:, ::-1]
        span = np.zeros(mouth.shape, np.uint8)
        cv2.fillPoly(span, [cv2.convexHull(lines.astype(np.int32))], 1)
        span = span.astype(bool)
        gap = span & paper[window] & ~core[window]
        # and the ink mostly inside it: the dashes of glazing drawn dashed, a window's lines
        _, pieces = cv2.connectedComponents(barrier[window].astype(np.uint8), connectivity=8)
        within = np.bincount(pieces[span], minlength=int(pieces.max()) + 1)
        within = within >= np.bincount(pieces.ravel(), minlength=within.size) / 2
        gap |= within[pieces] & (pieces > 0)
        if not gap.any():
            return None
        gaps[window][gap & (gaps[window] == 0)] = k
    # the paper with the gaps cut out: what still reaches the core stays outside
    cut = ((parts > 0) | rest) & (gaps == 0)
    _, regions = cv2.connectedComponents(cut.astype(np.uint8), connectivity=4)
    outside = np.unique(regions[core & cut])
    moved = np.zeros_like(parts)
    for region in np.setdiff1d(np.unique(regions[parts > 0]), [0]):
        owners = np.setdiff1d(np.unique(parts[regions == region]), [0])
        if region in outside or owners.size != 1:
            return None
        moved[regions == region] = owners[0]
    return gaps, moved


def _stats(components: np.ndarray) -> np.ndarray:
    """``cv2.connectedComponentsWithStats`` stats of labelled ``components`` (row per label; row 0,
    the lines, has its area only)."""
    n = int(components.max()) + 1
    stats = np.zeros((n, 5), np.int32)
    stats[:, cv2.CC_STAT_AREA] = np.bincount(components.ravel(), minlength=n)
    for k, box in enumerate(ndimage.find_objects(components), start=1):
        if box is not None:
            rows, cols = box
            stats[k, :4] = cols.start, rows.start, cols.stop - cols.start, rows.stop - rows.start
    return stats
