"""Set-valued labels in training: the loss, emphasised pixels, class sets through letterbox and
crops, R3D views mixed with generated plans, a tiny mixed run."""

from __future__ import annotations

import json

import numpy as np
import pytest
import torch
import torch.nn.functional as F
from helpers import bits, write_r3d_plan

from f2n_drake.core.classes import CLASS_ID
from f2n_drake.core.errors import InputError, run_cli
from f2n_drake.datasets import r3d
from f2n_drake.segmenter import dataset as ds
from f2n_drake.segmenter.dataset import as_class_sets
from f2n_drake.segmenter.losses import EMPHASIS_BIT, set_cross_entropy
from f2n_drake.segmenter.real_plans import MixedPlans, R3DPlans
from f2n_drake.segmenter.train import main as train_main


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


def test_emphasised_pixels_weigh_more_and_make_no_class_acceptable():
    torch.manual_seed(1)
    logits = torch.randn(1, 10, 2, 1)
    sets = torch.tensor([[[bits("living")], [bits("background")]]])
    p = logits.softmax(1)
    living_loss = -p[0, CLASS_ID["living"], 0, 0].log()
    background_loss = -p[0, CLASS_ID["background"], 1, 0].log()
    marked = sets.clone()
    marked[0, 1, 0] |= EMPHASIS_BIT
    torch.testing.assert_close(
        set_cross_entropy(logits, marked, emphasis=4.0), (living_loss + 4 * background_loss) / 5
    )
    torch.testing.assert_close(set_cross_entropy(logits, marked), set_cross_entropy(logits, sets))


def test_class_ids_and_r3d_sets_become_the_same_bit_masks():
    ids = np.array([[0, 7]], np.uint8)
    np.testing.assert_array_equal(as_class_sets(ids), [[1, 1 << 7]])
    sets = np.array([[bits("door", "window")]], np.uint16)
    np.testing.assert_array_equal(as_class_sets(sets), sets.astype(np.int64))


def test_letterbox_and_crop_keep_set_valued_labels_whole():
    sets = np.full((30, 50), bits("door", "window", "front_door"), np.uint16)
    image = np.zeros((30, 50), np.uint8)
    boxed_image, boxed = ds.letterbox(image, sets, 64)
    assert boxed.dtype == np.uint16
    assert set(np.unique(boxed)) == {0, bits("door", "window", "front_door")}  # 0: padding
    crop = ds.random_crop(boxed_image, boxed, 32, np.random.default_rng(0))[1]
    assert set(np.unique(as_class_sets(crop))) <= {0, bits("door", "window", "front_door")}


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


def test_r3d_views_mark_the_emphasised_classes_pixels(tmp_path):
    write_r3d_plan(tmp_path, "7")
    whole = dict(p_window=0.0, p_margin=0.0)
    plain = R3DPlans(tmp_path, ["7"], **whole)(0)[1]
    sets = R3DPlans(tmp_path, ["7"], emphasised=("closet",), **whole)(0)[1]
    marked = (sets & EMPHASIS_BIT) != 0
    assert marked.sum() == 30 * 30  # the closet, and nothing else
    assert (plain[marked] == bits("background")).all()
    np.testing.assert_array_equal(sets & ~np.uint16(EMPHASIS_BIT), plain)
    with pytest.raises(InputError, match="no class pantry"):
        R3DPlans(tmp_path, ["7"], emphasised=("pantry",))


def test_training_mixes_r3d_training_plans_with_generated_ones(tmp_path):
    write_r3d_plan(tmp_path, "not_in_dev")
    write_r3d_plan(tmp_path, r3d.dev_split_names()[0])
    out = tmp_path / "seg.pt"
    argv = ["--toy", "--r3d", str(tmp_path), "--p-r3d", "0.5", "--steps", "2", "--batch", "2"]
    argv += ["--crop", "64", "--input-size", "64", "--val-plans", "1", "--workers", "0"]
    argv += ["--threads", "1", "--width", "0.25", "--out", str(out), "--runs", str(tmp_path)]
    argv += ["--r3d-emphasised", "closet", "--emphasis", "4"]
    assert train_main([*argv, "--name", "mixed"]) == 0
    config = json.loads((tmp_path / "mixed" / "config.json").read_text())
    assert "1 R3D training plans" in config["data_description"]
    assert "R3D closet pixels counts 4 times" in config["data_description"]
    assert "R3D's real listing drawings" in (tmp_path / "MODEL_CARD.md").read_text()


@pytest.mark.parametrize(
    "argv, message",
    [
        (["--r3d-emphasised", "closet"], "needs --r3d"),
        (["--emphasis", "4"], "name them too"),
    ],
)
def test_emphasis_options_that_would_do_nothing_are_refused(argv, message, tmp_path, capsys):
    out = ["--out", str(tmp_path / "w.pt"), "--runs", str(tmp_path / "r")]
    assert run_cli(train_main, ["--toy", *argv, *out]) == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "r").exists()
