"""Distillation: the divergence from a teacher's answers, a teacher's logits of a training
square, and a tiny run that learns from a teacher."""

from __future__ import annotations

import numpy as np
import pytest
import torch
import torch.nn.functional as F
from helpers import TINY_RUN

from f2n_drake.core.errors import run_cli
from f2n_drake.segmenter import dataset as ds
from f2n_drake.segmenter.inference import Segmenter
from f2n_drake.segmenter.losses import distillation_loss
from f2n_drake.segmenter.network import DeepLabV3Plus
from f2n_drake.segmenter.train import main as train_main
from f2n_drake.segmenter.weights import load_segmenter


def test_divergence_is_zero_for_the_teachers_own_answer_and_kl_otherwise():
    torch.manual_seed(0)
    teacher, student = torch.randn(2, 10, 4, 3), torch.randn(2, 10, 4, 3)
    assert distillation_loss(teacher, teacher).abs() < 1e-6
    expected = F.kl_div(
        student.log_softmax(1), teacher.log_softmax(1), reduction="none", log_target=True
    )
    torch.testing.assert_close(distillation_loss(student, teacher), expected.sum(1).mean())


def test_a_pixel_weighs_the_weight_of_the_teachers_best_class():
    torch.manual_seed(1)
    student = torch.randn(1, 3, 1, 2)
    teacher = torch.tensor([[[[5.0, 0.0]], [[0.0, 5.0]], [[0.0, 0.0]]]])  # best: 0, then 1
    per_pixel = F.kl_div(
        student.log_softmax(1), teacher.log_softmax(1), reduction="none", log_target=True
    ).sum(1)[0, 0]
    weight = torch.tensor([1.0, 3.0, 9.0])
    torch.testing.assert_close(
        distillation_loss(student, teacher, weight), (per_pixel[0] + 3 * per_pixel[1]) / 4
    )


def test_logits_of_a_training_square_are_those_of_the_drawing_it_shows():
    torch.manual_seed(2)
    segmenter = Segmenter(DeepLabV3Plus(width=0.25), input_size=64, views=2)
    square = np.random.default_rng(0).integers(0, 256, (1, 64, 64), dtype=np.uint8)
    ink = torch.from_numpy(1.0 - square.astype(np.float32) / 255.0)[:, None]
    torch.testing.assert_close(segmenter.logits(ink), segmenter._forward(square))


def test_a_run_with_a_teacher_moves_towards_it_and_says_so_in_its_card(tmp_path):
    teacher = tmp_path / "teacher" / "seg.pt"
    runs = str(tmp_path / "runs")
    argv = [*TINY_RUN, "--steps", "20", "--out", str(teacher), "--runs", runs, "--name", "t"]
    assert train_main(argv) == 0
    argv = [*TINY_RUN, "--teacher", str(teacher), "--teacher-views", "1", "--distill", "1.0"]
    argv += ["--seed", "3", "--runs", runs]
    start, student = tmp_path / "start" / "seg.pt", tmp_path / "student" / "seg.pt"
    argv_start = ["--steps", "1", "--lr", "1e-9", "--out", str(start), "--name", "s0"]
    assert train_main([*argv, *argv_start]) == 0  # the student's first weights, unmoved
    argv_student = ["--steps", "12", "--lr", "2e-2", "--out", str(student), "--name", "s"]
    assert train_main([*argv, *argv_student]) == 0
    assert "distilled from" in (student.parent / "MODEL_CARD.md").read_text()
    toy = ds.ToyPlans(0, size_px=64)
    x = torch.stack([torch.from_numpy(1.0 - toy(i)[0] / np.float32(255))[None] for i in range(4)])
    with torch.no_grad():
        target = load_segmenter(teacher).model(x)
        # batch statistics: a dozen steps leave the running ones far from settled
        gap = [
            distillation_loss(load_segmenter(path).model.train()(x), target).item()
            for path in (start, student)
        ]
    assert gap[1] < 0.8 * gap[0]


@pytest.mark.parametrize("value", ["-0.1", "1.5"])
def test_a_distillation_share_outside_0_1_exits_with_code_2(value, tmp_path, capsys):
    runs = tmp_path / "runs"
    argv = [*TINY_RUN, f"--distill={value}", "--out", str(tmp_path / "s.pt"), "--runs", str(runs)]
    assert run_cli(train_main, argv) == 2
    assert "--distill: must be a finite number in [0, 1]" in capsys.readouterr().err
    assert not runs.exists()


@pytest.mark.parametrize(
    "argv, message",
    [
        (["--distill", "0.5"], "name it"),
        (["--teacher-views", "4"], "name it"),
        (["--teacher", "missing.pt"], "segmenter weights not found: missing.pt"),
    ],
)
def test_teacher_options_that_cannot_work_are_refused_before_anything_is_written(
    argv, message, tmp_path, capsys
):
    runs = tmp_path / "runs"
    out = ["--out", str(tmp_path / "s.pt"), "--runs", str(runs)]
    assert run_cli(train_main, [*TINY_RUN, *argv, *out]) == 2
    assert message in capsys.readouterr().err
    assert not runs.exists() and not (tmp_path / "s.pt").exists()
