"""Where a confident room name is written, there is a room: its extent, and its instance.

Real drawings draw doors as gaps in the walls, so the ink often leaves rooms open to each other
and to the outside, and the parse then has no room where a name is written (the region touches
the image border, or the network votes it background) or one instance running several rooms
together. The name still says a room is there (:func:`named_rooms`):

- its extent is the paper around the name once the gaps of the walls are closed: along rows and
  columns, a gap at most a wide door across (``perception.doorways.max_gap_px``) between the
  free end of a straight wall run and another wall (``perception.wall_gaps.collinear_gaps``);
  walls are the ink and what the network labels wall, window or door;
- a region still open to the outside is opened (eroded, then grown back) by the smallest radius
  at which the piece under the name parts from the image border, up to that gap; none when no
  radius does (a label outside the plan); a balcony's name there, or on a cell of hatching, names
  the piece of the drawing the flat's walls leave round it (``named_balconies``);
- a region holding confident names of several classes (an open plan, or rooms whose door the
  closing missed) is parted between them: each pixel to the class of the nearest name, the
  strip where two parts meet an opening;
- a named room runs through no door, window or front door the parse found (a gap the closing
  left open, beside a jamb's tick, would take the room beyond).

:func:`rooms_from_names` makes each named room an instance unless the instance under its names
already is it (IoU >= ``FITS``, holding names of one class), or is it with its fixtures (it holds
``HOLDS`` of the named room and lies in one extent of the walls,
``perception.fixture_pieces.room_extents``: the named room's paper is bounded by every line, a
counter's too, and the fixture step has joined the counters to the room): the room's pixels leave
the rooms (and the paper of no instance) they were in, and the closed gaps along its edge become
connectors, so the graph can join it to its neighbours: a door, window or front door where the
network sees one on the gap, else an opening (a gap the wall closing bridged with no door seen in
it is more often the space between a counter and a wall than a doorway). On drawings whose ink
closes every room (the generated ones) the parse has every named room, and nothing changes.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from f2n_drake.core.classes import CLASS_ID, CONNECTOR_CLASSES, NUM_CLASSES, OPENING, SPACE_CLASSES
from f2n_drake.core.parsed import Instance, ParsedPlan, instance_from_mask
from f2n_drake.core.text import TextBox
from f2n_drake.perception.doorways import max_gap_px
from f2n_drake.perception.fixture_pieces import INSIDE, room_extents, text_boxes
from f2n_drake.perception.ink import enclosed_by, free_marks
from f2n_drake.perception.priors.named_balconies import named_balconies
from f2n_drake.perception.reading import place_texts
from f2n_drake.perception.room_names import room_class
from f2n_drake.perception.wall_gaps import collinear_gaps

CONFIDENT = 0.8
"""A name read with at least this confidence makes its room (as it sets its class)."""
_BOUNDS = [CLASS_ID[c] for c in ("wall", *CONNECTOR_CLASSES)]
_SPECK = np.ones((4, 4), np.uint8)  # the network's specks smaller than this are noise
_CONNECTOR_IDS = [CLASS_ID[c] for c in CONNECTOR_CLASSES]
FITS = 0.5
"""An instance under a room's names with at least this IoU with the named room is that room."""
CELL_BOXES = 2
"""A balcony's name on closed paper smaller than this many times its box lies on a cell (of
hatching, of a fixture): its balcony is looked for as one open to the outside."""
HOLDS = 0.9
"""An instance holding this share of a named room, in one extent of the walls, is that room with
its fixtures."""
MIN_NEW_SHARE = 0.5
"""A named room becomes an instance only when at least this share of it is a room's paper or
no instance's (not a door, a window or an opening)."""
SMALL_ROOMS: tuple[str, ...] = ("bathroom",)
"""Classes of rooms that are never most of a plan."""
WITHIN_PLAN = 0.5
"""A room cut from paper open to the outside lies at least this share within the plan (the
convex hull of its walls, words and a frame round the sheet left out): a piece of the sheet's
margin cut off by the words printed on it is no room (a name beside the plan, with its
leader)."""
MOST_OF_PLAN = 0.5
"""A small room's name on paper more than this share of the plan's rooms (by area) names a room
whose walls the parse did not close (a WC's name on an open shop floor): it makes no room there,
and gives the room it lies in no class."""


@dataclass(frozen=True)
class NamedRoom:
    """The paper around confident names of one class (see module doc).

    Attributes:
        class_name: the class the names give (one of ``SPACE_CLASSES``).
        mask: (H, W) bool, the room's paper (the paper furniture encloses left out).
        texts: the names read in it.
        cut: (H, W) bool, the strip along which it was parted from the other named rooms of
            one open region (an opening between them), None when it is a region of its own.
    """

    class_name: str
    mask: np.ndarray
    texts: tuple[TextBox, ...]
    cut: np.ndarray | None = None


