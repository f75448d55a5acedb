"""Furniture drawn against the walls, on drawings whose answers are known."""

from __future__ import annotations

import cv2
import numpy as np
from helpers import BEDROOM, classes, two_rooms

from f2n_drake.core.classes import CLASS_ID
from f2n_drake.perception.furniture import (
    against_walls,
    furniture_outline,
    segment_around_furniture,
)
from f2n_drake.perception.instances import binarize, extract_instances
from f2n_drake.pipeline import parse_drawing

BALCONY = CLASS_ID["balcony"]
BED = (slice(41, 80), slice(141, 174))  # a bed's paper, in the bedroom, against its right wall
BED_CENTRE = (60, 157)
ROOM_POINT = (150, 140)  # the bedroom's paper, off the bed


def with_bed(bed_class: int = BALCONY, *, drawn: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """The two rooms with a bed outlined against the bedroom's right wall (its right side drawn
    over the wall's inner line), labelled ``bed_class`` as the network labels a box it never saw
    against a wall (or not ``drawn``: the bedroom's labels); 60 px of paper right of the flat,
    with a balcony against its outer wall."""
    img, lab = (
        np.pad(a, ((0, 0), (0, 60)), constant_values=v)
        for a, v in zip(two_rooms(), (255, 0), strict=True)
    )
    if drawn:
        cv2.rectangle(img, (140, 40), (174, 80), 0, 1)
        lab[BED] = bed_class
    cv2.rectangle(img, (180, 60), (230, 140), 0, 1)  # the balcony, outside
    lab[61:140, 181:230] = BALCONY
    return img, lab


def test_a_bed_against_a_wall_is_furniture_of_its_room():
    img, lab = with_bed()
    lines = binarize(img)
    parsed = extract_instances(img, lab, split=None, doorways=False)  # as furniture.py reads it
    bed, room = (int(parsed.instance_ids[p]) for p in (BED_CENTRE, ROOM_POINT))
    assert parsed.by_id()[bed].class_name == "balcony"
    assert against_walls(parsed, lines) == {bed: room}  # not the door, nor the real balcony
    outline = furniture_outline(parsed, lines, {bed: room})
    assert outline[60, 140] and outline[40, 157] and outline[80, 157]  # its free sides
    assert not outline[60, 174] and not outline[60, 180]  # not the walls it stands against
    assert not outline[38, 174] and not outline[82, 174]  # nor the wall beside its ends
    same = extract_instances(*with_bed(BEDROOM), split=None, doorways=False)
    assert against_walls(same, lines) == {}  # joined to the room it looks like
    pieces = extract_instances(*with_bed(BEDROOM), split=None, join_pieces=False, doorways=False)
    bed, room = (int(pieces.instance_ids[p]) for p in (BED_CENTRE, ROOM_POINT))
    assert against_walls(pieces, lines) == {}  # the network's own room: nothing to undo
    assert against_walls(pieces, lines, same_class=True) == {bed: room}


class BedStub:
    """A segmenter that calls the bed a balcony while its outline is drawn, and counts calls."""

    def __init__(self) -> None:
        self.seen: list[np.ndarray] = []

    def predict(self, image: np.ndarray) -> np.ndarray:
        self.seen.append(image)
        return with_bed(BALCONY if image[60, 140] < 128 else BEDROOM, drawn=image[60, 140] < 128)[1]


def test_the_drawing_is_segmented_again_with_the_furniture_painted_over():
    img, _ = with_bed()
    lines = binarize(img)
    stub = BedStub()
    (labels, _), furniture = segment_around_furniture(
        img,
        lines,
        lambda drawing: (stub.predict(drawing), None),
    )
    assert len(stub.seen) == 2
    cleaned = stub.seen[1]
    assert cleaned[60, 140] > 200 and cleaned[60, 174] < 128  # the bed's side gone, the wall kept
    assert labels[BED_CENTRE] == BEDROOM
    assert furniture[BED_CENTRE] and not furniture[ROOM_POINT] and furniture.sum() == 39 * 33


def test_parse_drawing_makes_furniture_against_a_wall_an_obstacle():
    img, _ = with_bed()
    parsed = parse_drawing(img, segmenter=BedStub())
    assert parsed.instance_ids[BED_CENTRE] == 0  # no instance: the planner keeps off the bed
    assert classes(parsed) == ["balcony", "bedroom", "door", "living", "wall", "wall", "wall"]
    plain = parse_drawing(with_bed(drawn=False)[0], segmenter=BedStub())
    assert classes(plain) == classes(parsed)  # the same rooms as without the bed


class SameClassStub(BedStub):
    """A segmenter that calls the bed its room's class, drawn or not."""

    def predict(self, image: np.ndarray) -> np.ndarray:
        self.seen.append(image)
        return with_bed(BEDROOM)[1]


def test_furniture_the_network_calls_its_room_is_painted_over_but_stays_part_of_the_room():
    img, _ = with_bed()
    stub = SameClassStub()
    (labels, _), furniture = segment_around_furniture(
        img,
        binarize(img),
        lambda drawing: (stub.predict(drawing), None),
    )
    assert len(stub.seen) == 2  # once as drawn, once without the bed; nothing new after that
    cleaned = stub.seen[1]
    assert cleaned[60, 140] > 200 and cleaned[40, 157] > 200  # the bed's free sides gone
    assert cleaned[38, 174] < 128 and cleaned[82, 174] < 128  # the wall beside it kept whole
    assert not furniture.any()  # no obstacle: the robot may drive over it, as before
    parsed = parse_drawing(img, segmenter=SameClassStub())
    assert parsed.instance_ids[BED_CENTRE] == parsed.instance_ids[ROOM_POINT]


def test_a_piece_touching_a_door_is_no_furniture_of_its_room():
    img, lab = two_rooms()
    cv2.rectangle(img, (103, 60), (125, 89), 0, 1)  # touching the door at a corner, as a swing
    lab[61:89, 104:125] = BEDROOM
    lines = binarize(img)
    pieces = extract_instances(img, lab, split=None, join_pieces=False)
    piece = int(pieces.instance_ids[75, 115])
    assert piece and pieces.by_id()[piece].class_name == "bedroom"
    assert against_walls(pieces, lines, same_class=True) == {}


def test_a_room_the_furniture_only_partly_covers_keeps_the_rest():
    # furniture found on the first segmentation whose outline no longer closes it (a leaf
    # drawn inside a hall): its paper is no instance, the room around it stays a room
    img, lab = two_rooms()
    furniture = np.zeros(lab.shape, bool)
    furniture[30:50, 110:130] = True  # 400 px of the bedroom's paper
    parsed = extract_instances(img, lab, split=None, furniture=furniture)
    room = int(parsed.instance_ids[ROOM_POINT])
    assert parsed.by_id()[room].class_name == "bedroom"
    assert not parsed.instance_ids[furniture].any()
    mostly = np.zeros(lab.shape, bool)
    mostly[27:174, 104:150] = True  # most of the bedroom
    covered = extract_instances(img, lab, split=None, furniture=mostly)
    assert covered.instance_ids[ROOM_POINT] == 0  # furniture's paper: an obstacle
    assert classes(covered) == ["door", "living", "wall", "wall", "wall"]
