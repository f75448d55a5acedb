"""Drawing + per-pixel labels -> instances: enclosed regions, majority vote, open-passage split.

An instance is a connected region of non-line pixels (4-connectivity, so an 8-connected line of
ink always separates two regions) that does not touch the image border. Its class is the majority
of the predicted labels inside it, which corrects scattered errors of the network. Regions voted
``background`` (storage, stairs, ... render as background) are dropped: their pixels get instance
id 0, like line pixels and the outside. Regions of one space class separated only by ink the
network also calls that class (a door swing's leaf and arc drawn inside a room, the lines of a
hatched floor) are one instance, unless two of them are rooms.
A door or window drawn with no white interior (thick outlines in a thin wall) becomes an instance
made of its ink pixels the network labels as that connector, so the rooms stay connected.
Free-standing marks (:func:`~f2n_drake.perception.ink.free_marks`) are no lines: an annotation (room
names, areas, dimensions, a sheet's frame) is paper of the room it stands in, and the paper
furniture encloses (a bed, a table) is no instance, an obstacle like the walls.

Open passages: a space region holding a substantial, compact part of its partner class (a
kitchen in a living room, or the reverse: ``SplitOptions.open_pairs``) is split along the
network's semantic boundary (see :mod:`f2n_drake.perception.open_passages`); the cut strip becomes
an
instance of class ``"opening"``. Given the segmenter's probabilities, every instance also gets
``scores``, the mean class probabilities over its pixels.

The candidate regions (:func:`enclosed_regions`) live in :mod:`f2n_drake.perception.regions`, the
labels after the vote (:func:`vote_corrected_labels`) in :mod:`f2n_drake.perception.voted_labels`,
binarisation (:func:`binarize`, :func:`as_grey`) in :mod:`f2n_drake.perception.ink`; all are
re-exported here, as are :class:`SplitOptions`, ``DEFAULT_SPLIT`` and :func:`split_region`.
"""

from __future__ import annotations

from collections.abc import Iterator

import cv2
import numpy as np
from scipy import ndimage

from f2n_drake.core.classes import (
    CLASS_ID,
    CLASS_NAMES,
    CONNECTOR_CLASSES,
    NUM_CLASSES,
    OPENING,
    SPACE_CLASSES,
)
from f2n_drake.core.errors import InputError
from f2n_drake.core.parsed import Instance, ParsedPlan, instance_from_mask
from f2n_drake.core.raster import PixelGrid
from f2n_drake.perception.doorways import (
    ROOM_SHARE,
    SECTOR_SHARE,
    Doorways,
    max_gap_px,
)
from f2n_drake.perception.ink import as_grey, binarize, stroke_width_px
from f2n_drake.perception.open_passages import DEFAULT_SPLIT, SplitOptions, split_region
from f2n_drake.perception.regions import EnclosedRegions, enclosed_regions
from f2n_drake.perception.voted_labels import vote_corrected_labels

__all__ = [
    "DEFAULT_SPLIT",
    "EnclosedRegions",
    "SplitOptions",
    "as_grey",
    "binarize",
    "enclosed_regions",
    "extract_instances",
    "split_region",
    "vote_corrected_labels",
]

_SPACE_IDS = np.array([CLASS_ID[name] for name in SPACE_CLASSES])
_CONNECTOR_IDS = np.array([CLASS_ID[name] for name in CONNECTOR_CLASSES])
_WALL_ID = CLASS_ID["wall"]
_MIN_INK_CONNECTOR_M2 = 0.1  # smallest connector made of ink alone (with a known scale) [m^2]
_MIN_INK_CONNECTOR_PX = 100  # the same without a scale [px]
_CONNECTOR_REACH_PX = 3  # an ink-only connector must have two non-wall regions this close
_SWING_SHARE = 0.25  # a door's swing cuts off at most this share of its room


