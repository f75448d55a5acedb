"""The regions of a drawing that become instances unless voted background.

The drawing's lines less its annotations cut the paper into 4-connected regions; given the
network's labels, the gaps the ink leaves in the walls are closed first
(:mod:`~f2n_drake.perception.doorways`), the windows drawn in the walls' lines with them
(:mod:`~f2n_drake.perception.window_inserts`), a door's swing is floor of the room beyond its arc
(:mod:`~f2n_drake.perception.door_swings`) and rooms open to the outside through a doorway-wide
gap are parted from it (:mod:`~f2n_drake.perception.outside`). A region is a candidate when it is
large enough, clear of the image border (or parted from the outside), and not largely furniture's
paper (furniture's paper itself is no region).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from f2n_drake.perception.door_swings import join_swings
from f2n_drake.perception.doorways import (
    WIDE_DOORWAY_SHARE,
    Doorways,
    find_doorways,
    max_gap_px,
    with_mouths,
)
from f2n_drake.perception.ink import enclosed_by, free_marks, stroke_width_px
from f2n_drake.perception.outside import part_from_outside
from f2n_drake.perception.window_inserts import (
    FAINT_DEPTH,
    find_wall_inserts,
    ink_depth,
    max_window_px,
    wall_piers,
)

FURNITURE_SHARE = 0.2
"""A region this much covered by furniture drawn against the walls is the furniture's paper (a
counter and the strip of paper beside it); less, it is a room with a piece of it inside (a leaf
drawn in a hall)."""


@dataclass(frozen=True)
class EnclosedRegions:
    """The regions of a drawing that become instances unless voted background.

    Attributes:
        lines: the drawing's lines less its annotations (room names, dimensions: paper of the
            room they stand in), (H, W) bool.
        furniture_marks: ink of free-standing furniture (:class:`~f2n_drake.perception.ink.Marks`).
        components: (H, W) int32 4-connected components of non-line pixels; 0 is the lines
            and the paper of furniture drawn against the walls (a component it cut stays one,
            in pieces).
        stats: ``cv2.connectedComponentsWithStats`` rows of the components.
        enclosed: per component, True when it is an instance candidate: big enough, clear of
            the image border or parted from the outside (:mod:`~f2n_drake.perception.outside`),
            and not largely the paper of furniture (``FURNITURE_SHARE``).
        doorways: the gaps in the walls closed with the network's labels
            (:mod:`~f2n_drake.perception.doorways`); their barrier is no component's paper.
            None when the regions come from the ink alone.
        door_outline_px: thickness of the lines along the sides of the doors drawn as boxes in
            thick walls [px] (``WallInserts.door_face_px``; 0: none).
    """

    lines: np.ndarray
    furniture_marks: np.ndarray
    components: np.ndarray
    stats: np.ndarray
    enclosed: np.ndarray
    doorways: Doorways | None = None
    door_outline_px: float = 0.0


def enclosed_regions(
    lines: np.ndarray,
    *,
    min_area_px: int = 12,
    furniture: np.ndarray | None = None,
    labels: np.ndarray | None = None,
    metres_per_px: float | None = None,
    grey: np.ndarray | None = None,
) -> EnclosedRegions:
    """The instance candidates of a binarised drawing (``extract_instances`` keeps those not
    voted background; the evaluation counts those it left out). ``furniture``: as
    ``extract_instances``. Given the network's ``labels``, the gaps the ink leaves in the walls
    are closed first (:func:`~f2n_drake.perception.doorways.find_doorways`; ``metres_per_px``,
    if known, sets the widest gap closed), and given the ``grey`` drawing too, the windows drawn
    in the walls' lines with them (:mod:`~f2n_drake.perception.window_inserts`; a piece of wall
    between two windows, free-standing ink, stays wall)."""
    marks = free_marks(lines)
    all_lines = lines
    lines = lines & ~marks.annotation  # words, symbols, a sheet's frame: the room's paper
    height, width = lines.shape
    doorways = inserts = None
    barrier = lines
    if labels is not None:
        not_furniture = ~marks.furniture
        if furniture is not None and furniture.any():  # a bed's outline is no wall to close
            not_furniture &= ~cv2.dilate(furniture.astype(np.uint8), np.ones((3, 3), np.uint8)) > 0
        walls = lines & not_furniture
        widest = max_gap_px(walls, metres_per_px)
        if grey is not None:
            inserts = find_wall_inserts(
                grey,
                all_lines & not_furniture,
                labels,
                max_window_px=max_window_px(walls, metres_per_px),
                max_door_px=widest,
                max_wide_door_px=int(round(WIDE_DOORWAY_SHARE * widest)),
            )
            piers = wall_piers(marks.annotation, inserts.windows)
            walls |= piers
            lines = lines | piers
        swing_ink = all_lines if grey is None else all_lines | (ink_depth(grey) >= FAINT_DEPTH)
        doorways = find_doorways(
            walls,
            labels,
            max_gap_px=widest,
            windows=None if inserts is None else inserts.windows,
            window_classes=None if inserts is None else inserts.classes,
            wall_px=0 if inserts is None else inserts.wall_px,
            wall_gaps=None if inserts is None else inserts.gaps,
            wide_wall_gaps=None if inserts is None else inserts.wide_gaps,
            swing_ink=swing_ink,
        )
        barrier = lines | doorways.barrier
    _, cc, stats, _ = cv2.connectedComponentsWithStats(
        (~barrier).astype(np.uint8), connectivity=4, ltype=cv2.CV_32S
    )
    parted = np.zeros(0, int)
    if doorways is not None:  # rooms open to the outside through a plain gap, and their gaps
        outside = part_from_outside(barrier, cc, stats, widest, labels)
        cc, stats, parted = outside.components, outside.stats, outside.rooms
        doorways = with_mouths(doorways, outside.mouths, labels)
        # a door's swing is floor of the room beyond its arc
        reach_px = 2 * stroke_width_px(lines) + 3
        join_swings(cc, stats, doorways.swings, doorways.connectors, reach_px)
    x, y, w, h, area = (stats[:, i] for i in range(5))
    keep = (area >= min_area_px) & (x > 0) & (y > 0) & (x + w < width) & (y + h < height)
    keep[parted] = area[parted] >= min_area_px
    keep[0] = False  # component 0 is the line pixels
    if marks.furniture.any():
        keep[np.unique(cc[enclosed_by(marks.furniture)])] = False  # a bed, a table: obstacles
    if furniture is not None and furniture.any():
        # a bed, a counter against a wall: obstacles. A region the furniture found on the first
        # segmentation only partly covers (its outline no longer closes it) keeps the rest.
        covered = np.bincount(cc[furniture], minlength=len(stats))
        keep[covered >= FURNITURE_SHARE * np.maximum(area, 1)] = False
        cc = np.where(furniture, 0, cc)
    outline_px = 0.0 if inserts is None else inserts.door_face_px
    return EnclosedRegions(lines, marks.furniture, cc, stats, keep, doorways, outline_px)
