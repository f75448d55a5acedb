"""A door or window fills its gap in the wall: between the wall's two ends, as thick as they are."""

from __future__ import annotations

import numpy as np

from f2n_drake.core.classes import CLASS_ID
from f2n_drake.core.parsed import ParsedPlan, instance_from_mask
from f2n_drake.perception.opening_depth import fill_wall_depth, join_depth_pieces

WALL_ROWS = slice(40, 50)  # a horizontal wall 10 px thick
GAP_COLS = slice(50, 80)  # and a 30 px gap in it


def gap_plan(door_rows: slice, *, crossing_wall: bool = False, door_cols: slice = GAP_COLS):
    """(grey, ink, plan) of a room above a wall with a gap, whose paper runs into the gap down
    to ``door_rows``, where a door instance lies; ``crossing_wall``: the wall left of the gap is
    a wall running across it (a corner), not the end of the wall's line."""
    ink = np.zeros((100, 130), bool)
    ink[WALL_ROWS, 5:125] = True
    ink[WALL_ROWS, GAP_COLS] = False
    if crossing_wall:
        ink[10:90, 40:50] = True
    room = np.zeros(ink.shape, bool)
    room[5:40, 5:125] = True
    room[40:50, GAP_COLS] = True  # the room's paper reaches into the gap
    door = np.zeros(ink.shape, bool)
    door[door_rows, door_cols] = True
    return plan_of(ink, room, door, "door", labelled_room=(slice(5, 40), slice(5, 125)))


def plan_of(
    ink: np.ndarray,
    room: np.ndarray,
    connector: np.ndarray,
    connector_class: str,
    labelled_room: tuple[slice, slice],
):
    """(grey, ink, plan): the drawing of ``ink``, a living room (instance 1) on ``room`` and a
    connector (instance 2) on ``connector`` (both off the ink); the network labels the ink wall,
    ``labelled_room`` living and the connector its class."""
    grey = np.where(ink, 0, 255).astype(np.uint8)
    labels = np.zeros(ink.shape, np.uint8)
    labels[ink] = CLASS_ID["wall"]
    labels[labelled_room] = CLASS_ID["living"]
    ids = np.zeros(ink.shape, np.int32)
    ids[room] = 1
    ids[connector] = 2
    ids[ink] = 0
    labels[ids == 2] = CLASS_ID[connector_class]
    instances = [
        instance_from_mask(k, name, ids == k, labels)
        for k, name in ((1, "living"), (2, connector_class))
    ]
    return grey, ink, ParsedPlan(ids, labels, instances)


def test_a_door_strip_on_the_walls_face_grows_to_the_gap():
    grey, ink, parsed = gap_plan(slice(48, 50))
    grown = fill_wall_depth(parsed, grey, ink)
    door = grown.instance_ids == 2
    expected = np.zeros_like(door)
    expected[WALL_ROWS, GAP_COLS] = True
    np.testing.assert_array_equal(door, expected)
    assert not np.any(grown.instance_ids[WALL_ROWS, GAP_COLS] == 1)
    areas = {inst.id: inst.area_px for inst in grown.instances}
    assert areas[2] == expected.sum()
    assert areas[1] == np.sum(grown.instance_ids == 1) == np.sum(parsed.instance_ids == 1) - 240


def test_a_door_as_deep_as_its_wall_is_left_as_it_is():
    grey, ink, parsed = gap_plan(WALL_ROWS)
    assert fill_wall_depth(parsed, grey, ink) is parsed


def test_a_door_beside_a_crossing_wall_is_not_grown():
    # one of its ends is a wall running across the gap's line: no two ends of one wall
    grey, ink, parsed = gap_plan(slice(48, 50), crossing_wall=True)
    assert fill_wall_depth(parsed, grey, ink) is parsed


def test_a_connector_lying_mostly_outside_the_walls_thickness_is_not_grown():
    # a strip on the wall's face joined to a block of the room (a label, a bay's curve): it is
    # no strip across a wall
    grey, ink, parsed = gap_plan(slice(48, 50))
    ids = parsed.instance_ids.copy()
    ids[20:40, GAP_COLS] = 2
    instances = [
        instance_from_mask(k, name, ids == k, parsed.labels)
        for k, name in ((1, "living"), (2, "door"))
    ]
    parsed = ParsedPlan(ids, parsed.labels, instances)
    assert fill_wall_depth(parsed, grey, ink) is parsed


