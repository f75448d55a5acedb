"""A room its fixtures cut into pieces is one instance (``perception.fixture_pieces``): hand-drawn
flats, a segmenter stub giving fixed labels."""

from __future__ import annotations

import cv2
import numpy as np
from helpers import BEDROOM, LIVING, Oracle

from f2n_drake.core.classes import CLASS_ID
from f2n_drake.core.parsed import ParsedPlan, instance_from_mask
from f2n_drake.perception.fixture_pieces import RoomExtents, join_fixture_pieces, wall_ink
from f2n_drake.perception.ink import binarize
from f2n_drake.perception.instances import extract_instances
from f2n_drake.pipeline import parse_drawing

WALL = CLASS_ID["wall"]


def flat(wall_px: int) -> tuple[np.ndarray, np.ndarray]:
    """A 260 x 300 px drawing of two rooms (walls ``wall_px`` thick, 20..280 x 20..180, no door
    between them) with a tub and a basin of 1 px lines in the left one; and its labels, the
    rooms' classes and walls, with the tub's outline labelled wall too (as the network often
    does)."""
    image = np.full((260, 300), 255, np.uint8)
    cv2.rectangle(image, (20, 20), (280, 180), 0, wall_px)
    cv2.line(image, (150, 20), (150, 180), 0, wall_px)
    cv2.rectangle(image, (24, 120), (70, 176), 0, 1)  # the tub, against two walls
    cv2.rectangle(image, (100, 24), (130, 44), 0, 1)  # the basin, against one
    labels = np.zeros((260, 300), np.uint8)
    labels[22:179, 22:149] = LIVING
    labels[22:179, 152:279] = BEDROOM
    cv2.rectangle(labels, (20, 20), (280, 180), WALL, wall_px)
    cv2.line(labels, (150, 20), (150, 180), WALL, wall_px)
    cv2.rectangle(labels, (24, 120), (70, 176), WALL, 1)
    return image, labels


def test_a_rooms_tub_and_basin_are_pieces_of_it():
    for wall_px in (4, 8):  # walls as thin as the network sees them, or drawn thick
        image, labels = flat(wall_px)
        voted = extract_instances(image, labels)
        assert voted.instance_ids[150, 45] != voted.instance_ids[80, 100]  # split by its tub
        parsed = join_fixture_pieces(voted, binarize(image))
        room = parsed.instance_ids[80, 100]
        assert parsed.instance_ids[150, 45] == room and parsed.instance_ids[34, 115] == room
        assert parsed.by_id()[room].class_name == "living"
        assert parsed.instance_ids[80, 220] not in (0, room)  # the room behind the wall stays
        ids = sorted(i.id for i in parsed.instances)
        assert ids == list(range(1, len(ids) + 1))  # renumbered 1..K
        assert set(np.unique(parsed.instance_ids)) == {0, *ids}
        joined = parsed.by_id()[room]
        assert joined.area_px == np.count_nonzero(parsed.instance_ids == room)


def test_thick_walls_are_the_thick_ink_not_the_networks_labels_on_fixtures():
    image, labels = flat(8)
    walls = wall_ink(binarize(image), labels)
    assert walls[100, 150] and walls[20, 100]  # the partition and the outer wall
    assert not walls[120, 50]  # the tub's outline, labelled wall


def test_a_room_walled_off_on_every_side_is_no_piece():
    image, labels = flat(4)
    cv2.rectangle(image, (200, 120), (278, 178), 0, 4)  # a walled box in the right room
    parsed = parse_drawing(image, segmenter=Oracle(labels), reader=None)
    assert parsed.instance_ids[150, 240] != parsed.instance_ids[60, 220]


def test_a_plan_without_fixtures_comes_back_unchanged():
    image, labels = flat(4)
    image[:] = 255
    cv2.rectangle(image, (20, 20), (280, 180), 0, 4)
    cv2.line(image, (150, 20), (150, 180), 0, 4)
    voted = extract_instances(image, labels)
    assert join_fixture_pieces(voted, binarize(image)) is voted


def test_with_thick_walls_a_room_open_to_the_outside_still_takes_its_fixtures():
    image, labels = flat(8)
    image[40:170, 16:24] = 255  # a long window in the left room's outer wall: one thin line
    image[40:170, 20] = 0  # closes the room, not its extent (open to the border)
    voted = extract_instances(image, labels, doorways=False)
    assert voted.instance_ids[150, 45] != voted.instance_ids[80, 100]
    parsed = join_fixture_pieces(voted, binarize(image))
    room = parsed.instance_ids[80, 100]
    assert room and parsed.instance_ids[150, 45] == room and parsed.instance_ids[34, 115] == room
    assert parsed.instance_ids[80, 220] not in (0, room)


def test_a_pieces_share_of_its_extent_leaves_out_walls_and_closed_gaps():
    regions = np.zeros((15, 10), np.int32)  # 0: walls and gaps closed between wall ends
    regions[:, :4], regions[:, 6:] = 1, 2
    extents = RoomExtents(regions == 0, regions, frozenset())
    ids = np.zeros((15, 10), np.int32)
    ids[:5, 1:6] = 1  # 3 columns in extent 1, 2 on the closed gap
    ids[5:10, 3:9] = 2  # 1 column in extent 1, 2 on the gap, 3 in extent 2
    ids[10:, 3:6] = 3  # 1 column in extent 1, 2 on the gap: mostly off the extents' paper
    region_of, share = extents.of_instances(ids)
    assert region_of[1] == 1 and share[1] == 1.0  # all of it on paper lies in extent 1
    assert region_of[2] == 2 and np.isclose(share[2], 3 / 4)
    assert region_of[3] == 1 and share[3] == 0.0


