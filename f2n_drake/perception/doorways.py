"""Doorways the ink leaves open: close a room's boundary where the drawing has a gap in a wall.

Real drawings draw a door as a gap in the wall (with a swing arc, or nothing), so the ink alone
does not close the rooms and two rooms, or a room and the outside, are one region. The boundary
is closed with two kinds of evidence, the drawing's and the network's:

- **Collinear gaps.** Along each row and each column, paper between two wall pixels at most
  ``max_gap_px`` apart, one of them the free end of a straight wall run at least
  ``min_run_px`` long, the other in a straight run too, is a gap in that wall (a door at a
  corner stops at the side of the crossing wall). Wall
  pixels are the ink and those the network labels wall (ink crossing a gap, a door's leaf, is
  left out of it). Given ``wall_gaps``, the gaps between two ends of one wall's line
  (:func:`~f2n_drake.perception.window_inserts.find_wall_inserts`) are gaps too, and given
  ``wide_wall_gaps`` those between two ends of a wall's line up to ``WIDE_DOORWAY_SHARE`` times
  the widest doorway (a double door, a closet's front), candidates apart from the others kept
  only where a swing is drawn or an opening seen in them.
- **The network's walls** off the ink (a faint wall the binarisation lost).

Each 8-connected piece of that evidence is kept only when it closes something (or is a door drawn as
such: a gap between two ends of a wall's line with a door's swing at it and an opening seen in it,
kept though a leak elsewhere still joins its two sides): with every piece in place, it must touch
two regions of paper that the ink alone leaves as one region, and part two rooms of different
classes (a gap at least ``_MIN_PLAIN_GAP_PX`` thick: one a pixel thick continues a single line to a
wall, no doorway), or (where the network labels at least ``_OPEN_SHARE`` of the gap an opening, or a
door's swing is drawn at it: :mod:`~f2n_drake.perception.door_swings`) two rooms or a room and the
outside (a region touching the image border): two parts of one room with neither are no doorway. A
swing also makes a door of a gap between a room and whatever region lies beyond (a cupboard), and so
does a gap between two ends of one wall's line, except between two parts of one room (an open
passage); both must be strips across a wall (``_STRIP_SHARE`` as thick as long, at most
``_STRIP_WALLS`` walls thick). A door drawn as such (a gap between two ends of a wall's line with a
swing at it and an opening seen in it) is kept wherever it closes, rooms or none on its sides (a
cupboard smaller than a room, its door's swing sector). A room is a region the network votes a space
class (living ... balcony) and at least ``ROOM_SHARE`` of the square of the widest doorway; the room
beyond a gap's swing arc counts as touched. A gap with an opening seen or a swing drawn, between two
ends of a wall's line, that a sill or leaf on its face parts from all but one region is judged by
the regions across that line; one a line across it (a threshold, a shut leaf) parts in two, with an
opening seen or a swing drawn, is a door though the ink alone already parts the rooms. A gap between
two ends of a wall's line that touches no room, and more than the inside of a door's box, is judged
with the rooms within ``_LEAVES_WALLS`` walls of it across the ink: a closet's bifold or sliding
leaves drawn across the gap on the room's side part the room from it. A piece filling a door box the
ink already closes, a notch, a gap between stair treads, a cut through a wall's hollow or through
the paper outside changes nothing or parts no rooms and is dropped, as are a gap amid the cells of a
lattice of ink (a cross-hatched terrace: only small enclosed paper beside it, many such cells around
it) and a gap the network mostly labels wall (the hollow of a wall drawn as two lines), so drawings
whose ink closes every room (the generated ones) keep their regions. A kept gap is a connector: the
gap itself, as thick as the wall.
A connector's class is the network's majority among door, window and front door on it; where it
votes none, a door when a swing (or a closet's leaves) is drawn at it or it lies between two ends
of one wall's line (a door's place), else an open passage (``Doorways.passages``: the gap between
a counter and a wall, a recess's mouth, a wall stopping short of another are closed as well as
doorways, and are no doors). The small region a bridge cuts off beside it (a quarter disc at most
as wide as the piece is long: the sector a door's swing arc draws), or one across a line of ink
at the gap's face that the network votes an opening (the leaf, the arc and a sill drawn on the
wall's face close it), is a swing (``Doorways.swings``): floor of the room beyond its arc
(:func:`~f2n_drake.perception.door_swings.join_swings`). A kept piece of network wall alone is
wall: a boundary, no instance. Windows drawn in a wall's line (``windows``) close their span as a
wall would and are connectors after the doorways."""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
from scipy import ndimage

