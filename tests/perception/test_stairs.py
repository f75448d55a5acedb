"""A flight of stairs drawn in a room makes it circulation; tiles and furniture do not."""

from __future__ import annotations

import dataclasses

import cv2
import numpy as np
import pytest
from helpers import Oracle, two_rooms

from f2n_drake.perception.ink import binarize
from f2n_drake.perception.stairs import holds_flight, stairs_are_circulation
from f2n_drake.pipeline import parse_drawing


def room_with(draw) -> tuple[np.ndarray, np.ndarray]:
    """(room paper, ink) of a 60 x 100 px room whose outline is ink, with ``draw(ink)`` in it."""
    ink = np.zeros((60, 100), bool)
    ink[0, :] = ink[-1, :] = ink[:, 0] = ink[:, -1] = True
    draw(ink)
    return ~ink, ink


def flight(ink: np.ndarray, treads: int = 8, step: int = 6) -> None:
    """Treads across rows 15..45, ``step`` px apart from column 20, and the flight's two sides."""
    for k in range(treads):
        ink[15:46, 20 + k * step] = True
    ink[15, 20 : 20 + (treads - 1) * step + 1] = True
    ink[45, 20 : 20 + (treads - 1) * step + 1] = True


def test_a_flight_is_found_along_rows_or_columns():
    assert holds_flight(*room_with(flight))
    paper, ink = room_with(flight)
    assert holds_flight(paper.T.copy(), ink.T.copy())


@pytest.mark.parametrize(
    "draw",
    [
        lambda ink: flight(ink, treads=4),  # too few treads: a shelf, a radiator
        lambda ink: [ink.__setitem__((slice(15, 46), c), True) for c in (20, 26, 40, 70, 74)],
        lambda ink: [  # tiles: lines both ways
            ink.__setitem__(idx, True)
            for k in range(1, 12)
            for idx in ((slice(None), 8 * k), (5 * k, slice(None)))
        ],
        lambda ink: ink.__setitem__((slice(20, 40), slice(30, 60)), True),  # a solid block
    ],
    ids=["four treads", "uneven lines", "tiles", "solid"],
)
def test_other_ink_is_no_flight(draw):
    assert not holds_flight(*room_with(draw))


def test_a_bathroom_or_bedroom_holding_a_flight_becomes_circulation():
    img, lab = two_rooms(300)
    parsed = parse_drawing(img, segmenter=Oracle(lab))
    ids = parsed.instance_ids
    bedroom = next(i for i in parsed.instances if i.class_name == "bedroom")
    rows, cols = np.nonzero(ids == bedroom.id)
    r0, c0 = rows.min() + 40, cols.min() + 20
    drawn = img.copy()
    for k in range(8):  # treads in the bedroom, and the flight's sides
        drawn[r0 : r0 + 60, c0 + 6 * k] = 0
    drawn[r0, c0 : c0 + 43] = drawn[r0 + 59, c0 : c0 + 43] = 0
    lines = binarize(drawn)
    stairs = stairs_are_circulation(parsed, lines, drawn)
    classes = {i.id: i.class_name for i in stairs.instances}
    assert classes[bedroom.id] == "living"
    colour = cv2.cvtColor(drawn, cv2.COLOR_GRAY2BGR)  # the parse steps take colour drawings too
    assert stairs_are_circulation(parsed, lines, colour).instances == stairs.instances
    assert stairs_are_circulation(parsed, binarize(img), img) is parsed  # no flight: unchanged
    kitchen = dataclasses.replace(
        parsed,
        instances=[
            dataclasses.replace(i, class_name="kitchen") if i.id == bedroom.id else i
            for i in parsed.instances
        ],
    )
    assert stairs_are_circulation(kitchen, lines, drawn) is kitchen  # an open kitchen may hold one