def named_rooms(
    lines: np.ndarray,
    texts: Sequence[TextBox],
    labels: np.ndarray,
    grey: np.ndarray | None = None,
) -> tuple[list[NamedRoom], np.ndarray]:
    """The named rooms of a drawing's ``lines`` (without its words), bounded by its walls and by
    the walls, windows and doors the network sees (``labels``: a window drawn too faint for
    the binarisation), and the (H, W) bool gaps closed to find them; ``([], all False)`` when
    no confident room name is read. A balcony's name on paper open to the outside, or on a
    cell of hatching, names the piece of the drawing (its ink, and ``grey``'s toned paper) that
    the flat's walls leave around it (``named_balconies``)."""
    named = [
        (t, cls)
        for t in texts
        if t.confidence >= CONFIDENT and (cls := room_class(t.text)) in SPACE_CLASSES
    ]
    if not named:
        return [], np.zeros(lines.shape, bool)
    marks = free_marks(lines)
    furniture = marks.furniture
    seen = cv2.morphologyEx(np.isin(labels, _BOUNDS).astype(np.uint8), cv2.MORPH_OPEN, _SPECK)
    walls = (lines & ~furniture) | (seen > 0)  # a window drawn apart from the walls, too
    widest = max_gap_px(walls)
    gaps = collinear_gaps(walls, max_gap_px=widest, min_run_px=max(3, widest // 2)) & ~walls
    _, paper = cv2.connectedComponents((~(walls | gaps)).astype(np.uint8), connectivity=4)
    outside = set(np.concatenate([paper[0], paper[-1], paper[:, 0], paper[:, -1]]).tolist())
    by_region: dict[int, list[tuple[TextBox, str]]] = {}
    balconies = []
    for text, cls in named:
        c0, r0, c1, r1 = text.box_px
        under = paper[r0:r1, c0:c1]
        under = under[under > 0]
        region = int(np.bincount(under).argmax()) if under.size else 0
        if cls == "balcony" and _open_or_cell(paper, region, outside, text):
            balconies.append(text)
        elif region:
            by_region.setdefault(region, []).append((text, cls))
    others = [t for t, cls in named if cls != "balcony"]
    rooms = [
        NamedRoom("balcony", mask, (text,))
        for text, mask in named_balconies(balconies, others, lines, labels, grey)
    ]
    floor = ~lines & ~enclosed_by(furniture)
    plan = None  # the plan's hull, once a name lies on paper open to the outside
    for region, found in sorted(by_region.items()):
        mask = paper == region
        if region not in outside:
            rooms += _of_one_class(mask & floor, found)
            continue
        plan = _hull(walls & ~marks.annotation) if plan is None else plan
        cut = [
            m
            for text, _ in found
            if (m := _cut_from_outside(mask, text, widest)) is not None
            and np.count_nonzero(m & plan) >= WITHIN_PLAN * np.count_nonzero(m)
        ]
        for k, room in enumerate(cut):
            if not any((room & other).any() for other in cut[:k]):
                rooms += _of_one_class(room & floor, [(t, c) for t, c in found if _on(t, room)])
    return rooms, gaps


def _open_or_cell(paper: np.ndarray, region: int, outside: set, text: TextBox) -> bool:
    """Whether the paper ``region`` under a name is open to the outside, or smaller than
    ``CELL_BOXES`` times the name's box (a cell of hatching, a fixture)."""
    if not region or region in outside:
        return True
    c0, r0, c1, r1 = text.box_px
    return np.count_nonzero(paper == region) < CELL_BOXES * (c1 - c0) * (r1 - r0)


def _on(text: TextBox, mask: np.ndarray) -> bool:
    col, row = text.centre_px
    return bool(mask[int(row), int(col)])


def _within_doors(room: NamedRoom, doors: np.ndarray) -> NamedRoom:
    """``room`` up to the ``doors`` (the parse's doors, windows and front doors): the pieces of
    its paper they leave that hold one of its names, or the room as it was when none does. Gaps
    the wall closing leaves open (a jamb's tick beside a door) let a name's paper run through a
    door the parse found into the room beyond."""
    if not (room.mask & doors).any():
        return room
    n, pieces = cv2.connectedComponents((room.mask & ~doors).astype(np.uint8), connectivity=4)
    named = {int(pieces[int(t.centre_px[1]), int(t.centre_px[0])]) for t in room.texts} - {0}
    if not named:
        return room
    return dataclasses.replace(room, mask=np.isin(pieces, sorted(named)))


def _of_one_class(mask: np.ndarray, found: list[tuple[TextBox, str]]) -> list[NamedRoom]:
    """The room ``mask`` of the names ``found`` in it; parted between its names when they are of
    several classes (an open plan, or rooms whose door the closing missed): each pixel goes to
    the class of the nearest name, and the 2 px strip where two parts meet is their cut."""
    classes = sorted({cls for _, cls in found})
    if not classes or not mask.any():
        return []
    if len(classes) == 1:
        return [NamedRoom(classes[0], mask, tuple(t for t, _ in found))]
    distances = []
    for cls in classes:
        names = np.ones(mask.shape, np.uint8)
        for text, c in found:
            if c == cls:
                c0, r0, c1, r1 = text.box_px
                names[r0:r1, c0:c1] = 0
        distances.append(cv2.distanceTransform(names, cv2.DIST_L2, 3))
    nearest = np.argmin(distances, axis=0)
    edges = (np.diff(nearest, axis=0, prepend=nearest[:1]) != 0) | (
        np.diff(nearest, axis=1, prepend=nearest[:, :1]) != 0
    )
    cut = cv2.dilate(edges.astype(np.uint8), np.ones((2, 2), np.uint8)).astype(bool) & mask
    return [
        NamedRoom(cls, mask & ~cut & (nearest == k), tuple(t for t, c in found if c == cls), cut)
        for k, cls in enumerate(classes)
    ]


def _hull(ink: np.ndarray) -> np.ndarray:
    """(H, W) bool: the convex hull of ``ink``."""
    hull = np.zeros(ink.shape, np.uint8)
    rows, cols = np.nonzero(ink)
    if rows.size:
        points = cv2.convexHull(np.stack([cols, rows], 1).astype(np.int32))
        cv2.fillConvexPoly(hull, points, 1)
    return hull.astype(bool)


def _cut_from_outside(region: np.ndarray, text: TextBox, widest_px: int) -> np.ndarray | None:
    """The room around ``text`` in a ``region`` of paper open to the outside (through a window
    too faint to binarise, a gap too wide or not straight to close): the region opened by the
    smallest radius, up to ``widest_px``, that parts the piece holding the text (the one
    nearest to it, at most the text's height away) from the image border; None when none
    does."""
    dist = cv2.distanceTransform(np.pad(region, 1).astype(np.uint8), cv2.DIST_L2, 3)[1:-1, 1:-1]
    h, w = region.shape
    col, row = text.centre_px
    step = max(1, widest_px // 16)
    for radius in range(step, widest_px + 1, step):
        core = dist > radius
        rows, cols = np.nonzero(core)
        if not rows.size:
            return None
        away = (rows - row) ** 2 + (cols - col) ** 2
        k = int(np.argmin(away))
        if away[k] > text.height_px**2:
            return None  # no piece of it under the text (a label outside the plan)
        _, piece, stats, _ = cv2.connectedComponentsWithStats(core.astype(np.uint8), connectivity=4)
        x, y, pw, ph = stats[piece[rows[k], cols[k]], :4]
        if min(x, y, w - x - pw, h - y - ph) > radius + 1:
            size = 2 * radius + 1
            disc = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (size, size))
            room = piece == piece[rows[k], cols[k]]
            return (cv2.dilate(room.astype(np.uint8), disc) > 0) & region
    return None


def _reshaped(inst: Instance, mask: np.ndarray, labels: np.ndarray) -> Instance:
    """``inst`` on the pixels ``mask`` left it: geometry and votes retraced, class, scores and
    name kept."""
    new = instance_from_mask(inst.id, inst.class_name, mask, labels)
    return dataclasses.replace(inst, **{f: getattr(new, f) for f in _GEOMETRY})


_GEOMETRY = ("contour_px", "area_px", "centroid_px", "votes")


def _fits(inst: np.ndarray, room: np.ndarray) -> bool:
    """Whether the instance ``inst`` is the named ``room`` (IoU at least ``FITS``)."""
    both = np.count_nonzero(inst & room)
    return both >= FITS * (np.count_nonzero(inst) + np.count_nonzero(room) - both)


def _holds(inst: np.ndarray, room: np.ndarray) -> bool:
    """Whether the instance ``inst`` holds the named ``room`` (``HOLDS`` of its pixels)."""
    return np.count_nonzero(inst & room) >= HOLDS * np.count_nonzero(room)


def _furnished_rooms(parsed: ParsedPlan, lines: np.ndarray) -> set[int]:
    """Ids of the space instances that lie in one extent of the walls
    (``fixture_pieces.room_extents``, ``INSIDE`` of them, not the outside): rooms with the
    pieces their fixtures cut off, whose names' own paper (bounded by every line) is smaller."""
    extents = room_extents(lines, parsed.labels, text_boxes(parsed.texts, lines.shape))
    region_of, share = extents.of_instances(parsed.instance_ids)
    return {
        i.id
        for i in parsed.instances
        if i.class_name in SPACE_CLASSES
        and region_of[i.id]
        and share[i.id] >= INSIDE
        and int(region_of[i.id]) not in extents.outside
    }


def _connector_class(labels: np.ndarray) -> str:
    """The network's majority among door, window and front door on a gap; an opening when it
    labels none of them there."""
    votes = np.bincount(labels, minlength=NUM_CLASSES)[_CONNECTOR_IDS]
    return CONNECTOR_CLASSES[int(np.argmax(votes))] if votes.any() else OPENING


def rooms_from_names(
    parsed: ParsedPlan, lines: np.ndarray, grey: np.ndarray | None = None
) -> ParsedPlan:
    """``parsed`` with an instance for each named room the parse has no room for, or has run
    together with another named room (see module doc), and connectors on the gaps along its edge;
    texts placed again. The same plan when there is none."""
    rooms, gaps = named_rooms(lines, parsed.texts, parsed.labels, grey)
    ids = parsed.instance_ids
    kept = {*SPACE_CLASSES, *CONNECTOR_CLASSES, OPENING}  # what a new room leaves as it is
    kept_px = np.isin(ids, [i.id for i in parsed.instances if i.class_name in kept])
    classes_in: dict[int, set[str]] = {}
    for text in parsed.texts:
        cls = room_class(text.text) if text.confidence >= CONFIDENT else None
        if text.instance_id is not None and cls in SPACE_CLASSES:
            classes_in.setdefault(text.instance_id, set()).add(cls)
    space_px = np.isin(ids, [i.id for i in parsed.instances if i.class_name in SPACE_CLASSES])
    new_ids = ids
    made: list[Instance] = []
    cuts: list[np.ndarray] = []
    furnished = _furnished_rooms(parsed, lines) if rooms else set()
    plan_px = np.count_nonzero(space_px)
    doors_px = np.isin(ids, [i.id for i in parsed.instances if i.class_name in CONNECTOR_CLASSES])
    for room in rooms:
        room = _within_doors(room, doors_px)
        if room.class_name in SMALL_ROOMS and room.mask.sum() > MOST_OF_PLAN * plan_px:
            continue  # not this room's walls: the parse did not close them
        under = {t.instance_id for t in room.texts} - {None}
        single = [i for i in under if len(classes_in.get(i, ())) == 1]
        if any(_fits(new_ids == i, room.mask) for i in single):
            continue  # the parse has the room: its names re-class it (name_rooms)
        if any(i in furnished and _holds(new_ids == i, room.mask) for i in single):
            continue  # the parse has the room with the pieces its fixtures cut off
        take = room.mask & (space_px | ~kept_px) & ~np.isin(new_ids, [m.id for m in made])
        if take.sum() < MIN_NEW_SHARE * room.mask.sum():
            continue
        new_ids = new_ids.copy() if new_ids is ids else new_ids
        iid = int(new_ids.max()) + 1
        new_ids[take] = iid
        made.append(instance_from_mask(iid, room.class_name, take, parsed.labels))
        doors = gaps & (space_px | ~kept_px) & ~np.isin(new_ids, [m.id for m in made])
        edge = cv2.dilate(take.astype(np.uint8), np.ones((3, 3), np.uint8)).astype(bool)
        _, pieces = cv2.connectedComponents(doors.astype(np.uint8), connectivity=8)
        for k in np.unique(pieces[edge & doors]):
            iid = int(new_ids.max()) + 1
            new_ids[pieces == k] = iid
            made.append(
                instance_from_mask(
                    iid, _connector_class(parsed.labels[pieces == k]), pieces == k, parsed.labels
                )
            )
        if room.cut is not None and not any(room.cut is c for c in cuts):
            cuts.append(room.cut)
            strip = room.cut & (space_px | ~kept_px) & ~np.isin(new_ids, [m.id for m in made])
            if strip.any():
                iid = int(new_ids.max()) + 1
                new_ids[strip] = iid
                made.append(instance_from_mask(iid, OPENING, strip, parsed.labels))
    if not made:
        return parsed
    changed = set(np.unique(ids[new_ids != ids]).tolist())
    instances = []
    for inst in parsed.instances:
        if inst.id not in changed:
            instances.append(inst)
        elif (mask := new_ids == inst.id).any():
            instances.append(_reshaped(inst, mask, parsed.labels))
    texts = place_texts(parsed.texts, new_ids)
    return dataclasses.replace(
        parsed, instance_ids=new_ids, instances=instances + made, texts=texts
    )
