"""A plan-level prior on space classes: an apartment has one kitchen.

The network tells a kitchen from a living room or a bedroom by shape and context only, and the
open-passage split cuts a kitchen out of a living room wherever the network paints a compact
kitchen-coloured patch, so a parse sometimes holds two kitchens: a bedroom voted kitchen, or a
corner of the living room split off as a second, open kitchen. A flat has one kitchen (the
FloorPlan2Nav data and ResPlan are single apartments), so :func:`assign_kitchens` keeps the
``count`` kitchens with the highest mean kitchen probability (``Instance.scores``; the share of
kitchen votes without probabilities). Every other kitchen is undone:

- a kitchen the split cut out of a room (it touches ``opening`` strips) joins that room again:
  the piece, its openings and the parts across them become one instance of the room's class;
- an enclosed kitchen takes its runner-up space class.

A flat also has a kitchen: when the parse has none, the bedroom or bathroom (not the flat's only
bathroom) with the most kitchen evidence becomes the kitchen, if that evidence is at least
``MIN_EVIDENCE``. A living room is never taken: a kitchen missing there is open to it, and the
room is still the living room.

Buildings with several flats pass their count; ``None`` keeps the plain vote.
"""

from __future__ import annotations

import dataclasses
import logging

import cv2
import numpy as np

from f2n_drake.core.classes import CLASS_ID, OPENING, SPACE_CLASSES
from f2n_drake.core.parsed import Instance, ParsedPlan, outer_contour

log = logging.getLogger(__name__)

KITCHEN = "kitchen"
_KITCHEN_ID = CLASS_ID[KITCHEN]
_OTHER_SPACE_IDS = {CLASS_ID[n] for n in SPACE_CLASSES} - {_KITCHEN_ID}

MIN_EVIDENCE = 0.15
"""Smallest mean kitchen probability of a room that becomes the missing kitchen."""


def kitchen_evidence(instance: Instance) -> float:
    """How kitchen-like an instance is, in 0..1: mean probability, else vote share."""
    return instance.evidence(_KITCHEN_ID)


def _touching(instance_ids: np.ndarray, ids: set[int]) -> set[int]:
    """Ids of the instances 8-adjacent to the pixels of ``ids`` (``ids`` themselves excluded)."""
    mask = np.isin(instance_ids, list(ids)).astype(np.uint8)
    ring = cv2.dilate(mask, np.ones((3, 3), np.uint8)).astype(bool)
    return set(np.unique(instance_ids[ring]).tolist()) - ids - {0}


def _merged(parts: list[Instance], instance_ids: np.ndarray) -> Instance:
    """``parts[0]`` grown by the other parts, whose pixels ``instance_ids`` already gives
    ``parts[0].id``: votes summed, scores and centroid area-weighted, contour retraced."""
    keep = parts[0]
    area = sum(p.area_px for p in parts)
    votes: dict[int, int] = {}
    scores: dict[int, float] = {}
    for p in parts:
        for c, v in p.votes.items():
            votes[c] = votes.get(c, 0) + v
        for c, s in p.scores.items():
            scores[c] = scores.get(c, 0.0) + s * p.area_px / area
    if not all(p.scores for p in parts):
        scores = {}
    rows, cols = np.nonzero(instance_ids == keep.id)
    r0, r1, c0, c1 = rows.min(), rows.max() + 1, cols.min(), cols.max() + 1
    return dataclasses.replace(
        keep,
        contour_px=outer_contour(instance_ids[r0:r1, c0:c1] == keep.id, (int(c0), int(r0))),
        area_px=area,
        centroid_px=(
            sum(p.centroid_px[0] * p.area_px for p in parts) / area,
            sum(p.centroid_px[1] * p.area_px for p in parts) / area,
        ),
        votes=votes,
        scores={c: round(s, 4) for c, s in scores.items()},
    )


def _missing_kitchen(parsed: ParsedPlan, min_evidence: float) -> ParsedPlan:
    """``parsed`` with its most kitchen-like bedroom or spare bathroom made the kitchen."""
    bathrooms = parsed.of_class("bathroom")
    rooms = parsed.of_class("bedroom") + (bathrooms if len(bathrooms) > 1 else [])
    best = max((r for r in rooms if r.scores), key=kitchen_evidence, default=None)
    if best is None or kitchen_evidence(best) < min_evidence:
        return parsed
    log.info(
        "kitchen prior: no kitchen; instance %d %s -> kitchen (kitchen probability %.2f)",
        best.id,
        best.class_name,
        kitchen_evidence(best),
    )
    instances = [
        dataclasses.replace(i, class_name=KITCHEN) if i.id == best.id else i
        for i in parsed.instances
    ]
    return dataclasses.replace(parsed, instances=instances)


def _cut_from(
    kitchen: Instance, instance_ids: np.ndarray, by_id: dict[int, Instance]
) -> tuple[list[int], list[int]]:
    """(opening ids, room ids largest first) of a kitchen the split cut out of a room: the
    opening strips it touches and the non-kitchen spaces across them; ([], []) if none."""
    openings = [i for i in _touching(instance_ids, {kitchen.id}) if by_id[i].class_name == OPENING]
    if not openings:
        return [], []
    rooms = [
        i
        for i in _touching(instance_ids, set(openings)) - {kitchen.id}
        if by_id[i].class_name in SPACE_CLASSES and by_id[i].class_name != KITCHEN
    ]
    return openings, sorted(rooms, key=lambda i: by_id[i].area_px, reverse=True)


def assign_kitchens(
    parsed: ParsedPlan, count: int | None = 1, *, min_evidence: float = MIN_EVIDENCE
) -> ParsedPlan:
    """``parsed`` with at most ``count`` kitchens, and one if it had none and ``count`` allows
    (see the module docstring).

    Args:
        parsed: instances, with ``scores`` for the missing-kitchen rule.
        count: most kitchens kept; ``None`` returns ``parsed``.
        min_evidence: smallest mean kitchen probability of a room that becomes the missing
            kitchen.

    Instances and the id image are replaced, not edited.

    Raises:
        ValueError: ``count`` is negative.
    """
    if count is None:
        return parsed
    if count < 0:
        raise ValueError(f"count must be >= 0 or None, got {count}")
    kitchens = sorted(parsed.of_class(KITCHEN), key=kitchen_evidence, reverse=True)
    if not kitchens and count:
        return _missing_kitchen(parsed, min_evidence)
    if len(kitchens) <= count:
        return parsed
    by_id = parsed.by_id()  # updated as instances are relabelled, grown and removed
    instance_ids = parsed.instance_ids.copy()
    for kitchen in kitchens[count:]:
        openings, rooms = _cut_from(kitchen, instance_ids, by_id)
        if not rooms:
            runner_up = kitchen.best_class(_OTHER_SPACE_IDS, default="living")
            log.info("kitchen prior: instance %d kitchen -> %s", kitchen.id, runner_up)
            by_id[kitchen.id] = dataclasses.replace(kitchen, class_name=runner_up)
            continue
        room = by_id[rooms[0]]
        parts = [room, kitchen, *(by_id[i] for i in [*openings, *rooms[1:]])]
        for part in parts[1:]:
            instance_ids[instance_ids == part.id] = room.id
            del by_id[part.id]
        log.info(
            "kitchen prior: instance %d kitchen rejoins %s %d", kitchen.id, room.class_name, room.id
        )
        by_id[room.id] = _merged(parts, instance_ids)
    instances = [by_id[i.id] for i in parsed.instances if i.id in by_id]
    return dataclasses.replace(parsed, instance_ids=instance_ids, instances=instances)
