"""A plan-level prior on doors: every room of a flat can be entered.

In a line drawing a door is an outlined box in the wall strip, the same box as a short piece of
wall; when the network calls it wall, the rooms behind it have no way in and the ground robot
cannot reach them. Real flats have no sealed rooms, so :func:`open_sealed_rooms` looks at each
group of spaces that no door, front door or opening joins to the entrance (the front door's
group, else the largest), takes the wall instances touching both that group and another space,
and turns the most door-like of them into a door: the one with the highest mean door probability,
if it is at least ``min_evidence`` and it is no wider than a door can be
(:func:`f2n_drake.perception.priors.connector_sizes.oversized`). It repeats until every group is
joined or no
wall qualifies. "Joins" and "touching" are the connectivity graph's rule
(:func:`f2n_drake.mapping.graph.joined`), so a door that only grazes a room with a corner joins
nothing
here either. Without probabilities (ground truth, label-only segmenters) nothing changes.
"""

from __future__ import annotations

import dataclasses
import logging

import networkx as nx

from f2n_drake.core.classes import CLASS_ID, SPACE_CLASSES
from f2n_drake.core.parsed import ParsedPlan
from f2n_drake.mapping.graph import (
    OUTSIDE_ID,
    contact_px,
    joined,
    kernel_size_px,
    line_gap_px,
    plan_exterior,
)
from f2n_drake.perception.priors.connector_sizes import oversized

log = logging.getLogger(__name__)

DOOR_LIKE: tuple[str, ...] = ("door", "front_door", "opening")
"""Connector classes a person walks through."""

MIN_EVIDENCE = 0.1
"""Smallest mean door probability for a wall to become a door."""

_DOOR_ID = CLASS_ID["door"]


def open_sealed_rooms(
    parsed: ParsedPlan, *, min_evidence: float = MIN_EVIDENCE, kernel_px: int | None = None
) -> ParsedPlan:
    """``parsed`` with wall instances turned into doors until no group of spaces is sealed off.

    Args:
        parsed: instances with ``scores`` (mean class probabilities).
        min_evidence: smallest mean door probability of a wall that may become a door.
        kernel_px: dilation kernel finding touching instances [px]; default as the graph's
            (``f2n_drake.mapping.graph.kernel_size_px`` with the drawing's line gap).

    Returns:
        ``parsed`` itself when nothing changes, else a copy with replaced instances.
    """
    spaces = {i.id for i in parsed.instances if i.class_name in SPACE_CLASSES}
    walls = [i for i in parsed.instances if i.class_name == "wall" and i.scores]
    if len(spaces) < 2 or not walls:
        return parsed
    k = kernel_px or kernel_size_px(parsed.grid, line_gap_px=line_gap_px(parsed))
    doors = [i for i in parsed.instances if i.class_name in DOOR_LIKE]
    exterior = plan_exterior(parsed, k)
    slices = parsed.boxes()

    def joined_spaces(ids: list[int]) -> dict[int, set[int]]:
        """Instance id -> the spaces it joins, by the graph's contact rule."""
        return {
            i: set(joined(contact_px(parsed.instance_ids, i, spaces, exterior, k, slices), k))
            - {OUTSIDE_ID}
            for i in ids
        }

    touching = joined_spaces([i.id for i in doors])
    rooms = nx.Graph()
    rooms.add_nodes_from(spaces)
    for door in doors:
        nx.add_path(rooms, sorted(touching[door.id]))  # joins every space the door touches
    if nx.is_connected(rooms):
        return parsed
    too_wide = oversized(parsed, walls, "door")
    walls = [w for w in walls if w.id not in too_wide]
    touching |= joined_spaces([w.id for w in walls])
    area = {i.id: i.area_px for i in parsed.instances}
    at_front_door = {
        s for i in parsed.instances if i.class_name == "front_door" for s in touching[i.id]
    }
    opened: set[int] = set()
    while not nx.is_connected(rooms):
        groups = list(nx.connected_components(rooms))
        entrance = _entrance(groups, at_front_door, area)
        candidates = [
            w
            for w in walls
            if any(touching[w.id] & g and touching[w.id] - g for g in groups if g is not entrance)
        ]
        best = max(candidates, key=lambda w: w.scores.get(_DOOR_ID, 0.0), default=None)
        if best is None or best.scores.get(_DOOR_ID, 0.0) < min_evidence:
            break
        opened.add(best.id)
        nx.add_path(rooms, sorted(touching[best.id]))
        log.info(
            "sealed-room prior: wall instance %d -> door (door probability %.2f)",
            best.id,
            best.scores.get(_DOOR_ID, 0.0),
        )
    if not opened:
        return parsed
    instances = [
        dataclasses.replace(i, class_name="door") if i.id in opened else i for i in parsed.instances
    ]
    return dataclasses.replace(parsed, instances=instances)


def _entrance(groups: list[set[int]], at_front_door: set[int], area: dict[int, int]) -> set[int]:
    """The group holding a space at the front door, else the one of largest area."""
    for group in groups:
        if group & at_front_door:
            return group
    return max(groups, key=lambda g: sum(area[s] for s in g))
