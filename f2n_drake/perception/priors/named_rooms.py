"""Room names give room types: a room whose printed name the lexicon knows takes its class.

A name read with at least ``CONFIDENT`` confidence outweighs the network's pixels; one read with
less is one more piece of evidence, its confidence times ``NAME_WEIGHT`` added to the network's
mean probability of the class it names (``Instance.evidence``). Only rooms (``SPACE_CLASSES``)
are re-classed, and only to room classes: a name never makes a door or a wall, a name of no
class (hall, closet: ``perception.room_names.NO_CLASS``) leaves the room as voted, unless it was
voted balcony (a storeroom, a hall, a study is indoors: it takes its runner-up room class), and so
do names of different classes in one instance (rooms the parse ran together: "Kitchen" and
"Bedroom" in one region say nothing of which it is). Every room
keeps its printed name (``Instance.name``). Without text, the plan comes back unchanged.

A region the network votes background is no instance; when a confident room name is written in
it, :func:`label_named_regions` gives its pixels the named class before the vote, so that it is.
Where the parse still has no room under a confident name, or one running several named rooms
together, :func:`name_rooms` makes the room first (``perception.priors.named_regions``); the
pieces a named room's fixtures cut off take its class (``perception.priors.named_pieces``).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np

from f2n_drake.core.classes import CLASS_ID, SPACE_CLASSES
from f2n_drake.core.parsed import Instance, ParsedPlan
from f2n_drake.core.text import TextBox
from f2n_drake.perception.priors.named_pieces import join_named_pieces
from f2n_drake.perception.priors.named_regions import (
    CONFIDENT,
    MOST_OF_PLAN,
    SMALL_ROOMS,
    named_rooms,
    rooms_from_names,
)
from f2n_drake.perception.room_names import NO_CLASS, room_class

_INDOOR_IDS = [CLASS_ID[c] for c in SPACE_CLASSES if c != "balcony"]
NAME_WEIGHT = 0.5
"""Evidence a less confident name adds to its class, per unit of confidence."""
BACKGROUND_SHARE = 0.25


def _named_class(inst: Instance, names: list[tuple[TextBox, str]], plan_share: float) -> str:
    inst_class = inst.class_name
    room_sized = plan_share <= MOST_OF_PLAN  # else a small room's name is not this region's
    classed = [
        (t, c) for t, c in names if c in SPACE_CLASSES and (room_sized or c not in SMALL_ROOMS)
    ]
    if (
        not classed
        and inst_class == "balcony"
        and any(c == NO_CLASS and t.confidence >= CONFIDENT for t, c in names)
    ):  # a storeroom, a hall, a study: named indoors, so no balcony
        return inst.best_class(_INDOOR_IDS, inst_class)
    if not classed or inst_class not in SPACE_CLASSES or len({c for _, c in classed}) > 1:
        return inst_class
    text, cls = max(classed, key=lambda tc: tc[0].confidence)
    if text.confidence >= CONFIDENT:
        return cls
    named = inst.evidence(CLASS_ID[cls]) + NAME_WEIGHT * text.confidence
    return cls if named > inst.evidence(CLASS_ID[inst_class]) else inst_class


def name_rooms(
    parsed: ParsedPlan, lines: np.ndarray | None = None, grey: np.ndarray | None = None
) -> ParsedPlan:
    """``parsed`` with each room that has a printed name (``parsed.texts`` placed in it) named
    and, where the name gives a class, re-classed; the same plan when no name is read. Given
    the drawing's ``lines`` (without its words), a named room the parse has no instance for,
    or ran together with another, is made one first
    (``named_regions.rooms_from_names``), and the pieces its fixtures cut from a named room take
    its class after (``named_pieces.join_named_pieces``)."""
    if lines is not None and parsed.texts:
        parsed = rooms_from_names(parsed, lines, grey)
    names: dict[int, list[tuple[TextBox, str]]] = {}
    for text in parsed.texts:
        cls = room_class(text.text) if text.instance_id is not None else None
        if cls is not None:
            names.setdefault(text.instance_id, []).append((text, cls))
    if not names:
        return parsed
    room_area = sum(i.area_px for i in parsed.instances if i.class_name in SPACE_CLASSES)
    instances = []
    for inst in parsed.instances:
        if inst.id in names:
            read = sorted(names[inst.id], key=lambda tc: (tc[0].box_px[1], tc[0].box_px[0]))
            inst = dataclasses.replace(
                inst,
                class_name=_named_class(inst, read, inst.area_px / max(room_area, 1)),
                name=" / ".join(t.text for t, _ in read),
            )
        instances.append(inst)
    parsed = dataclasses.replace(parsed, instances=instances)
    return parsed if lines is None else join_named_pieces(parsed, lines)


def _on_background(labels: np.ndarray, text: TextBox) -> bool:
    if text.confidence < CONFIDENT or room_class(text.text) not in SPACE_CLASSES:
        return False
    c0, r0, c1, r1 = text.box_px
    grow = 2 * (r1 - r0)
    around = labels[max(r0 - grow, 0) : r1 + grow, max(c0 - grow, 0) : c1 + grow]
    return bool(around.size) and np.count_nonzero(around == 0) >= BACKGROUND_SHARE * around.size


def label_named_regions(
    labels: np.ndarray,
    lines: np.ndarray,
    texts: Sequence[TextBox],
    grey: np.ndarray | None = None,
) -> np.ndarray:
    """``labels`` with every room a confident name names (``named_regions.named_rooms``) that
    the network votes background labelled the named class; the same array when there is
    none. Rooms are looked for only when the network labels at least ``BACKGROUND_SHARE`` of
    the paper round some confident name (its box grown by twice its height) background."""
    if not any(_on_background(labels, t) for t in texts):
        return labels
    rooms, _ = named_rooms(lines, texts, labels, grey)
    out = labels
    for room in rooms:
        if room.mask.any() and np.bincount(labels[room.mask]).argmax() == 0:
            out = out.copy() if out is labels else out
            out[room.mask] = CLASS_ID[room.class_name]
    return out
