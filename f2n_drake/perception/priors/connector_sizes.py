"""A prior on connector sizes: a door or a window is no wider than such an opening can be.

Where a drawing outlines its walls, the paper inside a wall strip is an enclosed region like a
door's or a window's box, and in thick-lined drawings the network calls some of those strips
door or window (ResPlan plan 13 drawn in random styles: 25 of 53 wrong instances in 20
drawings). A "door" running 2.5 m along a wall is a piece of wall, and taking it for a door lets
the ground robot plan through the wall; a "window" 4 m long lets the drone fly through one. So
:func:`wall_off_oversized` gives every door wider than ``MAX_OPENING_M["door"]`` (a double door
of two 1 m leaves) and every window wider than ``MAX_OPENING_M["window"]`` the class wall,
measured from jamb line centre to jamb line centre
(:func:`f2n_drake.perception.scale.opening_widths_m`).
Front doors are the front-door prior's to choose; the sealed-room prior never makes a door of a
wall this wide (:func:`oversized`).

It needs the drawing's scale (``run --scale``, or a plan's own grid). Estimated from the doors,
the scale would judge the doors by themselves: where blur breaks most door boxes into short
pieces, the median door is a piece, the true doors look three to six times too wide and were
walled (test plan 35 drawn in a random style), which also spoils the scale estimate. Without a
scale nothing changes.
"""

from __future__ import annotations

import dataclasses
import logging

from f2n_drake.core.parsed import Instance, ParsedPlan
from f2n_drake.perception.scale import opening_widths_m

log = logging.getLogger(__name__)

MAX_OPENING_M: dict[str, float] = {"door": 2.0, "window": 3.0}
"""Widest opening [m] of each connector class: a double door of two 1 m leaves; a window as wide
as the generator's widest (``VARIED_SIZES``)."""


def oversized(parsed: ParsedPlan, instances: list[Instance], as_class: str) -> set[int]:
    """Ids of the ``instances`` whose opening is wider than a ``as_class`` can be (none without
    a scale)."""
    if parsed.grid is None:
        return set()
    widths = opening_widths_m(parsed, instances)
    limit = MAX_OPENING_M[as_class]
    return {i for i, w in widths.items() if w is not None and w > limit}


def wall_off_oversized(parsed: ParsedPlan, enabled: bool = True) -> ParsedPlan:
    """``parsed`` with every door and window wider than ``MAX_OPENING_M`` of its class made
    wall. Instances are replaced, not edited; ``enabled=False`` returns ``parsed``."""
    if not enabled:
        return parsed
    walled = set()
    for class_name in MAX_OPENING_M:
        walled |= oversized(parsed, parsed.of_class(class_name), class_name)
    if not walled:
        return parsed
    instances = []
    for inst in parsed.instances:
        if inst.id in walled:
            log.info("connector-size prior: instance %d %s -> wall", inst.id, inst.class_name)
            inst = dataclasses.replace(inst, class_name="wall")
        instances.append(inst)
    return dataclasses.replace(parsed, instances=instances)
