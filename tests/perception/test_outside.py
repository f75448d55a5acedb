"""The outside of a plan is the paper the sheet's border reaches through more than a doorway."""

from __future__ import annotations

import cv2
import numpy as np

from f2n_drake.core.classes import CLASS_ID
from f2n_drake.perception.outside import part_from_outside


def components(lines: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    _, cc, stats, _ = cv2.connectedComponentsWithStats(
        (~lines).astype(np.uint8), connectivity=4, ltype=cv2.CV_32S
    )
    return cc, stats


def test_a_room_open_to_the_outside_through_a_doorway_is_parted_from_it():
    lines = np.zeros((200, 240), bool)
    lines[40, 40:201] = lines[160, 40:201] = lines[40:161, 40] = True
    lines[40:90, 200] = lines[110:161, 200] = True  # a 20 px gap in the east wall
    cc, stats = components(lines)
    assert cc[100, 100] == cc[0, 0]  # one region with the outside
    parted = part_from_outside(lines, cc, stats, gap_px=30)
    room = parted.components[100, 100]
    assert list(parted.rooms) == [room] and room != parted.components[0, 0]
    area = parted.stats[room, cv2.CC_STAT_AREA]
    assert area == np.count_nonzero(parted.components == room) and area > 0.9 * 159 * 119
    assert parted.components[100, 230] == parted.components[0, 0]  # beyond the gap: outside
    # the gap is the room's mouth, a doorway: paper of neither
    rows, cols = np.nonzero(parted.mouths)
    assert parted.mouths.max() == 1 and set(range(90, 110)) <= set(rows)
    assert 190 <= cols.min() and cols.max() <= 210
    assert not parted.components[parted.mouths > 0].any()
    # a gap wider than a doorway leaves the room outside, and so do the corners of the outside
    same = part_from_outside(lines, cc, stats, gap_px=10)
    assert same.rooms.size == 0 and (same.components == cc).all() and not same.mouths.any()


def test_a_plan_drawn_to_the_images_edge_is_parted_from_it():
    lines = np.zeros((120, 160), bool)
    lines[:, 0] = lines[0, :] = lines[-1, :] = True  # three walls on the image's edge
    lines[:50, -1] = lines[70:, -1] = True  # the fourth with a 20 px gap, also on the edge
    cc, stats = components(lines)
    parted = part_from_outside(lines, cc, stats, gap_px=30)
    assert list(parted.rooms) == [parted.components[60, 80]]


def test_paper_the_network_votes_no_room_stays_outside():
    lines = np.zeros((200, 240), bool)
    lines[40, 40:201] = lines[160, 40:201] = lines[40:161, 40] = True
    lines[40:90, 200] = lines[110:161, 200] = True
    cc, stats = components(lines)
    background = np.zeros(lines.shape, np.uint8)  # a recess of the facade, say
    parted = part_from_outside(lines, cc, stats, gap_px=30, labels=background)
    assert parted.rooms.size == 0 and not parted.mouths.any()
    living = np.full(lines.shape, CLASS_ID["living"], np.uint8)
    assert part_from_outside(lines, cc, stats, gap_px=30, labels=living).rooms.size == 1


def test_a_mouth_is_the_gap_through_its_wall_not_the_arc_of_the_disc():
    lines = np.zeros((200, 240), bool)
    lines[40:42, 40:202] = lines[159:161, 40:202] = lines[40:161, 40:42] = True
    lines[40:86, 200:202] = lines[114:161, 200:202] = True  # a 28 px gap in a 2 px east wall
    cc, stats = components(lines)
    parted = part_from_outside(lines, cc, stats, gap_px=30)
    rows, cols = np.nonzero(parted.mouths)
    assert set(rows) == set(range(86, 114)) and set(cols) == {200, 201}
    room = parted.components[100, 100]
    # the disc reaching through the gap no longer takes the room's paper behind the wall's line
    assert (parted.components[86:114, 190:200] == room).all()
    assert parted.components[100, 205] == parted.components[0, 0]


def test_glazing_drawn_dashed_is_one_mouth_with_its_dashes():
    lines = np.zeros((200, 240), bool)
    lines[40:42, 40:202] = lines[159:161, 40:202] = lines[40:161, 40:42] = True
    lines[40:80, 200:202] = lines[120:161, 200:202] = True
    for top in range(84, 118, 8):  # dashes across the 40 px gap
        lines[top : top + 3, 200:202] = True
    cc, stats = components(lines)
    parted = part_from_outside(lines, cc, stats, gap_px=44)
    assert parted.rooms.size == 1 and parted.mouths.max() == 1
    n_pieces, _ = cv2.connectedComponents((parted.mouths > 0).astype(np.uint8), connectivity=4)
    assert n_pieces == 2  # one mouth, the dashes in it
    assert parted.mouths[84:117, 200].all()
