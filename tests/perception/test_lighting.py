"""An unevenly lit drawing is lit evenly before it is read; other drawings pass untouched."""

from __future__ import annotations

import cv2
import numpy as np
from helpers import Oracle, two_rooms

from f2n_drake.evaluate.photos import dimmed
from f2n_drake.perception.ink import binarize
from f2n_drake.perception.lighting import MAX_DIMMING, evenly_lit, paper_light
from f2n_drake.pipeline import parse_drawing


def drawing(size: int = 400) -> np.ndarray:
    """Rooms, a door gap and some text-like strokes, anti-aliased, on white paper."""
    img = np.full((size, size), 255, np.uint8)
    cv2.rectangle(img, (40, 40), (size - 40, size - 40), 0, 6)
    cv2.line(img, (size // 2, 40), (size // 2, size // 2 - 30), 0, 4, cv2.LINE_AA)
    cv2.line(img, (size // 2, size // 2 + 30), (size // 2, size - 40), 0, 4, cv2.LINE_AA)
    cv2.line(img, (40, 150), (size // 2, 150), 0, 1, cv2.LINE_AA)
    cv2.putText(img, "Lounge", (80, 260), cv2.FONT_HERSHEY_SIMPLEX, 0.6, 0, 1, cv2.LINE_AA)
    return img


def test_an_evenly_lit_drawing_comes_back_as_it_is():
    img = drawing()
    assert evenly_lit(img) is img
    slightly = dimmed(img, darkest=MAX_DIMMING + 0.05)  # a scan's faint fall-off: left alone
    assert evenly_lit(slightly) is slightly


def test_dimmed_paper_is_white_again_and_the_lines_stay_dark():
    img = drawing()
    shaded = dimmed(img, 0.55)
    assert paper_light(shaded) is not None
    lit = evenly_lit(shaded)
    paper = img == 255
    assert np.abs(lit[paper].astype(int) - 255).max() <= 12  # was down to 140
    assert lit[img == 0].max() <= 40
    assert np.count_nonzero(binarize(lit) != binarize(img)) <= 0.002 * img.size


def test_solid_fills_and_negatives_are_not_taken_for_shadow():
    img = drawing()
    img[60:200, 220:340] = 0  # a solid black block (poché, a title bar) on evenly lit paper
    img[220:340, 60:180] = 200  # a grey room fill
    assert evenly_lit(img) is img
    negative = 255 - dimmed(drawing(), 0.55)
    assert evenly_lit(negative) is negative


def test_a_dimmed_drawing_parses_as_the_evenly_lit_one():
    img, lab = two_rooms(300)
    clean = parse_drawing(img, segmenter=Oracle(lab))
    shaded = parse_drawing(dimmed(img, darkest=0.5), segmenter=Oracle(lab))
    assert [i.class_name for i in shaded.instances] == [i.class_name for i in clean.instances]
    np.testing.assert_array_equal(shaded.instance_ids, clean.instance_ids)
