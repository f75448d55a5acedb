"""A plan-level prior on connector classes: an apartment has one front door.

In a line drawing a front door, a window and a short piece of facade wall are often the same
outlined box; the network tells them apart only by context, so a drawing often gets two front
doors or none. A flat has exactly one entrance (the FloorPlan2Nav data, ResPlan, are single
apartments), so :func:`assign_front_doors` keeps the ``count`` connectors the network finds most
front-door-like and gives every other front-door vote its runner-up class. Evidence is the
instance's mean front-door probability (``Instance.scores``) when the segmenter gave
probabilities, else its share of front-door pixel votes. Buildings with several entrances pass
their count; ``None`` keeps the plain majority vote.

The evidence of a connector that could not be an entrance counts ``UNLIKELY_ENTRANCE_WEIGHT``
of that of one that could (:func:`possible_entrances`): an entrance is at least ``MIN_WIDTH_M``
wide (building codes ask 0.8-0.9 m of clear width), measured like ``scale.door_openings_px``
from jamb line centre to jamb line centre so that thick outlines do not narrow it, opens into a
room, and never into a bedroom, a bathroom or a balcony. Without a scale, "wide enough" is
``MIN_WIDTH_OF_DOORS`` of the median interior door, both measured between their jamb lines.

An entrance is also door-sized: a box much wider than a door is more likely a window in
the same facade, so each candidate's evidence is weighed by :func:`door_likeness` of its opening
(``perception.scale.opening_widths_m``: in metres, or at the scale estimated from the doors).

An entrance leads into the building: the rooms its side reaches through doors are most of the
parse's. A door or window into a room that nothing else opens into (an office off a corridor
that the crop's edge makes the outside, a window of a room whose doors were missed) is weighed
by :func:`reach_weight`, the share of rooms it reaches against the candidate reaching most.
"""

from __future__ import annotations

import dataclasses
import logging
import math

import networkx as nx
import numpy as np

from f2n_drake.core.classes import CLASS_ID, CONNECTOR_CLASSES, OPENING, SPACE_CLASSES
from f2n_drake.core.parsed import Instance, ParsedPlan
from f2n_drake.mapping.graph import (
    build_connectivity_graph,
    contact_px,
    joined,
    kernel_size_px,
    line_gap_px,
    node_keys,
    plan_exterior,
)
from f2n_drake.perception.scale import clear_widths_px, jamb_line_px, opening_widths_m

log = logging.getLogger(__name__)

FRONT_DOOR = "front_door"
_FRONT_DOOR_ID = CLASS_ID[FRONT_DOOR]
_RUNNER_UP_IDS = {CLASS_ID[name] for name in ("door", "window", "wall")}
"""A connector that is no front door stays an opening or is wall, never a room: a gap closed
as a doorway holds its rooms' paper, and their class would make a room of it."""

MIN_WIDTH_M = 0.8
"""Narrowest entrance [m], jamb line centre to jamb line centre: the paper between the jamb
lines plus one jamb line's thickness (:func:`~f2n_drake.perception.scale.jamb_line_px`)."""
MIN_WIDTH_OF_DOORS = 0.9
"""Narrowest entrance without a scale, as a fraction of the median door's width."""
PRIVATE_ROOMS: tuple[str, ...] = ("bedroom", "bathroom", "balcony")
"""Spaces an entrance never opens into."""
DOOR_WIDTH_M = 0.9
"""An entrance's usual opening [m], the door width the scale estimate assumes."""
EXTRA_WIDTH_M = 0.3
"""Width beyond ``DOOR_WIDTH_M`` [m] at which the width part of :func:`door_likeness` falls to
1/e."""
UNLIKELY_ENTRANCE_WEIGHT = 0.1
"""Weight of a connector's evidence when it could not be an entrance (too narrow, or opening into
a private room): unlikely, not impossible, as blur breaks some front doors' boxes into pieces
narrower than an entrance."""
MIN_DOOR_LIKENESS = 0.2
"""The least :func:`door_likeness`: width never outweighs the network more than five times over,
as a front door whose box runs into the wall's paper (blur, thick lines) measures wide."""
MIN_REACH_WEIGHT = 0.25
"""The least :func:`reach_weight`: a surer network still names an entrance into a room the parse
left on its own (its inner doors missed)."""
_PASSAGES = ("door", FRONT_DOOR, OPENING)
"""Connectors walked through from an entrance to count the rooms it reaches."""


def front_door_evidence(instance: Instance) -> float:
    """How front-door-like an instance is, in 0..1: mean probability, else vote share."""
    return instance.evidence(_FRONT_DOOR_ID)


def runner_up_class(instance: Instance) -> str:
    """The instance's best class among door, window and wall (``"wall"`` if none)."""
    return instance.best_class(_RUNNER_UP_IDS, default="wall")