from f2n_drake.core.classes import CLASS_ID, CONNECTOR_CLASSES, NUM_CLASSES, SPACE_CLASSES
from f2n_drake.perception.door_swings import swing_evidence
from f2n_drake.perception.ink import stroke_width_px
from f2n_drake.perception.wall_gaps import amid_cells, gap_pieces

_CONNECTOR_IDS = np.array([CLASS_ID[name] for name in CONNECTOR_CLASSES])
_SPACE_IDS = np.array([CLASS_ID[name] for name in SPACE_CLASSES])
_WALL = CLASS_ID["wall"]
_DOOR = CLASS_ID["door"]
_WINDOW = CLASS_ID["window"]
MAX_DOORWAY_M = 1.6
"""Widest gap in a wall closed as a doorway when the scale is known [m] (a double door)."""
MAX_DOORWAY_SHARE = 0.1
"""Widest gap closed when the scale is unknown, as a share of the wall ink's extent."""
SECTOR_SHARE = 0.8
"""A door's swing sector is a quarter disc: at most this share of the square of its width."""
ROOM_SHARE = 0.5
"""A room is at least this share of the square of the widest doorway (smaller paper is a piece:
a swing's sector, a fixture's or a hatching's cell)."""
_ROUNDS = 3  # passes dropping connectors that join no two rooms (each may free the next)
_MIN_NET_PX = 4  # network wall/opening specks smaller than this side are noise [px]
_STRIP_SHARE = 0.6  # a gap across a wall is at most this thick for its length (a door's strip)
_STRIP_WALLS = 2.0  # and at most this many walls thick
_MIN_PLAIN_GAP_PX = 2  # a gap with neither opening nor swing this thin is a line's end
_GROUP_REACH_PX = 2  # gap pieces of one axis this close are one gap
_OPEN_SHARE = 0.05  # a gap the network labels door, window or front door this much is an opening
_LEAVES_WALLS = 2.0  # leaves drawn across a gap (a bifold's zigzag) reach this many walls off it
WIDE_DOORWAY_SHARE = 1.5
"""A gap up to this many times the widest doorway is a candidate where a door is drawn in it: a
double door or a closet's front between two ends of a wall's line, a swing drawn or an opening
seen in it."""


@dataclass(frozen=True)
class Doorways:
    """Where the ink's gaps are closed (:func:`find_doorways`).

    Attributes:
        barrier: (H, W) bool, every kept piece: paper that is no room.
        connectors: (H, W) int32, 0 or ``k + 1`` for the k-th connector (the closed gap).
        classes: (K,) class id of each connector (door, window or front door).
        passages: (K,) bool, True for a connector with no door seen in it nor drawn at it: an
            open passage (class ``opening``), not a door; None: none is.
        swings: (H, W) int32, 0 or ``k + 1`` on the paper the k-th connector's swing cuts off
            (the sector between its leaf and arc): floor of the room beyond the arc
            (:func:`swing_rooms`). None where there is none.
    """

    barrier: np.ndarray
    connectors: np.ndarray
    classes: np.ndarray
    swings: np.ndarray | None = None
    passages: np.ndarray | None = None

    def is_passage(self, k: int) -> bool:
        """Whether the k-th connector (0-based) is an open passage, not a door."""
        return self.passages is not None and bool(self.passages[k])


