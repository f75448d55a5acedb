"""``evaluate segmentation --r3d``: pixel and class accuracy in R3D's merged classes, rooms and
openings recovered by the full parse, refused drawings (tiny plans written in tmp_path)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from helpers import write_r3d_plan

from f2n_drake.core.errors import InputError, run_cli
from f2n_drake.core.parsed import Instance, ParsedPlan
from f2n_drake.core.text import TextBox
from f2n_drake.datasets import r3d
from f2n_drake.evaluate import segmentation
from f2n_drake.evaluate.r3d import (
    connectors_on_openings,
    evaluate_r3d,
    format_r3d_table,
    region_matches,
    thickness_px,
)
from f2n_drake.segmenter.inference import Segmenter


class TruthSegmenter:
    """Labels each pixel with the first acceptable class of the plan's R3D labels."""

    FIRST = np.array([0, 0, 3, 1, 2, 1, 5, 0, 8, 6], np.uint8)  # in R3D_CLASSES order

    def __init__(self, plan: r3d.R3DPlan) -> None:
        self.labels = self.FIRST[plan.labels]

    def predict(self, image: np.ndarray) -> np.ndarray:
        return self.labels.copy()


def test_right_labels_recover_every_room_and_window(tmp_path):
    write_r3d_plan(tmp_path, "7")
    plan = r3d.load_r3d_plan(tmp_path, "7")
    report = evaluate_r3d([plan], TruthSegmenter(plan))
    assert report["pixel_accuracy"] == report["mean_class_accuracy"] == 1.0
    assert report["class_accuracy"]["hall"] is None  # no hall pixel to score
    assert report["rooms_recovered"] == {"recovered": 2, "total": 2, "fraction": 1.0}
    assert report["openings_recovered"]["fraction"] == 1.0
    by_thickness = report["openings_recovered_by_thickness"]
    assert by_thickness["3_px_or_more"] == report["openings_recovered"]
    assert by_thickness["under_3_px"]["total"] == 0
    placed = report["connectors_on_openings"]
    assert placed["total"] >= 1 and placed["fraction"] == 1.0  # every connector on an opening
    assert report["refused"] == 0
    assert "rooms recovered 2/2" in format_r3d_table(report)


def test_a_zoomed_drawing_is_scored_on_its_enlarged_labels(tmp_path):
    write_r3d_plan(tmp_path, "7")
    plan = r3d.load_r3d_plan(tmp_path, "7")
    big = r3d.enlarged(plan, 2.0)
    assert big.image.shape == big.labels.shape == (240, 320)
    assert set(np.unique(big.labels)) == set(np.unique(plan.labels))  # no blended class ids
    report = evaluate_r3d([plan], TruthSegmenter(big), zoom=2.0)
    assert report["pixel_accuracy"] == 1.0
    assert report["rooms_recovered"] == {"recovered": 2, "total": 2, "fraction": 1.0}
    assert report["openings_recovered"]["fraction"] == 1.0
    with pytest.raises(InputError, match="--r3d"):
        segmentation.main(["--synthetic", "1", "--zoom", "2"])


def test_a_drawing_laid_askew_is_turned_upright_with_its_labels(tmp_path):
    write_r3d_plan(tmp_path, "7")
    plan = r3d.load_r3d_plan(tmp_path, "7")
    assert r3d.askew(plan, 0.0) is plan
    crooked = r3d.askew(plan, 3.0)
    assert crooked.image.shape == crooked.labels.shape
    assert crooked.image.shape[0] > plan.image.shape[0]  # measured askew and turned upright
    assert set(np.unique(crooked.labels)) == set(np.unique(plan.labels))  # no blended class ids
    report = evaluate_r3d([plan], TruthSegmenter(crooked), askew_deg=3.0)
    assert report["pixel_accuracy"] == 1.0
    assert report["rooms_recovered"]["fraction"] == 1.0
    with pytest.raises(InputError, match="--r3d"):
        segmentation.main(["--synthetic", "1", "--askew", "2"])