def test_a_balcony_beyond_a_thin_railing_is_no_piece_of_the_room():
    image, labels = flat(4)
    image[23:46, 99:132] = 255  # no basin
    cv2.line(image, (18, 60), (152, 60), 0, 1)  # a railing in a thin line across the left room
    labels[22:60, 22:149] = CLASS_ID["balcony"]
    voted = extract_instances(image, labels)
    assert not voted.of_class("door")
    parsed = join_fixture_pieces(voted, binarize(image))
    room, balcony = parsed.instance_ids[100, 100], parsed.instance_ids[40, 60]
    assert parsed.by_id()[room].class_name == "living"
    assert parsed.by_id()[balcony].class_name == "balcony" and balcony != room
    assert parsed.instance_ids[150, 45] == room  # the tub still joins the room


def test_a_room_spilling_through_its_doorway_still_takes_its_fixtures():
    image = np.full((260, 300), 255, np.uint8)
    cv2.rectangle(image, (20, 20), (280, 180), 0, 4)
    cv2.line(image, (200, 20), (200, 80), 0, 4)  # a partition with a 20 px doorway the
    cv2.line(image, (200, 100), (200, 180), 0, 4)  # extents close, the instances do not
    cv2.rectangle(image, (24, 120), (70, 176), 0, 1)  # the tub
    labels = np.zeros((260, 300), np.uint8)
    labels[22:179, 22:279] = LIVING  # one room to the network, two extents to the walls
    voted = extract_instances(image, labels)
    room = voted.instance_ids[80, 100]
    assert voted.instance_ids[80, 240] == room != voted.instance_ids[150, 45]
    parsed = join_fixture_pieces(voted, binarize(image))
    assert parsed.instance_ids[150, 45] == parsed.instance_ids[80, 100]


def tub_across(
    line_label: str, door_on_line: bool = False, wall_px: int = 9, room: str = "bathroom"
):
    """(ink, plan) of a bathroom (walls ``wall_px`` thick round 13..147 x 13..107) cut in two by
    a tub's 1 px outline run from wall to wall (row 70): the floor above (instance 1, its door in
    the top wall instance 4), the tub below (instance 2), and an opening the doorway step closed
    between the tub and the right wall (instance 3, "opening", no door seen). The network labels
    the room ``room``, the walls wall and the tub's outline ``line_label``; ``door_on_line``: a
    door (instance 5) on the outline between them."""
    ink = np.zeros((130, 170), bool)
    top, bottom, left, right = 13 - wall_px, 108 + wall_px, 13 - wall_px, 148 + wall_px
    ink[top:13, left:right] = ink[108:bottom, left:right] = True
    ink[top:bottom, left:13] = ink[top:bottom, 148:right] = True
    ink[70, 13:148] = True
    labels = np.full(ink.shape, CLASS_ID[room], np.uint8)
    labels[ink] = CLASS_ID["wall"]
    labels[70, 13:148] = CLASS_ID[line_label]
    ids = np.zeros(ink.shape, np.int32)
    ids[13:70, 13:148] = 1
    ids[71:108, 13:138] = 2
    ids[71:108, 138:148] = 3
    ids[top:13, 60:80] = 4
    if door_on_line:
        ids[69:72, 40:60] = 5
    names = {1: room, 2: room, 3: "opening", 4: "door", 5: "door"}
    instances = [
        instance_from_mask(k, name, ids == k, labels) for k, name in names.items() if k in ids
    ]
    return ink, ParsedPlan(ids, labels, instances)


def test_a_tub_run_from_wall_to_wall_is_part_of_the_bathroom_across_its_outline():
    for wall_px in (9, 3):  # walls drawn thick, or as thin lines (a bathroom's fixtures fill it)
        ink, plan = tub_across("bathroom", wall_px=wall_px)
        parsed = join_fixture_pieces(plan, ink)
        room = parsed.instance_ids[40, 80]
        assert parsed.instance_ids[90, 60] == room  # the tub, next to an opening (no door seen)
        assert parsed.instance_ids[90, 142] == room  # the opening between the tub and the wall
        assert parsed.by_id()[room].class_name == "bathroom"
        assert parsed.by_id()[parsed.instance_ids[11, 70]].class_name == "door"  # its door stays


def test_rooms_of_one_class_stay_apart_across_a_wall_a_door_or_thin_lines_outside_bathrooms():
    for line_label, door_on_line, wall_px, room in (
        ("wall", False, 9, "bathroom"),
        ("bathroom", True, 9, "bathroom"),
        ("living", False, 3, "living"),  # walls drawn as thin as the line: no telling them apart
    ):
        ink, plan = tub_across(line_label, door_on_line, wall_px, room)
        parsed = join_fixture_pieces(plan, ink)
        assert parsed.instance_ids[40, 80] != parsed.instance_ids[90, 60]
