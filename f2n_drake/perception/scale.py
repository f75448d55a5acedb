"""Deciding the metres-per-pixel scale of a parsed drawing.

Four sources, in this order: an explicit ``metres_per_px`` argument (the user knows best), the
grid the plan came with (ground truth from a ``FloorPlan``), the room sizes printed on the
drawing (``f2n_drake.perception.printed_sizes``), else an estimate that makes the median door
``assumed_door_width_m`` wide (doors are the one standard-size thing in a plan).

Only plausible doors set that yardstick (:func:`plausible_doors`): a door instance that is one
whole gap through a wall, from wall to wall at both ends, and in a door's proportion to the
walls' thickness. A door shattered into pieces, or a strip of one, would pull the median down
and the flat up in size; when no door is plausible, all are measured. Doors opening on
storage from at most one room (a cupboard's door, a closet's bifold front) are left out when
others remain (:func:`storage_door_ids`): they are no standard doors.

A door's instance is the paper between its jamb lines, each drawn centred on the end of the
wall, so the opening is one outline thicker than the instance (:func:`door_openings_px`); a
drawing in thick lines would otherwise measure its doors narrow and its flat large.
``python -m f2n_drake.evaluate scale`` measures the estimate against drawings of known scale.
"""

from __future__ import annotations

import dataclasses
import logging
import math

import cv2
import numpy as np

from f2n_drake.core.classes import CLASS_ID, SPACE_CLASSES
from f2n_drake.core.errors import InputError
from f2n_drake.core.parsed import Instance, ParsedPlan
from f2n_drake.core.raster import PixelGrid
from f2n_drake.mapping.graph import clear_width_px, line_gap_px
from f2n_drake.perception.printed_sizes import printed_scale
from f2n_drake.perception.runs import stroke_widths_px

log = logging.getLogger(__name__)

DOOR_CLASSES: tuple[str, ...] = ("door", "front_door")
DOOR_AGREEMENT = 2.0
"""A scale read from one printed size (one room's, or the total area) is left out when
``DOORS_TO_DOUBT`` doors or more measure outside this factor of the assumed door width at that
scale (their median): one misread size ("=23 x13m" for "5.23x3.39m", "1017 SQM" for 101.7)
would otherwise scale the whole plan. Sizes printed in two rooms or more check each other
(their spread), and one or two doors are no check: a studio's one door found may be a
cupboard's."""
DOORS_TO_DOUBT = 3
DOOR_TO_WALL = (2.0, 12.0)
"""A plausible door's opening is this many times the walls' thickness, at least and at most
(0.7-1.0 m doors in 0.08-0.4 m walls)."""
_DEPTH_TO_WALL = 2.5  # and its instance at most this many walls thick (a gap through one wall)
_END_WALL_SHARE = 0.5  # and this share of the samples past each end on a wall
_END_REACH_WALLS = 0.5  # samples up to this many walls' thickness past each end (at least 3 px)
_SIDE_REACH_PX = 3  # a door's rooms and storage lie this close to it (across a jamb line) [px]


def jamb_line_px(parsed: ParsedPlan) -> float:
    """Thickness of a door's jamb lines [px]: the unlabelled outlines between connectors and
    rooms (:func:`f2n_drake.mapping.graph.line_gap_px`), or, where every connector touches its
    rooms (doors drawn as boxes across thick walls, their sides part of the door), the lines
    along those boxes' sides (``ParsedPlan.door_outline_px``), drawn with the same pen; 0 for
    ground truth, whose doors reach the jambs' centres."""
    return line_gap_px(parsed) or parsed.door_outline_px


def walls_thickness_px(parsed: ParsedPlan) -> float:
    """The walls' typical thickness [px]: the median stroke width
    (:func:`~f2n_drake.perception.runs.stroke_widths_px`) of the pixels labelled wall;
    0 when none is."""
    wall = parsed.labels == CLASS_ID["wall"]
    if not wall.any():
        return 0.0
    return float(np.median(stroke_widths_px(wall)[wall]))


