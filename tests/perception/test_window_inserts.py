"""Windows drawn in a wall's line (thin parallel lines where the thick wall stops) are window
instances that close the room; a gap with no lines across it is no window."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from f2n_drake.core.classes import CLASS_ID
from f2n_drake.perception.instances import extract_instances
from f2n_drake.perception.runs import stroke_widths_px
from f2n_drake.perception.wall_angles import oblique_wall_angles
from f2n_drake.perception.window_inserts import (
    count_lines,
    face_lines_px,
    find_wall_inserts,
    wall_bands,
    wall_line_gaps,
)

LIVING, WALL = CLASS_ID["living"], CLASS_ID["wall"]
WALL_PX = 8


def room_with_window(lines_grey: int | None = 170, lines_across: int = 3):
    """A 160x200 room drawn with 8 px solid walls; its top wall stops for 40 px (columns
    80-119) and ``lines_across`` 1 px lines of grey ``lines_grey`` run across the gap along the
    wall (on its two faces and in its middle; none when ``lines_grey`` is None). Network labels:
    the room living, the thick ink wall."""
    img = np.full((160, 200), 255, np.uint8)
    cv2.rectangle(img, (20, 20), (179, 139), 0, -1)
    img[28:132, 28:172] = 255  # walls rows 20-27 (top), 132-139; columns 20-27, 172-179
    img[20:28, 80:120] = 255
    if lines_grey is not None:
        for row in np.linspace(20, 27, lines_across).round().astype(int):
            img[row, 80:120] = lines_grey
    labels = np.zeros(img.shape, np.uint8)
    labels[28:132, 28:172] = LIVING
    labels[img < 128] = WALL
    return img, labels


def test_stroke_widths_are_the_shorter_run_across_each_pixel():
    ink = np.zeros((20, 30), bool)
    ink[5:9, 2:28] = True  # a horizontal stroke 4 px thick
    ink[2:18, 14] = True  # a vertical hairline crossing it
    widths = stroke_widths_px(ink)
    assert widths[6, 5] == 4
    assert widths[3, 14] == 1
    assert widths[0, 0] == 0


def test_count_lines_parts_lines_whose_blur_touches():
    assert count_lines(np.array([0, 8, 58, 13, 45, 58, 39, 7])) == 2  # blurred, a pixel apart
    assert count_lines(np.array([0, 40, 0, 40, 0, 40, 0])) == 3
    assert count_lines(np.array([0, 50, 50, 50, 0])) == 1  # one thick line
    assert count_lines(np.array([0, 5, 8, 6, 0])) == 0  # paper noise


def test_wall_line_gaps_join_two_ends_of_one_wall_only():
    band = np.zeros((60, 120), bool)
    band[10:18, 5:40] = band[10:18, 70:115] = True  # one wall's two ends, 30 px apart
    band[30:38, 5:40] = True  # a wall ending before a wall crossing its line
    band[20:58, 70:78] = True
    gaps = wall_line_gaps(band, wall_px=8, max_span_px=50)
    assert gaps[10:18, 40:70].all()
    assert not gaps[30:38, 40:70].any()  # no line continues into the crossing wall
    assert not wall_line_gaps(band, wall_px=8, max_span_px=20).any()


def test_a_ragged_edge_reaching_the_next_wall_does_not_join_the_gaps():
    band = np.zeros((40, 180), bool)
    band[10:18, 5:40] = band[10:18, 70:120] = band[10:18, 150:175] = True  # a wall, two gaps
    band[9, 30:40] = band[9, 150:160] = True  # a ragged upper face: row 9 spans both gaps
    gaps = wall_line_gaps(band, wall_px=8, max_span_px=120)
    assert gaps[10:18, 40:70].all() and gaps[10:18, 120:150].all()
    assert not gaps[9].any()  # the edge's lone row is no gap: the gaps stay two rectangles


def test_thin_lines_in_a_wall_gap_are_a_window():
    img, labels = room_with_window()
    inserts = find_wall_inserts(img, img < 200, labels, max_window_px=60, max_door_px=30)
    assert inserts.windows.max() == 1
    assert (inserts.windows[20:28, 80:120] == 1).all()  # the gap, the wall's thickness
    assert not inserts.gaps[20:28, 80:120].any()


def test_a_gap_with_no_lines_is_no_window():
    img, labels = room_with_window(lines_grey=None)
    inserts = find_wall_inserts(img, img < 200, labels, max_window_px=60, max_door_px=45)
    assert not inserts.windows.any()
    assert inserts.gaps[20:28, 80:120].all()  # a door's place
    img, labels = room_with_window(lines_across=1)  # one line: no window either
    inserts = find_wall_inserts(img, img < 200, labels, max_window_px=60, max_door_px=30)
    assert not inserts.windows.any()


def test_a_gap_wider_than_a_doorway_is_a_wide_doors_place_up_to_its_bound():
    img, labels = room_with_window(lines_grey=None)  # a gap 40 px long
    options = dict(max_window_px=60, max_door_px=30)
    inserts = find_wall_inserts(img, img < 200, labels, **options)
    assert not inserts.gaps.any() and inserts.wide_gaps is None
    inserts = find_wall_inserts(img, img < 200, labels, max_wide_door_px=45, **options)
    assert inserts.wide_gaps[20:28, 80:120].all() and not inserts.gaps.any()
    inserts = find_wall_inserts(img, img < 200, labels, max_wide_door_px=36, **options)
    assert not inserts.wide_gaps.any()  # longer than the widest double door


def test_a_window_insert_closes_the_room_and_is_a_window_instance():
    img, labels = room_with_window(lines_grey=200)  # light lines the binarisation may lose
    parsed = extract_instances(img, labels)
    names = sorted(i.class_name for i in parsed.instances)
    assert names == ["living", "window"]
    (window,) = parsed.of_class("window")
    assert parsed.mask(window.id)[20:28, 80:120].mean() > 0.9
    (room,) = parsed.of_class("living")
    assert room.area_px > 0.9 * 104 * 144


def test_a_gap_the_network_labels_window_is_a_window_whatever_its_ink():
    img, labels = room_with_window(lines_grey=None)
    img[20:28, 80:120] = 200  # a grey fill, no lines to count
    labels[20:28, 80:120] = CLASS_ID["window"]
    inserts = find_wall_inserts(img, img < 230, labels, max_window_px=60, max_door_px=45)
    assert inserts.classes.tolist() == [CLASS_ID["window"]]
    assert (inserts.windows[20:28, 80:120] == 1).all()  # the strip between the wall's faces
    assert not inserts.gaps.any()
    for seen in (LIVING, CLASS_ID["door"]):  # a room or a door: a door's place, no window
        labels[20:28, 80:120] = seen
        inserts = find_wall_inserts(img, img < 230, labels, max_window_px=60, max_door_px=45)
        assert not inserts.windows.any()
        assert inserts.gaps[20:28, 80:120].any()


def test_a_grey_window_the_network_sees_closes_the_room_as_a_window_instance():
    img, labels = room_with_window(lines_grey=None)
    img[20:28, 80:120] = 140  # dark enough to be ink: a solid grey window
    labels[20:28, 80:120] = CLASS_ID["window"]
    parsed = extract_instances(img, labels)
    assert sorted(i.class_name for i in parsed.instances) == ["living", "window"]
    (window,) = parsed.of_class("window")
    assert parsed.mask(window.id)[20:28, 80:120].all()
    assert window.area_px == 8 * 40  # the wall's opening, no more


def test_a_door_box_across_a_thick_wall_is_a_door_the_size_of_the_opening():
    img, labels = room_with_window(lines_grey=0, lines_across=2)  # the box's two long sides
    img[20:22, 80:120] = img[26:28, 80:120] = 0  # drawn 2 px thick
    labels[20:28, 80:120] = CLASS_ID["door"]
    inserts = find_wall_inserts(img, img < 200, labels, max_window_px=60, max_door_px=45)
    assert inserts.classes.tolist() == [CLASS_ID["door"]]
    assert inserts.door_face_px == 2  # the pen of its jambs
    parsed = extract_instances(img, labels)
    (door,) = parsed.of_class("door")
    assert door.area_px == 8 * 40  # the strip between the wall's faces, its sides included
    assert parsed.door_outline_px == 2


def test_face_lines_are_the_inked_rows_on_both_long_sides():
    insert = np.ones((8, 30), bool)
    ink = np.zeros((8, 30), bool)
    ink[:2] = ink[5:] = True
    assert face_lines_px(insert, ink) == 2.5
    assert face_lines_px(insert.T, ink.T) == 2.5  # a box standing upright
    ink[5:] = False
    assert face_lines_px(insert, ink) == 0  # a line on one side only: no box
    assert face_lines_px(insert, np.ones((8, 30), bool)) == 0  # ink all through


def test_a_mullion_across_a_window_parts_two_lights():
    img, labels = room_with_window(lines_grey=90)
    img[20:28, 100] = 0  # a line across the wall's depth in the middle of the insert
    lines = img < 200
    inserts = find_wall_inserts(img, lines, labels, max_window_px=60, max_door_px=30)
    assert inserts.windows.max() == 2  # two lights, each 20 px long
    left, right = (np.flatnonzero((inserts.windows == k).any(axis=0)) for k in (1, 2))
    assert left.min() == 80 and right.max() == 119 and left.max() < right.min()
    img[20:28, 84] = 0  # a line 4 px from the jamb leaves a light shorter than a wall is thick
    img[20:28, 100] = 90
    inserts = find_wall_inserts(img, img < 200, labels, max_window_px=60, max_door_px=30)
    assert inserts.windows.max() == 1


def test_a_mullion_parts_a_window_whose_lines_binarise_to_one_band():
    img, labels = room_with_window(lines_grey=90, lines_across=4)
    img[20:28, 100] = 0
    lines = img < 200
    lines[20:28, 80:120] = True  # the glass lines merged into one band of ink
    inserts = find_wall_inserts(img, lines, labels, max_window_px=60, max_door_px=30)
    assert inserts.windows.max() == 2  # the mullion is found on the drawing's darkness


def test_a_window_in_a_wall_drawn_at_an_angle_is_found_turned():
    img, labels = room_with_window()
    gap = np.zeros(img.shape, np.uint8)
    gap[20:28, 80:120] = 1
    turn = cv2.getRotationMatrix2D((100, 80), 30, 1.0)  # 30 degrees counter-clockwise
    turn[:, 2] += (60, 60)
    size = (320, 280)

    def turned(image: np.ndarray, paper: int) -> np.ndarray:
        return cv2.warpAffine(image, turn, size, flags=cv2.INTER_NEAREST, borderValue=paper)

    img, labels, gap = turned(img, 255), turned(labels, 0), turned(gap, 0) > 0
    ink = img < 128
    assert oblique_wall_angles(wall_bands(img, ink, labels)[0], WALL_PX) == pytest.approx(
        [30.0], abs=1.5
    )
    inserts = find_wall_inserts(img, ink, labels, max_window_px=60, max_door_px=40)
    windows = inserts.windows > 0
    assert (windows & gap).sum() >= 0.8 * gap.sum()  # the window, turned back onto the drawing
    assert (windows & ~gap).sum() <= 0.5 * gap.sum()
    assert inserts.classes.tolist() == [CLASS_ID["window"]]
