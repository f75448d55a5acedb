"""A page photographed at an angle is found and squared; drawings, sheets and negatives are not
taken for one."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from test_lighting import drawing

from f2n_drake.evaluate.photos import photographed
from f2n_drake.perception.page import MAX_SIDE_PX, find_page, squared_page


def test_a_photographed_page_is_found_at_its_corners_and_squared():
    img = drawing()
    photo, to_photo = photographed(img)
    page = find_page(photo)
    assert page is not None
    pad = round(0.08 * 400)
    side = 400 + 2 * pad  # the page: the drawing and its white margin
    truth = cv2.perspectiveTransform(
        np.float32([[[0, 0], [side, 0], [side, side], [0, side]]]) - pad, to_photo
    )[0]
    assert np.abs(page.corners - truth).max() <= 0.02 * max(photo.shape)
    squared, found = squared_page(photo)
    assert found is not None and squared.shape == (page.size[1], page.size[0])
    assert abs(page.size[0] / page.size[1] - 1) < 0.1  # the square page comes back square
    # the drawing's frame, a 6 px black square, is straight again: dark along the rows at its
    # top and bottom edges, which a perspective would slant
    sy, sx = squared.shape[0] / side, squared.shape[1] / side
    rows = [round((pad + 40) * sy), round((pad + 360) * sy)]
    cols = slice(round((pad + 60) * sx), round((pad + 340) * sx))
    for row in rows:
        band = squared[row - 3 : row + 4, cols].min(axis=0)
        assert np.mean(band < 128) > 0.95


def test_colour_photos_are_squared_in_colour():
    photo, _ = photographed(drawing())
    colour = cv2.cvtColor(photo, cv2.COLOR_GRAY2BGR)
    squared, page = squared_page(colour)
    assert page is not None and squared.ndim == 3 and squared.shape[2] == 3


@pytest.mark.parametrize(
    "kind", ["drawing", "negative", "sheet", "page off the edge", "blank", "upright on dark"]
)
def test_what_is_no_photographed_page_comes_back_unchanged(kind):
    img = drawing()
    if kind == "negative":
        img = 255 - img
    elif kind == "sheet":  # a small plan on a big sheet: its paper runs to every border
        img = cv2.copyMakeBorder(img, 200, 200, 300, 300, cv2.BORDER_CONSTANT, value=255)
    elif kind == "page off the edge":  # the photo cuts the page's corners off
        photo, _ = photographed(img)
        h, w = photo.shape
        img = np.ascontiguousarray(photo[h // 5 : h - h // 5, w // 5 : w - w // 5])
    elif kind == "upright on dark":  # a house's floor on its lawn, a scan on a dark bed
        img = cv2.copyMakeBorder(img, 60, 60, 60, 60, cv2.BORDER_CONSTANT, value=90)
    elif kind == "blank":
        img = np.full((300, 300), 255, np.uint8)
    squared, page = squared_page(img)
    assert page is None and squared is img


def test_a_page_turned_far_keeps_its_corners_apart():
    photo, _ = photographed(drawing())
    h, w = photo.shape
    side = int(1.5 * max(h, w))
    table = np.full((side, side), 90, np.uint8)
    table[(side - h) // 2 : (side - h) // 2 + h, (side - w) // 2 : (side - w) // 2 + w] = photo
    turned = cv2.warpAffine(
        table, cv2.getRotationMatrix2D((side / 2, side / 2), 40, 1.0), (side, side), borderValue=90
    )
    page = find_page(turned)
    assert page is not None
    assert (
        min(
            np.linalg.norm(a - b) for i, a in enumerate(page.corners) for b in page.corners[i + 1 :]
        )
        > 100
    )
    assert abs(page.size[0] / page.size[1] - 1) < 0.15


def test_a_large_photo_is_squared_to_at_most_the_working_size():
    photo, _ = photographed(drawing())
    large = cv2.resize(photo, None, fx=5, fy=5, interpolation=cv2.INTER_LINEAR)
    squared, page = squared_page(large)
    assert page is not None and max(page.size) == MAX_SIDE_PX
    assert squared.shape == (page.size[1], page.size[0])


def test_a_page_on_a_wooden_table_is_found_on_the_picture_s_plain_grey(tmp_path):
    from f2n_drake.perception.image import load_image, plain_grey

    photo, _ = photographed(drawing())
    picture = cv2.cvtColor(photo, cv2.COLOR_GRAY2BGR)
    picture[np.abs(photo.astype(int) - 90) <= 8] = (40, 90, 150)  # brown, where the table is
    cv2.imwrite(str(tmp_path / "photo.png"), picture)
    grey = load_image(tmp_path / "photo.png")  # its coloured marks made paper: the table too
    assert squared_page(grey)[1] is None
    squared, page = squared_page(grey, luminance=plain_grey(tmp_path / "photo.png", grey.shape))
    assert page is not None and squared.shape == (page.size[1], page.size[0])
