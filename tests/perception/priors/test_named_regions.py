"""A confident room name makes its room where the parse has none or ran rooms together
(``perception.priors.named_regions``): a hand-drawn flat of two rooms, a stub reader and a
segmenter stub giving fixed labels."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from helpers import BEDROOM, LIVING, Oracle

from f2n_drake.core.classes import CLASS_ID, OPENING
from f2n_drake.core.text import TextBox
from f2n_drake.perception.ink import binarize
from f2n_drake.perception.priors.named_regions import NamedRoom, _within_doors, named_rooms
from f2n_drake.pipeline import parse_drawing

LEFT_NAME = (50, 90, 110, 102)  # a name's box in the left room
RIGHT_NAME = (190, 90, 250, 102)  # and in the right room
DOOR = CLASS_ID["door"]


def flat(middle: str) -> np.ndarray:
    """A 200 x 300 px flat of 3 px walls: two rooms side by side; ``middle`` is the wall
    between them: "wall", "door" (a 20 px gap) or "none" (one open room)."""
    image = np.full((200, 300), 255, np.uint8)
    cv2.rectangle(image, (20, 20), (280, 180), 0, 3)
    if middle == "wall":
        cv2.line(image, (150, 20), (150, 180), 0, 3)
    elif middle == "door":
        cv2.line(image, (150, 20), (150, 90), 0, 3)
        cv2.line(image, (150, 110), (150, 180), 0, 3)
    return image


def labels(left: int, right: int) -> np.ndarray:
    out = np.zeros((200, 300), np.uint8)
    out[22:179, 22:150] = left
    out[22:179, 150:279] = right
    return out


def reader(*names: tuple[str, tuple[int, int, int, int]]):
    return lambda _grey: [TextBox(text, 0.95, box) for text, box in names]


def test_a_room_open_to_the_outside_is_made_where_its_name_is():
    image = flat("wall")
    image[178:183, 60:80] = 255  # a doorway in the outer wall: the left room is not enclosed
    segmenter = Oracle(labels(LIVING, BEDROOM))
    unread = parse_drawing(image, segmenter=segmenter, reader=None)
    (room,) = unread.of_class("living")  # parted from the outside at its doorway
    assert unread.instance_ids[190, 150] != room.id

    parsed = parse_drawing(image, segmenter=segmenter, reader=reader(("Lounge", LEFT_NAME)))
    (lounge,) = parsed.of_class("living")
    assert lounge.name == "Lounge"
    assert lounge.area_px > 0.9 * 126 * 156  # the room, not the outside
    assert parsed.instance_ids[190, 150] == 0
    (door,) = parsed.of_class("door")  # the doorway closed is a door
    assert abs(door.centroid_px[1] - 180) <= 3 and 60 <= door.centroid_px[0] <= 80


@pytest.mark.usefixtures("drawings_at_own_size")
def test_rooms_the_parse_ran_together_are_parted_at_their_gap():
    """The gap between the two named rooms is a door where the network sees one in it, else an
    opening (the closing bridged a gap nothing says is a door)."""
    image = flat("door")
    one_room = labels(LIVING, LIVING)  # the network sees one room
    segmenter = Oracle(one_room)
    assert len(parse_drawing(image, segmenter=segmenter, reader=None).instances) == 1

    names = reader(("Kitchen", LEFT_NAME), ("Bedroom", RIGHT_NAME))
    parsed = parse_drawing(image, segmenter=segmenter, reader=names)
    by_id = parsed.by_id()
    assert by_id[int(parsed.instance_ids[60, 60])].class_name == "kitchen"
    assert by_id[int(parsed.instance_ids[60, 240])].class_name == "bedroom"
    assert by_id[int(parsed.instance_ids[100, 150])].class_name == OPENING
    assert not parsed.of_class("door")

    with_door = one_room.copy()
    with_door[92:109, 147:154] = DOOR  # and a door in the gap between them
    parsed = parse_drawing(image, segmenter=Oracle(with_door), reader=names)
    assert parsed.by_id()[int(parsed.instance_ids[100, 150])].class_name == "door"


@pytest.mark.usefixtures("drawings_at_own_size")
def test_an_open_plan_named_twice_is_parted_between_its_names():
    image = flat("none")
    segmenter = Oracle(labels(LIVING, LIVING))
    names = reader(("Kitchen", LEFT_NAME), ("Lounge", RIGHT_NAME))
    parsed = parse_drawing(image, segmenter=segmenter, reader=names)
    by_id = parsed.by_id()
    assert by_id[int(parsed.instance_ids[60, 60])].class_name == "kitchen"
    assert by_id[int(parsed.instance_ids[60, 240])].class_name == "living"
    assert by_id[int(parsed.instance_ids[60, 150])].class_name == OPENING


def test_a_room_open_along_a_whole_side_or_a_doubtful_name_makes_no_room():
    image = flat("wall")
    image[178:183, 30:140] = 255  # the left room open to the outside along its whole side
    texts = [TextBox("Lounge", 0.95, LEFT_NAME), TextBox("Bedroom", 0.5, RIGHT_NAME)]
    rooms, gaps = named_rooms(binarize(image), texts, labels(LIVING, BEDROOM))
    assert rooms == []
    assert not gaps[180, 85]  # wider than a door: not closed

    rooms, _ = named_rooms(binarize(image), [TextBox("Bedroom", 0.95, RIGHT_NAME)], labels(0, 0))
    assert [(r.class_name, r.mask[60, 240], r.mask[60, 60]) for r in rooms] == [
        ("bedroom", True, False)
    ]


def test_a_named_room_the_fixture_step_made_whole_keeps_its_counters():
    image = flat("wall")
    cv2.line(image, (70, 22), (70, 178), 0, 1)  # counters along two walls, in 1 px lines,
    cv2.line(image, (22, 80), (148, 80), 0, 1)  # deeper than a counter is: the floor is small
    floor_name = (90, 120, 140, 132)
    segmenter = Oracle(labels(LIVING, BEDROOM))
    parsed = parse_drawing(image, segmenter=segmenter, reader=reader(("Kitchen", floor_name)))
    (kitchen,) = parsed.of_class("kitchen")
    assert kitchen.name == "Kitchen"
    assert kitchen.area_px > 0.9 * 126 * 156  # floor and counters, not the floor alone
    assert {int(parsed.instance_ids[y, x]) for y, x in [(50, 40), (50, 100), (120, 40)]} == {
        kitchen.id
    }


def test_a_small_rooms_name_does_not_make_most_of_the_plan_its_room():
    image = flat("none")  # an open floor: the WC's own walls are not drawn closed
    segmenter = Oracle(labels(LIVING, LIVING))
    (floor,) = parse_drawing(image, segmenter=segmenter, reader=reader(("WC", LEFT_NAME))).instances
    assert floor.class_name == "living" and floor.name == "WC"
    (room,) = parse_drawing(
        image, segmenter=segmenter, reader=reader(("Bedroom", LEFT_NAME))
    ).instances
    assert room.class_name == "bedroom"  # a bedroom may be most of a plan
    parted = parse_drawing(
        flat("door"), segmenter=segmenter, reader=reader(("WC", LEFT_NAME), ("Hall", RIGHT_NAME))
    )
    assert parted.by_id()[int(parted.instance_ids[60, 60])].class_name == "bathroom"


def test_a_name_beside_the_plan_on_a_framed_sheet_makes_no_room():
    image = np.full((300, 420), 255, np.uint8)
    image[50:250, 30:330] = flat("wall")  # the plan on a sheet ...
    cv2.rectangle(image, (4, 4), (415, 295), 0, 3)  # ... in a frame
    image[:16, :16] = 255  # the frame's corner left open: the margin joins the image border
    beside = (340, 140, 400, 152)  # a name right of the plan, on the margin
    texts = [TextBox("Kitchen", 0.95, beside)]
    rooms, _ = named_rooms(binarize(image), texts, np.zeros_like(image))
    assert rooms == []  # the margin parted from its corner lies outside the plan: no room


def test_a_named_room_stops_at_the_doors_the_parse_found():
    # a WC's paper runs through its door into the passage beyond (a jamb's tick left the gap
    # open to the wall closing): the door the parse found bounds the named room
    wc, passage, door = np.zeros((3, 60, 90), bool)
    wc[10:50, 10:40] = True
    passage[10:50, 45:80] = True
    door[30:45, 40:45] = True
    name = TextBox("WC", 0.95, (15, 20, 30, 28))
    room = NamedRoom("bathroom", wc | passage | door, (name,))
    np.testing.assert_array_equal(_within_doors(room, door).mask, wc)
    assert _within_doors(room, np.zeros_like(door)) is room  # no door in it: as it was
    on_door = NamedRoom("bathroom", room.mask, (TextBox("WC", 0.95, (40, 35, 45, 40)),))
    assert _within_doors(on_door, door) is on_door  # its name on the door: as it was
