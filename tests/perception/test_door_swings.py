"""A door's swing (arc or open leaf) is found at its gap; a plain gap, or a wall running on from
the jamb, is no swing."""

from __future__ import annotations

import cv2
import numpy as np

from f2n_drake.perception.door_swings import swing_evidence


def wall_with_gap() -> tuple[np.ndarray, np.ndarray]:
    """A 120x120 drawing: a 6 px wall along row 60 with a 24 px gap (columns 50-73), and the
    gap as piece 1."""
    img = np.full((120, 120), 255, np.uint8)
    img[57:63, 5:50] = img[57:63, 74:115] = 0
    pieces = np.zeros(img.shape, np.int32)
    pieces[57:63, 50:74] = 1
    return img, pieces


def swung(img: np.ndarray, pieces: np.ndarray) -> bool:
    return bool(swing_evidence(pieces, img < 128, np.array([False, True]))[1])


def test_an_arc_hinged_at_a_jamb_is_a_swing():
    img, pieces = wall_with_gap()
    cv2.ellipse(img, (50, 56), (24, 24), 0, -90, 0, 0, 1)  # swings up, hinged on the left
    assert swung(img, pieces)
    img, pieces = wall_with_gap()
    cv2.ellipse(img, (73, 63), (24, 24), 0, 90, 180, 0, 1)  # swings down, hinged on the right
    assert swung(img, pieces)


def test_two_half_arcs_are_a_double_door():
    img, pieces = wall_with_gap()
    cv2.ellipse(img, (50, 56), (12, 12), 0, -90, 0, 0, 1)
    cv2.ellipse(img, (73, 56), (12, 12), 0, 180, 270, 0, 1)
    assert swung(img, pieces)


def test_an_open_leaf_is_a_swing():
    img, pieces = wall_with_gap()
    cv2.line(img, (50, 56), (67, 39), 0, 1)  # at 45 degrees, as long as the gap is wide
    assert swung(img, pieces)


def test_a_plain_gap_or_a_wall_from_the_jamb_is_no_swing():
    img, pieces = wall_with_gap()
    assert not swung(img, pieces)
    cv2.line(img, (50, 56), (50, 5), 0, 1)  # a wall running on from the jamb, not a leaf
    assert not swung(img, pieces)
    img, pieces = wall_with_gap()
    img[20:56, 30:95:3] = 0  # hatching beside the gap: ink everywhere, no thin curve
    assert not swung(img, pieces)
