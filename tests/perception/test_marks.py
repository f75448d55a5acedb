"""Marks: room names, furniture and sheet frames standing free of the plan's structure."""

from __future__ import annotations

import cv2
import numpy as np
from helpers import BEDROOM, DOOR, LIVING, classes, two_rooms

from f2n_drake.perception.ink import as_grey, enclosed_by, free_marks
from f2n_drake.perception.instances import binarize, extract_instances
from f2n_drake.perception.preparation import to_grey

GREEN, RED = (40, 150, 0), (30, 30, 210)  # BGR


def test_letters_in_a_room_are_no_instances():
    img, lab = (
        cv2.resize(a, None, fx=2, fy=2, interpolation=cv2.INTER_NEAREST) for a in two_rooms()
    )
    lab[lab == LIVING] = BEDROOM
    lab[120:150, 60:180] = DOOR  # the network paints the letters' counters as a door
    # a room name 10 px high in a plan 322 px across: free-standing words are marks
    cv2.putText(img, "BOB 80", (64, 144), cv2.FONT_HERSHEY_SIMPLEX, 0.45, 0, 1, cv2.LINE_AA)
    expected = ["bedroom", "bedroom", "door", "wall", "wall", "wall"]
    assert classes(extract_instances(img, lab)) == expected
    parsed = extract_instances(img, lab)
    left = parsed.instance_ids[200, 80]
    words = binarize(img)[100:160, 60:185]
    assert words.sum() > 100
    assert (parsed.instance_ids[100:160, 60:185][words] == left).all()  # the room's paper


def test_furniture_standing_in_a_room_is_no_instance():
    img, lab = (
        cv2.resize(a, None, fx=2, fy=2, interpolation=cv2.INTER_NEAREST) for a in two_rooms()
    )
    cv2.rectangle(img, (90, 110), (150, 200), 0, 2)  # a bed in the living room...
    cv2.line(img, (90, 130), (150, 130), 0, 2)
    lab[110:201, 90:151] = BEDROOM  # ...that the network would call a bedroom
    parsed = extract_instances(img, lab)
    assert classes(parsed) == ["bedroom", "door", "living", "wall", "wall", "wall"]
    bed = np.zeros(img.shape, bool)
    bed[114:197, 94:147] = True
    assert not parsed.instance_ids[bed].any()  # an obstacle: no instance, so not free space


def test_marks_are_small_free_ink_larger_ink_within_the_plan_or_ink_far_beside_it():
    lines = np.zeros((220, 400), bool)
    lines[10:210, 10] = lines[10:210, 390] = lines[10, 10:391] = lines[209, 10:391] = True
    lines[10:210, 200] = True  # the plan: two rooms, 380 px across, so text is <= 15 px
    plan = lines.copy()
    ring = np.zeros(lines.shape, np.uint8)
    cv2.circle(ring, (100, 110), 5, 1, 1)  # an "o" inside the left room: text
    cv2.circle(ring, (205, 110), 5, 1, 1)  # an "o" touching the middle wall: structure
    table = np.zeros(lines.shape, np.uint8)
    cv2.rectangle(table, (260, 80), (320, 140), 1, 1)  # large, standing in a room: furniture
    marks = free_marks(plan | (ring > 0) | (table > 0))
    letter = np.zeros(lines.shape, np.uint8)
    cv2.circle(letter, (100, 110), 5, 1, 1)
    np.testing.assert_array_equal(marks.annotation, letter > 0)
    np.testing.assert_array_equal(marks.furniture, table > 0)
    np.testing.assert_array_equal(marks.ink, (letter > 0) | (table > 0))
    top = np.zeros(lines.shape, np.uint8)
    cv2.rectangle(top, (261, 81), (319, 139), 1, -1)
    np.testing.assert_array_equal(enclosed_by(marks.furniture), top > 0)
    assert not free_marks(plan).ink.any()  # one piece of ink: the structure
    outside = np.zeros((300, 560), bool)
    outside[:220, :400] = plan
    annex = np.zeros(outside.shape, np.uint8)
    cv2.rectangle(annex, (400, 40), (480, 180), 1, 1)  # large, built against the plan: structure
    cv2.putText(annex, "N", (440, 214), cv2.FONT_HERSHEY_SIMPLEX, 0.3, 1, 1)  # small: text
    title = np.zeros(outside.shape, np.uint8)
    cv2.rectangle(title, (420, 236), (550, 290), 1, 1)  # large, 8 % of the plan away...
    cv2.line(title, (420, 263), (550, 263), 1, 1)
    box = free_marks(outside | (annex > 0) | (title > 0))
    assert not box.ink[230:].any()  # an empty box: structure (a shed)
    cv2.putText(title, "A-1", (430, 255), cv2.FONT_HERSHEY_SIMPLEX, 0.3, 1, 1)  # ...with words:
    marks = free_marks(outside | (annex > 0) | (title > 0))  # the sheet's title block
    assert marks.annotation[200:220, 430:470].any() and not marks.ink[:190].any()
    np.testing.assert_array_equal(marks.annotation[230:], title[230:] > 0)
    sheet = np.zeros((300, 480), bool)
    sheet[40:260, 40:440] = plan
    border = np.zeros(sheet.shape, np.uint8)
    cv2.rectangle(border, (5, 5), (474, 294), 1, 3)  # a sheet's frame, heavier than the plan
    assert (border > 0).sum() > plan.sum()
    marks = free_marks(sheet | (border > 0))
    np.testing.assert_array_equal(marks.annotation, border > 0)  # the frame, not the plan
    walls = np.zeros(sheet.shape, np.uint8)
    cv2.rectangle(walls, (28, 28), (451, 271), 1, 1)  # an outer wall line 12 px out: structure
    assert not free_marks(sheet | (walls > 0)).ink.any()