def plausible_doors(parsed: ParsedPlan, instances: list[Instance]) -> list[Instance]:
    """The ``instances`` (doors) that are one whole gap through a wall: opening (clear width plus
    one outline) ``DOOR_TO_WALL`` times the walls' thickness, instance at most
    ``_DEPTH_TO_WALL`` walls thick, and a wall's end past both ends of its length (labelled
    wall, or ink with no instance at least half a wall thick: not a stair's tread, a fixture's
    outline, another piece of door or a room), less those opening on storage when others remain
    (:func:`storage_door_ids`). All of them when none is plausible or the walls' thickness is
    unknown (nothing labelled wall)."""
    wall_px = walls_thickness_px(parsed)
    if wall_px <= 0:
        return list(instances)
    outline_px = jamb_line_px(parsed)
    ids = parsed.instance_ids
    h, w = ids.shape
    slices = parsed.boxes()
    # a wall: labelled wall, or ink (no instance) at least half a wall thick
    ink = ids == 0
    wall = (parsed.labels == CLASS_ID["wall"]) | (stroke_widths_px(ink) >= wall_px / 2)
    reach = 1.0 + np.arange(max(3, int(round(_END_REACH_WALLS * wall_px))))
    kept = []
    for inst in instances:
        sl = slices[inst.id - 1] if inst.id <= len(slices) else None
        if sl is None:
            continue
        pts = np.argwhere(ids[sl] == inst.id)[:, ::-1].astype(np.float32)
        pts += (sl[1].start, sl[0].start)
        (cx, cy), (a, b), angle = cv2.minAreaRect(pts)
        length, depth = max(a, b) + 1.0, min(a, b) + 1.0
        ratio = (length + outline_px) / wall_px
        if not DOOR_TO_WALL[0] <= ratio <= DOOR_TO_WALL[1] or depth > _DEPTH_TO_WALL * wall_px:
            continue
        theta = np.deg2rad(angle if a >= b else angle + 90.0)
        along = np.array([np.cos(theta), np.sin(theta)])
        across = np.array([-along[1], along[0]])
        offsets = np.linspace(-0.3, 0.3, 5) * depth
        ends_walled = True
        for sign in (-1.0, 1.0):
            xy = (
                np.array([cx, cy])
                + sign * (length / 2 + reach)[:, None, None] * along
                + offsets[None, :, None] * across
            ).reshape(-1, 2)
            x = np.clip(np.rint(xy[:, 0]).astype(int), 0, w - 1)
            y = np.clip(np.rint(xy[:, 1]).astype(int), 0, h - 1)
            ends_walled &= bool(wall[y, x].mean() >= _END_WALL_SHARE)
        if ends_walled:
            kept.append(inst)
    storage = storage_door_ids(parsed, kept)
    passages = [inst for inst in kept if inst.id not in storage]
    return passages or kept or list(instances)


def storage_door_ids(parsed: ParsedPlan, instances: list[Instance]) -> set[int]:
    """Ids of the ``instances`` that open on storage from at most one room: within
    ``_SIDE_REACH_PX`` of them lies paper of no instance that the network calls background and
    that does not reach the image border (a cupboard, a closet), and no second room. A
    cupboard's door and a closet's bifold front are no standard doors."""
    ids = parsed.instance_ids
    room_ids = [inst.id for inst in parsed.instances if inst.class_name in SPACE_CLASSES]
    rooms = np.zeros(max([int(ids.max()), *room_ids]) + 1, bool)  # a room may hold no pixel
    rooms[room_ids] = True
    free = (ids == 0) & (parsed.labels == CLASS_ID["background"])
    _, parts = cv2.connectedComponents(free.astype(np.uint8), connectivity=4)
    edge = np.concatenate([parts[0], parts[-1], parts[:, 0], parts[:, -1]])
    stored = (parts > 0) & ~np.isin(parts, edge[edge > 0])
    square = np.ones((2 * _SIDE_REACH_PX + 1,) * 2, np.uint8)
    slices = parsed.boxes()
    found = set()
    for inst in instances:
        sl = slices[inst.id - 1] if inst.id <= len(slices) else None
        if sl is None:
            continue
        sl = tuple(slice(max(s.start - _SIDE_REACH_PX, 0), s.stop + _SIDE_REACH_PX) for s in sl)
        door = ids[sl] == inst.id
        ring = (cv2.dilate(door.astype(np.uint8), square) > 0) & ~door
        if stored[sl][ring].any() and rooms[np.unique(ids[sl][ring])].sum() <= 1:
            found.add(inst.id)
    return found


def clear_widths_px(parsed: ParsedPlan, instances: list[Instance]) -> dict[int, float]:
    """Instance id -> clear width [px] (:func:`f2n_drake.mapping.graph.clear_width_px`; 0 if it has
    no
    pixels)."""
    slices = parsed.boxes()
    widths = {}
    for inst in instances:
        sl = slices[inst.id - 1] if inst.id <= len(slices) else None
        widths[inst.id] = clear_width_px(parsed.instance_ids[sl] == inst.id) if sl else 0.0
    return widths


def door_widths_px(parsed: ParsedPlan, *, plausible: bool = True) -> list[float]:
    """Clear width [px] of every door and front door instance (only the plausible ones,
    :func:`plausible_doors`, unless ``plausible`` is False)."""
    doors = parsed.of_class(*DOOR_CLASSES)
    if plausible:
        doors = plausible_doors(parsed, doors)
    widths = clear_widths_px(parsed, doors).values()
    return [w for w in widths if w > 0]