def _regions(
    cc: np.ndarray,
    stats: np.ndarray,
    keep: np.ndarray,
    winner: np.ndarray,
    labels: np.ndarray,
    lines: np.ndarray,
    bridge_px: int = 5,
    join: bool = True,
    max_swing_px: float = np.inf,
    min_room_px: float = 0.0,
) -> Iterator[tuple[int, tuple[int, int, int, int], np.ndarray]]:
    """Yield ``(class id, (x0, y0, x1, y1), bool crop)`` per region to turn into instances.

    With ``join``, kept components of one space class that ink predicted as that same class
    separates (a door swing's arc and leaf drawn inside a room) are one region: a ``bridge_px``
    closing of their union, limited to those components and that ink, joins them, bridging ink
    included. The closing spans at least twice the drawing's stroke width, so a scan's thick
    strokes join too. Two rooms are never joined, only a room and the pieces its door's swing
    cuts off, or the cells of a hatched floor: a group holding two components larger than
    ``max_swing_px`` (with doorways closed, a quarter disc twice the widest doorway wide), or
    than both ``_SWING_SHARE`` of its largest and ``min_room_px`` (a room's least area), stays
    apart. Without ``join``, every kept component is its own region.
    """
    bridge_px = max(bridge_px, 2 * stroke_width_px(lines) + 1)
    kernel = np.ones((bridge_px, bridge_px), np.uint8)
    merged = np.zeros(len(keep), dtype=bool)
    groups: list[tuple[int, np.ndarray]] = []
    for cls in _SPACE_IDS if join else ():
        members = keep & (winner == cls)
        if members.sum() < 2:
            continue
        union = members[cc]
        allowed = union | (lines & (labels == cls))
        closed = cv2.morphologyEx(union.astype(np.uint8), cv2.MORPH_CLOSE, kernel).astype(bool)
        n, group = cv2.connectedComponents((closed & allowed).astype(np.uint8), connectivity=4)
        ids = np.flatnonzero(members)
        # a component's group holds most of its pixels (furniture's paper taken out, or a
        # swing's sector joined to it, can leave a component in pieces)
        pair, count = np.unique(cc[union].astype(np.int64) * n + group[union], return_counts=True)
        pair = pair[np.argsort(count, kind="stable")]  # the largest share written last
        group_of = np.zeros(len(keep), dtype=np.int32)
        group_of[pair // n] = pair % n
        anchor = group_of[ids]
        for g in np.unique(anchor):
            together = ids[anchor == g]
            area = stats[together, cv2.CC_STAT_AREA]
            rooms = np.count_nonzero(
                (area > max_swing_px) | ((area > _SWING_SHARE * area.max()) & (area >= min_room_px))
            )
            if together.size > 1 and rooms <= 1:
                merged[together] = True
                # its components, and the ink of its class bridging them
                groups.append((int(cls), ((group == g) & ~union) | np.isin(cc, together)))
    for k in np.flatnonzero(keep & ~merged):
        x0, y0 = stats[k, cv2.CC_STAT_LEFT], stats[k, cv2.CC_STAT_TOP]
        x1, y1 = x0 + stats[k, cv2.CC_STAT_WIDTH], y0 + stats[k, cv2.CC_STAT_HEIGHT]
        yield int(winner[k]), (x0, y0, x1, y1), cc[y0:y1, x0:x1] == k
    for cls, mask in groups:
        x0, y0, w, h = cv2.boundingRect(mask.astype(np.uint8))
        yield cls, (x0, y0, x0 + w, y0 + h), mask[y0 : y0 + h, x0 : x0 + w]


def _add_ink_connectors(
    lines: np.ndarray,
    marks: np.ndarray,
    labels: np.ndarray,
    regions: tuple[np.ndarray, np.ndarray],
    instance_ids: np.ndarray,
    instances: list[Instance],
    min_area_px: int,
    probabilities: np.ndarray | None,
) -> None:
    """Add connectors drawn with no white interior (thick outlines in a thin wall fill the whole
    door rectangle): an 8-connected blob of ink the network labels door/window/front door
    becomes an instance of its majority connector class when it has ``min_area_px`` pixels
    (0.1 m^2, or 100 px without a scale: smaller blobs are mostly misread wall),
    touches no connector instance, and joins two regions that are not walls (two rooms, or a
    room and the outside), and is no furniture (``marks``; annotations are no longer ``lines``).
    ``regions`` is (component image, winner class per component). Edits ``instance_ids`` and
    ``instances`` in place."""
    ink_conn = lines & ~marks & np.isin(labels, _CONNECTOR_IDS)
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
        crop_probs = None if probabilities is None else probabilities[:, y0:y1, x0:x1]
        instances.append(
            instance_from_mask(iid, CLASS_NAMES[cls], blob, crop_labels, crop_probs, (x0, y0))
        )


def _add_doorways(
    doorways: Doorways,
    labels: np.ndarray,
    instance_ids: np.ndarray,
    instances: list[Instance],
    probabilities: np.ndarray | None,
) -> None:
    """Add each closed gap of ``doorways`` as a connector instance: of its class, or an
    ``opening`` where it is an open passage (``Doorways.passages``). Edits ``instance_ids`` and
    ``instances`` in place."""
    for k, box in enumerate(ndimage.find_objects(doorways.connectors), start=1):
        if box is None:
            continue
        crop = doorways.connectors[box] == k
        iid = len(instances) + 1
        instance_ids[box][crop] = iid
        crop_probs = None if probabilities is None else probabilities[(slice(None), *box)]
        offset = (box[1].start, box[0].start)
        cls = OPENING if doorways.is_passage(k - 1) else CLASS_NAMES[int(doorways.classes[k - 1])]
        instances.append(instance_from_mask(iid, cls, crop, labels[box], crop_probs, offset))


def extract_instances(
    image: np.ndarray,
    labels: np.ndarray,
    *,
    grid: PixelGrid | None = None,
    min_area_px: int = 12,
    split: SplitOptions | None = DEFAULT_SPLIT,
    lines: np.ndarray | None = None,
    scale_source: str | None = None,
    probabilities: np.ndarray | None = None,
    furniture: np.ndarray | None = None,
    join_pieces: bool = True,
    doorways: bool = True,
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
        probabilities: (NUM_CLASSES, H, W) class probabilities per pixel, if the segmenter gives
            them; each instance's ``scores`` are their means over its pixels.
        furniture: (H, W) bool, paper of furniture drawn against the walls
            (:func:`~f2n_drake.perception.furniture.segment_around_furniture`): no instance, an
            obstacle.
        join_pieces: pieces of a room that ink the network gives the room's class separates (a
            door swing) are one instance; False keeps every enclosed region its own.
        doorways: close the gaps the ink leaves in the walls with the network's labels, each
            gap that separates two regions a connector instance
            (:mod:`~f2n_drake.perception.doorways`); False: regions of the ink alone.

    Returns:
        ParsedPlan with ``labels`` the given labels (unchanged) and instance ids 1..K.

    Raises:
        InputError: shapes differ or labels hold ids >= NUM_CLASSES.
    """
    labels = np.asarray(labels)
    if labels.shape != np.shape(image)[:2]:
        raise InputError(f"labels {labels.shape} and image {np.shape(image)[:2]} differ in size")
    if probabilities is not None and probabilities.shape != (NUM_CLASSES, *labels.shape):
        raise InputError(
            f"probabilities {probabilities.shape} do not match {NUM_CLASSES} classes of "
            f"{labels.shape} labels"
        )
    if labels.size and int(labels.max()) >= NUM_CLASSES:
        raise InputError(f"label id {int(labels.max())} is not a class (< {NUM_CLASSES})")
    labels = labels.astype(np.uint8, copy=False)
    if lines is None:
        lines = binarize(image)
    regions = enclosed_regions(
        lines,
        min_area_px=min_area_px,
        furniture=furniture,
        labels=labels if doorways else None,
        metres_per_px=grid.metres_per_px if grid else None,
        grey=as_grey(image) if doorways else None,
    )
    lines, cc, stats = regions.lines, regions.components, regions.stats
    n = len(stats)
    votes = np.bincount((cc * NUM_CLASSES + labels).ravel(), minlength=n * NUM_CLASSES)
    votes = votes.reshape(n, NUM_CLASSES)
    winner = votes.argmax(axis=1)
    keep = regions.enclosed & (winner != 0)

    min_part_floor = split.min_part_px if split else 0
    abs_px = grid.length_px(1.0) ** 2 * split.min_area_m2 if (split and grid) else np.inf
    instance_ids = np.zeros(labels.shape, dtype=np.int32)
    instances: list[Instance] = []
    max_swing_px, min_room_px = np.inf, 0.0
    if regions.doorways is not None:
        # twice the widest doorway: the gap estimate of a drawing of unknown scale is coarse
        gap_px = max_gap_px(lines, grid.metres_per_px if grid else None)
        max_swing_px = SECTOR_SHARE * (2 * gap_px) ** 2
        min_room_px = ROOM_SHARE * gap_px**2  # the doorways' least room
    for cls, (x0, y0, x1, y1), crop in _regions(
        cc,
        stats,
        keep,
        winner,
        labels,
        lines,
        join=join_pieces,
        max_swing_px=max_swing_px,
        min_room_px=min_room_px,
    ):
        crop_labels = labels[y0:y1, x0:x1]
        crop_probs = None if probabilities is None else probabilities[:, y0:y1, x0:x1]
        result = None
        if split and cls in _SPACE_IDS:
            region_votes = np.bincount(crop_labels[crop], minlength=NUM_CLASSES)
            min_px = int(max(min_part_floor, min(split.min_fraction * crop.sum(), abs_px)))
            partners = split.partners(cls)
            if partners.size and region_votes[partners].max() >= min_px:
                result = split_region(crop, crop_labels, cls, min_px, split)
        ids_view = instance_ids[y0:y1, x0:x1]
        if result is None:
            iid = len(instances) + 1
            ids_view[crop] = iid
            instances.append(
                instance_from_mask(iid, CLASS_NAMES[cls], crop, crop_labels, crop_probs, (x0, y0))
            )
            continue
        parts, cuts = result
        for part_cls, piece in parts:
            iid = len(instances) + 1
            ids_view[piece] = iid
            instances.append(
                instance_from_mask(
                    iid, CLASS_NAMES[part_cls], piece, crop_labels, crop_probs, (x0, y0)
                )
            )
        for strip in cuts:
            iid = len(instances) + 1
            ids_view[strip] = iid
            instances.append(
                instance_from_mask(iid, OPENING, strip, crop_labels, crop_probs, (x0, y0))
            )
    if regions.doorways is not None:
        _add_doorways(regions.doorways, labels, instance_ids, instances, probabilities)
    min_ink_px = grid.length_px(1.0) ** 2 * _MIN_INK_CONNECTOR_M2 if grid else _MIN_INK_CONNECTOR_PX
    _add_ink_connectors(
        lines,
        regions.furniture_marks,
        labels,
        (cc, winner),
        instance_ids,
        instances,
        max(min_area_px, min_ink_px),
        probabilities,
    )
    if scale_source is None:
        scale_source = "argument" if grid is not None else "unknown"
    return ParsedPlan(
        instance_ids,
        labels,
        instances,
        grid,
        scale_source,
        door_outline_px=regions.door_outline_px,
    )
