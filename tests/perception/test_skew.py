"""The skew of a drawing laid askew, measured and undone; drawings square or of many angles left."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from f2n_drake.core.paths import REPO_ROOT
from f2n_drake.perception.skew import MAX_SKEW_DEG, MIN_SKEW_DEG, skew_deg, upright

EXAMPLE_PNG = REPO_ROOT / "examples" / "plan.png"


def flat() -> np.ndarray:
    """A 400 px flat: an outer wall 6 px thick, a partition with a door gap, a second room."""
    img = np.full((400, 400), 255, np.uint8)
    cv2.rectangle(img, (40, 40), (360, 360), 0, 6)
    cv2.line(img, (200, 40), (200, 170), 0, 4)
    cv2.line(img, (200, 220), (200, 360), 0, 4)
    cv2.line(img, (40, 250), (200, 250), 0, 4)
    return img


def turned(img: np.ndarray, degrees: float) -> np.ndarray:
    """``img`` turned ``degrees`` counter-clockwise as shown (a page laid askew)."""
    h, w = img.shape[:2]
    matrix = cv2.getRotationMatrix2D((w / 2, h / 2), degrees, 1.0)
    return cv2.warpAffine(img, matrix, (w, h), flags=cv2.INTER_CUBIC, borderValue=255)


@pytest.mark.parametrize("degrees", [-3.0, 1.2, 2.0, 6.5])
def test_the_skew_of_a_drawing_laid_askew_is_measured(degrees):
    assert skew_deg(turned(flat(), degrees)) == pytest.approx(degrees, abs=0.15)


def test_a_square_drawing_or_one_barely_askew_is_left_as_drawn():
    assert skew_deg(flat()) == 0.0
    assert skew_deg(turned(flat(), MIN_SKEW_DEG / 2)) == 0.0
    assert skew_deg(cv2.imread(str(EXAMPLE_PNG), cv2.IMREAD_GRAYSCALE)) == 0.0
    assert skew_deg(np.full((50, 80), 255, np.uint8)) == 0.0  # nothing drawn
    assert skew_deg(turned(flat(), MAX_SKEW_DEG + 4)) == 0.0  # oblique: scanned turned later


def test_a_plan_whose_facade_alone_is_slanted_is_left_as_drawn():
    # the walls along the columns are square; the long top and bottom walls run 3 degrees off
    # the rows: a page laid askew turns both alike, so this is no skew
    img = np.full((400, 400), 255, np.uint8)
    for x in (40, 140, 250, 360):
        cv2.line(img, (x, 40), (x, 360), 0, 5)
    rise = int(round(320 * np.tan(np.radians(3))))
    cv2.line(img, (40, 40 + rise), (360, 40), 0, 5)
    cv2.line(img, (40, 360), (360, 360 - rise), 0, 5)
    assert skew_deg(img) == 0.0


def test_upright_undoes_the_skew_on_a_canvas_holding_all_of_it():
    askew = turned(flat(), 2.0)
    straight = upright(askew, skew_deg(askew))
    h, w = askew.shape
    assert straight.shape[0] > h and straight.shape[1] > w
    assert straight[0, 0] == straight[-1, -1] == 255  # the corners added are paper
    assert skew_deg(straight) == 0.0
    # the partition's door gap runs along a column again: the wall's columns are dark
    dark_cols = np.flatnonzero(
        (straight[60:-60] < 128).sum(axis=0) > 0.5 * (straight.shape[0] - 120)
    )
    assert dark_cols.size >= 2
    colour = cv2.cvtColor(askew, cv2.COLOR_GRAY2BGR)
    assert upright(colour, 2.0).shape == (*straight.shape, 3)
    assert upright(askew, 0.0) is askew
