"""Fine drawings are parsed shrunk and the parse lies on the drawing's own grid."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from f2n_drake.core.classes import CLASS_ID
from f2n_drake.core.parsed import ParsedPlan, instance_from_mask
from f2n_drake.core.raster import PixelGrid
from f2n_drake.core.text import TextBox
from f2n_drake.perception.fine_drawings import (
    FINE_PLAN_PX,
    READ_PLAN_PX,
    on_drawing_grid,
    reduction,
)
from f2n_drake.pipeline import parse_drawing
from tests.helpers import two_rooms


def walls(side: int, rooms: int, stroke: int) -> np.ndarray:
    """Ink of a square plan ``side`` px across cut into ``rooms`` x ``rooms`` rooms by walls
    ``stroke`` px thick."""
    lines = np.zeros((side, side), bool)
    for k in np.linspace(0, side - stroke, rooms + 1).astype(int):
        lines[k : k + stroke, :] = lines[:, k : k + stroke] = True
    return lines


def test_only_plans_longer_than_the_threshold_are_shrunk_to_the_read_length():
    box = (0, 2400, 0, 2400)
    assert reduction(walls(2400, 2, 12), box) == pytest.approx(2400 / READ_PLAN_PX)
    small = walls(FINE_PLAN_PX, 2, 12)
    assert reduction(small, (0, FINE_PLAN_PX, 0, FINE_PLAN_PX)) == 1.0
    # a small plan on a large sheet: its box decides
    sheet = np.zeros((2400, 2400), bool)
    sheet[100:1100, 100:1100] = walls(1000, 2, 12)
    assert reduction(sheet, (90, 1110, 90, 1110)) == 1.0


def test_lines_and_rooms_are_never_shrunk_below_their_least_widths():
    box = (0, 2400, 0, 2400)
    assert reduction(walls(2400, 2, 1), box) == 1.0  # hairlines stay as drawn
    assert reduction(walls(2400, 2, 2), box) == pytest.approx(2.0)  # 2 px lines become 1
    # a building of 36 x 36 rooms, about 60 px wide: shrunk only to rooms 40 px wide
    factor = reduction(walls(2400, 36, 6), box)
    assert 1.3 < factor < 1.7


def test_a_parse_on_the_shrunk_drawing_is_brought_back_onto_its_grid():
    ids = np.zeros((50, 80), np.int32)
    ids[10:30, 20:60] = 7
    labels = np.where(ids == 7, CLASS_ID["bedroom"], 0).astype(np.uint8)
    room = instance_from_mask(7, "bedroom", ids == 7, labels)
    text = TextBox("Bedroom", 0.9, (25, 15, 40, 20), instance_id=7)
    grid = PixelGrid.from_scale(0.04, ids.shape)
    parsed = ParsedPlan(ids, labels, [room], grid, texts=[text], door_outline_px=2.0)
    back = on_drawing_grid(parsed, (100, 160))
    assert back.instance_ids.shape == back.labels.shape == (100, 160)
    (inst,) = back.instances
    assert inst.area_px == 4 * room.area_px == np.count_nonzero(back.instance_ids == 7)
    assert inst.centroid_px == pytest.approx((79.5, 39.5))
    assert inst.votes == {CLASS_ID["bedroom"]: 4 * room.area_px}
    # outlines through the centres of the blocks the shrunk pixels became
    assert inst.contour_px.min(axis=0) == pytest.approx((40.5, 20.5))
    assert inst.contour_px.max(axis=0) == pytest.approx((118.5, 58.5))
    assert back.texts[0].box_px == (50, 30, 80, 40) and back.texts[0].instance_id == 7
    assert back.grid.metres_per_px == 0.02 and back.grid.shape == (100, 160)
    assert back.door_outline_px == 4.0
    assert on_drawing_grid(parsed, ids.shape) is parsed


class ResizingOracle:
    """Fixed labels, resized to the drawing it is asked about; records the drawings' shapes."""

    def __init__(self, labels: np.ndarray) -> None:
        self.labels = labels
        self.shapes: list[tuple[int, ...]] = []

    def predict(self, image: np.ndarray) -> np.ndarray:
        self.shapes.append(image.shape)
        height, width = image.shape[:2]
        return cv2.resize(self.labels, (width, height), interpolation=cv2.INTER_NEAREST)


def test_a_fine_drawing_is_parsed_shrunk_onto_its_own_grid():
    img, lab = two_rooms()  # 200 px, 1 px lines
    fine = cv2.resize(img, None, fx=13, fy=13, interpolation=cv2.INTER_NEAREST)  # 13 px lines
    truth = cv2.resize(lab, None, fx=13, fy=13, interpolation=cv2.INTER_NEAREST)
    segmenter = ResizingOracle(truth)
    parsed = parse_drawing(fine, segmenter=segmenter, metres_per_px=0.004, reader=None)
    assert all(max(shape) < 1300 for shape in segmenter.shapes)  # the network saw it shrunk
    assert any("parsed shrunk" in note for note in parsed.drawing_notes)
    assert parsed.instance_ids.shape == parsed.labels.shape == fine.shape
    assert parsed.grid.metres_per_px == pytest.approx(0.004, rel=0.01)
    assert parsed.grid.shape == fine.shape
    names = sorted(i.class_name for i in parsed.instances if i.class_name != "wall")
    assert names == ["bedroom", "door", "living"]
    for name in ("living", "bedroom"):
        (inst,) = parsed.of_class(name)
        drawn = np.count_nonzero(truth == CLASS_ID[name])
        assert inst.area_px == pytest.approx(drawn, rel=0.05)
        assert inst.area_px == np.count_nonzero(parsed.instance_ids == inst.id)