def max_gap_px(walls: np.ndarray, metres_per_px: float | None = None) -> int:
    """Widest gap to close [px]: ``MAX_DOORWAY_M`` at a known scale, else
    ``MAX_DOORWAY_SHARE`` of the extent of the ``walls`` ink (0 when there is none)."""
    if metres_per_px:
        return int(round(MAX_DOORWAY_M / metres_per_px))
    rows, cols = np.nonzero(walls)
    if rows.size == 0:
        return 0
    extent = max(rows.max() - rows.min(), cols.max() - cols.min()) + 1
    return int(round(MAX_DOORWAY_SHARE * extent))


def find_doorways(
    ink: np.ndarray,
    labels: np.ndarray,
    *,
    max_gap_px: int,
    min_run_px: int | None = None,
    windows: np.ndarray | None = None,
    window_classes: np.ndarray | None = None,
    wall_gaps: np.ndarray | None = None,
    swing_ink: np.ndarray | None = None,
    wall_px: int = 0,
    wide_wall_gaps: np.ndarray | None = None,
) -> Doorways:
    """Close the gaps the ``ink`` leaves in a plan's walls (see module doc).

    Args:
        ink: (H, W) bool, the plan's lines (annotations and free-standing furniture left out).
        labels: (H, W) per-pixel class ids from the network.
        max_gap_px: widest gap closed [px] (:func:`max_gap_px`).
        min_run_px: shortest wall run a gap may end [px]; default half of ``max_gap_px``
            (longer than any wall is thick).
        windows: (H, W) int32, 0 or ``k + 1`` on the k-th window drawn in a wall's line
            (:func:`~f2n_drake.perception.window_inserts.find_window_inserts`): each closes its
            span as the wall would and is a connector, after the doorways, of its class in
            ``window_classes`` (default window).
        wall_gaps: (H, W) bool, more gaps to try: the paper between two ends of one wall's
            line (:func:`~f2n_drake.perception.window_inserts.find_wall_inserts`).
        swing_ink: (H, W) bool, the ink a door's swing is looked for on
            (:func:`~f2n_drake.perception.door_swings.swing_evidence`); default ``ink``.
        wall_px: the walls' typical thickness [px], if known (0: not): a gap with a swing or
            between two ends of a wall's line is at most ``_STRIP_WALLS`` of it thick.
        wide_wall_gaps: (H, W) bool, the paper between two ends of one wall's line longer than
            a doorway (``WallInserts.wide_gaps``): wide gaps to try.
    """
    ink = np.asarray(ink, bool)
    if windows is not None and windows.any():
        doorways = find_doorways(
            ink | (windows > 0),
            labels,
            max_gap_px=max_gap_px,
            min_run_px=min_run_px,
            wall_gaps=wall_gaps,
            swing_ink=swing_ink,
            wall_px=wall_px,
            wide_wall_gaps=wide_wall_gaps,
        )
        return _with_windows(doorways, windows, window_classes)
    none = Doorways(np.zeros(ink.shape, bool), np.zeros(ink.shape, np.int32), np.zeros(0, int))
    if max_gap_px < 2 or not ink.any():
        return none
    min_run_px = max(3, max_gap_px // 2) if min_run_px is None else min_run_px
    speck = np.ones((_MIN_NET_PX, _MIN_NET_PX), np.uint8)
    net_wall = cv2.morphologyEx((labels == _WALL).astype(np.uint8), cv2.MORPH_OPEN, speck) > 0
    n_gaps, pieces, n_cols, wide_gap = gap_pieces(
        ink | net_wall, ink, max_gap_px, min_run_px, wall_gaps, wide_wall_gaps
    )
    gaps = pieces > 0
    n_walls, wall_pieces = cv2.connectedComponents(
        (net_wall & ~ink & ~gaps).astype(np.uint8), connectivity=8
    )
    pieces = np.where(wall_pieces > 0, wall_pieces + n_gaps - 1, pieces)
    n_pieces = n_gaps + n_walls - 1
    if n_pieces <= 1:
        return none
    boxes = [_grown(box, ink.shape) for box in ndimage.find_objects(pieces)]
    _, before = cv2.connectedComponents((~ink).astype(np.uint8), connectivity=4)
    connector = np.arange(n_pieces) < n_gaps  # gaps are connectors, the network's walls walls
    min_room_px = ROOM_SHARE * max_gap_px**2
    reach = np.ones((2 * stroke_width_px(ink) + 3,) * 2, np.uint8)
    across = 2 * stroke_width_px(ink) + 1  # a ring reaching over a line of ink [px]
    # the network sees an opening or a room's paper in a doorway; a gap it sees as wall is the
    # hollow of a wall drawn as two lines
    walled = np.bincount(pieces[labels == _WALL], minlength=n_pieces)
    size = np.bincount(pieces.ravel(), minlength=n_pieces)
    kept = ~connector | (2 * walled < size)
    # pieces of one gap side by side along one axis (a gap found twice, a door's gap and the
    # paper beside its jamb) are judged and become a connector together
    group = _groups(pieces, n_gaps, n_cols, boxes)
    # a gap amid the cells of a cross-hatched floor (a terrace's lattice) is no gap in a wall
    kept &= ~(connector & amid_cells(pieces, group, before, ink, boxes, max_gap_px))
    # the network sees a door, window or front door in the gap
    opened = np.bincount(pieces[np.isin(labels, _CONNECTOR_IDS)], minlength=n_pieces)
    seen_open = opened >= _OPEN_SHARE * size
    # a door's swing (arc or open leaf) is drawn at the gap
    # a door drawn as such: its swing (arc or open leaf) at a gap shaped like a wall's
    # (a strip across the wall, not a patch of paper)
    strip = np.zeros(n_pieces, bool)
    strip[1:] = [_is_strip(box, wall_px) for box in boxes]
    swung = swing_evidence(pieces, ink if swing_ink is None else swing_ink, connector & strip)
    # a door's place: the gap between two ends of one wall's line (mostly)
    in_line = np.zeros(n_pieces, bool)
    if wall_gaps is not None:
        places = wall_gaps if wide_wall_gaps is None else wall_gaps | wide_wall_gaps
        in_line = np.bincount(pieces[places & ~ink], minlength=n_pieces)
        in_line = connector & strip & (2 * in_line >= size)
    # a gap wider than a doorway is one only where a door is drawn in it
    wide = np.zeros(n_pieces, bool)
    wide[:n_gaps] = wide_gap
    kept &= ~wide | (in_line & (swung | seen_open))
    kept[0] = False
    leaves = np.zeros(n_pieces, bool)  # a closet's leaves drawn across the gap: a door drawn
    for _ in range(_ROUNDS):
        barrier = ink | np.isin(pieces, np.flatnonzero(kept))
        _, regions, stats, _ = cv2.connectedComponentsWithStats(
            (~barrier).astype(np.uint8), connectivity=4
        )
        origin = _origins(regions, before)
        area = stats[:, cv2.CC_STAT_AREA]
        votes = np.bincount(
            (regions.astype(np.int64) * NUM_CLASSES + labels).ravel(),
            minlength=len(area) * NUM_CLASSES,
        ).reshape(-1, NUM_CLASSES)
        roomlike = np.isin(votes.argmax(axis=1), _SPACE_IDS)
        space = roomlike & (area >= min_room_px)
        outside = np.zeros(len(area), bool)
        outside[np.concatenate([regions[0], regions[-1], regions[:, 0], regions[:, -1]])] = True
        region_boxes = ndimage.find_objects(regions)
        now = kept.copy()
        for k in np.flatnonzero(kept):
            together = np.flatnonzero(kept & (group == group[k]))
            box = _union_box([boxes[j - 1] for j in together])
            sides = _sides(pieces, together, box, regions, barrier)
            door = seen_open[together].any() or swung[together].any()
            line = in_line[together].any()
            if door and line and sides.size < 2:  # a sill or leaf drawn at the gap's face
                sides = _sides(pieces, together, box, regions, barrier, across)
            # a door's leaf or sill drawn across the gap closes it already: the gap between two
            # ends of a wall's line, or one a line parts into pieces on both its sides (a
            # threshold), with an opening seen or a swing drawn, is a door all the same
            drawn_shut = door and (line or together.size >= 2) and sides.size >= 2
            closes = sides.size >= 2 and (np.unique(origin[sides]).size < sides.size or drawn_shut)
            # a door drawn in a wall's line, its swing at it, that the network sees too, is one
            # even where a leak elsewhere still joins its two sides (a later step may part them)
            drawn_door = line and swung[together].any() and seen_open[together].any()
            if not (closes or drawn_door):
                now[k] = False  # it closes nothing
                continue
            rooms = set(sides[space[sides]])
            boxed = all(_within(region_boxes[r - 1], box) for r in sides)  # a door's box
            if line and not rooms and not boxed and wall_px:  # leaves across it: a room behind
                ring_px = int(_LEAVES_WALLS * wall_px) + across
                behind = _sides(pieces, together, box, regions, barrier, ring_px)
                rooms.update(behind[space[behind]])
                leaves[together] = space[behind].any()
            swings = sides[~space[sides] & roomlike[sides] & connector[k]]
            for r in swings:  # a swing's sector: the room beyond its arc
                box = _grown(region_boxes[r - 1], ink.shape, reach.shape[0])
                near = cv2.dilate((regions[box] == r).astype(np.uint8), reach).astype(bool)
                beyond = np.unique(regions[box][near])
                rooms.update(beyond[space[beyond]])
            # it parts two rooms of different classes, or two rooms or a room and the outside
            # where the network sees an opening or a swing is drawn: one room's two parts are
            # no doorway. A swing parts a room from whatever lies beyond (a cupboard too), and
            # so does a gap between two ends of a wall's line, unless a room of the same class
            # lies beyond (an open passage within one space)
            kinds = {int(votes[r].argmax()) for r in rooms}
            thick = min(s.stop - s.start for s in box) - 2 >= _MIN_PLAIN_GAP_PX
            parts_rooms = len(rooms) >= 2 and ((len(kinds) >= 2 and thick) or door or line)
            opens_out = len(rooms) >= 1 and outside[sides].any() and (door or line)
            beyond = (swung[together].any() and len(rooms) >= 1) or (line and len(rooms) == 1)
            # a door drawn and seen in a wall's line is one whatever lies on its sides (a
            # cupboard and its swing's sector, both smaller than a room)
            now[k] = bool(parts_rooms or opens_out or beyond or drawn_door)
        if np.array_equal(now, kept):
            break
        kept = now
    if not kept.any():
        return none
    barrier = np.isin(pieces, np.flatnonzero(kept))
    return _connectors(
        ink,
        barrier,
        pieces,
        np.flatnonzero(kept & connector),
        labels,
        max_gap_px,
        before,
        group,
        swung | leaves | in_line,
    )


def _groups(
    pieces: np.ndarray, n_gaps: int, n_cols: int, boxes: list[tuple[slice, slice]]
) -> np.ndarray:
    """Per piece, the label of its group: gap pieces of one axis (columns: labels below
    ``n_cols``) at most ``_GROUP_REACH_PX`` apart (a line of ink, a door's leaf or sill, may
    part them) are one group; every other piece is its own."""
    parent = np.arange(int(pieces.max()) + 1)

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    square = np.ones((2 * _GROUP_REACH_PX + 1,) * 2, np.uint8)
    for k in range(1, n_gaps):
        box = _grown(boxes[k - 1], pieces.shape, _GROUP_REACH_PX)
        near = cv2.dilate((pieces[box] == k).astype(np.uint8), square).astype(bool)
        for j in np.unique(pieces[box][near]):
            same_axis = (j < n_cols) == (k < n_cols)
            if 0 < j < n_gaps and j != k and same_axis:
                parent[root(int(j))] = root(k)
    return np.array([root(i) for i in range(parent.size)])


def _union_box(boxes: list[tuple[slice, slice]]) -> tuple[slice, slice]:
    """The bounding box of several boxes."""
    return tuple(
        slice(min(b[i].start for b in boxes), max(b[i].stop for b in boxes)) for i in range(2)
    )


def with_mouths(doorways: Doorways, mouths: np.ndarray, labels: np.ndarray) -> Doorways:
    """``doorways`` with the ``mouths`` (labels, 0: none; ``perception.outside``) added as
    connectors after its own, each of the network's majority among door, window and front door
    on it, ``door`` when it votes none."""
    if not mouths.any():
        return doorways
    return _with_windows(doorways, mouths, _connector_classes(_connector_votes(mouths, labels)))


def _connector_votes(
    connectors: np.ndarray, labels: np.ndarray, count: int | None = None
) -> np.ndarray:
    """(K, 3) pixels of each connector of ``connectors`` (0 or ``k + 1``; ``count`` of them,
    default the largest ``k + 1``) the network labels door, window, front door."""
    n = (int(connectors.max()) if count is None else count) + 1
    return np.bincount(
        (connectors.astype(np.int64) * NUM_CLASSES + labels).ravel(), minlength=n * NUM_CLASSES
    ).reshape(n, NUM_CLASSES)[1:, _CONNECTOR_IDS]


def _connector_classes(votes: np.ndarray) -> np.ndarray:
    """Class id per connector of its ``votes`` (:func:`_connector_votes`): the network's
    majority among door, window and front door on it, ``door`` when it votes none."""
    return np.where(votes.any(axis=1), _CONNECTOR_IDS[np.argmax(votes, axis=1)], _DOOR)


def _with_windows(
    doorways: Doorways, windows: np.ndarray, classes: np.ndarray | None = None
) -> Doorways:
    """``doorways`` with the ``windows`` (labels, 0: none) added as connectors after its own, of
    ``classes`` (default window); a window pixel a doorway already holds stays the doorway's."""
    count = len(doorways.classes)
    connectors = doorways.connectors.copy()
    free = (windows > 0) & (connectors == 0)
    connectors[free] = windows[free] + count
    if classes is None:
        classes = np.full(int(windows.max()), _WINDOW)
    passages = None
    if doorways.passages is not None:
        passages = np.concatenate([doorways.passages, np.zeros(len(classes), bool)])
    classes = np.concatenate([doorways.classes, classes])
    barrier = doorways.barrier | (windows > 0)
    return Doorways(barrier, connectors, classes.astype(int), doorways.swings, passages)


def _is_strip(box: tuple[slice, slice], wall_px: int = 0) -> bool:
    """Whether a (grown) bounding box is a strip across a wall: at most ``_STRIP_SHARE`` as
    thick as it is long, and at most ``_STRIP_WALLS`` walls thick (``wall_px`` [px], if known)."""
    sides = sorted(s.stop - s.start - 2 for s in box)
    thin = not wall_px or sides[0] <= _STRIP_WALLS * wall_px
    return thin and sides[0] <= _STRIP_SHARE * sides[1]


def _grown(box: tuple[slice, slice], shape: tuple[int, int], by: int = 1) -> tuple[slice, slice]:
    """A bounding box (``ndimage.find_objects``) grown by ``by`` px, clipped to ``shape``."""
    return tuple(
        slice(max(s.start - by, 0), min(s.stop + by, size))
        for s, size in zip(box, shape, strict=True)
    )


def _within(inner: tuple[slice, slice], outer: tuple[slice, slice]) -> bool:
    """Whether bounding box ``inner`` lies within bounding box ``outer``."""
    return all(i.start >= o.start and i.stop <= o.stop for i, o in zip(inner, outer, strict=True))


def _origins(after: np.ndarray, before: np.ndarray) -> np.ndarray:
    """Per label of ``after`` (a finer partition of the paper), the label of ``before`` holding
    it."""
    origin = np.zeros(int(after.max()) + 1, np.int64)
    origin[after.ravel()] = before.ravel()
    return origin


def _sides(
    pieces: np.ndarray,
    k: int | np.ndarray,
    box: tuple[slice, slice],
    regions: np.ndarray,
    barrier: np.ndarray,
    ring_px: int = 3,
) -> np.ndarray:
    """Labels of the ``regions`` of paper 8-adjacent to piece ``k`` or pieces ``k`` (``box``:
    their grown box), or within a ``ring_px`` square of them (across a line of ink)."""
    if ring_px > 3:
        box = _grown(box, pieces.shape, ring_px // 2)
    piece = np.isin(pieces[box], k)
    ring = cv2.dilate(piece.astype(np.uint8), np.ones((ring_px, ring_px), np.uint8)).astype(bool)
    return np.unique(regions[box][ring & ~barrier[box]])


def _connectors(
    ink: np.ndarray,
    barrier: np.ndarray,
    pieces: np.ndarray,
    connector_ids: np.ndarray,
    labels: np.ndarray,
    max_gap_px: int,
    before: np.ndarray,
    group: np.ndarray | None = None,
    drawn: np.ndarray | None = None,
) -> Doorways:
    """Connector instances of the kept connector pieces (one per ``group``, default one per
    piece) and the swing sectors beside each, or across a line of ink on its face (at most
    ``SECTOR_SHARE`` of the square of the piece's length, or of ``max_gap_px``: regions the
    network votes a room that the barrier cuts off from a larger one, or votes an opening).
    ``drawn``: per piece, a door is drawn there (its swing, a closet's leaves, or two ends of one
    wall's line about it); a connector none of whose pieces is, and on which the network sees no
    door, window or front door, is an open passage."""
    paper = ~(ink | barrier)
    _, regions, stats, _ = cv2.connectedComponentsWithStats(paper.astype(np.uint8), connectivity=4)
    whole_area = np.bincount(before.ravel())[_origins(regions, before)]
    area = stats[:, cv2.CC_STAT_AREA]
    votes = np.bincount(
        (regions.astype(np.int64) * NUM_CLASSES + labels).ravel(),
        minlength=len(area) * NUM_CLASSES,
    ).reshape(-1, NUM_CLASSES)
    roomlike = np.isin(votes.argmax(axis=1), _SPACE_IDS)  # a swing is drawn in a room
    opening = np.isin(votes.argmax(axis=1), _CONNECTOR_IDS)  # or the network sees a door there
    across = 2 * stroke_width_px(ink) + 1
    boxes = ndimage.find_objects(pieces)
    region_boxes = ndimage.find_objects(regions)
    connectors = np.zeros(ink.shape, np.int32)
    swings = np.zeros(ink.shape, np.int32)
    taken = np.zeros(len(area), bool)
    taken[0] = True
    group = np.arange(int(pieces.max()) + 1) if group is None else group
    heads = np.unique(group[connector_ids])
    for iid, head in enumerate(heads, start=1):
        k = connector_ids[group[connector_ids] == head]
        box = _grown(_union_box([boxes[j - 1] for j in k]), ink.shape)
        # with the thin ink between a gap's pieces (a door's leaf or sill drawn across it)
        members = np.isin(pieces[box], k)
        if k.size > 1:
            reach = np.ones((2 * _GROUP_REACH_PX + 1,) * 2, np.uint8)
            shut = cv2.morphologyEx(members.astype(np.uint8), cv2.MORPH_CLOSE, reach) > 0
            members |= shut & ink[box] & (connectors[box] == 0)
        connectors[box][members] = iid
        length = min(max(box[0].stop - box[0].start, box[1].stop - box[1].start), max_gap_px)
        for r in _sides(pieces, k, box, regions, ~paper, across):
            small = area[r] <= SECTOR_SHARE * length**2
            # cut off by the gap, or shut by the leaf, the arc and a sill, voted an opening
            cut = area[r] < whole_area[r] and roomlike[r]
            if not taken[r] and small and (cut or opening[r]):
                sector = region_boxes[r - 1]
                swings[sector][regions[sector] == r] = iid
                taken[r] = True
    votes = _connector_votes(connectors, labels, len(heads))
    door_drawn = [drawn is not None and drawn[group == head].any() for head in heads]
    passages = ~votes.any(axis=1) & ~np.array(door_drawn, bool)
    classes = _connector_classes(votes).astype(int)
    return Doorways(barrier | (connectors > 0), connectors, classes, swings, passages)