def test_a_drawing_without_walls_is_left_as_it_is():
    grey, ink, parsed = gap_plan(slice(48, 50))
    parsed = ParsedPlan(parsed.instance_ids, np.zeros_like(parsed.labels), parsed.instances)
    assert fill_wall_depth(parsed, grey, ink) is parsed


def test_a_colour_drawing_grows_its_doors_as_its_grey_one_does():
    grey, ink, parsed = gap_plan(slice(48, 50))
    bgr = np.repeat(grey[..., None], 3, axis=2)
    np.testing.assert_array_equal(
        fill_wall_depth(parsed, bgr, ink).instance_ids,
        fill_wall_depth(parsed, grey, ink).instance_ids,
    )


def reveal_plan(connector: str):
    """(grey, ink, plan) of a room above a wall 10 px thick whose room-side face steps back 4 px
    round a 30 px gap (the reveal, columns 46-83, rows 40-43, paper of the room); the connector
    fills the gap between the wall's ends below it (rows 44-49)."""
    ink = np.zeros((100, 130), bool)
    ink[WALL_ROWS, 5:125] = True
    ink[40:44, 46:84] = False  # the reveal
    ink[44:50, GAP_COLS] = False
    room = np.zeros(ink.shape, bool)
    room[5:44, 5:125] = True
    gap = np.zeros(ink.shape, bool)
    gap[44:50, GAP_COLS] = True
    return plan_of(ink, room & ~gap, gap, connector, labelled_room=(slice(5, 44), slice(5, 125)))


def test_a_window_takes_the_reveal_beside_it_and_a_door_does_not():
    grey, ink, parsed = reveal_plan("window")
    grown = fill_wall_depth(parsed, grey, ink)
    expected = np.zeros(ink.shape, bool)
    expected[WALL_ROWS, GAP_COLS] = True  # the wall's whole thickness across the gap
    np.testing.assert_array_equal(grown.instance_ids == 2, expected)
    assert (grown.instance_ids[40:44, 46:50] == 1).all()  # the reveal beyond it stays the room's
    grey, ink, parsed = reveal_plan("door")
    assert fill_wall_depth(parsed, grey, ink) is parsed


def strips_plan(*strips: tuple[str, slice, slice]) -> ParsedPlan:
    """A living room (instance 1) above a wall's gap (rows 40-49) and connector instances 2, 3,
    ... of the given (class, rows, columns), labelled their classes."""
    ids = np.zeros((100, 130), np.int32)
    labels = np.zeros(ids.shape, np.uint8)
    ids[5:40, 5:125] = 1
    labels[5:40, 5:125] = CLASS_ID["living"]
    for k, (name, rows, cols) in enumerate(strips, start=2):
        ids[rows, cols] = k
        labels[rows, cols] = CLASS_ID[name]
    names = ["living"] + [name for name, _, _ in strips]
    instances = [instance_from_mask(k, n, ids == k, labels) for k, n in enumerate(names, start=1)]
    return ParsedPlan(ids, labels, instances)


def test_a_window_parted_lengthwise_across_the_walls_depth_is_one():
    parsed = strips_plan(
        ("window", slice(40, 45), GAP_COLS), ("window", slice(45, 50), slice(52, 78))
    )
    joined = join_depth_pieces(parsed)
    assert [i.class_name for i in joined.instances] == ["living", "window"]
    window = np.zeros(parsed.instance_ids.shape, bool)
    window[40:45, GAP_COLS] = True
    window[45:50, 52:78] = True
    np.testing.assert_array_equal(joined.instance_ids == 2, window)
    assert joined.instances[1].area_px == window.sum()


def test_panes_end_to_end_other_classes_and_a_short_strip_beside_a_long_one_stay_apart():
    panes = strips_plan(("window", WALL_ROWS, slice(50, 65)), ("window", WALL_ROWS, slice(65, 80)))
    assert join_depth_pieces(panes) is panes
    door_by_window = strips_plan(
        ("door", slice(40, 45), GAP_COLS), ("window", slice(45, 50), GAP_COLS)
    )
    assert join_depth_pieces(door_by_window) is door_by_window
    short_beside_long = strips_plan(
        ("window", slice(40, 45), slice(20, 110)), ("window", slice(45, 50), GAP_COLS)
    )
    assert join_depth_pieces(short_beside_long) is short_beside_long