def test_coloured_marks_are_paper_and_the_lines_they_cross_are_joined_again():
    img, lab = two_rooms()
    sign = cv2.cvtColor(img, cv2.COLOR_GRAY2BGR)
    cv2.line(sign, (60, 105), (140, 105), GREEN, 3, cv2.LINE_8)  # a route through the door box
    cv2.circle(sign, (150, 31), 5, RED, -1, cv2.LINE_8)  # an extinguisher over the wall's line
    cv2.circle(sign, (60, 150), 8, RED, 1, cv2.LINE_AA)  # "you are here", anti-aliased
    crossed = (sign != img[..., None]).any(axis=2)
    assert (img[crossed] == 0).sum() > 10  # the marks cover pieces of the outlines
    grey = as_grey(sign)
    assert np.abs(grey.astype(int) - img).max() <= 8  # at most the faintest anti-aliasing left
    np.testing.assert_array_equal(binarize(grey), binarize(img))  # outlines whole again
    np.testing.assert_array_equal(to_grey(sign), grey)  # the network sees the same grey
    assert classes(extract_instances(sign, lab)) == classes(extract_instances(img, lab))


def test_colour_that_is_the_drawing_is_kept():
    img, _ = two_rooms()
    blueprint = np.empty((*img.shape, 3), np.uint8)
    blueprint[:] = (150, 80, 20)  # white lines on blue paper
    blueprint[img < 128] = 255
    in_red = np.full((*img.shape, 3), 255, np.uint8)
    in_red[img < 128] = RED  # a plan drawn in red
    for drawing in (blueprint, in_red):
        np.testing.assert_array_equal(as_grey(drawing), cv2.cvtColor(drawing, cv2.COLOR_BGR2GRAY))


def test_the_plans_other_half_holding_words_is_no_title_block():
    lines = np.zeros((220, 440), bool)
    lines[10:210, 230] = lines[10, 230:431] = lines[209, 230:431] = lines[10:210, 430] = True
    lines[10:210, 330] = True  # the right half: two rooms
    left = np.zeros(lines.shape, np.uint8)  # the left half, 30 px away (gaps in the walls)
    cv2.rectangle(left, (10, 10), (200, 209), 1, 1)
    cv2.putText(left, "WC", (60, 110), cv2.FONT_HERSHEY_SIMPLEX, 0.3, 1, 1)  # a room's name
    walls = np.zeros(lines.shape, np.uint8)
    cv2.rectangle(walls, (10, 10), (200, 209), 1, 1)
    marks = free_marks(lines | (left > 0))
    assert marks.annotation[95:115, 55:90].any()  # the name is a word
    assert not (marks.annotation & (walls > 0)).any()  # the walls stay walls