def door_openings_px(parsed: ParsedPlan, *, plausible: bool = True) -> list[float]:
    """Width [px] of every door and front door opening (the plausible ones unless
    ``plausible`` is False), jamb line centre to jamb line centre: its clear width plus the
    thickness of the drawn outlines (:func:`jamb_line_px`, 0 for ground truth, whose doors
    touch their walls)."""
    outline_px = jamb_line_px(parsed)
    return [w + outline_px for w in door_widths_px(parsed, plausible=plausible)]


def opening_widths_m(
    parsed: ParsedPlan, instances: list[Instance], assumed_door_width_m: float = 0.9
) -> dict[int, float | None]:
    """Instance id -> opening [m], jamb line centre to jamb line centre (clear width plus one
    outline). Without a grid, the median interior door's opening is taken to be
    ``assumed_door_width_m`` (front doors, which the front-door prior measures with this, do not
    set the yardstick); None for all when there is neither grid nor door."""
    outline_px = jamb_line_px(parsed)
    openings = {i: w + outline_px for i, w in clear_widths_px(parsed, instances).items()}
    if parsed.grid is not None:
        metres_per_px = parsed.grid.metres_per_px
    else:
        plausible = plausible_doors(parsed, parsed.of_class("door"))
        doors = [w for w in clear_widths_px(parsed, plausible).values() if w > 0]
        if not doors:
            return dict.fromkeys(openings)
        metres_per_px = assumed_door_width_m / (float(np.median(doors)) + outline_px)
    return {i: w * metres_per_px for i, w in openings.items()}


def resolve_scale(
    parsed: ParsedPlan,
    *,
    metres_per_px: float | None = None,
    assumed_door_width_m: float = 0.9,
) -> ParsedPlan:
    """A copy of ``parsed`` with ``grid`` and ``scale_source`` set.

    Args:
        parsed: a parsed plan, with or without a grid.
        metres_per_px: known scale [m/px]; overrides the plan's own grid ("argument").
        assumed_door_width_m: opening a median door is taken to have when estimating [m].

    Returns:
        The plan unchanged if it has a grid and no argument is given ("input" or whatever its
        source was); else with ``PixelGrid.from_scale`` (origin at the image's top-left corner),
        from the printed room sizes when the drawing prints some ("from 6 printed room sizes,
        spread 4 %"; one size alone only when the doors do not contradict it, ``DOOR_AGREEMENT``),
        else from its doors.

    Raises:
        InputError: ``metres_per_px`` is not a positive number, or there is no scale and no
            door to estimate one from.
    """
    shape = tuple(int(v) for v in parsed.instance_ids.shape)
    if metres_per_px is not None:
        if not (
            isinstance(metres_per_px, (int, float))
            and math.isfinite(metres_per_px)
            and metres_per_px > 0
        ):
            raise InputError(f"metres per pixel must be a positive number, got {metres_per_px}")
        grid = PixelGrid.from_scale(float(metres_per_px), shape)
        return dataclasses.replace(parsed, grid=grid, scale_source="argument")
    if parsed.grid is not None:
        return parsed
    printed = printed_scale(parsed)
    checked = printed is not None and printed.n_rooms >= 2  # two rooms' sizes check each other
    widths = [] if checked else door_openings_px(parsed)
    left_out = ""
    if printed is not None and not checked and len(widths) >= DOORS_TO_DOUBT:
        door_m = printed.metres_per_px * float(np.median(widths))
        if not 1 / DOOR_AGREEMENT <= door_m / assumed_door_width_m <= DOOR_AGREEMENT:
            left_out = f"; a printed size left out: doors {door_m:.1f} m wide at its scale"
            printed = None
    if printed is not None:
        log.info("scale %.4f m/px %s", printed.metres_per_px, printed.describe())
        grid = PixelGrid.from_scale(printed.metres_per_px, shape)
        return dataclasses.replace(parsed, grid=grid, scale_source=printed.describe())
    if not widths:
        raise InputError(
            "cannot estimate the scale: no door found to measure; give the scale in metres per "
            "pixel (run --scale M_PER_PX, or metres_per_px)"
        )
    median_px = float(np.median(widths))
    scale = assumed_door_width_m / median_px
    log.info(
        "scale %.4f m/px from the median of %d door openings (%.1f px)",
        scale,
        len(widths),
        median_px,
    )
    source = f"door-width estimate, {assumed_door_width_m:g} m doors{left_out}"
    return dataclasses.replace(parsed, grid=PixelGrid.from_scale(scale, shape), scale_source=source)
