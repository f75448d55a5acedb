"""A named room cut into pieces by its fixtures is one room: its pieces take the name's class.

A bathroom's tub, basin and toilet, a kitchen's counters, a bedroom's wardrobes are drawn in
thin lines that the parse takes as boundaries: the room becomes a named piece (the one holding
the name) and unnamed pieces around it, which keep whatever the network voted (the inside of a
tub voted living). The room's walls are thicker than its fixtures, or seen by the network:

- the room's extent is the one under its name (``perception.fixture_pieces.room_extents``: paper
  bounded by the walls alone, their gaps closed); none when it reaches the image border (the
  walls leave it open) or holds confident names of another class;
- a room instance lying in it (``INSIDE`` of its pixels) holding no name of a class is one of
  its pieces when fixtures bound it (``perception.fixture_pieces.bounded_by_fixtures``), and when
  it touches the named piece, or a piece that does, across a line thinner than a wall.

The parse has already joined each room's fixture pieces to its largest one
(``perception.fixture_pieces``); what is left here are pieces of a room whose largest piece is
not the named one.

:func:`join_named_pieces` gives each such piece the class of the room's names. Without text, or
on drawings whose rooms hold no fixture, the plan comes back unchanged.
"""

from __future__ import annotations

import dataclasses

import cv2
import numpy as np

from f2n_drake.core.classes import SPACE_CLASSES
from f2n_drake.core.parsed import ParsedPlan
from f2n_drake.perception.fixture_pieces import (
    DOOR_LIKE,
    WALL_REACH,
    bounded_by_fixtures,
    room_extents,
    text_boxes,
    touching,
)
from f2n_drake.perception.room_names import room_class

CONFIDENT = 0.8
"""A name read with at least this confidence gives its room's pieces its class (as it sets the
class of the piece it lies on, ``perception.priors.named_rooms``)."""
INSIDE = 0.8
"""Share of a piece's pixels that must lie in the named room's extent."""


def _names(parsed: ParsedPlan) -> dict[int, set[str]]:
    """Instance id -> the classes of the confident room names placed in it."""
    names: dict[int, set[str]] = {}
    for text in parsed.texts:
        if text.instance_id is None or text.confidence < CONFIDENT:
            continue
        if (cls := room_class(text.text)) in SPACE_CLASSES:
            names.setdefault(text.instance_id, set()).add(cls)
    return names


def join_named_pieces(parsed: ParsedPlan, lines: np.ndarray) -> ParsedPlan:
    """``parsed`` with the unnamed pieces of each named room (see module doc) re-classed to the
    room's named class; the same plan when there is none. ``lines`` is the drawing's ink without
    its words."""
    names = _names(parsed)
    by_id = parsed.by_id()
    named = {i: next(iter(c)) for i, c in names.items() if len(c) == 1}
    named = {i: c for i, c in named.items() if by_id[i].class_name == c}
    if not named:
        return parsed
    extents = room_extents(lines, parsed.labels, text_boxes(parsed.texts, lines.shape))
    outside = extents.outside
    ids = parsed.instance_ids
    region_of, share = extents.of_instances(ids)
    classes_in: dict[int, set[str]] = {}
    for iid, cls in names.items():
        classes_in.setdefault(int(region_of[iid]), set()).update(cls)
    room_of = {}
    for iid, cls in named.items():
        region = int(region_of[iid])
        if region and region not in outside and classes_in[region] == {cls}:
            room_of[region] = cls
    doors = np.isin(ids, [i.id for i in parsed.instances if i.class_name in DOOR_LIKE])
    near_door = cv2.dilate(doors.astype(np.uint8), WALL_REACH).astype(bool)
    pieces: dict[int, list[int]] = {}
    for inst in parsed.instances:
        region = int(region_of[inst.id])
        if (
            region in room_of
            and inst.id not in names
            and inst.class_name in SPACE_CLASSES
            and inst.class_name != room_of[region]
            and share[inst.id] >= INSIDE
            and not near_door[ids == inst.id].any()  # a room has a door, a fixture none
            and bounded_by_fixtures(ids == inst.id, lines, extents.walls)
        ):
            pieces.setdefault(region, []).append(inst.id)
    changed = {}
    for region, candidates in pieces.items():
        rooms = [i for i in named if region_of[i] == region]
        largest = max(by_id[i].area_px for i in rooms)
        smaller = [i for i in candidates if by_id[i].area_px < largest]  # a fixture's piece
        for iid in touching(ids, np.isin(ids, rooms), smaller):
            changed[iid] = room_of[region]
    if not changed:
        return parsed
    instances = [
        dataclasses.replace(i, class_name=changed[i.id]) if i.id in changed else i
        for i in parsed.instances
    ]
    return dataclasses.replace(parsed, instances=instances)
