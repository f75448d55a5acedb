"""A drawing lying on its side or upside down is turned upright by its words (the OCR model
runs: slow)."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from f2n_drake.perception.orientation import quarter_turns, turned

WORDS = ("KITCHEN", "BEDROOM 2", "4.50 x 2.08m", "LIVING ROOM", "BATHROOM", "GROUND FLOOR")


def page_of_words(words=WORDS) -> np.ndarray:
    """A 420 x 360 px page with one line of words per row, along the rows."""
    page = np.full((420, 360), 255, np.uint8)
    for k, word in enumerate(words):
        cv2.putText(page, word, (30, 50 + 60 * k), cv2.FONT_HERSHEY_SIMPLEX, 0.9, 0, 2)
    return page


def test_quarter_turns_are_exact():
    page = np.arange(12, dtype=np.uint8).reshape(3, 4)
    assert np.array_equal(turned(turned(page, 1), 3), page)
    assert turned(page, 1).shape == (4, 3) and turned(page, 1).flags.c_contiguous


@pytest.mark.slow
@pytest.mark.parametrize("lying", [1, 2, 3])
def test_a_page_on_its_side_or_upside_down_is_turned_back_upright(lying):
    page = page_of_words()
    scanned = turned(page, lying)
    back = quarter_turns(scanned)
    assert back == 4 - lying
    assert np.array_equal(turned(scanned, back), page)


@pytest.mark.slow
def test_an_upright_page_a_wordless_one_and_a_mixed_one_stay_as_they_lie():
    page = page_of_words()
    assert quarter_turns(page) == 0
    assert quarter_turns(np.full((300, 300), 255, np.uint8)) == 0
    # dimension chains written up the sides of a plan whose names run along its rows
    mixed = np.full((420, 780), 255, np.uint8)
    mixed[:, :360] = page
    mixed[:360, 360:] = turned(page_of_words(WORDS[:3] + ("3.20m", "1.10m", "2.75m")), 1)
    assert quarter_turns(mixed) == 0


@pytest.mark.slow
def test_a_negative_on_its_side_is_turned_too():
    assert quarter_turns(255 - turned(page_of_words(), 3)) == 1
