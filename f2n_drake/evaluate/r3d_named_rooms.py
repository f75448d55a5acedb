"""Room types where the drawing prints the room's name: R3D rooms scored with and without names.

An R3D room (a 4-connected region of one room class, ``datasets.r3d.ROOM_CLASSES``, of at least
``evaluate.r3d.MIN_ROOM_PX``) is *named* when a line of the parse's text layer
(``ParsedPlan.texts``) that the lexicon knows as a room name (``perception.room_names.room_class``
not None: a class, or ``none`` for a hall, a study, a laundry) lies on it, at least half of the
line's box on the room. The parse's class at a room is the room type most of its instances'
pixels there take, walls, doors, windows and openings left out (they bound rooms and have no
room type; R3D paints its walls over its rooms), and so is the paper of no instance (the
furniture the parse leaves out as obstacles); background when no room instance lies on it. A
room the parse cuts into pieces (a bath split by its tub and basin, a kitchen by its counters)
is scored by all its pieces, not by its largest one. The class is right when acceptable for the
room's R3D class (``datasets.r3d.ACCEPTABLE``). The same rooms are scored on a parse of the same
drawing without reading (``parse_drawing(..., reader=None)``: the network, the vote and the
priors alone), so the gain of the names is measured on the rooms that print one."""

from __future__ import annotations

from collections.abc import Callable, Sequence

import cv2
import numpy as np

from f2n_drake.core.classes import CLASS_ID, CLASS_NAMES, CONNECTOR_CLASSES, OPENING
from f2n_drake.core.parsed import ParsedPlan
from f2n_drake.core.text import TextBox
from f2n_drake.datasets.r3d import ACCEPTABLE_MASK, R3D_CLASSES, R3D_ID, ROOM_CLASSES
from f2n_drake.perception.room_names import room_class

ON_ROOM = 0.5
"""Share of a text box's pixels that must lie on a room for the text to name it."""
NOT_ROOM_TYPES = ("wall", *CONNECTOR_CLASSES, OPENING)
"""Parse classes that bound rooms and are no room type: left out of a room's class."""


def room_regions(r3d_labels: np.ndarray, min_px: int) -> tuple[np.ndarray, list[str]]:
    """(H, W) int32 room index (0 on no room, k on the k-th room of at least ``min_px``) and
    each room's R3D class (the k-th room is ``classes[k - 1]``)."""
    regions = np.zeros(r3d_labels.shape, np.int32)
    classes: list[str] = []
    for name in ROOM_CLASSES:
        n, cc, stats, _ = cv2.connectedComponentsWithStats(
            (r3d_labels == R3D_ID[name]).astype(np.uint8), connectivity=4
        )
        for k in range(1, n):
            if stats[k, cv2.CC_STAT_AREA] >= min_px:
                classes.append(name)
                regions[cc == k] = len(classes)
    return regions, classes


def names_by_room(regions: np.ndarray, texts: Sequence[TextBox]) -> dict[int, list[TextBox]]:
    """Room index -> the room names of ``texts`` lying on it (``ON_ROOM`` of their box)."""
    named: dict[int, list[TextBox]] = {}
    for text in texts:
        if room_class(text.text) is None:
            continue
        c0, r0, c1, r1 = text.box_px
        under = regions[r0:r1, c0:c1].ravel()
        if not under.size:
            continue
        counts = np.bincount(under)
        counts[0] = 0
        if counts.max() >= ON_ROOM * under.size:
            named.setdefault(int(counts.argmax()), []).append(text)
    return named


def class_at(parsed: ParsedPlan | None, room: np.ndarray) -> str:
    """The parse's room type at the (H, W) bool ``room``: the class most of its instances'
    pixels take, walls, doors, windows and openings left out; background when no other instance
    lies on it, or no parse."""
    if parsed is None:
        return "background"
    class_of = np.full(int(parsed.instance_ids.max()) + 1, -1, np.int64)  # -1: left out
    for inst in parsed.instances:
        class_of[inst.id] = -1 if inst.class_name in NOT_ROOM_TYPES else CLASS_ID[inst.class_name]
    classes = class_of[parsed.instance_ids[room]]
    counts = np.bincount(classes[classes >= 0], minlength=len(CLASS_NAMES))
    return CLASS_NAMES[int(counts.argmax())] if counts.any() else "background"


def acceptable(r3d_class: str, class_name: str) -> bool:
    """Whether f2n_drake's ``class_name`` is acceptable for ``r3d_class``."""
    mask = int(ACCEPTABLE_MASK[R3D_CLASSES.index(r3d_class)])
    return class_name in CLASS_ID and bool(mask >> CLASS_ID[class_name] & 1)


def score_named_rooms(
    r3d_labels: np.ndarray,
    parsed: ParsedPlan | None,
    parse_unread: Callable[[], ParsedPlan | None],
    min_px: int,
) -> list[dict]:
    """One row per named room (of at least ``min_px``): its R3D class, the names read on it,
    the parse's class with names (``parsed``) and without (the plan ``parse_unread`` returns,
    called only when a room is named; None for a refused drawing), and whether each is
    right."""
    if parsed is None:
        return []
    regions, classes = room_regions(r3d_labels, min_px)
    named = names_by_room(regions, parsed.texts)
    unread = parse_unread() if named else None
    rows = []
    for k, texts in sorted(named.items()):
        room = regions == k
        r3d_class = classes[k - 1]
        with_names, without = class_at(parsed, room), class_at(unread, room)
        rows.append(
            {
                "r3d_class": r3d_class,
                "names": [t.text for t in texts],
                "name_classes": [room_class(t.text) for t in texts],
                "confidence": [round(t.confidence, 3) for t in texts],
                "parsed": with_names,
                "without_names": without,
                "right": acceptable(r3d_class, with_names),
                "right_without_names": acceptable(r3d_class, without),
            }
        )
    return rows


def named_rooms_summary(rows: Sequence[dict]) -> dict:
    """``count``, ``accuracy`` and ``accuracy_without_names`` over ``rows`` (None when no room
    is named)."""
    n = len(rows)
    return {
        "count": n,
        "accuracy": sum(r["right"] for r in rows) / n if n else None,
        "accuracy_without_names": sum(r["right_without_names"] for r in rows) / n if n else None,
    }
