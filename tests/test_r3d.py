"""R3D: the reader's merged classes as sets of acceptable classes, the fixed development split,
the set-valued loss, the training views and the evaluation (tiny plans written in tmp_path)."""

from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np
import pytest
import torch
import torch.nn.functional as F

from f2n_drake.core.classes import CLASS_ID
from f2n_drake.core.errors import InputError, run_cli
from f2n_drake.core.parsed import Instance, ParsedPlan
from f2n_drake.datasets import r3d
from f2n_drake.evaluate import segmentation
from f2n_drake.evaluate.r3d import evaluate_r3d, format_r3d_table, recovered_regions
from f2n_drake.segmenter import dataset as ds
from f2n_drake.segmenter.dataset import as_class_sets
from f2n_drake.segmenter.inference import Segmenter
from f2n_drake.segmenter.losses import set_cross_entropy
from f2n_drake.segmenter.real_plans import MixedPlans, R3DPlans
from f2n_drake.segmenter.train import main as train_main

LIVING, BEDROOM, CLOSET = (224, 255, 192), (255, 224, 128), (192, 192, 224)


def write_r3d_plan(root: Path, name: str) -> None:
    """A 120 x 160 px flat: a living room and a bedroom side by side behind 6 px walls, a closet
    in the bedroom's corner (no wall of its own), a window drawn as a box in the top wall."""
    h, w = 120, 160
    rooms = np.zeros((h, w, 3), np.uint8)
    rooms[10:110, 10:78] = LIVING
    rooms[10:110, 84:150] = BEDROOM
    rooms[80:110, 120:150] = CLOSET
    wall = np.zeros((h, w), np.uint8)
    wall[4:116, 4:156] = 255
    wall[(rooms > 0).any(axis=2)] = 0
    close = np.zeros((h, w), np.uint8)
    close[4:10, 30:50] = 255
    wall[close > 0] = 0
    drawing = np.full((h, w), 255, np.uint8)
    drawing[(wall > 0) | (close > 0)] = 0
    drawing[5:9, 31:49] = 255
    cv2.imwrite(str(root / f"{name}.jpg"), drawing)
    cv2.imwrite(str(root / f"{name}_rooms.png"), rooms[:, :, ::-1])
    cv2.imwrite(str(root / f"{name}_wall.png"), wall)
    cv2.imwrite(str(root / f"{name}_close.png"), close)


def bits(*names: str) -> int:
    return sum(1 << CLASS_ID[n] for n in names)


def test_reader_maps_colours_walls_and_openings_to_r3d_classes(tmp_path):
    write_r3d_plan(tmp_path, "7")
    plan = r3d.load_r3d_plan(tmp_path, "7")
    assert plan.image.shape == plan.labels.shape == (120, 160)
    assert plan.labels[50, 40] == r3d.R3D_ID["living"]
    assert plan.labels[50, 100] == r3d.R3D_ID["bedroom"]
    assert plan.labels[100, 140] == r3d.R3D_ID["closet"]
    assert plan.labels[50, 80] == r3d.R3D_ID["wall"]
    assert plan.labels[8, 40] == r3d.R3D_ID["opening"]  # openings are painted over walls
    assert plan.labels[2, 2] == r3d.R3D_ID["background"]
    sets = plan.class_sets
    assert sets[50, 40] == bits("living", "kitchen")
    assert sets[8, 40] == bits("door", "window", "front_door")
    assert sets[100, 140] == bits("background")


def test_every_r3d_class_accepts_some_class_and_hall_is_living():
    assert all(r3d.ACCEPTABLE_MASK > 0)
    assert r3d.ACCEPTABLE_MASK[r3d.R3D_ID["hall"]] == bits("living")
    other = r3d.ACCEPTABLE_MASK[r3d.R3D_ID["other"]]
    assert other & bits("bedroom") and not other & bits("balcony", "wall")


def test_names_need_all_label_images_and_an_empty_folder_is_refused(tmp_path):
    with pytest.raises(InputError, match="no R3D plans"):
        r3d.r3d_names(tmp_path)
    write_r3d_plan(tmp_path, "b")
    write_r3d_plan(tmp_path, "a")
    (tmp_path / "a_wall.png").unlink()
    assert r3d.r3d_names(tmp_path) == ["b"]


def test_development_split_is_30_listed_plans_kept_out_of_train(tmp_path):
    dev = r3d.dev_split_names()
    assert len(dev) == len(set(dev)) == 30
    for name in [dev[0], dev[1], "not_in_dev"]:
        write_r3d_plan(tmp_path, name)
    assert r3d.split_names(tmp_path, "dev") == sorted(dev[:2])
    assert r3d.split_names(tmp_path, "train") == ["not_in_dev"]
    assert len(r3d.split_names(tmp_path, "all")) == 3
    with pytest.raises(InputError, match="unknown R3D split"):
        r3d.split_names(tmp_path, "test")


