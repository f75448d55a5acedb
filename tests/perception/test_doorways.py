"""Doorways the ink leaves open are closed with the network's labels: two rooms joined by a gap
in their wall become two rooms and a door (an open passage where no door is seen nor drawn)."""

from __future__ import annotations

import cv2
import numpy as np

from f2n_drake.core.classes import CLASS_ID, OPENING
from f2n_drake.perception import wall_gaps
from f2n_drake.perception.doorways import find_doorways
from f2n_drake.perception.instances import extract_instances
from f2n_drake.perception.wall_gaps import collinear_gaps

LIVING, BEDROOM, WALL = CLASS_ID["living"], CLASS_ID["bedroom"], CLASS_ID["wall"]
DOOR = CLASS_ID["door"]


def two_rooms_with_gap(swing: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """A 200x120 flat: two rooms side by side, the wall between them open for 16 px (a door
    drawn as a gap, with its leaf and swing arc if ``swing``), network labels per room."""
    img = np.full((120, 200), 255, np.uint8)
    cv2.rectangle(img, (10, 10), (189, 109), 0, 4)
    cv2.rectangle(img, (98, 10), (101, 109), 0, -1)
    img[50:66, 96:104] = 255
    if swing:
        cv2.line(img, (100, 50), (116, 50), 0, 1)
        cv2.ellipse(img, (100, 50), (16, 16), 0, 0, 90, 0, 1)
    labels = np.zeros(img.shape, np.uint8)
    labels[12:108, 12:100] = LIVING
    labels[12:108, 100:188] = BEDROOM
    labels[img < 128] = WALL
    return img, labels


def classes(parsed) -> list[str]:
    return sorted(i.class_name for i in parsed.instances)


def test_a_gap_in_a_wall_is_a_door_between_two_rooms():
    img, labels = two_rooms_with_gap()
    labels[50:66, 96:104] = DOOR  # the network sees a door in the gap
    assert classes(extract_instances(img, labels, doorways=False)) == ["living"]
    parsed = extract_instances(img, labels)
    assert classes(parsed) == ["bedroom", "door", "living"]
    (door,) = parsed.of_class("door")
    door_mask = parsed.mask(door.id)
    assert door_mask[52:64, 98:102].all()  # the gap, as thick as the wall
    ids = {i.class_name: i.id for i in parsed.instances}
    ring = cv2.dilate(door_mask.astype(np.uint8), np.ones((3, 3), np.uint8)).astype(bool)
    assert {ids["living"], ids["bedroom"]} <= set(np.unique(parsed.instance_ids[ring]))


def test_a_gap_with_no_door_seen_nor_drawn_is_an_open_passage():
    """A door is seen (the network), or drawn (a swing, a closet's leaves, a gap between two ends
    of one wall's line); a partition stopping short of the outer wall, the network seeing no
    door there, leaves a passage between its two rooms."""
    img, labels = two_rooms_with_gap()
    img[50:66, 96:104] = 0  # the partition's gap drawn shut
    img[92:108, 98:102] = 255  # it stops short of the outer wall: no two ends of one line
    labels[img < 128] = WALL
    labels[92:108, 96:100], labels[92:108, 100:104] = LIVING, BEDROOM  # the rooms run on
    parsed = extract_instances(img, labels)
    assert classes(parsed) == ["bedroom", "living", OPENING]
    (passage,) = parsed.of_class(OPENING)
    assert parsed.mask(passage.id)[94:106, 98:102].all()  # the gap, as thick as the wall
    labels[92:108, 96:104] = DOOR  # the network sees a door in it
    assert classes(extract_instances(img, labels)) == ["bedroom", "door", "living"]


def test_a_door_is_its_gap_and_its_swing_is_floor_of_the_room_beyond_the_arc():
    img, labels = two_rooms_with_gap(swing=True)
    parsed = extract_instances(img, labels)
    assert classes(parsed) == ["bedroom", "door", "living"]
    (door,) = parsed.of_class("door")
    door_mask = parsed.mask(door.id)
    assert door_mask[52:64, 98:102].all()  # the gap, as thick as the wall
    assert not door_mask[55, 106]  # the swing's sector is no door
    (bedroom,) = parsed.of_class("bedroom")
    assert parsed.mask(bedroom.id)[55, 106]  # but the bedroom's floor
    assert bedroom.area_px > 80 * 90


def test_a_gap_with_a_swing_is_a_door_between_rooms_of_one_class():
    img, labels = two_rooms_with_gap(swing=True)
    labels[labels == BEDROOM] = LIVING  # the network sees one room and no opening
    assert classes(extract_instances(img, labels)) == ["door", "living", "living"]
    img, labels = two_rooms_with_gap()  # no swing, but a gap between two ends of one wall
    labels[labels == BEDROOM] = LIVING
    assert classes(extract_instances(img, labels)) == ["door", "living", "living"]


def test_a_leaf_drawn_across_the_gap_is_part_of_its_door():
    img, labels = two_rooms_with_gap(swing=True)
    img[50:66, 100] = 0  # a line across the gap: the ink alone closes the rooms
    labels[50:66, 96:104] = CLASS_ID["door"]  # the network sees the opening
    parsed = extract_instances(img, labels)
    assert classes(parsed) == ["bedroom", "door", "living"]
    (door,) = parsed.of_class("door")
    door_mask = parsed.mask(door.id)
    assert door_mask[52:64, 98:102].all()  # both sides of the line and the line: one door
    ids = {i.class_name: i.id for i in parsed.instances}
    ring = cv2.dilate(door_mask.astype(np.uint8), np.ones((3, 3), np.uint8)).astype(bool)
    assert {ids["living"], ids["bedroom"]} <= set(np.unique(parsed.instance_ids[ring]))


def test_a_threshold_across_the_gap_leaves_it_a_door_without_a_walls_line_to_follow():
    # the same door, judged on the gap pieces alone (no gaps between two ends of a wall's
    # line, as where the wall's ends are not drawn in line): the pieces on both sides of the
    # threshold are one door, though the ink alone already parts the rooms
    img, labels = two_rooms_with_gap(swing=True)
    img[50:66, 100] = 0
    labels[50:66, 96:104] = CLASS_ID["door"]
    ink = img < 128
    doorways = find_doorways(ink, labels, max_gap_px=20, wall_gaps=None)
    door = doorways.connectors[52:64, 98:102]  # the gap in the wall, columns 98-101
    assert (door[:, :2] > 0).all() and (door[:, 3] > 0).all()  # both sides of the line
    assert np.unique(door[door > 0]).size == 1  # one connector
    assert doorways.classes.tolist() == [CLASS_ID["door"]]


def test_a_sill_drawn_at_the_gaps_face_leaves_the_gap_a_door_and_its_swing_floor():
    img, labels = two_rooms_with_gap(swing=True)
    img[50:68, 103] = 0  # a sill on the wall's face: leaf, arc and sill close the swing
    labels[51:66, 104:116] = CLASS_ID["door"]  # the network calls the swing's sector door
    parsed = extract_instances(img, labels)
    door_at_gap = [d for d in parsed.of_class("door") if parsed.mask(d.id)[52:64, 98:102].all()]
    assert len(door_at_gap) == 1  # the gap between the wall's ends, not only the sector
    (living,) = parsed.of_class("living")
    ring = cv2.dilate(parsed.mask(door_at_gap[0].id).astype(np.uint8), np.ones((3, 3), np.uint8))
    assert living.id in set(np.unique(parsed.instance_ids[ring.astype(bool)]))
    (bedroom,) = parsed.of_class("bedroom")
    assert parsed.mask(bedroom.id)[54, 106]  # the sector is floor of the room beyond the arc
    assert classes(parsed) == ["bedroom", "door", "living"]


def test_a_gap_in_the_outer_wall_closes_the_room_as_a_door():
    img = np.full((120, 200), 255, np.uint8)
    cv2.rectangle(img, (10, 10), (189, 109), 0, 4)  # walls: rows 107-111 at the bottom
    img[107:112, 90:106] = 255  # the front door: a 16 px gap in the outer wall
    labels = np.zeros(img.shape, np.uint8)
    labels[12:108, 12:188] = LIVING
    labels[img < 128] = WALL
    assert classes(extract_instances(img, labels, doorways=False)) == []  # it leaks out
    for swing in (False, True):  # two ends of one wall's line, or a leaf and its arc too
        if swing:
            cv2.line(img, (90, 106), (90, 90), 0, 1)  # the leaf, open into the room
            cv2.ellipse(img, (90, 106), (16, 16), 0, -90, 0, 0, 1)
        parsed = extract_instances(img, labels)
        assert classes(parsed) == ["door", "living"]
        (door,) = parsed.of_class("door")
        assert parsed.mask(door.id)[107:112, 92:104].all()


def test_furniture_and_text_do_not_split_a_room():
    img, labels = two_rooms_with_gap()
    cv2.rectangle(img, (30, 30), (60, 50), 0, 1)  # a table
    cv2.putText(img, "BED", (120, 90), cv2.FONT_HERSHEY_SIMPLEX, 0.4, 0, 1)
    parsed = extract_instances(img, labels)
    assert classes(parsed) == ["bedroom", "door", "living"]


def test_ink_that_closes_the_rooms_is_left_as_it_is():
    img, labels = two_rooms_with_gap()
    cv2.rectangle(img, (96, 50), (103, 65), 0, 1)  # the door drawn as a box
    labels[51:65, 97:103] = CLASS_ID["door"]
    with_doorways = extract_instances(img, labels)
    without = extract_instances(img, labels, doorways=False)
    assert classes(with_doorways) == classes(without) == ["bedroom", "door", "living"]
    np.testing.assert_array_equal(with_doorways.instance_ids, without.instance_ids)


def test_a_gap_parting_no_rooms_is_not_closed():
    img, labels = two_rooms_with_gap()
    labels[labels == BEDROOM] = 0  # the network sees no room beyond the gap
    doorways = find_doorways(img < 128, labels, max_gap_px=18)
    assert not doorways.connectors.any()


def test_collinear_gaps_fill_gaps_in_walls_and_not_across_rooms():
    walls = np.zeros((60, 100), bool)
    walls[10:13, 5:40] = walls[10:13, 55:95] = True  # a wall with a 15 px gap
    walls[20:40, 60:62] = True  # a wall stopping 7 px short of it (a door beside a corner)
    walls[30:32, 5:50] = True  # the stem of a T ending in a wall that carries on both ways
    walls[15:58, 50:53] = True
    gaps = collinear_gaps(walls, max_gap_px=20, min_run_px=10)
    assert gaps[10:13, 40:55].all()
    assert gaps[13:20, 60:62].all()
    assert not gaps[30:32, 53:60].any()  # no gap continues the stem past the crossing wall
    assert not collinear_gaps(walls, max_gap_px=10, min_run_px=10)[10:13, 40:55].any()


def test_two_parts_of_one_room_are_no_doorway_unless_an_opening_is_seen():
    img, labels = two_rooms_with_gap()
    img[50:66, 96:104] = 0
    img[92:108, 98:102] = 255  # the wall stops short of the outer wall: no two ends of one line
    labels[labels == BEDROOM] = LIVING  # one room on both sides of the gap, no opening seen
    assert classes(extract_instances(img, labels)) == ["living"]
    labels[92:108, 96:104] = CLASS_ID["door"]  # the network sees a door in the gap
    assert classes(extract_instances(img, labels)) == ["door", "living", "living"]


def test_a_single_lines_end_one_pixel_from_a_wall_parts_no_rooms():
    """A wall's one line ending short of the opposite wall leaves a gap one pixel thick: with no
    opening seen and no swing drawn it is no doorway, whatever classes the network gives the
    paper on either side."""
    img = np.full((120, 200), 255, np.uint8)
    cv2.rectangle(img, (10, 10), (189, 109), 0, 2)
    img[60, 11:176] = 0  # a line from the west wall, 13 px short of the east wall
    labels = np.zeros(img.shape, np.uint8)
    labels[12:60, 12:188] = LIVING
    labels[61:108, 12:188] = BEDROOM
    labels[img < 128] = WALL
    assert not {"door", OPENING} & set(classes(extract_instances(img, labels)))
    img[59:62, 11:176] = 0  # a wall three pixels thick: its gap is a passage between the rooms
    assert OPENING in classes(extract_instances(img, labels))


def test_a_closet_front_drawn_across_its_gap_is_a_door():
    # a bifold door's zigzag drawn across the gap in the closet's wall, on the room's side: the
    # ink alone parts the closet (which the network calls no room, up to the leaves) from the
    # room, and no side of the gap is the room; the room lies behind the leaves
    img, labels = two_rooms_with_gap()
    labels[labels == BEDROOM] = 0  # the closet: storage, no room
    labels[49:67, 90:98] = 0
    zigzag = np.array([(97, 49), (91, 53), (97, 57), (91, 61), (97, 66)], np.int32)
    cv2.polylines(img, [zigzag], False, 0, 1)
    labels[img < 128] = WALL
    parsed = extract_instances(img, labels)
    assert classes(parsed) == ["door", "living"]
    (door,) = parsed.of_class("door")
    assert parsed.mask(door.id)[52:64, 98:102].all()  # the gap between the wall's ends


def test_gaps_amid_the_cells_of_a_cross_hatched_terrace_are_no_doorways(monkeypatch):
    """Below the two rooms a terrace drawn as a lattice of ink (cross-hatching binarised: 4 px
    cells of paper 6 px apart) with a clearing (its name taken off), which the network labels
    balcony, ink and paper alike. Lines of ``wall_gaps`` run through rows of its cells, as the
    wall-line finder reports them in such a lattice; the door's gap lies in a wall's line too."""
    img, labels = two_rooms_with_gap()
    drawing = np.full((220, 200), 255, np.uint8)
    drawing[:120] = img
    cv2.rectangle(drawing, (10, 106), (189, 209), 0, 4)
    drawing[110:206, 14:186] = 0
    for row in range(112, 204, 6):
        for col in range(16, 184, 6):
            drawing[row : row + 4, col : col + 4] = 255
    drawing[140:170, 70:130] = 255
    network = np.zeros(drawing.shape, np.uint8)
    network[:120] = labels
    network[108:208, 12:188] = CLASS_ID["balcony"]
    network[(drawing < 128) & (network == 0)] = WALL
    ink = drawing < 128
    line_gaps = np.zeros(ink.shape, bool)
    line_gaps[[114, 126, 138, 174, 192], 16:184] = True
    line_gaps &= ~ink
    line_gaps[138:172, 68:132] = False
    line_gaps[50:66, 98:102] = True

    def connectors() -> np.ndarray:
        found = find_doorways(ink, network, max_gap_px=40, wall_gaps=line_gaps, wall_px=4)
        return found.connectors

    found = connectors()
    assert found.max() == 1 and found[52:64, 98:102].all()  # the door alone
    monkeypatch.setattr(wall_gaps, "LATTICE_CELLS", 10**9)  # every gap judged as any other
    assert connectors().max() > 10 and connectors()[108:208].any()


def test_a_door_drawn_and_seen_in_a_walls_line_is_kept_though_a_leak_joins_its_rooms():
    # a door between two ends of the partition's line, its leaf and arc drawn faint (swing ink,
    # not the walls' ink), which the network labels door; further down the partition is open
    # wider than a doorway, so the two rooms stay one region of paper: the gap closes nothing yet
    drawn, labels = two_rooms_with_gap(swing=True)
    walls, _ = two_rooms_with_gap()
    walls[80:105, 96:104] = drawn[80:105, 96:104] = 255
    labels[80:105, 96:104] = LIVING
    labels[50:66, 96:104] = CLASS_ID["door"]
    line = np.zeros(walls.shape, bool)
    line[50:66, 96:104] = True  # the gap between two ends of the wall's line
    options = dict(max_gap_px=18, wall_gaps=line, swing_ink=drawn < 128)
    doorways = find_doorways(walls < 128, labels, **options)
    assert doorways.connectors[52:64, 98:102].all()
    assert not doorways.connectors[80:105].any()  # the wide opening stays open
    labels[50:66, 96:104] = LIVING  # the network sees no opening there: no door yet
    assert not find_doorways(walls < 128, labels, **options).connectors[52:64, 98:102].any()


def test_a_door_drawn_and_seen_in_a_walls_line_is_kept_with_no_room_beside_it():
    # a cupboard's door: the regions on both sides of the gap (the cupboard, the swing's sector,
    # what lies beyond) are all smaller than a room at this widest doorway
    drawn, labels = two_rooms_with_gap(swing=True)
    labels[50:66, 96:104] = CLASS_ID["door"]
    line = np.zeros(drawn.shape, bool)
    line[50:66, 96:104] = True  # the gap between two ends of the wall's line
    options = dict(max_gap_px=140, min_run_px=10, wall_gaps=line)
    doorways = find_doorways(drawn < 128, labels, **options)
    assert doorways.connectors.max() == 1 and doorways.connectors[52:64, 98:102].all()
    labels[50:66, 96:104] = LIVING  # no opening seen: no door drawn and seen
    assert not find_doorways(drawn < 128, labels, **options).connectors.any()


def test_a_gap_wider_than_a_doorway_is_a_door_only_where_one_is_drawn_in_a_walls_line():
    # a double door (or a closet's front) 24 px wide where the widest doorway is 18 px: a
    # candidate up to 1.5 doorways wide, kept where a swing is drawn at it or an opening seen
    def drawing(width: int, swing: bool):
        img, labels = two_rooms_with_gap()
        img[50:66, 96:104] = 0
        img[40 : 40 + width, 96:104] = 255
        labels[img < 128] = WALL
        labels[40 : 40 + width, 96:100], labels[40 : 40 + width, 100:104] = LIVING, BEDROOM
        if swing:
            cv2.line(img, (100, 40), (100 + width, 40), 0, 1)
            cv2.ellipse(img, (100, 40), (width, width), 0, 0, 90, 0, 1)
        line = np.zeros(img.shape, bool)
        line[40 : 40 + width, 98:102] = True  # between two ends of the wall's line
        return img, labels, line

    def door_across(width: int, swing: bool) -> bool:
        img, labels, line = drawing(width, swing)
        options = dict(max_gap_px=18, min_run_px=9, wall_gaps=np.zeros_like(line))
        found = find_doorways(
            img < 128, labels, wide_wall_gaps=line, swing_ink=img < 128, **options
        )
        return bool(found.connectors[42 : 38 + width, 98:102].all())

    assert door_across(24, swing=True)
    assert not door_across(24, swing=False)  # nothing drawn: no door that wide
