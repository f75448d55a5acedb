"""Hatched walls: found by their diagonal grain, made ink for the instances at any resolution."""

from __future__ import annotations

import json

import cv2
import numpy as np
import pytest
from helpers import InkModel

from f2n_drake.core.classes import CLASS_ID
from f2n_drake.core.errors import run_cli
from f2n_drake.evaluate import hatching as hatching_cli
from f2n_drake.perception.hatching import hatched_walls, with_hatch_cells
from f2n_drake.perception.ink import binarize
from f2n_drake.perception.instances import extract_instances
from f2n_drake.perception.preparation import solid_hatching
from f2n_drake.segmenter.inference import Segmenter


def rooms_with_walls(side: int, wall: int, rooms: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """``rooms`` x ``rooms`` square rooms, walls ``wall`` px thick: (walls, rooms) masks."""
    band = np.zeros((side, side), bool)
    for k in np.linspace(0, side - wall, rooms + 1).astype(int):
        band[k : k + wall, :] = True
        band[:, k : k + wall] = True
    return band, ~band


def drawn(band: np.ndarray, step: int = 0, mirrored: bool = False) -> np.ndarray:
    """The walls outlined 1 px thick and, if ``step``, hatched with 45-degree lines that far
    apart (along a row)."""
    outline = band & ~cv2.erode(band.astype(np.uint8), np.ones((3, 3), np.uint8)).astype(bool)
    ink = outline
    if step:
        rows, cols = np.mgrid[0 : band.shape[0], 0 : band.shape[1]]
        ink = ink | (band & (((cols + rows) if mirrored else (cols - rows)) % step == 0))
    return np.where(ink, 0, 255).astype(np.uint8)


@pytest.mark.parametrize("mirrored", [False, True])
def test_hatching_is_found_by_its_diagonal_grain(mirrored):
    band, _ = rooms_with_walls(240, 8)
    hatched = drawn(band, step=3, mirrored=mirrored)
    walls = hatched_walls(hatched, binarize(hatched))
    assert walls is not None and walls[band].mean() > 0.9 and not walls[~band].any()
    plain = drawn(band)
    assert hatched_walls(plain, binarize(plain)) is None  # outlines: no thick ink
    filled = np.where(band, 0, 255).astype(np.uint8)
    assert hatched_walls(filled, binarize(filled)) is None  # thick, but no grain


def test_a_large_hatched_drawing_has_no_instance_per_hatching_cell():
    band, rooms = rooms_with_walls(1200, 24)  # shrunk to 512 px: walls 10 px, lines 4 px apart
    hatched = drawn(band, step=9)
    ink = binarize(hatched)
    assert ink[band].mean() > 0.97 and not ink[rooms].any()  # the cells are ink, rooms paper
    labels = np.where(band, CLASS_ID["wall"], CLASS_ID["living"]).astype(np.uint8)
    parsed = extract_instances(hatched, labels, split=None)
    assert len(parsed.instances) == 9  # the rooms, not hundreds of cells


@pytest.mark.parametrize(
    "side, wall, step",  # at 512 px: walls 10, 10 and 6 px thick, hatching 4, 5.5 and 3 px apart
    [(1200, 24, 9), (1200, 24, 13), (512, 6, 3)],
)
def test_a_window_in_a_hatched_wall_stays_open(side, wall, step):
    band, rooms = rooms_with_walls(side, wall)
    window = np.zeros_like(band)
    window[0:wall, 150:300] = True  # in the top wall: outlined, not hatched
    hatched = drawn(band & ~window, step=step)
    cv2.rectangle(hatched, (150, 0), (299, wall - 1), 0, 1)
    ink = binarize(hatched)
    inside = np.zeros_like(band)
    inside[2 : wall - 2, 152:298] = True
    assert not ink[inside].any()  # the window's box is paper
    assert ink[band & ~window].mean() > 0.97  # the hatching's cells are ink


def test_drawings_without_hatching_keep_their_ink():
    band, _ = rooms_with_walls(1200, 24)
    for drawing in (drawn(band), np.where(band, 0, 255).astype(np.uint8)):
        ink = drawing < 128
        assert with_hatch_cells(drawing, ink, lambda small: small < 128) is ink


@pytest.mark.parametrize("mirrored", [False, True])
def test_the_network_sees_hatched_walls_filled_solid(mirrored):
    band, rooms = rooms_with_walls(240, 8)
    drawing = drawn(band, step=3, mirrored=mirrored)
    assert (drawing[band] < 128).mean() < 0.7  # stripes: a third to a half of the wall is paper
    solid = solid_hatching(drawing)
    assert (solid[band] < 128).mean() > 0.97
    np.testing.assert_array_equal(solid[rooms], drawing[rooms])  # the rooms stay paper
    labels = Segmenter(InkModel(), input_size=240).predict(drawing)  # InkModel: 1 on ink
    assert labels[band].mean() > 0.97 and not labels[rooms].any()


def test_the_network_sees_unhatched_walls_as_drawn():
    band, _ = rooms_with_walls(240, 8)
    outline = drawn(band)
    filled = np.where(band, 0, 255).astype(np.uint8)
    rng = np.random.default_rng(0)
    for drawing in (
        outline,
        filled,
        np.where(band, 90, 255).astype(np.uint8),  # filled in grey
        cv2.GaussianBlur(outline, (5, 5), 1.0),  # blurred
        np.clip(filled + rng.normal(0, 12, band.shape), 0, 255).astype(np.uint8),  # noisy
    ):
        assert solid_hatching(drawing) is drawing


def test_thin_lines_that_look_hatched_are_shown_as_drawn():
    # Two close 1 px lines at 40 degrees (a door leaf beside its arc) are the only wall band of
    # a thin-lined drawing, and their grain is diagonal; but no ink is thick enough to fill.
    band, _ = rooms_with_walls(240, 8)
    drawing = drawn(band)
    cv2.line(drawing, (100, 100), (118, 115), 0, 1)
    cv2.line(drawing, (97, 104), (115, 119), 0, 1)
    assert hatched_walls(drawing, binarize(drawing)) is not None
    assert solid_hatching(drawing) is drawing


def test_the_hatching_cli_finds_hatched_walls_only_where_drawn(capsys):
    args = ["--synthetic", "3", "--seed", "5", "--json"]
    hatching_cli.main([*args, "--look", "hatched"])
    hatched = json.loads(capsys.readouterr().out)
    hatching_cli.main([*args, "--look", "drawn"])
    plain = json.loads(capsys.readouterr().out)
    assert hatched["n_images"] == plain["n_images"] == 3
    assert hatched["hatching_found"] == 3 and plain["hatching_found"] == 0
    assert plain["asymmetry_max"] < hatched["threshold"] <= hatched["asymmetry_min"]
    assert run_cli(hatching_cli.main, ["--synthetic", "1", "--draws", "0"]) == 2
    assert "--draws must be at least 1" in capsys.readouterr().err
