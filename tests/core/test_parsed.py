"""Instances of a parse as polygons in metres, thin ones included."""

from __future__ import annotations

import numpy as np

from f2n_drake.core.parsed import Instance, ParsedPlan
from f2n_drake.core.raster import PixelGrid


def instance(contour_px: list[tuple[int, int]], area_px: int) -> Instance:
    return Instance(
        id=1,
        class_name="door",
        contour_px=np.array(contour_px, np.int32).reshape(-1, 2),
        area_px=area_px,
        centroid_px=(0.0, 0.0),
    )


def test_a_thin_instance_is_the_box_of_its_pixels():
    grid = PixelGrid.from_scale(0.01, (100, 100))
    for contour, area in (([(5, 5)], 1), ([(5, 5), (5, 8)], 4)):
        poly = instance(contour, area).polygon_m(grid)
        assert poly.is_valid and abs(poly.area - area * 1e-4) < 1e-12


def test_a_room_keeps_its_outline():
    grid = PixelGrid.from_scale(0.01, (100, 100))
    poly = instance([(10, 10), (10, 40), (50, 40), (50, 10)], 30 * 40).polygon_m(grid)
    assert abs(poly.area - 0.30 * 0.40) < 1e-9


def test_an_instance_without_a_contour_is_an_empty_polygon():
    assert instance([], 0).polygon_m(PixelGrid.from_scale(0.01, (10, 10))).is_empty


def test_a_plans_boxes_are_its_instances_bounding_boxes_found_once():
    ids = np.zeros((6, 8), np.int32)
    ids[1:3, 2:5] = 1
    ids[4, 7] = 3  # id 2 holds no pixel
    plan = ParsedPlan(ids, np.zeros_like(ids, np.uint8), [])
    boxes = plan.boxes()
    assert boxes == [(slice(1, 3), slice(2, 5)), None, (slice(4, 5), slice(7, 8))]
    assert plan.boxes() is boxes
