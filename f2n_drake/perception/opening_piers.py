"""Openings parted at the piers between them: a run of windows and doors is one opening each.

A facade glazed from end to end draws its windows and doors side by side, each between two short
piers of solid wall; two doors drawn as boxes next to each other share a side. The step that
closes a wall's gaps (``perception.doorways``, ``perception.window_inserts``) can take the whole
run as one connector, piers included, which matches none of its openings (R3D paints each one
apart) and gives the robot one opening as wide as the facade.

:func:`part_at_piers` cuts each door, window and front door across its length where a pier
crosses it: a stretch of its length on which its pixels across are ink (at least ``PIER_INK``
of them) and, mostly (``PIER_WALL``), wall band (the drawing's dark ink a ``_MIN_THICK_PX``
square fits in: :func:`~f2n_drake.perception.window_inserts.wall_bands`). A window's glass and
sill lines run along it and cross no stretch; a mullion or the sash drawn across a window is a
thin or light line, no band, and leaves it one window, as R3D paints it. Each stretch between
piers at least ``MIN_PIECE_PX`` long becomes its own connector of the same class; the piers are
wall (no instance). A connector filling less than ``MIN_FILL`` of its bounding box (drawn in an
angled or curved wall) is left whole.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from scipy import ndimage

from f2n_drake.core.classes import CONNECTOR_CLASSES
from f2n_drake.core.parsed import Instance, ParsedPlan, instance_from_mask
from f2n_drake.perception.ink import as_grey
from f2n_drake.perception.window_inserts import wall_bands

PIER_INK = 0.8
"""Share of a connector's pixels across it that are ink where a pier crosses it."""
PIER_WALL = 0.5
"""Share of a pier's pixels that are wall band (dark, thick ink), not a thin line."""
MIN_PIECE_PX = 3
"""Shortest stretch between piers that is an opening of its own [px]."""
MIN_FILL = 0.6
"""Least share of its bounding box a connector fills to be cut (a strip along rows or columns)."""


def part_at_piers(
    parsed: ParsedPlan,
    grey: np.ndarray,
    lines: np.ndarray,
    probabilities: np.ndarray | None = None,
    *,
    walls: tuple[np.ndarray, np.ndarray, int] | None = None,
) -> ParsedPlan:
    """``parsed`` with each connector cut at the piers crossing it (module doc); the same plan
    when none is.

    Args:
        parsed: the instances of a drawing.
        grey: (H, W) uint8 grey drawing, dark lines on light paper (or BGR/BGRA, made grey).
        lines: (H, W) bool, its walls' ink.
        probabilities: (NUM_CLASSES, H, W) class probabilities, for the new instances' scores.
        walls: ``wall_bands(grey, lines, parsed.labels)`` when already computed.
    """
    connectors = [inst for inst in parsed.instances if inst.class_name in CONNECTOR_CLASSES]
    if not connectors:
        return parsed
    _, bands, _ = walls or wall_bands(as_grey(grey), lines, parsed.labels)
    ids = parsed.instance_ids.copy()
    boxes = parsed.boxes()
    next_id = max(inst.id for inst in parsed.instances) + 1
    pieces: dict[int, list[int]] = {}  # connector id -> the ids of its pieces
    for inst in connectors:
        box = boxes[inst.id - 1] if inst.id <= len(boxes) else None
        if box is None:
            continue
        stretches = _stretches(parsed.instance_ids[box] == inst.id, lines[box], bands[box])
        if len(stretches) < 2:
            continue
        mask = parsed.instance_ids[box] == inst.id
        window = ids[box]  # a view: writes the box of ids
        window[mask] = 0  # the piers: wall
        new_ids = [inst.id] + list(range(next_id, next_id + len(stretches) - 1))
        next_id += len(stretches) - 1
        for iid, stretch in zip(new_ids, stretches, strict=True):
            window[mask & stretch] = iid
        pieces[inst.id] = new_ids
    if not pieces:
        return parsed
    instances: list[Instance] = []
    for inst in parsed.instances:
        if inst.id not in pieces:
            instances.append(inst)
            continue
        for iid in pieces[inst.id]:
            piece = instance_from_mask(
                iid, inst.class_name, ids == iid, parsed.labels, probabilities
            )
            instances.append(dataclasses.replace(piece, name=inst.name if iid == inst.id else None))
    return dataclasses.replace(parsed, instance_ids=ids, instances=instances)


def _stretches(mask: np.ndarray, ink: np.ndarray, bands: np.ndarray) -> list[np.ndarray]:
    """The stretches of a connector (``mask`` in its bounding box) between the piers crossing
    it, each a bool mask of the box's columns (rows) it spans, in order; fewer than two when no
    pier parts it."""
    h, w = mask.shape
    if mask.sum() < MIN_FILL * h * w:
        return []
    across = 0 if w >= h else 1  # the axis its depth is counted along
    depth = mask.sum(axis=across)
    inked = (mask & ink).sum(axis=across)
    banded = (mask & bands).sum(axis=across)
    pier = (depth > 0) & (inked >= PIER_INK * depth)
    runs, n_runs = ndimage.label(pier)
    for k in range(1, n_runs + 1):
        run = runs == k
        if banded[run].sum() < PIER_WALL * depth[run].sum():
            pier[run] = False  # a thin line across: a mullion, a sash, a door's leaf
    between, n = ndimage.label(~pier & (depth > 0))
    spans = [np.flatnonzero(between == k) for k in range(1, n + 1)]
    spans = [span for span in spans if span.size >= MIN_PIECE_PX]
    if len(spans) < 2:
        return []
    stretches = []
    for span in spans:
        along = np.zeros(depth.size, bool)
        along[span[0] : span[-1] + 1] = True
        stretches.append(along[None, :] if across == 0 else along[:, None])
    return stretches
