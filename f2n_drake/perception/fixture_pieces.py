"""A room its fixtures cut into pieces is one room.

A bathroom's tub, shower tray and toilet, a kitchen's counters, a bedroom's wardrobe and a
balcony's hatching are drawn in thin closed lines, which the parse takes as boundaries: the room
becomes one large piece and small pieces around it. The room's walls are thicker than its
fixtures, or seen by the network:

- the drawing's **walls** (:func:`wall_ink`) are its ink at least ``WALL_PX`` thick and what the
  network labels wall, window or door, never inside a text's box;
- a room's **extent** (:func:`room_extents`) is paper bounded by those walls alone once their gaps
  (a wide door at most, ``perception.wall_gaps.collinear_gaps``) are closed; an extent reaching
  the image border is the outside, where pieces are looked for only when the walls are drawn
  thick (no wall is then thin enough for a piece to touch a room across it);
- a space instance of an extent (``INSIDE`` of its pixels that lie in extents, not on walls or
  closed gaps, in it) is a **piece** when it is not the extent's largest, less than
  ``MAX_WALL_SHARE`` of the ink along its outline is wall
  (fixtures bound it, where a room beside it behind a missed door is walled), and no door
  touches it (a room has one, a fixture none; a window may: tubs and counters stand under
  them); the extent's other instances are its rooms;
- each piece joins the largest room larger than it that it touches across a line thinner than a
  wall, or through pieces that do, a balcony's only a balcony and a room's only a room
  (``OUTDOOR``).

A door or an opening the doorway step put between a fixture and a wall leaves a room in pieces
that rule does not join (a piece touches none): a bathroom whose tub and shower run from wall to
wall is three or four instances, each beside a connector. The network labels a fixture's
outline as the room it stands in and a wall as wall, so a second rule (:func:`outline_pieces`)
joins two instances of one class that touch across ink thinner than a wall (and at most twice
the drawing's stroke), of which at most ``OUTLINE_WALL_SHARE`` is wall (:func:`wall_ink`) or
labelled wall, door or window, with no door, window or front door between them and no door or
front door touching the smaller (a room has one, a fixture none); an opening (no door seen)
touching only one such room's instances is its floor. Where the walls are drawn as thin lines, a
fixture and a wall look alike, and only ``THIN_WALLED_CLASSES`` are joined so.

:func:`join_fixture_pieces` makes each room and its pieces one instance, classed by the majority
of the labels on all of them. Drawings whose rooms hold no fixture come back unchanged.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import cv2
import numpy as np

from f2n_drake.core.classes import (
    CLASS_ID,
    CLASS_NAMES,
    CONNECTOR_CLASSES,
    OPENING,
    SPACE_CLASSES,
)
from f2n_drake.core.parsed import Instance, ParsedPlan, joined_instances
from f2n_drake.core.text import TextBox
from f2n_drake.perception.doorways import max_gap_px
from f2n_drake.perception.ink import stroke_width_px
from f2n_drake.perception.runs import stroke_widths_px
from f2n_drake.perception.wall_gaps import collinear_gaps

INSIDE = 0.6
"""Share of a piece's pixels in extents that must lie in the room's extent (its pixels on the
gaps closed between wall ends count for none: a recess the closing runs across; a room spills
through its door's closed gap into the next extent)."""
ON_PAPER = 0.5
"""Share of an instance's pixels that must lie in extents (not on walls or closed gaps) for it
to be a piece or a room of one."""
MAX_WALL_SHARE = 0.9
"""A piece with this share of its outline wall or more is a room of its own (a tub in a corner
has half its outline on walls, a room behind a door the closing missed all of it but the door's
swing and leaf)."""
WALL_PX = 3
"""Ink at least this thick may be a wall; thinner strokes draw fixtures, hatching, railings."""
WALL_SHARE = 0.5
"""Where walls are drawn thicker, ink under this share of their typical thickness is no wall."""

OUTDOOR: tuple[str, ...] = ("balcony",)
"""Outdoor space: its pieces join only outdoor rooms, and the reverse (a terrace beyond a railing
drawn in a thin line is no fixture of the living room)."""
DOOR_LIKE: tuple[str, ...] = ("door", "front_door", OPENING)
"""Connector classes a room is entered through: no fixture touches one."""
OUTLINE_WALL_SHARE = 0.3
"""Two instances of one class are one room where at most this share of what lies between them is
wall or labelled wall, door or window (a fixture's outline, :func:`outline_pieces`)."""
THIN_WALLED_CLASSES: tuple[str, ...] = ("bathroom",)
"""Where the walls are drawn as thin lines, only instances of these classes are joined across an
outline: the network's labels alone tell a wall from a fixture there, and a bathroom is the room
its fixtures fill (an office's small rooms joined their corridor when every class was)."""

_BOUNDS = [CLASS_ID[c] for c in ("wall", *CONNECTOR_CLASSES)]
_SPACE_IDS = np.array([CLASS_ID[c] for c in SPACE_CLASSES])
_SPECK = np.ones((4, 4), np.uint8)
WALL_REACH = np.ones((2 * WALL_PX + 1, 2 * WALL_PX + 1), np.uint8)
"""What lies a wall's thickness from a piece touches it (a door; a room across a thinner line)."""


def wall_ink(lines: np.ndarray, labels: np.ndarray, width: int | None = None) -> np.ndarray:
    """(H, W) bool walls of a drawing: its ink at least ``WALL_PX`` thick and what the network
    ``labels`` wall, window or door (specks left out). Where the walls are drawn thick
    (:func:`wall_width_px` above ``WALL_PX``; ``width``, if already known), they are the ink at
    least that thick, whatever the network says (it often labels tubs, toilets and the paper
    around them wall)."""
    seen = _seen_walls(labels)
    width = wall_width_px(lines, labels) if width is None else width
    kernel = np.ones((width, width), np.uint8)
    thick = cv2.morphologyEx(lines.astype(np.uint8), cv2.MORPH_OPEN, kernel) > 0
    return thick if width > WALL_PX else thick | seen


def wall_width_px(lines: np.ndarray, labels: np.ndarray) -> int:
    """The thinnest ink that is a wall [px]: ``WALL_SHARE`` of the median stroke width of the ink
    the network labels wall, window or door, at least ``WALL_PX``."""
    return max(WALL_PX, int(round(WALL_SHARE * _thickness_px(_seen_walls(labels) & lines))))


def _seen_walls(labels: np.ndarray) -> np.ndarray:
    opened = cv2.morphologyEx(np.isin(labels, _BOUNDS).astype(np.uint8), cv2.MORPH_OPEN, _SPECK)
    return opened > 0


def _thickness_px(walls: np.ndarray) -> float:
    """Median stroke width of the ink ``walls`` [px] (0 when empty)."""
    if not walls.any():
        return 0.0
    return float(np.median(stroke_widths_px(walls)[walls]))


def text_boxes(texts: Sequence[TextBox], shape: tuple[int, int]) -> np.ndarray:
    """(H, W) bool: the boxes of every text read; what is left of its ink there (strokes running
    out of the box, the network's labels on them) is no wall."""
    boxes = np.zeros(shape, bool)
    for text in texts:
        c0, r0, c1, r1 = text.box_px
        boxes[r0:r1, c0:c1] = True
    return boxes


@dataclasses.dataclass(frozen=True)
class RoomExtents:
    """The paper of a drawing cut by its walls (gaps closed).

    Attributes:
        walls: (H, W) bool, the walls (:func:`wall_ink` outside text boxes).
        regions: (H, W) int32 extent id per pixel, 0 on walls and closed gaps.
        outside: extent ids reaching the image border.
        wall_px: the thinnest ink that is a wall [px] (:func:`wall_width_px`).
    """

    walls: np.ndarray
    regions: np.ndarray
    outside: frozenset[int]
    wall_px: int = WALL_PX

    @property
    def thick_walls(self) -> bool:
        """The walls are drawn thicker than ``WALL_PX`` (no wall is within the reach of
        :func:`touching`, and a fixture's outline is thinner than any)."""
        return self.wall_px > WALL_PX

    def of_instances(self, instance_ids: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Per instance id: the extent holding most of its pixels (0: none) and its share of
        the pixels in extents (0 when under ``ON_PAPER`` of the instance lies in any)."""
        n = int(self.regions.max()) + 1
        pairs = instance_ids.astype(np.int64) * n + self.regions
        counts = np.bincount(pairs.ravel(), minlength=(int(instance_ids.max()) + 1) * n)
        counts = counts.reshape(-1, n)
        on_paper = counts[:, 1:].sum(axis=1)
        counts[:, 0] = 0
        size = np.bincount(instance_ids.ravel(), minlength=len(counts))
        share = counts.max(axis=1) / np.maximum(on_paper, 1)
        return counts.argmax(axis=1), np.where(on_paper >= ON_PAPER * size, share, 0.0)


def room_extents(lines: np.ndarray, labels: np.ndarray, boxes: np.ndarray) -> RoomExtents:
    """The extents of a drawing (``lines``: its ink; ``labels``: the network's; ``boxes``: its
    text boxes, :func:`text_boxes`)."""
    width = wall_width_px(lines, labels)
    walls = wall_ink(lines, labels, width) & ~boxes
    widest = max_gap_px(walls)
    gaps = collinear_gaps(walls, max_gap_px=widest, min_run_px=max(3, widest // 2)) & ~walls
    _, regions = cv2.connectedComponents((~(walls | gaps)).astype(np.uint8), connectivity=4)
    border = np.concatenate([regions[0], regions[-1], regions[:, 0], regions[:, -1]])
    outside = frozenset(int(r) for r in np.unique(border))
    return RoomExtents(walls, regions, outside, width)


def bounded_by_fixtures(piece: np.ndarray, lines: np.ndarray, walls: np.ndarray) -> bool:
    """Whether less than ``MAX_WALL_SHARE`` of the ink along ``piece``'s outline (the pixels
    next to it) is wall."""
    rows, cols = np.nonzero(piece)
    r0, r1 = max(rows.min() - 2, 0), rows.max() + 3
    c0, c1 = max(cols.min() - 2, 0), cols.max() + 3
    box = piece[r0:r1, c0:c1].astype(np.uint8)
    ring = (cv2.dilate(box, np.ones((3, 3), np.uint8)) > 0) & ~box.astype(bool)
    ink = ring & (lines[r0:r1, c0:c1] | walls[r0:r1, c0:c1])
    if not ink.any():
        return False
    return np.count_nonzero(ink & walls[r0:r1, c0:c1]) < MAX_WALL_SHARE * np.count_nonzero(ink)


def touching(ids: np.ndarray, room: np.ndarray, candidates: Sequence[int]) -> list[int]:
    """The ``candidates`` (instance ids) that touch ``room`` (bool mask) across a line thinner
    than a wall (``WALL_PX`` reach), or touch one that does, and so on."""
    room = room.copy()
    joined: list[int] = []
    grew = True
    while grew:
        grew = False
        for iid in candidates:
            if iid in joined:
                continue
            rows, cols = np.nonzero(ids == iid)
            r0, r1 = max(rows.min() - WALL_PX, 0), rows.max() + WALL_PX + 1
            c0, c1 = max(cols.min() - WALL_PX, 0), cols.max() + WALL_PX + 1
            piece = (ids[r0:r1, c0:c1] == iid).astype(np.uint8)
            if (cv2.dilate(piece, WALL_REACH).astype(bool) & room[r0:r1, c0:c1]).any():
                joined.append(iid)
                room[r0:r1, c0:c1] |= piece.astype(bool)
                grew = True
    return joined


def _pieces(parsed: ParsedPlan, lines: np.ndarray, extents: RoomExtents) -> dict[int, list[int]]:
    """Room instance id -> the ids of its fixture pieces (module doc)."""
    ids = parsed.instance_ids
    region_of, share = extents.of_instances(ids)
    doors = np.isin(ids, [i.id for i in parsed.instances if i.class_name in DOOR_LIKE])
    near_door = cv2.dilate(doors.astype(np.uint8), WALL_REACH).astype(bool)
    by_region: dict[int, list[Instance]] = {}
    for inst in parsed.instances:
        region = int(region_of[inst.id])
        open_ok = extents.thick_walls or region not in extents.outside
        if inst.class_name in SPACE_CLASSES and region and open_ok and share[inst.id] >= INSIDE:
            by_region.setdefault(region, []).append(inst)
    pieces = {}
    for members in by_region.values():
        if len(members) < 2:
            continue
        largest = max(members, key=lambda i: i.area_px)
        candidates = set()
        for inst in members:
            mask = ids == inst.id
            if (
                inst is not largest
                and not near_door[mask].any()
                and bounded_by_fixtures(mask, lines, extents.walls)
            ):
                candidates.add(inst.id)
        rooms = sorted(
            (i for i in members if i.id not in candidates), key=lambda i: i.area_px, reverse=True
        )
        area = {i.id: i.area_px for i in members}
        outdoor = {i.id: i.class_name in OUTDOOR for i in members}
        for room in rooms:
            smaller = [
                c
                for c in sorted(candidates)
                if area[c] < room.area_px and outdoor[c] == outdoor[room.id]
            ]
            if joined := touching(ids, ids == room.id, smaller):
                pieces[room.id] = joined
                candidates -= set(joined)
    return pieces


def outline_pieces(
    parsed: ParsedPlan, lines: np.ndarray, extents: RoomExtents
) -> dict[int, list[int]]:
    """Room instance id -> the ids of the instances it is one room with across fixtures' outlines
    (module doc): space instances of its class, and openings touching only them. The room is
    the largest of them."""
    ids, walls = parsed.instance_ids, extents.walls
    # what lies between two is ink at most twice the drawing's stroke, and thinner than a wall
    radius = max(1, min(stroke_width_px(lines), (extents.wall_px + 1) // 2))
    by_id = parsed.by_id()
    boxes = parsed.boxes()

    def window(members: Sequence[int], reach: int) -> tuple[slice, slice]:
        rows = [boxes[i - 1][0] for i in members]
        cols = [boxes[i - 1][1] for i in members]
        return (
            slice(max(min(r.start for r in rows) - reach, 0), max(r.stop for r in rows) + reach),
            slice(max(min(c.start for c in cols) - reach, 0), max(c.stop for c in cols) + reach),
        )

    def reach_of(iid: int, box: tuple[slice, slice], reach: int) -> np.ndarray:
        kernel = np.ones((2 * reach + 1, 2 * reach + 1), np.uint8)
        return cv2.dilate((ids[box] == iid).astype(np.uint8), kernel) > 0

    def neighbours(iid: int) -> set[int]:
        box = window([iid], 2 * radius)
        return {int(i) for i in np.unique(ids[box][reach_of(iid, box, 2 * radius)])} - {0, iid}

    def is_door(iid: int) -> bool:
        return by_id[iid].class_name in ("door", "front_door")

    def outline_between(a: int, b: int) -> bool:
        box = window([a, b], radius)
        both = reach_of(a, box, radius) & reach_of(b, box, radius)
        if any(
            by_id[int(i)].class_name in CONNECTOR_CLASSES for i in np.unique(ids[box][both]) if i
        ):
            return False
        seam = both & (ids[box] == 0)
        wall = walls[box][seam] | np.isin(parsed.labels[box][seam], _BOUNDS)
        return seam.any() and wall.mean() <= OUTLINE_WALL_SHARE

    classes = SPACE_CLASSES if extents.thick_walls else THIN_WALLED_CLASSES
    spaces = [
        i.id
        for i in parsed.instances
        if i.class_name in classes and i.id <= len(boxes) and boxes[i.id - 1] is not None
    ]
    near = {iid: neighbours(iid) for iid in spaces}
    root = {iid: iid for iid in spaces}

    def find(iid: int) -> int:
        while root[iid] != iid:
            iid = root[iid] = root[root[iid]]
        return iid

    for a in spaces:
        for b in sorted(near[a]):
            if b <= a or b not in root or by_id[b].class_name != by_id[a].class_name:
                continue
            smaller = min((a, b), key=lambda i: by_id[i].area_px)
            if any(is_door(i) for i in near[smaller]) or not outline_between(a, b):
                continue
            root[find(b)] = find(a)
    groups: dict[int, list[int]] = {}
    for iid in spaces:
        groups.setdefault(find(iid), []).append(iid)
    groups = {k: g for k, g in groups.items() if len(g) > 1}
    if not groups:
        return {}
    for inst in parsed.instances:  # an opening between a room's fixtures is its floor
        if inst.class_name != OPENING or inst.id > len(boxes) or boxes[inst.id - 1] is None:
            continue
        beside = neighbours(inst.id)
        if len(beside) >= 2 and all(i in root for i in beside):
            owners = {find(i) for i in beside}
            if len(owners) == 1 and (owner := owners.pop()) in groups:
                groups[owner].append(inst.id)
    return {
        max(g, key=lambda i: (by_id[i].class_name in SPACE_CLASSES, by_id[i].area_px)): g
        for g in groups.values()
    }


def _joined(
    parsed: ParsedPlan, pieces: dict[int, list[int]], probabilities: np.ndarray | None
) -> ParsedPlan:
    """``parsed`` with each room of ``pieces`` and its pieces (room id -> piece ids; the room's
    own id may be among them) one instance, classed by the majority of the space labels on them,
    instance ids renumbered 1..K in their order."""

    def space_class(_: Instance, mask: np.ndarray) -> str:
        votes = np.bincount(parsed.labels[mask], minlength=len(CLASS_NAMES))
        return CLASS_NAMES[int(_SPACE_IDS[np.argmax(votes[_SPACE_IDS])])]

    room_of = {piece: room for room, joined in pieces.items() for piece in joined if piece != room}
    return joined_instances(parsed, room_of, space_class, probabilities)


def join_fixture_pieces(
    parsed: ParsedPlan,
    lines: np.ndarray,
    texts: Sequence[TextBox] = (),
    probabilities: np.ndarray | None = None,
) -> ParsedPlan:
    """``parsed`` with each room and its fixture pieces one instance (module doc: the pieces its
    walls bound with it, then those across fixtures' outlines), instance ids renumbered 1..K in
    their order; the same plan when no room has pieces.

    Args:
        parsed: the voted instances of a drawing.
        lines: its ink without its words (``binarize``, ``without_text``).
        texts: the words read on it; their boxes are no walls.
        probabilities: (NUM_CLASSES, H, W) class probabilities, for the joined rooms' scores.
    """
    extents = room_extents(lines, parsed.labels, text_boxes(texts, lines.shape))
    if pieces := _pieces(parsed, lines, extents):
        parsed = _joined(parsed, pieces, probabilities)
    if pieces := outline_pieces(parsed, lines, extents):
        parsed = _joined(parsed, pieces, probabilities)
    return parsed
