"""A plan-level prior on balconies: a balcony is open to the air.

A balcony stands outside the facade: at least one of its sides is a railing, drawn as a line
with the outside of the building behind it. A small room in the facade (a bathroom with one
window, a storeroom) can look like one to the network, but walls close it on every side. So
:func:`close_balconies` gives every balcony that reaches no exterior its runner-up room class.

"Reaches the exterior" (:func:`reaches_exterior`): grown pixel by pixel through the drawn lines
the network calls balcony or background (a railing, however thick its pen), for up to
``reach_px`` pixels, the balcony touches the paper outside the building
(:func:`f2n_drake.mapping.graph.exterior_mask`). Walls, windows and doors stop it: an instance, or
ink
the network calls anything else.
"""

from __future__ import annotations

import dataclasses
import logging

import cv2
import numpy as np

from f2n_drake.core.classes import CLASS_ID, SPACE_CLASSES
from f2n_drake.core.parsed import Instance, ParsedPlan
from f2n_drake.mapping.graph import grown_window, kernel_size_px, line_gap_px, plan_exterior

log = logging.getLogger(__name__)

BALCONY = "balcony"
_ROOM_IDS = {CLASS_ID[name] for name in SPACE_CLASSES} - {CLASS_ID[BALCONY]}
_RAILING_LABELS = [CLASS_ID["background"], CLASS_ID[BALCONY]]

MIN_ROOM_EVIDENCE = 0.05
"""Least evidence (mean probability, else vote share) for the room a closed balcony becomes;
with less, the network saw nothing but a balcony there and the balcony stays."""


def reaches_exterior(
    parsed: ParsedPlan,
    instance_id: int,
    exterior: np.ndarray,
    reach_px: int,
    slices: list | None = None,
) -> bool:
    """Whether instance ``instance_id``, grown up to ``reach_px`` pixels through line pixels
    (no instance) labelled background or balcony, touches ``exterior`` ((H, W) bool)."""
    if slices is None:
        slices = parsed.boxes()
    if instance_id > len(slices) or slices[instance_id - 1] is None:
        return False
    window = grown_window(slices[instance_id - 1], reach_px + 1, parsed.instance_ids.shape)
    ids = parsed.instance_ids[window]
    grown = (ids == instance_id).astype(np.uint8)
    passable = ((ids == 0) & np.isin(parsed.labels[window], _RAILING_LABELS)).astype(np.uint8)
    outside = exterior[window]
    step = np.ones((3, 3), np.uint8)
    for _ in range(reach_px):
        grown = cv2.dilate(grown, step)
        if np.any(outside & (grown > 0)):
            return True
        grown &= passable | (ids == instance_id)
    return False


def close_balconies(parsed: ParsedPlan, enabled: bool = True) -> ParsedPlan:
    """``parsed`` with every balcony that reaches no exterior turned into the room class it looks
    most like, if that has at least ``MIN_ROOM_EVIDENCE``. The reach is three times the
    connectivity graph's kernel. Instances are replaced, not edited; ``enabled=False`` returns
    ``parsed``."""
    balconies = parsed.of_class(BALCONY)
    if not enabled or not balconies:
        return parsed
    k = kernel_size_px(parsed.grid, line_gap_px=line_gap_px(parsed))
    exterior = plan_exterior(parsed, k)
    slices = parsed.boxes()
    new_class = {}
    for inst in balconies:
        room = _likeliest_room(inst)
        if room and not reaches_exterior(parsed, inst.id, exterior, 3 * k, slices):
            new_class[inst.id] = room
    if not new_class:
        return parsed
    instances = []
    for inst in parsed.instances:
        if inst.id in new_class:
            log.info("balcony prior: instance %d balcony -> %s", inst.id, new_class[inst.id])
            inst = dataclasses.replace(inst, class_name=new_class[inst.id])
        instances.append(inst)
    return dataclasses.replace(parsed, instances=instances)


def _likeliest_room(inst: Instance) -> str | None:
    """The room class (a space other than balcony) ``inst`` looks most like, None if it has
    less than ``MIN_ROOM_EVIDENCE`` for every one."""
    room = inst.best_class(_ROOM_IDS, default=BALCONY)
    if room == BALCONY or inst.evidence(CLASS_ID[room]) < MIN_ROOM_EVIDENCE:
        return None
    return room
