"""The per-pixel labels a parse hands on: every instance's pixels take its class, and what is
no instance is voted too (:func:`vote_corrected_labels`)."""

from __future__ import annotations

import cv2
import numpy as np

from f2n_drake.core.classes import (
    CLASS_ID,
    CONNECTOR_CLASSES,
    NUM_CLASSES,
    PAINT_ORDER,
    SPACE_CLASSES,
)
from f2n_drake.core.errors import InputError
from f2n_drake.core.parsed import ParsedPlan
from f2n_drake.perception.ink import stroke_width_px

_CONNECTOR_IDS = np.array([CLASS_ID[name] for name in CONNECTOR_CLASSES])
_SPACE_IDS = np.array([CLASS_ID[name] for name in SPACE_CLASSES])
_WALL_ID = CLASS_ID["wall"]
_OUTLINE_REACH_PX = 3  # a connector's outline: line pixels this close to it (thickest style line)


def vote_corrected_labels(parsed: ParsedPlan, lines: np.ndarray | None = None) -> np.ndarray:
    """(H, W) uint8 labels after the vote: every instance's pixels take its class.

    Given the drawing's ``lines`` (``binarize(image)``), the vote also covers what is no
    instance: each connected region of non-line, instance-free pixels (the outside, a region
    voted background such as a storeroom, a speck) takes the majority of its labels, as an
    instance would, background where that is a space no room instance of its class lies beside
    (paper the parse made no room of; furniture's paper takes its room's class), and line pixels
    within ``_OUTLINE_REACH_PX`` of a connector instance that the network labels as some
    connector take that instance's class (the outline of a window the front-door prior made a
    front door). In a drawing of 1 px outlines (``stroke_width_px``), a line pixel of no
    instance then takes, of the classes voted on the pixels 8-adjacent to it that are no such
    line pixel, the one painted last in ``PAINT_ORDER``: an outline lies on the edge two
    polygons share, and labels are rasterised so that the later polygon (door over wall over
    room) owns it. Last, every pixel of no instance the network labels wall is wall (a wall's
    lines and the paper between them). Other line pixels, ``opening`` strips and, without
    ``lines``, every pixel of no instance keep the network's label.
    """
    labels = parsed.labels
    voted = labels.copy()
    if lines is not None:
        if lines.shape != labels.shape:
            raise InputError(f"lines {lines.shape} and labels {labels.shape} differ in size")
        leftover = ~lines & (parsed.instance_ids == 0)
        n, regions = cv2.connectedComponents(leftover.astype(np.uint8), connectivity=4)
        votes = np.bincount(
            (regions * NUM_CLASSES + labels)[leftover], minlength=n * NUM_CLASSES
        ).reshape(n, NUM_CLASSES)
        region_class = _no_room_without_instance(
            votes.argmax(axis=1), regions, leftover, parsed, stroke_width_px(lines) + 1
        )
        voted[leftover] = region_class.astype(np.uint8)[regions[leftover]]
    if not parsed.instances:
        return voted
    lut = np.full(max(inst.id for inst in parsed.instances) + 1, -1, dtype=np.int16)
    for inst in parsed.instances:
        if inst.class_name in CLASS_ID:
            lut[inst.id] = CLASS_ID[inst.class_name]
    by_instance = lut[parsed.instance_ids]
    if lines is not None:
        # a connector's outline, where the network calls it a connector, follows the vote
        conn = np.where(np.isin(by_instance, _CONNECTOR_IDS), by_instance + 1, 0)
        reach = np.ones((2 * _OUTLINE_REACH_PX + 1,) * 2, np.uint8)
        near = cv2.dilate(conn.astype(np.uint8), reach)
        outline = lines & (near > 0) & np.isin(labels, _CONNECTOR_IDS)
        voted[outline] = near[outline] - 1
    voted = np.where(by_instance >= 0, by_instance, voted).astype(np.uint8)
    if lines is not None and stroke_width_px(lines) == 1:
        _paint_thin_outlines(voted, lines & (parsed.instance_ids == 0))
    if lines is not None:
        voted[(parsed.instance_ids == 0) & (labels == _WALL_ID)] = _WALL_ID
    return voted


def _no_room_without_instance(
    region_class: np.ndarray,
    regions: np.ndarray,
    leftover: np.ndarray,
    parsed: ParsedPlan,
    reach_px: int,
) -> np.ndarray:
    """``region_class`` (the majority class of each region of ``regions``, the paper of no
    instance, ``leftover``) with a space's class made background, unless a room instance of that
    class lies within ``reach_px`` of the region (across its outline: furniture against its
    wall) or round it (furniture standing in it): the room's floor. Elsewhere the parse made no
    room (a storeroom voted background, a speck): a room's class there would be a room no
    instance, graph or route has."""
    space_voted = np.isin(region_class, _SPACE_IDS)
    space_voted[0] = False  # label 0 of ``regions``: no leftover paper
    if not space_voted.any():
        return region_class
    room_ids = {cls: [] for cls in np.unique(region_class[space_voted])}
    for inst in parsed.instances:
        if inst.class_name in SPACE_CLASSES and CLASS_ID[inst.class_name] in room_ids:
            room_ids[CLASS_ID[inst.class_name]].append(inst.id)
    square = np.ones((2 * reach_px + 1,) * 2, np.uint8)
    own_room = np.zeros(region_class.size, bool)
    for cls, ids in room_ids.items():
        if not ids:
            continue
        room = np.isin(parsed.instance_ids, ids)
        near = (cv2.dilate(room.astype(np.uint8), square) > 0) | _holes(room)
        touched = np.unique(regions[near & leftover])
        own_room[touched[region_class[touched] == cls]] = True
    return np.where(space_voted & ~own_room, 0, region_class)


def _holes(mask: np.ndarray) -> np.ndarray:
    """(H, W) bool: the pixels ``mask`` encloses (4-connected, not reaching the image border)."""
    _, parts = cv2.connectedComponents((~mask).astype(np.uint8), connectivity=4)
    border = np.unique(np.concatenate([parts[0], parts[-1], parts[:, 0], parts[:, -1]]))
    return ~mask & ~np.isin(parts, border)


def _paint_thin_outlines(voted: np.ndarray, outlines: np.ndarray) -> None:
    """Each ``outlines`` pixel takes, of the ``voted`` classes of the pixels 8-adjacent to it
    that are not in ``outlines``, the one latest in ``PAINT_ORDER`` (background first); pixels
    with only outline pixels around keep theirs. Edits ``voted`` in place."""
    paper_classes = np.where(~outlines, voted, NUM_CLASSES)  # NUM_CLASSES: no class here
    square = np.ones((3, 3), np.uint8)
    for name in ("background", *PAINT_ORDER):
        paper = (paper_classes == CLASS_ID[name]).astype(np.uint8)
        beside = outlines & (cv2.dilate(paper, square) > 0)
        voted[beside] = CLASS_ID[name]
