"""Floors painted with planks or tiles become plain fills; the drawing's own lines stay."""

from __future__ import annotations

import cv2
import numpy as np

from f2n_drake.perception.floor_textures import without_floor_textures
from f2n_drake.perception.ink import binarize, enclosed_by

FILL = 200  # a light wood's grey
PLANK = 165  # its planks' edges: faint against it


def drawing(size: int = 400) -> np.ndarray:
    """Two rooms filled grey between black walls, a door gap, a name and a door's arc."""
    img = np.full((size, size), 255, np.uint8)
    img[44 : size - 44, 44 : size - 44] = FILL
    cv2.rectangle(img, (40, 40), (size - 40, size - 40), 0, 8)
    cv2.line(img, (size // 2, 40), (size // 2, size // 2 - 30), 0, 6)
    cv2.line(img, (size // 2, size // 2 + 30), (size // 2, size - 40), 0, 6)
    cv2.ellipse(img, (size // 2, size // 2 - 30), (60, 60), 0, 90, 180, 0, 1, cv2.LINE_AA)
    cv2.putText(img, "Lounge", (80, 300), cv2.FONT_HERSHEY_SIMPLEX, 0.7, 0, 2, cv2.LINE_AA)
    return img


def rooms(ink: np.ndarray, min_px: int = 100) -> int:
    """Regions of paper the ink encloses, at least ``min_px`` large."""
    n, regions = cv2.connectedComponents(enclosed_by(ink).astype(np.uint8), connectivity=4)
    return int(np.count_nonzero(np.bincount(regions.ravel())[1:] >= min_px))


def planked(img: np.ndarray, spacing: int = 7, value: int = PLANK) -> np.ndarray:
    """``img`` with plank edges every ``spacing`` px across its fill."""
    out = img.copy()
    rows = np.zeros(img.shape, bool)
    rows[::spacing] = True
    out[rows & (img == FILL)] = value
    return out


def tiled(img: np.ndarray, paper: int, spacing: int = 10, value: int = PLANK) -> np.ndarray:
    """``img`` with a tile grid every ``spacing`` px on the pixels of grey ``paper``."""
    out = img.copy()
    grid = np.zeros(img.shape, bool)
    grid[::spacing] = True
    grid[:, ::spacing] = True
    out[grid & (img == paper)] = value
    return out


def test_planks_become_their_fill_and_the_rooms_close_as_drawn():
    plain = drawing()
    textured = planked(plain)
    assert np.count_nonzero(binarize(textured) & ~binarize(plain)) > 10_000  # each plank is ink
    cleaned = without_floor_textures(textured)
    ink, drawn = binarize(cleaned), binarize(plain)
    beside_lines = cv2.dilate(drawn.astype(np.uint8), np.ones((7, 7), np.uint8)) > 0
    assert np.count_nonzero((ink != drawn) & ~beside_lines) <= 5  # stubs where planks met lines
    assert rooms(ink) == rooms(drawn) == 1  # the two rooms meet at the door's gap
    walls_and_name = plain < 100
    assert np.array_equal(cleaned[walls_and_name], plain[walls_and_name])
    planks = textured != plain
    assert np.mean(np.abs(cleaned[planks].astype(int) - FILL) <= 6) >= 0.95  # all but stubs


def test_tiles_on_a_tinted_floor_go_too():
    plain = drawing()
    textured = tiled(plain, FILL, spacing=12)
    assert rooms(binarize(textured)) > 100  # every tile a room
    assert rooms(binarize(without_floor_textures(textured))) == 1


def test_drawings_without_a_textured_floor_come_back_as_they_are():
    plain = drawing()
    assert without_floor_textures(plain) is plain
    white = np.where(plain == FILL, 255, plain).astype(np.uint8)
    tiles_on_white = tiled(white, 255)  # or a wall's hatching: white paper is left alone
    assert without_floor_textures(tiles_on_white) is tiles_on_white
    negative = 255 - planked(plain)
    assert without_floor_textures(negative) is negative


def test_a_halftone_grey_and_a_few_grey_lines_are_no_texture():
    plain = drawing()
    halftone = plain.copy()
    diagonal = (np.add.outer(np.arange(400), np.arange(400)) % 3) == 0  # R3D's terrace grey
    halftone[diagonal & (plain == FILL)] = 150
    assert without_floor_textures(halftone) is halftone
    lines = plain.copy()
    for y in (120, 180, 260):  # furniture's or dimensions' grey lines, far apart
        lines[y, 60:180] = PLANK
    assert without_floor_textures(lines) is lines


def test_light_hairlines_on_a_page_lit_a_little_unevenly_are_the_drawing():
    size = 400
    hairlines = np.full((size, size), 255, np.uint8)
    for x in range(40, size - 40, 12):  # offices in light-grey one-pixel lines, close together
        hairlines[40 : size - 40, x] = 170
    for y in (40, size // 2, size - 41):
        hairlines[y, 40 : size - 40] = 170
    cv2.putText(hairlines, "101", (60, 100), cv2.FONT_HERSHEY_SIMPLEX, 0.6, 0, 2)
    light = np.linspace(1.0, 0.87, size)[None, :]  # too little for lighting.evenly_lit
    dim = (hairlines * light).round().astype(np.uint8)
    assert without_floor_textures(dim) is dim