@pytest.mark.parametrize("read_back", [True, False])
def test_a_drawing_on_its_side_is_turned_back_where_its_words_say_so(
    tmp_path, monkeypatch, read_back
):
    from f2n_drake.perception import orientation

    write_r3d_plan(tmp_path, "7")
    plan = r3d.load_r3d_plan(tmp_path, "7")
    assert r3d.scanned_turned(plan, 0) is plan
    monkeypatch.setattr(orientation, "quarter_turns", lambda image: 3 * read_back)
    lying = r3d.scanned_turned(plan, 1)
    if read_back:
        assert np.array_equal(lying.image, plan.image)
        assert np.array_equal(lying.labels, plan.labels)
    else:  # left on its side, its labels turned alike
        assert np.array_equal(lying.image, np.rot90(plan.image))
        assert np.array_equal(lying.labels, np.rot90(plan.labels))
    report = evaluate_r3d([plan], TruthSegmenter(lying), quarter_turns=1)
    assert report["pixel_accuracy"] == 1.0
    with pytest.raises(InputError, match="--r3d"):
        segmentation.main(["--synthetic", "1", "--quarter-turns", "1"])


@pytest.mark.usefixtures("drawings_at_own_size")
def test_floors_painted_with_planks_are_parsed_as_plain_rooms(tmp_path, monkeypatch):
    write_r3d_plan(tmp_path, "7")
    plan = r3d.load_r3d_plan(tmp_path, "7")
    painted = r3d.textured_floors(plan, seed=3)
    assert np.array_equal(painted.labels, plan.labels)
    assert np.array_equal(painted.image, r3d.textured_floors(plan, seed=3).image)  # seeded
    floors = np.isin(plan.labels, [r3d.R3D_ID["living"], r3d.R3D_ID["bedroom"]])
    assert painted.image[floors].mean() < 225 and painted.image[floors].std() > 5
    assert painted.image[plan.image < 50].max() < 50  # the lines lie on top
    report = evaluate_r3d([painted], TruthSegmenter(plan))
    assert report["rooms_recovered"]["fraction"] == 1.0
    monkeypatch.setattr("f2n_drake.pipeline.without_floor_textures", lambda grey: grey)
    as_painted = evaluate_r3d([painted], TruthSegmenter(plan))
    assert as_painted["rooms_recovered"]["fraction"] < 1.0  # planks part the rooms into strips
    with pytest.raises(InputError, match="--r3d"):
        segmentation.main(["--synthetic", "1", "--textured-floors"])


@pytest.mark.usefixtures("drawings_at_own_size")
def test_a_drawing_on_squared_paper_is_parsed_as_on_plain_paper(tmp_path, monkeypatch):
    write_r3d_plan(tmp_path, "7")
    plan = r3d.load_r3d_plan(tmp_path, "7")
    gridded = r3d.on_squared_paper(plan, 8, grey=190)
    assert np.array_equal(gridded.labels, plan.labels)
    assert (gridded.image[::8, 3] == 190).all() and (gridded.image[plan.image < 50] < 50).all()
    shown = []

    class Watching(TruthSegmenter):
        def predict(self, image: np.ndarray) -> np.ndarray:
            shown.append(image)
            return super().predict(image)

    report = evaluate_r3d([gridded], Watching(plan), reader=None)
    assert report["pixel_accuracy"] == 1.0 and report["rooms_recovered"]["fraction"] == 1.0
    assert (shown[0][0:105:8, :3] > 240).all()  # the network saw no grid beside the walls
    monkeypatch.setattr("f2n_drake.pipeline.without_paper_grid", lambda grey: grey)
    evaluate_r3d([gridded], Watching(plan), reader=None)
    assert (shown[-1][0:105:8, :3] == 190).all()
    with pytest.raises(InputError, match="spacing"):
        r3d.on_squared_paper(plan, 1)
    with pytest.raises(InputError, match="--r3d"):
        segmentation.main(["--synthetic", "1", "--squared-paper", "10"])