def test_dev_split_rule_is_seeded_and_sorted():
    names = [f"{i:03d}" for i in range(179)]
    assert r3d.choose_dev_split(names) == r3d.choose_dev_split(list(reversed(names)))
    assert r3d.choose_dev_split(names) == sorted(r3d.choose_dev_split(names))


def test_set_loss_is_cross_entropy_for_one_class_and_union_for_several():
    torch.manual_seed(0)
    logits = torch.randn(2, 10, 5, 5)
    labels = torch.randint(0, 10, (2, 5, 5))
    weight = torch.rand(10) + 0.5
    torch.testing.assert_close(
        set_cross_entropy(logits, 1 << labels, weight),
        F.cross_entropy(logits, labels, weight=weight),
    )
    merged = torch.full((2, 5, 5), bits("living", "kitchen"))
    p = logits.softmax(1)
    expected = -(p[:, CLASS_ID["living"]] + p[:, CLASS_ID["kitchen"]]).log().mean()
    torch.testing.assert_close(set_cross_entropy(logits, merged), expected)
    ignored = merged.clone()
    ignored[0] = 0  # no acceptable class: left out of the mean
    torch.testing.assert_close(
        set_cross_entropy(logits, ignored), -(p[1, 1] + p[1, 4]).log().mean()
    )


def test_class_ids_and_r3d_sets_become_the_same_bit_masks():
    ids = np.array([[0, 7]], np.uint8)
    np.testing.assert_array_equal(as_class_sets(ids), [[1, 1 << 7]])
    sets = np.array([[bits("door", "window")]], np.uint16)
    np.testing.assert_array_equal(as_class_sets(sets), sets.astype(np.int64))


def test_r3d_views_keep_image_and_labels_aligned_and_mixing_is_seeded(tmp_path):
    write_r3d_plan(tmp_path, "7")
    views = R3DPlans(tmp_path, ["7"], seed=3)
    for index in range(6):
        image, sets = views(index)
        assert image.shape == sets.shape and sets.dtype == np.uint16
        assert (image[sets == bits("wall")] < 128).all()
    synthetic = lambda i: (np.full((8, 8), 255, np.uint8), np.zeros((8, 8), np.uint8))
    synthetic.seed = lambda i: 1000 + i
    mixed = MixedPlans(synthetic, views, 0.5, seed=1)
    taken = [mixed(i)[1].dtype == np.uint16 for i in range(40)]
    assert 5 < sum(taken) < 35
    assert taken == [mixed(i)[1].dtype == np.uint16 for i in range(40)]


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
    assert report["refused"] == 0
    assert "rooms recovered 2/2" in format_r3d_table(report)


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
    assert recovered_regions(plan.labels, parsed, "living", 50) == (1, 1)
    assert recovered_regions(plan.labels, parsed, "bedroom", 50) == (1, 0)
    assert recovered_regions(plan.labels, None, "living", 50) == (1, 0)


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
    assert [p["plan"] for p in report["per_plan"]] == ["not_in_dev"]
    assert report["rooms_recovered"]["fraction"] == 1.0


def test_training_mixes_r3d_training_plans_with_generated_ones(tmp_path):
    write_r3d_plan(tmp_path, "not_in_dev")
    write_r3d_plan(tmp_path, r3d.dev_split_names()[0])
    out = tmp_path / "seg.pt"
    argv = ["--toy", "--r3d", str(tmp_path), "--p-r3d", "0.5", "--steps", "2", "--batch", "2"]
    argv += ["--crop", "64", "--input-size", "64", "--val-plans", "1", "--workers", "0"]
    argv += ["--threads", "1", "--width", "0.25", "--out", str(out), "--runs", str(tmp_path)]
    assert train_main([*argv, "--name", "mixed"]) == 0
    config = json.loads((tmp_path / "mixed" / "config.json").read_text())
    assert "1 R3D training plans" in config["data_description"]
    assert "R3D's real listing drawings" in (tmp_path / "MODEL_CARD.md").read_text()


def test_letterbox_and_crop_keep_set_valued_labels_whole():
    sets = np.full((30, 50), bits("door", "window", "front_door"), np.uint16)
    image = np.zeros((30, 50), np.uint8)
    boxed_image, boxed = ds.letterbox(image, sets, 64)
    assert boxed.dtype == np.uint16
    assert set(np.unique(boxed)) == {0, bits("door", "window", "front_door")}  # 0: padding
    crop = ds.random_crop(boxed_image, boxed, 32, np.random.default_rng(0))[1]
    assert set(np.unique(as_class_sets(crop))) <= {0, bits("door", "window", "front_door")}
