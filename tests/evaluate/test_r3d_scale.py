"""``evaluate scale --r3d``: the door-width scale of real drawings against their printed sizes
(a tiny plan written in tmp_path, its words given by a stub reader)."""

from __future__ import annotations

import json

import cv2
import numpy as np
import pytest
from helpers import write_r3d_plan

from f2n_drake.core.errors import run_cli
from f2n_drake.core.text import TextBox
from f2n_drake.datasets import r3d
from f2n_drake.evaluate import r3d_scale, scale
from f2n_drake.segmenter.inference import Segmenter

FIRST = np.array([0, 0, 3, 1, 2, 1, 5, 0, 8, 6], np.uint8)  # an acceptable class per R3D class
DOOR = (slice(50, 71), slice(78, 84))  # a door box in the wall between the two rooms
SIZES = [  # the living room is 68 x 100 px, the bedroom 66 x 100 px, inside their outlines
    TextBox("3.2 x 4.1m", 0.95, (20, 40, 60, 50)),
    TextBox("3.0 x 4.0m", 0.95, (95, 40, 140, 50)),
]


class DoorSegmenter:
    """The plan's own labels, its door box labelled door."""

    def __init__(self, plan: r3d.R3DPlan) -> None:
        self.labels = FIRST[plan.labels]
        self.labels[DOOR] = 7

    def predict(self, image: np.ndarray) -> np.ndarray:
        return self.labels.copy()


def _plan_with_a_door(root) -> r3d.R3DPlan:
    write_r3d_plan(root, "7")
    drawing = cv2.imread(str(root / "7.jpg"), cv2.IMREAD_GRAYSCALE)
    drawing[DOOR] = 0
    drawing[51:70, 79:83] = 255  # 19 px of paper between the door's 1 px jambs
    cv2.imwrite(str(root / "7.jpg"), drawing)
    return r3d.load_r3d_plan(root, "7")


@pytest.mark.usefixtures("drawings_at_own_size")
def test_door_estimate_is_compared_with_printed_sizes_only_when_enough_agree(tmp_path, monkeypatch):
    plan = _plan_with_a_door(tmp_path)
    rows = r3d_scale.r3d_scale_rows(
        [plan], DoorSegmenter(plan), reader=lambda _grey: SIZES, progress=False
    )
    (row,) = rows
    assert row["printed_rooms"] == 2 and row["printed_spread"] < 0.05
    assert row["printed_m_per_px"] == pytest.approx(0.0433, rel=0.02)  # about 4.1 m / 100 px
    assert row["n_doors"] == 1 and row["estimate"] == pytest.approx(0.9 / 20)  # jamb to jamb
    assert row["true_m_per_px"] is None  # two room sizes are no reference
    report = scale.r3d_report_of(rows, 0.9, "all")
    assert report["n_printed"] == 1 and report["n_reference"] == report["n_estimated"] == 0

    monkeypatch.setattr(r3d_scale, "MIN_PRINTED_ROOMS", 2)
    rows = r3d_scale.r3d_scale_rows(
        [plan], DoorSegmenter(plan), reader=lambda _grey: SIZES, progress=False
    )
    report = scale.r3d_report_of(rows, 0.9, "all")
    error = rows[0]["estimate"] / rows[0]["printed_m_per_px"] - 1
    assert report["n_reference"] == report["n_estimated"] == 1
    assert report["median_error"] == pytest.approx(error) and 0 < error < 0.1
    assert report["within_10_percent"] == 1.0 and report["off_40_percent"] == 0.0

    far = scale.error_summary([{"estimate": 2.0, "true_m_per_px": 1.0}], "estimate")
    assert far["off_40_percent"] == 1.0 and far["within_10_percent"] == 0.0


def test_cli_reports_the_split_and_refused_drawings(tmp_path, monkeypatch, capsys):
    plan = _plan_with_a_door(tmp_path)
    blank = r3d.R3DPlan("blank", np.full_like(plan.image, 255), plan.labels)
    cv2.imwrite(str(tmp_path / "blank.jpg"), blank.image)
    for suffix in ("_rooms.png", "_wall.png", "_close.png"):
        (tmp_path / f"blank{suffix}").write_bytes((tmp_path / f"7{suffix}").read_bytes())
    monkeypatch.setattr(Segmenter, "load", classmethod(lambda cls, *a, **k: DoorSegmenter(plan)))

    assert run_cli(scale.main, ["--r3d", str(tmp_path), "--split", "all", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["split"] == "all" and report["n_images"] == 2 and report["refused"] == 1
    assert [row["name"] for row in report["per_drawing"]] == ["7", "blank"]
    assert report["per_drawing"][0]["n_doors"] == 1
    assert run_cli(scale.main, ["--r3d", str(tmp_path), "--split", "all"]) == 0
    assert "2 R3D drawings (all), 1 refused" in capsys.readouterr().out
