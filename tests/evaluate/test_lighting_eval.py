"""``evaluate lighting``: a dimmed drawing parsed with and without lighting it evenly."""

from __future__ import annotations

import json

import cv2
import numpy as np
import pytest
from helpers import Oracle, two_rooms

from f2n_drake.core.errors import InputError
from f2n_drake.evaluate import lighting


def test_dimming_darkens_towards_the_bottom_right_corner():
    image = np.full((50, 80), 200, np.uint8)
    dim = lighting.dimmed(image, 0.5)
    assert dim[0, 0] == 200 and dim[-1, -1] == 100 and dim[25, 40] == pytest.approx(150, abs=2)
    colour = lighting.dimmed(np.full((50, 80, 3), 200, np.uint8), 0.5)
    assert colour.shape == (50, 80, 3) and colour[-1, -1, 2] == 100


def test_agreement_counts_the_labelled_pixels_and_refusals_score_nothing():
    reference = np.array([[0, 1, 1, 2]], np.uint8)
    assert lighting.agreement(reference.copy(), reference) == 1.0
    assert lighting.agreement(np.array([[0, 1, 2, 2]], np.uint8), reference) == pytest.approx(2 / 3)
    assert lighting.agreement(None, reference) == 0.0


def test_the_benchmark_prints_one_row_per_drawing_and_dimming(tmp_path, monkeypatch, capsys):
    img, lab = two_rooms(300)
    cv2.imwrite(str(tmp_path / "rooms.png"), img)
    monkeypatch.setattr(
        "f2n_drake.segmenter.inference.Segmenter.load", classmethod(lambda cls: Oracle(lab))
    )
    argv = [str(tmp_path / "rooms.png"), "--darkest", "0.5", "--json"]
    assert lighting.main(argv) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["drawings"] == 1 and len(report["per_drawing"]) == 1
    row = report["per_drawing"][0]
    assert row["darkest"] == 0.5 and row["refused"] == []
    assert row["agreement_lit"] == 1.0  # the stub labels alike; lit evenly, the lines are too
    with pytest.raises(InputError):
        lighting.main([str(tmp_path / "rooms.png"), "--darkest", "1.5"])
