"""Small drawings are parsed enlarged and the parse lies on the drawing's own grid."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from f2n_drake.core.classes import CLASS_ID, NUM_CLASSES
from f2n_drake.perception.small_drawings import (
    READ_SIDE_PX,
    SMALL_DRAWING_PX,
    enlargement,
    read_at_drawing_size,
)
from f2n_drake.pipeline import parse_drawing
from tests.helpers import Oracle, two_rooms
from tests.perception.test_sheet import legend, plan


class RecordedOracle(Oracle):
    """Fixed labels; records the shape of every drawing it is asked about."""

    def __init__(self, labels: np.ndarray) -> None:
        super().__init__(labels)
        self.shapes: list[tuple[int, ...]] = []

    def predict(self, image: np.ndarray) -> np.ndarray:
        self.shapes.append(image.shape)
        return super().predict(image)


def test_only_drawings_under_the_threshold_are_enlarged_by_a_whole_factor():
    assert enlargement((SMALL_DRAWING_PX, 50)) == 1
    assert enlargement((3000, 2000)) == 1
    assert enlargement((SMALL_DRAWING_PX - 1, 100)) == 2
    assert enlargement((300, 200)) == 2
    assert enlargement((100, 150)) == 4  # the longer side decides: 150 -> 600
    for side in range(16, SMALL_DRAWING_PX):
        factor = enlargement((side, side))
        assert factor >= 2 and side * factor >= READ_SIDE_PX
        assert side * (factor - 1) < READ_SIDE_PX or factor == 2  # the least such factor


def test_the_network_reads_the_drawing_at_its_own_size_and_is_enlarged_after():
    labels = np.zeros((40, 30), np.int64)  # any integer type a segmenter gives
    labels[10:20, 5:15] = CLASS_ID["bedroom"]
    probabilities = np.eye(NUM_CLASSES, dtype=np.float32)[labels].transpose(2, 0, 1)
    asked = []

    def predict(image):
        asked.append(image.shape)
        return labels, probabilities

    big_labels, big_probabilities = read_at_drawing_size(predict, 3)(np.zeros((120, 90), np.uint8))
    assert asked == [(40, 30)]
    assert big_labels.shape == (120, 90) and big_probabilities.shape == (NUM_CLASSES, 120, 90)
    assert big_labels.dtype == labels.dtype
    np.testing.assert_array_equal(big_labels[::3, ::3], labels)
    np.testing.assert_allclose(big_probabilities.sum(axis=0), 1.0, atol=1e-5)
    assert big_probabilities[CLASS_ID["bedroom"], 45, 30] == pytest.approx(1.0)


def test_a_small_drawing_is_parsed_enlarged_onto_its_own_grid():
    img, lab = two_rooms()  # 200 px: enlarged 3 times
    segmenter = RecordedOracle(lab)
    parsed = parse_drawing(img, segmenter=segmenter, metres_per_px=0.05, reader=None)
    assert set(segmenter.shapes) == {img.shape}  # the network saw the drawing as it is
    assert parsed.instance_ids.shape == parsed.labels.shape == img.shape
    assert parsed.grid.metres_per_px == 0.05 and parsed.grid.shape == img.shape
    assert any("parsed enlarged 3 times" in note for note in parsed.drawing_notes)
    assert sorted(i.class_name for i in parsed.instances if i.class_name != "wall") == [
        "bedroom",
        "door",
        "living",
    ]
    own = parse_drawing(img, segmenter=Oracle(lab), metres_per_px=0.05, enlarge_small=False)
    assert own.drawing_notes == ()
    for name in ("living", "bedroom", "door"):
        enlarged_one, own_one = parsed.of_class(name)[0], own.of_class(name)[0]
        # the same room; the lines come back a pixel thicker at most
        assert enlarged_one.area_px == pytest.approx(own_one.area_px, rel=0.1)
        assert np.allclose(enlarged_one.centroid_px, own_one.centroid_px, atol=1.0)
        assert enlarged_one.contour_px.max() <= img.shape[0]


def test_a_sheet_note_gives_rows_and_columns_of_the_drawing_itself():
    img = np.full((250, 399), 255, np.uint8)  # enlarged twice
    plan(img, 10, 20, 200, 200)
    legend(img, 240, 20)
    ink = CLASS_ID["wall"]

    class LabelsOfInk:
        def predict(self, image):
            dark = image < 128
            return np.where(dark, ink, CLASS_ID["living"]).astype(np.uint8)

    parsed = parse_drawing(img, segmenter=LabelsOfInk(), reader=None)
    assert "left out" in parsed.sheet_note
    rows, cols = parsed.sheet_note.split("rows ")[1].split(";")[0].split(", columns ")
    r1, c1 = int(rows.split("-")[1]), int(cols.split("-")[1])
    assert 220 <= r1 < 250 and 210 <= c1 < 240  # the plan's box, not the enlarged drawing's


def test_a_thin_lined_thumbnail_keeps_its_rooms_apart_at_the_door():
    """A listing shrunk to a thumbnail: walls two pixels thick, a door gap 9 px wide."""
    img = np.full((150, 220), 255, np.uint8)
    cv2.rectangle(img, (10, 10), (209, 139), 0, 2)
    cv2.line(img, (110, 10), (110, 60), 0, 2)
    cv2.line(img, (110, 70), (110, 139), 0, 2)  # a door gap at rows 61-69
    lab = np.full(img.shape, CLASS_ID["living"], np.uint8)
    lab[:, 111:] = CLASS_ID["bedroom"]
    lab[img < 128] = CLASS_ID["wall"]
    lab[61:70, 108:114] = CLASS_ID["door"]
    parsed = parse_drawing(img, segmenter=Oracle(lab), reader=None)
    assert sorted(i.class_name for i in parsed.instances) == ["bedroom", "door", "living"]
    door = parsed.of_class("door")[0]
    assert 60 <= door.centroid_px[1] <= 70 and 105 <= door.centroid_px[0] <= 115
