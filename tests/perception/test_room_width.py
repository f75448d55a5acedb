"""Room width of a drawing (``perception.room_width``): the wide enclosed regions, with the door
gaps closed."""

from __future__ import annotations

import numpy as np

from f2n_drake.perception.room_width import room_width_px


def test_room_width_is_the_median_width_of_the_wide_enclosed_regions():
    lines = np.zeros((300, 400), bool)
    assert room_width_px(lines) is None  # all paper touches the border
    lines[20:280:, 20:380] = True
    lines[22:278, 22:378] = False  # one outlined box, 256 px of paper inside
    lines[22:278, 150:152] = True  # split: rooms 128 px wide (left) and 226 px (right) ...
    lines[22:278, 158:160] = True  # ... and a 6 px wall interior between them
    lines[150:152, 160:378] = True  # right part split again: rooms 218 x 126 and 218 x 128
    width = room_width_px(lines)
    assert 124 <= width <= 130  # the rooms' narrow sides; the wall interior does not count
    lines[:] = True
    assert room_width_px(lines) is None


def test_room_width_is_measured_with_the_door_gaps_closed():
    lines = np.zeros((300, 400), bool)
    lines[20:280, 20:380] = True
    lines[24:276, 24:376] = False  # a flat's outline, 4 px walls
    lines[24:276, 198:202] = True  # two rooms, 174 and 174 px wide, 252 px deep
    lines[100:116, 198:202] = False  # a door gap between them
    lines[276:280, 100:116] = False  # and the front door's gap to the outside
    for row, col in ((60, 60), (60, 80), (200, 300), (220, 320)):  # letters: small closed rings
        lines[row : row + 8, col : col + 8] = True
        lines[row + 2 : row + 6, col + 2 : col + 6] = False
    # the ink alone encloses only the rings (4 px); the rooms, with the gaps closed
    assert 170 <= room_width_px(lines) <= 178
