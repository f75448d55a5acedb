"""Furniture drawn against the walls: a bed, a sofa, a kitchen counter, a bathtub.

Furniture standing free in a room is a piece of ink of its own (:func:`~f2n_drake.perception.ink.
free_marks`). Furniture drawn against a wall is part of the plan's ink: with the wall it encloses
paper the network never saw in training. It calls a bed against a wall a balcony (a box outlined
against a wall), or gives a counter the kitchen's class and the kitchen another. Such paper is
known by what borders it across a single stroke: one room and nothing else but walls and windows.
A door's box borders two rooms, a window's a room and the outside, a door swing its room and its
door, a balcony the outside, a wall's paper rooms on both sides or none.

:func:`segment_around_furniture` segments a drawing, finds such furniture from the labels
(:func:`against_walls`), and, if there is any, segments the drawing again with the furniture's
outline painted over (:func:`furniture_outline`), so the network sees the room as it learned
rooms. Furniture the network called something else than its room is then an obstacle, like
free-standing furniture: its paper is no instance.
"""

from __future__ import annotations

from collections.abc import Callable

import cv2
import numpy as np

from f2n_drake.core.classes import SPACE_CLASSES
from f2n_drake.core.parsed import ParsedPlan
from f2n_drake.perception.image import Prediction
from f2n_drake.perception.ink import as_grey, stroke_width_px
from f2n_drake.perception.instances import extract_instances
from f2n_drake.perception.preparation import without_marks

MAX_SEGMENTATIONS = 3
"""Segmentations of a drawing at most: the first, and two with furniture painted over."""
_IGNORED_SIDES = ("wall", "window")  # what furniture may border besides its room
_MIN_SIDE_SHARE = 0.2  # a contact under this share of the strongest one is a corner touching
_DOORS = ("door", "front_door")


def _exterior(parsed: ParsedPlan, lines: np.ndarray) -> np.ndarray:
    """(H, W) bool: paper of no instance connected to the image border (the outside)."""
    paper = (parsed.instance_ids == 0) & ~lines
    n, comp = cv2.connectedComponents(paper.astype(np.uint8), connectivity=4)
    border = np.unique(np.concatenate([comp[0], comp[-1], comp[:, 0], comp[:, -1]]))
    outside = np.zeros(n, bool)
    outside[border[border > 0]] = True
    return outside[comp]


def against_walls(
    parsed: ParsedPlan, lines: np.ndarray, *, same_class: bool = False
) -> dict[int, int]:
    """Space instances of ``parsed`` that are furniture drawn against a wall -> their room.

    An instance is furniture when, across one stroke of ``lines`` (the drawing's stroke width
    plus 2 px), it borders exactly one other instance besides walls and windows, a space larger
    than itself and of another class, and not the outside. Contacts under ``_MIN_SIDE_SHARE`` of
    the strongest (a corner touching a door's box) and under twice the reach do not count.

    With ``same_class``, a piece of its room's class counts too when no door or front door
    touches it within that stroke, not even at a corner: a door's swing, whose arc cuts a piece
    off the room at the door's hinge, is no furniture.
    """
    reach = stroke_width_px(lines) + 2
    kernel = np.ones((2 * reach + 1,) * 2, np.uint8)
    ids = parsed.instance_ids
    by_id = parsed.by_id()
    outside = _exterior(parsed, lines)
    slices = parsed.boxes()
    found = {}
    for inst in parsed.instances:
        if inst.class_name not in SPACE_CLASSES or slices[inst.id - 1] is None:
            continue
        rows, cols = slices[inst.id - 1]
        r0, c0 = max(rows.start - reach, 0), max(cols.start - reach, 0)
        window = (slice(r0, rows.stop + reach), slice(c0, cols.stop + reach))
        crop = ids[window]
        own = crop == inst.id
        ring = (cv2.dilate(own.astype(np.uint8), kernel) > 0) & ~own
        sides, counts = np.unique(crop[ring], return_counts=True)
        contact = {
            int(j): int(c)
            for j, c in zip(sides, counts, strict=True)
            if j and by_id[int(j)].class_name not in _IGNORED_SIDES
        }
        outside_px = int(np.count_nonzero(outside[window] & ring))
        least = max(2 * reach, _MIN_SIDE_SHARE * max([outside_px, *contact.values()]))
        rooms = [j for j, c in contact.items() if c >= least]
        if outside_px >= least or len(rooms) != 1:
            continue
        room = by_id[rooms[0]]
        if room.class_name not in SPACE_CLASSES or room.area_px <= inst.area_px:
            continue
        if room.class_name == inst.class_name:
            touches_door = any(by_id[int(j)].class_name in _DOORS for j in sides if j)
            if not same_class or touches_door:
                continue
        found[inst.id] = room.id
    return found


def furniture_outline(parsed: ParsedPlan, lines: np.ndarray, found: dict[int, int]) -> np.ndarray:
    """(H, W) bool: the ink between each furniture instance in ``found`` and its room, a stroke
    from both and near no other paper: its outline but for the wall it stands against, whose
    lines run on beside the wall's own paper or the outside, or are a filled wall's edge."""
    stroke = stroke_width_px(lines)
    ids = parsed.instance_ids

    def near(mask: np.ndarray, reach: int) -> np.ndarray:
        kernel = np.ones((2 * reach + 1,) * 2, np.uint8)
        return cv2.dilate(mask.astype(np.uint8), kernel) > 0

    furniture, rooms = np.isin(ids, list(found)), np.isin(ids, list(found.values()))
    other_paper = ~lines & ~furniture & ~rooms
    between = near(furniture, stroke) & near(rooms, stroke)
    return lines & between & ~near(other_paper, stroke + 2)


def segment_around_furniture(
    image: np.ndarray, lines: np.ndarray, predict: Callable[[np.ndarray], Prediction]
) -> tuple[Prediction, np.ndarray]:
    """The prediction of a drawing made with its furniture against walls painted over, and the
    furniture's paper ((H, W) bool, no instance: an obstacle).

    Each segmentation that finds furniture (:func:`against_walls` on every enclosed region, the
    pieces the network gives their room's class included) is followed by another with all
    furniture found so far painted over, up to ``MAX_SEGMENTATIONS`` in all: a piece may show
    only once others are gone (a bed the network called a bedroom beside a room it called
    something else). Only pieces the network gave another class than their room's are
    obstacles; a piece it gave its room's class is painted over too (a counter's lines hid an
    open kitchen from it) but stays part of the room, as it always was.

    Args:
        image: the drawing, as ``predict`` takes it.
        lines: its binarised ink.
        predict: drawing -> prediction (the segmenter).
    """
    prediction = predict(image)
    furniture = np.zeros(lines.shape, bool)
    outline = np.zeros(lines.shape, bool)
    for _ in range(MAX_SEGMENTATIONS - 1):
        pieces = extract_instances(
            image, prediction[0], split=None, lines=lines, join_pieces=False, doorways=False
        )
        found = against_walls(pieces, lines, same_class=True)
        new_outline = furniture_outline(pieces, lines, found) & ~outline
        if not new_outline.any():
            break
        by_id = pieces.by_id()
        unlike = [i for i, room in found.items() if by_id[i].class_name != by_id[room].class_name]
        furniture |= np.isin(pieces.instance_ids, unlike)
        outline |= new_outline
        prediction = predict(without_marks(as_grey(image), lines, outline))
    return prediction, furniture
