"""The plans on a sheet are parsed: a legend or a frame beside them is left out."""

from __future__ import annotations

import cv2
import numpy as np

from f2n_drake.core.classes import CLASS_ID
from f2n_drake.perception.ink import binarize, free_marks
from f2n_drake.perception.sheet import find_plan, only_the_plan
from f2n_drake.pipeline import parse_drawing


def plan(img: np.ndarray, x: int, y: int, w: int, h: int) -> None:
    """Draw a three-room plan with thick walls and door gaps at (x, y), w x h px."""
    cv2.rectangle(img, (x, y), (x + w, y + h), 0, 5)
    cv2.line(img, (x + w // 2, y), (x + w // 2, y + h), 0, 4)
    cv2.line(img, (x + w // 2, y + h // 2), (x + w, y + h // 2), 0, 4)
    img[y + h // 4 : y + h // 4 + 20, x + w // 2 - 3 : x + w // 2 + 3] = 255  # door gaps
    img[y + h // 2 - 3 : y + h // 2 + 3, x + 3 * w // 4 : x + 3 * w // 4 + 20] = 255


def legend(img: np.ndarray, x: int, y: int) -> None:
    """A legend box with four lines of words."""
    cv2.rectangle(img, (x, y), (x + 150, y + 110), 0, 1)
    for row in range(4):
        cv2.putText(img, "KEY ITEM", (x + 10, y + 25 + 25 * row), 0, 0.5, 0, 1)


def test_a_legend_beside_the_plan_is_left_out():
    img = np.full((400, 600), 255, np.uint8)
    plan(img, 20, 40, 340, 320)
    legend(img, 420, 40)
    lines = binarize(img)
    found = find_plan(lines)
    r0, r1, c0, c1 = found.box
    assert r0 <= 40 and r1 >= 360 and c0 <= 20 and 360 <= c1 < 420
    assert found.plans == 1 and found.left_out
    kept, _ = only_the_plan(img, lines)
    assert (kept[:, 420:] == 255).all()  # the legend is paper now
    np.testing.assert_array_equal(kept[:, :400], img[:, :400])  # the plan is untouched
    assert "left out" in found.describe()


def test_a_grey_title_bar_beside_the_plan_is_paper_too():
    img = np.full((400, 600), 255, np.uint8)
    plan(img, 20, 70, 340, 320)
    legend(img, 420, 70)
    img[5:30, 5:595] = 200  # a tinted title bar, lighter than ink: never binarised
    cv2.putText(img, "PLAN", (240, 25), 0, 0.6, 255, 2)
    lines = binarize(img)
    kept, found = only_the_plan(img, lines)
    assert found.left_out and found.box[0] > 30 and (kept[:30, :] == 255).all()
    np.testing.assert_array_equal(kept[65:395, 15:365], img[65:395, 15:365])


def test_a_part_of_the_plan_taken_for_a_legend_stays_in_its_box():
    img = np.full((500, 700), 255, np.uint8)
    for y in (20, 130, 240, 350):
        legend(img, 20, y)
    cv2.rectangle(img, (15, 15), (190, 480), 0, 6)  # the legends' column: the largest ink
    plan(img, 300, 260, 340, 200)
    cv2.line(img, (600, 260), (600, 120), 0, 4)  # a wall of the plan runs on up
    # beside it, apart from the rest (a broken outline), a room with words: "a legend"
    cv2.rectangle(img, (300, 80), (560, 248), 0, 3)
    cv2.putText(img, "SHOP", (380, 170), 0, 0.6, 0, 1)
    lines = binarize(img)
    assert free_marks(lines).annotation[80, 400]
    found = find_plan(lines)
    assert found.box[0] <= 80 and found.box[2] > 200
    kept, _ = only_the_plan(img, lines)
    np.testing.assert_array_equal(kept[75:465, 295:645], img[75:465, 295:645])


def test_a_sheet_of_two_plans_parses_both_and_says_so():
    img = np.full((400, 900), 255, np.uint8)
    plan(img, 20, 40, 340, 320)
    plan(img, 440, 100, 220, 200)
    legend(img, 720, 100)
    lines = binarize(img)
    found = find_plan(lines)
    assert found.plans == 2
    r0, r1, c0, c1 = found.box
    assert r0 <= 40 and r1 >= 360 and c0 <= 20 and 660 <= c1 < 720  # both floors, no legend
    assert "2 plans" in found.describe()
    kept, _ = only_the_plan(img, lines)
    np.testing.assert_array_equal(kept[:, :700], img[:, :700])
    assert (kept[:, 720:] == 255).all()


def test_a_frame_round_a_legend_is_no_second_plan():
    img = np.full((400, 700), 255, np.uint8)
    plan(img, 20, 40, 340, 320)
    legend(img, 460, 100)
    cv2.rectangle(img, (440, 60), (640, 300), 0, 5)  # a frame as thick as the walls round it
    found = find_plan(binarize(img))
    assert found.plans == 1 and found.box[3] < 440


def test_a_plan_alone_is_unchanged():
    img = np.full((400, 400), 255, np.uint8)
    plan(img, 20, 40, 340, 320)
    cv2.putText(img, "LOUNGE", (60, 120), 0, 0.5, 0, 1)
    lines = binarize(img)
    kept, found = only_the_plan(img, lines)
    assert kept is img
    assert not found.left_out and found.plans == 1


class _LabelsOfInk:
    """A stub segmenter: living on paper inside the ink's box, wall on ink."""

    def predict(self, image: np.ndarray) -> np.ndarray:
        ink = binarize(image)
        labels = np.zeros(image.shape[:2], np.uint8)
        rows, cols = np.nonzero(ink)
        labels[rows.min() : rows.max() + 1, cols.min() : cols.max() + 1] = CLASS_ID["living"]
        labels[ink] = CLASS_ID["wall"]
        return labels


def test_parse_drawing_says_which_part_of_the_sheet_it_parsed():
    img = np.full((400, 600), 255, np.uint8)
    plan(img, 20, 40, 340, 320)
    legend(img, 420, 40)
    parsed = parse_drawing(img, segmenter=_LabelsOfInk(), reader=None)
    assert "left out" in parsed.sheet_note
    assert not parsed.instance_ids[:, 420:].any()  # no instance in the legend
    alone = parse_drawing(img, segmenter=_LabelsOfInk(), reader=None, leave_out_sheet=False)
    assert alone.sheet_note == ""
