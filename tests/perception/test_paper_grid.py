"""A drawing on squared paper loses the paper's grid; the drawing's own lines stay."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from f2n_drake.core.classes import CLASS_ID
from f2n_drake.perception.ink import binarize, enclosed_by
from f2n_drake.perception.paper_grid import without_paper_grid
from f2n_drake.pipeline import parse_drawing

FILL = 215  # a room's light grey fill
GRID = 190  # the squared paper's printed lines


def drawing(size: int = 300) -> np.ndarray:
    """Two rooms between black walls, the right one filled grey, a light pencil stroke (a
    door's arc) and a door gap in the wall between them."""
    img = np.full((size, size), 255, np.uint8)
    img[38 : size - 38, size // 2 : size - 38] = FILL
    cv2.rectangle(img, (36, 36), (size - 36, size - 36), 0, 6)
    cv2.line(img, (size // 2, 36), (size // 2, size // 2 - 10), 0, 5)
    cv2.line(img, (size // 2, size // 2 + 10), (size // 2, size - 36), 0, 5)
    cv2.ellipse(img, (size // 2, size // 2 - 10), (20, 20), 0, 90, 180, 150, 1)
    return img


def on_squared_paper(img: np.ndarray, spacing: int = 10, grey: int = GRID) -> np.ndarray:
    """``img`` printed over a grid ``spacing`` px apart, one pixel wide, ``grey`` dark."""
    grid = np.full(img.shape, 255, np.uint8)
    grid[::spacing] = grey
    grid[:, ::spacing] = grey
    return np.minimum(img, grid)


def rooms(grey: np.ndarray) -> int:
    """Regions of paper the ink encloses, at least 50 px large."""
    n, regions = cv2.connectedComponents(enclosed_by(binarize(grey)).astype(np.uint8), 4)
    return int(np.count_nonzero(np.bincount(regions.ravel())[1:] >= 50))


def test_the_grid_goes_and_the_drawing_stays():
    plain = drawing()
    gridded = on_squared_paper(plain)
    assert rooms(gridded) > 50  # every square a room
    cleaned = without_paper_grid(gridded)
    assert rooms(cleaned) == rooms(plain) == 1  # the two rooms, joined at their door gap
    off = np.abs(cleaned.astype(int) - plain.astype(int))
    assert np.mean(off > 20) < 0.002  # grid crossings beside the drawing's lines at most
    walls = plain < 100
    assert (cleaned[walls] < 100).all()  # the walls, grid lines along them included
    arc = plain == 150
    assert np.mean(cleaned[arc] <= 160) > 0.95  # a light stroke crossing the grid stays


def test_ruled_paper_loses_its_lines_too():
    plain = drawing()
    ruled = plain.copy()
    ruled[::10] = np.minimum(ruled[::10], GRID)  # lines along the rows only
    cleaned = without_paper_grid(ruled)
    assert np.mean(np.abs(cleaned.astype(int) - plain.astype(int)) > 20) < 0.002


def test_drawings_without_a_grid_come_back_as_they_are():
    plain = drawing()
    assert without_paper_grid(plain) is plain
    few = plain.copy()
    few[[10, 20, 30]] = GRID  # three long light lines are no grid
    assert without_paper_grid(few) is few
    ruled = on_squared_paper(plain, grey=0)  # lines as dark as the walls are the drawing's own
    assert without_paper_grid(ruled) is ruled


class FixedLabels:
    """A segmenter that labels the two rooms of :func:`drawing` whatever it is shown."""

    def __init__(self, shape: tuple[int, int]) -> None:
        h, w = shape
        self.labels = np.zeros(shape, np.uint8)
        self.labels[40 : h - 40, 40 : w // 2] = CLASS_ID["living"]
        self.labels[40 : h - 40, w // 2 : w - 40] = CLASS_ID["bedroom"]
        self.labels[binarize(drawing()) & (self.labels > 0)] = CLASS_ID["wall"]
        self.labels[h // 2 - 10 : h // 2 + 10, w // 2 - 3 : w // 2 + 3] = CLASS_ID["door"]

    def predict(self, image: np.ndarray) -> np.ndarray:
        return self.labels.copy()


@pytest.mark.usefixtures("drawings_at_own_size")
def test_the_network_sees_a_plan_sketched_on_squared_paper_as_on_plain_paper():
    plain = drawing()
    gridded = on_squared_paper(plain)
    segmenter = FixedLabels(plain.shape)
    shown = []

    def parse(image: np.ndarray, **options):
        original = segmenter.predict
        segmenter.predict = lambda drawing: shown.append(drawing) or original(drawing)
        try:
            return parse_drawing(image, segmenter=segmenter, reader=None, **options)
        finally:
            segmenter.predict = original

    as_drawn = parse(plain)
    assert sorted(i.class_name for i in as_drawn.instances) == ["bedroom", "door", "living"]
    assert as_drawn.drawing_notes == ()
    on_grid = parse(gridded)
    assert any("printed lines painted out" in note for note in on_grid.drawing_notes)
    assert np.mean((on_grid.instance_ids > 0) != (as_drawn.instance_ids > 0)) < 0.001
    assert np.mean(np.abs(shown[-1].astype(int) - shown[0].astype(int)) > 20) < 0.002
    parse(gridded, paper_grid=False)
    assert np.mean(np.abs(shown[-1].astype(int) - shown[0].astype(int)) > 20) > 0.1