def test_a_coarse_scan_fades_thin_lines_and_keeps_the_labels(tmp_path):
    write_r3d_plan(tmp_path, "7")
    drawn = r3d.load_r3d_plan(tmp_path, "7")
    image = drawn.image.copy()
    image[30:90, 40] = 0  # a one-pixel line in the living room: a table's edge
    plan = r3d.R3DPlan(drawn.name, image, drawn.labels)
    scanned = r3d.coarse_scan(plan, 50)
    assert np.array_equal(scanned.labels, plan.labels)
    assert scanned.image.shape == plan.image.shape and scanned.image.dtype == np.uint8
    assert scanned.image[30:90, 40].mean() > 60  # the thin line fades to grey
    assert scanned.image[20:100, 6].mean() < 40  # the 6 px wall stays dark
    assert np.array_equal(scanned.image, r3d.coarse_scan(plan, 50).image)  # no randomness
    with pytest.raises(InputError, match="quality"):
        r3d.coarse_scan(plan, 0)
    with pytest.raises(InputError, match="--r3d"):
        segmentation.main(["--synthetic", "1", "--coarse-scan", "50"])


def test_a_room_voted_another_class_or_split_is_not_recovered(tmp_path):
    write_r3d_plan(tmp_path, "7")
    plan = r3d.load_r3d_plan(tmp_path, "7")
    ids = np.zeros(plan.labels.shape, np.int32)
    ids[10:110, 10:78] = 1  # the living room, voted kitchen: acceptable
    ids[10:110, 84:110] = 2  # the bedroom cut in two: neither part has IoU >= 0.5
    ids[10:110, 110:150] = 3
    instances = [
        Instance(k, name, np.zeros((0, 2)), int((ids == k).sum()), (0.0, 0.0))
        for k, name in ((1, "kitchen"), (2, "bedroom"), (3, "bedroom"))
    ]
    parsed = ParsedPlan(ids, np.zeros_like(plan.labels), instances)

    def recovered(parsed, name: str) -> list[bool]:
        return [hit for _, hit in region_matches(plan.labels, parsed, name, 50)]

    assert recovered(parsed, "living") == [True]
    assert recovered(parsed, "bedroom") == [False]
    assert recovered(None, "living") == [False]


def test_openings_thinner_than_a_wall_strip_are_told_apart():
    truth = np.zeros((60, 60), np.uint8)
    truth[10:14, 10:40] = r3d.R3D_ID["opening"]  # a door 4 px thick
    truth[30:32, 10:40] = r3d.R3D_ID["opening"]  # a closet front's strip, 2 px
    for k in range(20):  # a strip at 45 degrees, 2 px across
        truth[40 + k, 10 + k : 12 + k] = r3d.R3D_ID["opening"]
    ids = np.zeros(truth.shape, np.int32)
    ids[10:16, 10:40] = 1  # the door, 6 px thick: IoU 4/6
    ids[28:34, 10:40] = 2  # a connector as thick over the strip: IoU 2/6
    instances = [
        Instance(k, "door", np.zeros((0, 2)), int((ids == k).sum()), (0.0, 0.0)) for k in (1, 2)
    ]
    parsed = ParsedPlan(ids, np.zeros_like(truth), instances)
    matches = region_matches(truth, parsed, "opening", 10)
    assert [hit for _, hit in matches] == [True, False, False]
    widths = [thickness_px(pixels) for pixels, _ in matches]
    assert widths[0] == pytest.approx(4.0) and widths[1] == pytest.approx(2.0)
    assert widths[2] < 3.0  # measured across the strip, not along the image's axes