def door_likeness(opening_m: float | None) -> float:
    """1 for an opening no wider than a door, falling as a Gaussian of the excess width
    (``EXTRA_WIDTH_M``) to ``MIN_DOOR_LIKENESS``; 1 when the width is unknown."""
    if opening_m is None:
        return 1.0
    excess = max(0.0, opening_m - DOOR_WIDTH_M) / EXTRA_WIDTH_M
    return MIN_DOOR_LIKENESS + (1.0 - MIN_DOOR_LIKENESS) * math.exp(-(excess**2))


def reach_weight(reached: int, most_reached: int) -> float:
    """1 for a candidate reaching as many rooms as the best reaching one, falling linearly with
    the share it reaches to ``MIN_REACH_WEIGHT`` (1 when no candidate reaches a room)."""
    if most_reached <= 0:
        return 1.0
    return MIN_REACH_WEIGHT + (1.0 - MIN_REACH_WEIGHT) * reached / most_reached


def reached_rooms(parsed: ParsedPlan, candidates: list[Instance]) -> dict[int, int]:
    """Instance id -> the number of spaces reachable from each candidate's sides through doors,
    front doors and openings (never through the outside), on the connectivity graph
    (:func:`f2n_drake.mapping.graph.build_connectivity_graph`)."""
    graph = build_connectivity_graph(parsed)
    walk = graph.subgraph(
        n for n, d in graph.nodes(data=True) if d["kind"] == "space" or d["class_name"] in _PASSAGES
    )
    keys = node_keys(parsed)
    reached = {}
    for inst in candidates:
        rooms: set[str] = set()
        for side in graph.nodes[keys[inst.id]].get("sides", ()):
            if side in walk and side not in rooms:
                rooms |= nx.node_connected_component(walk, side)
        reached[inst.id] = sum(graph.nodes[n]["kind"] == "space" for n in rooms)
    return reached


def possible_entrances(parsed: ParsedPlan, candidates: list[Instance]) -> set[int]:
    """Ids of the ``candidates`` that could be the flat's entrance: wide enough, opening into a
    room and into no private room (module docstring). Sides are the connectivity graph's
    (:func:`f2n_drake.mapping.graph.joined`)."""
    slices = parsed.boxes()
    by_id = parsed.by_id()
    spaces = {i.id for i in parsed.instances if i.class_name in SPACE_CLASSES}
    k = kernel_size_px(parsed.grid, line_gap_px=line_gap_px(parsed))
    exterior = plan_exterior(parsed, k)

    widths = clear_widths_px(parsed, candidates)
    if parsed.grid is not None:
        min_width_px = parsed.grid.length_px(MIN_WIDTH_M) - jamb_line_px(parsed)
    else:
        doors = clear_widths_px(parsed, parsed.of_class("door")).values()
        min_width_px = MIN_WIDTH_OF_DOORS * float(np.median(list(doors))) if doors else 0.0
    possible = set()
    for inst in candidates:
        contacts = contact_px(parsed.instance_ids, inst.id, spaces, exterior, k, slices)
        sides = {by_id[j].class_name for j in joined(contacts, k) if j in by_id}
        if widths[inst.id] >= min_width_px and sides and not sides & set(PRIVATE_ROOMS):
            possible.add(inst.id)
    return possible


def assign_front_doors(parsed: ParsedPlan, count: int | None = 1) -> ParsedPlan:
    """``parsed`` with exactly ``count`` front doors among its connector instances.

    The ``count`` door/window/front-door instances with the most front-door evidence, weighed
    by :func:`door_likeness`, by :func:`reach_weight` of the rooms they reach
    (:func:`reached_rooms`) and, for those that could not be an entrance
    (:func:`possible_entrances`), by ``UNLIKELY_ENTRANCE_WEIGHT``, become front doors (if their
    evidence is above zero); other front-door instances take their runner-up class.
    Instances are replaced, not edited; ``count=None`` returns ``parsed``.

    Raises:
        ValueError: ``count`` is negative.
    """
    if count is None:
        return parsed
    if count < 0:
        raise ValueError(f"count must be >= 0 or None, got {count}")
    candidates = [i for i in parsed.instances if i.class_name in CONNECTOR_CLASSES]
    likely = [i for i in candidates if front_door_evidence(i) > 0]
    possible = possible_entrances(parsed, likely) if likely else set()
    widths = opening_widths_m(parsed, likely, DOOR_WIDTH_M) if likely else {}
    reached = reached_rooms(parsed, likely) if likely else {}
    most_reached = max(reached.values(), default=0)

    def rank(inst: Instance) -> float:
        weight = 1.0 if inst.id in possible else UNLIKELY_ENTRANCE_WEIGHT
        weight *= reach_weight(reached[inst.id], most_reached)
        return weight * front_door_evidence(inst) * door_likeness(widths[inst.id])

    ranked = sorted(likely, key=rank, reverse=True)
    chosen = {i.id for i in ranked[:count]}
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
