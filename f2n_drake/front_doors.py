"""A plan-level prior on connector classes: an apartment has one front door.

In a line drawing a front door, a window and a short piece of facade wall are often the same
outlined box; the network tells them apart only by context, so a drawing often gets two front
doors or none. A flat has exactly one entrance (the FloorPlan2Nav data, ResPlan, are single
apartments), so :func:`assign_front_doors` keeps the ``count`` connectors the network finds most
front-door-like and gives every other front-door vote its runner-up class. Evidence is the
instance's mean front-door probability (``Instance.scores``) when the segmenter gave
probabilities, else its share of front-door pixel votes. Buildings with several entrances pass
their count; ``None`` keeps the plain majority vote.
"""

from __future__ import annotations

import dataclasses
import logging

from f2n_drake.classes import CLASS_ID, CLASS_NAMES, CONNECTOR_CLASSES
from f2n_drake.parsed import Instance, ParsedPlan

log = logging.getLogger(__name__)

FRONT_DOOR = "front_door"
_FRONT_DOOR_ID = CLASS_ID[FRONT_DOOR]
_RUNNER_UP_IDS = set(range(len(CLASS_NAMES))) - {CLASS_ID["background"], _FRONT_DOOR_ID}


def front_door_evidence(instance: Instance) -> float:
    """How front-door-like an instance is, in 0..1: mean probability, else vote share."""
    return instance.evidence(_FRONT_DOOR_ID)


def runner_up_class(instance: Instance) -> str:
    """The instance's best class other than front door and background (``"wall"`` if none)."""
    return instance.best_class(_RUNNER_UP_IDS, default="wall")


def assign_front_doors(parsed: ParsedPlan, count: int | None = 1) -> ParsedPlan:
    """``parsed`` with exactly ``count`` front doors among its connector instances.

    The ``count`` door/window/front-door instances with the most front-door evidence become
    front doors (if their evidence is above zero); other front-door instances take their
    runner-up class. Instances are replaced, not edited; ``count=None`` returns ``parsed``.

    Raises:
        ValueError: ``count`` is negative.
    """
    if count is None:
        return parsed
    if count < 0:
        raise ValueError(f"count must be >= 0 or None, got {count}")
    candidates = [i for i in parsed.instances if i.class_name in CONNECTOR_CLASSES]
    ranked = sorted(candidates, key=front_door_evidence, reverse=True)
    chosen = {i.id for i in ranked[:count] if front_door_evidence(i) > 0}
    new_class = {}
    for inst in candidates:
        if inst.id in chosen and inst.class_name != FRONT_DOOR:
            new_class[inst.id] = FRONT_DOOR
        elif inst.id not in chosen and inst.class_name == FRONT_DOOR:
            new_class[inst.id] = runner_up_class(inst)
    if not new_class:
        return parsed
    instances = []
    for inst in parsed.instances:
        if inst.id in new_class:
            log.info(
                "front-door prior: instance %d %s -> %s",
                inst.id,
                inst.class_name,
                new_class[inst.id],
            )
            inst = dataclasses.replace(inst, class_name=new_class[inst.id])
        instances.append(inst)
    return dataclasses.replace(parsed, instances=instances)