def test_a_door_on_no_r3d_opening_counts_against_the_doors_placed():
    truth = np.zeros((60, 60), np.uint8)
    truth[10:14, 20:50] = r3d.R3D_ID["opening"]
    ids = np.zeros(truth.shape, np.int32)
    ids[10:14, 20:30] = 1  # a door on the opening
    ids[40:44, 20:40] = 2  # a door where R3D draws none
    ids[10:14, 40:60] = 3  # a window half on the opening: on it
    ids[20:40, 20:40] = 4  # a room: no connector
    instances = [
        Instance(k, name, np.zeros((0, 2)), int((ids == k).sum()), (0.0, 0.0))
        for k, name in ((1, "door"), (2, "door"), (3, "window"), (4, "living"))
    ]
    parsed = ParsedPlan(ids, np.zeros_like(truth), instances)
    assert connectors_on_openings(truth, parsed) == (3, 2)
    ids[10:14, 40:45] = 0  # a third of the window on it: off
    assert connectors_on_openings(truth, parsed) == (3, 1)
    assert connectors_on_openings(truth, None) == (0, 0)


def test_a_drawing_without_closed_outlines_is_refused_and_still_scored(tmp_path):
    write_r3d_plan(tmp_path, "7")
    plan = r3d.load_r3d_plan(tmp_path, "7")
    blank = r3d.R3DPlan("blank", np.full_like(plan.image, 255), plan.labels)
    report = evaluate_r3d([blank], TruthSegmenter(plan))
    assert report["refused"] == 1 and report["refused_plans"] == ["blank"]
    assert report["pixel_accuracy"] == 1.0  # the network's labels of the plain drawing
    assert report["rooms_recovered"]["recovered"] == 0


def test_cli_scores_the_chosen_split_as_json(tmp_path, monkeypatch, capsys):
    write_r3d_plan(tmp_path, r3d.dev_split_names()[0])
    write_r3d_plan(tmp_path, "not_in_dev")
    plan = r3d.load_r3d_plan(tmp_path, "not_in_dev")
    monkeypatch.setattr(Segmenter, "load", classmethod(lambda cls, *a, **k: TruthSegmenter(plan)))
    argv = ["--r3d", str(tmp_path), "--split", "train", "--json"]
    assert run_cli(segmentation.main, argv) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["split"] == "train" and report["n_drawings"] == 1
    assert report["storage_network"] is False  # the stub reads alone
    assert [p["plan"] for p in report["per_plan"]] == ["not_in_dev"]
    assert report["rooms_recovered"]["fraction"] == 1.0
    write_r3d_plan(tmp_path, "not_in_dev_either")
    assert run_cli(segmentation.main, [*argv, "--plans", "1"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert [p["plan"] for p in report["per_plan"]] == ["not_in_dev"]  # the first of two


@pytest.mark.usefixtures("drawings_at_own_size")
def test_rooms_whose_name_is_read_are_scored_with_and_without_the_names(tmp_path):
    write_r3d_plan(tmp_path, "7")
    plan = r3d.load_r3d_plan(tmp_path, "7")
    segmenter = TruthSegmenter(plan)
    bedroom = plan.labels == r3d.R3D_ID["bedroom"]
    segmenter.labels[bedroom] = TruthSegmenter.FIRST[r3d.R3D_ID["living"]]  # voted living

    names = [
        TextBox("Bedroom", 0.95, (95, 40, 140, 50)),
        TextBox("3.2 x 4.1m", 0.95, (20, 40, 60, 50)),
    ]
    report = evaluate_r3d([plan], segmenter, reader=lambda _grey: names)
    assert report["named_rooms"] == {"count": 1, "accuracy": 1.0, "accuracy_without_names": 0.0}
    assert report["per_plan"][0]["named_rooms"] == [1, 1]
    assert "rooms whose name is read 1: type right 100.0% with the names,   0.0% without" in (
        format_r3d_table(report)
    )
    assert evaluate_r3d([plan], segmenter, reader=None)["named_rooms"]["count"] == 0
