"""The pieces a named room's fixtures cut off take the room's class, and a balcony named on
paper open to the outside is the piece of the drawing around its name
(``perception.priors.named_pieces``, ``perception.priors.named_balconies``): a hand-drawn flat
of 4 px walls, stub readers and a segmenter stub giving fixed labels."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from helpers import BEDROOM, DOOR, LIVING, Oracle

from f2n_drake.core.text import TextBox
from f2n_drake.perception.priors.named_balconies import drawing_extent
from f2n_drake.pipeline import parse_drawing

BATH_NAME = (50, 60, 110, 72)  # a name's box in the left room
TERRACE_NAME = (120, 196, 180, 208)  # in the terrace below the flat


def flat() -> np.ndarray:
    """A 260 x 300 px drawing: a flat of two rooms (4 px walls, 20..280 x 20..180), a tub of
    1 px lines in the left room's lower corner."""
    image = np.full((260, 300), 255, np.uint8)
    cv2.rectangle(image, (20, 20), (280, 180), 0, 4)
    cv2.line(image, (150, 20), (150, 180), 0, 4)
    cv2.rectangle(image, (22, 130), (70, 178), 0, 1)  # the tub, against two walls
    return image


def labels() -> np.ndarray:
    out = np.zeros((260, 300), np.uint8)
    out[22:179, 22:149] = LIVING
    out[22:179, 152:279] = BEDROOM
    return out


def reader(*names: tuple[str, tuple[int, int, int, int]]):
    return lambda _grey: [TextBox(text, 0.95, box) for text, box in names]


def class_at(parsed, row: int, col: int) -> str | None:
    iid = int(parsed.instance_ids[row, col])
    return parsed.by_id()[iid].class_name if iid else None


def test_the_pieces_a_named_rooms_fixtures_cut_off_take_its_class():
    image = flat()
    segmenter = Oracle(labels())
    unread = parse_drawing(image, segmenter=segmenter, reader=None)
    assert class_at(unread, 150, 45) == "living"  # the tub's inside: a piece of the room
    assert unread.instance_ids[150, 45] == unread.instance_ids[60, 100]

    parsed = parse_drawing(image, segmenter=segmenter, reader=reader(("Bath", BATH_NAME)))
    assert class_at(parsed, 60, 100) == "bathroom"  # the named piece
    assert class_at(parsed, 150, 45) == "bathroom"  # the tub's inside
    assert class_at(parsed, 60, 220) == "bedroom"  # the room behind the wall stays


@pytest.mark.usefixtures("drawings_at_own_size")
def test_a_named_room_behind_a_wall_keeps_its_class():
    image = flat()
    segmenter = Oracle(labels())
    names = reader(("Bath", BATH_NAME), ("Lounge", (190, 60, 250, 72)))
    parsed = parse_drawing(image, segmenter=segmenter, reader=names)
    assert class_at(parsed, 60, 220) == "living"  # named, walled: not a piece of the bath
    assert class_at(parsed, 150, 45) == "bathroom"


def terrace() -> np.ndarray:
    """``flat`` with a terrace below it: grey tone without an outline (20..280 x 184..230), its
    name on a white box."""
    image = flat()
    image[184:230, 20:281] = 200
    image[192:212, 114:186] = 255
    return image


@pytest.mark.usefixtures("drawings_at_own_size")
def test_a_terrace_drawn_as_tone_without_outline_is_the_tone_around_its_name():
    image = terrace()
    extent = drawing_extent(image, image < 128)
    assert extent[200, 150] and extent[220, 30] and not extent[245, 150]

    segmenter = Oracle(labels())
    unread = parse_drawing(image, segmenter=segmenter, reader=None)
    assert class_at(unread, 200, 150) is None

    parsed = parse_drawing(image, segmenter=segmenter, reader=reader(("Terrace", TERRACE_NAME)))
    (balcony,) = parsed.of_class("balcony")
    assert balcony.name == "Terrace"
    assert 0.9 * 261 * 46 < balcony.area_px < 1.05 * 261 * 46  # the tone, not the sheet
    assert class_at(parsed, 60, 100) == "living" and class_at(parsed, 60, 220) == "bedroom"


@pytest.mark.usefixtures("drawings_at_own_size")
def test_a_terrace_name_on_blank_paper_makes_no_balcony():
    image = flat()
    parsed = parse_drawing(
        image, segmenter=Oracle(labels()), reader=reader(("Terrace", TERRACE_NAME))
    )
    assert parsed.of_class("balcony") == []


def hatched_balcony() -> np.ndarray:
    """``flat`` with a balcony below it: a 1 px outline (20..280 x 180..230) cross-hatched by
    1 px diagonals 16 px apart, so the paper round its name is one small cell."""
    image = flat()
    cv2.rectangle(image, (20, 180), (280, 230), 0, 1)
    strip = np.full((50, 260), 255, np.uint8)
    for k in range(-60, 320, 16):
        cv2.line(strip, (k, 0), (k + 50, 50), 0, 1)
        cv2.line(strip, (k + 50, 0), (k, 50), 0, 1)
    image[181:230, 21:280] = strip[1:, 1:]
    return image


@pytest.mark.usefixtures("drawings_at_own_size")
def test_a_balcony_named_on_a_cell_of_its_hatching_is_the_whole_hatched_strip():
    image = hatched_balcony()
    segmenter = Oracle(labels())
    names = reader(("Balcony", (130, 198, 170, 208)))
    parsed = parse_drawing(image, segmenter=segmenter, reader=names)
    (balcony,) = parsed.of_class("balcony")
    assert balcony.area_px > 0.8 * 259 * 49  # the strip, hatching and all, not one cell
    assert class_at(parsed, 60, 100) == "living" and class_at(parsed, 60, 220) == "bedroom"


def test_a_piece_with_a_door_is_a_room_of_its_own():
    image = flat()
    cv2.rectangle(image, (22, 130), (70, 178), 255, 1)  # no tub
    cv2.line(image, (22, 120), (148, 120), 0, 1)  # a thin line parts the left room
    image[145:165, 17:24] = 255  # a door's gap in the outer wall, beside the lower part
    lab = labels()
    lab[143:167, 16:24] = DOOR
    named = parse_drawing(image, segmenter=Oracle(lab), reader=reader(("Bath", BATH_NAME)))
    assert class_at(named, 60, 100) == "bathroom"
    assert class_at(named, 150, 100) == "living"  # entered by a door: no piece of the bath
    assert any(i.class_name in ("door", "front_door") for i in named.instances)
