"""Which drawings an evaluation draws (``f2n_drake.evaluate.drawings``): plans repeated per
draw, random styles, varied openings, and the options it refuses."""

from __future__ import annotations

import json

import numpy as np
import pytest

from f2n_drake.core.errors import InputError, run_cli
from f2n_drake.core.paths import resplan_sample_path
from f2n_drake.evaluate import drawings, segmentation


def _json(capsys) -> dict:
    return json.loads(capsys.readouterr().out)


def test_drawn_times_repeats_each_plan_in_a_row():
    plans = [("a", "plan a"), ("b", "plan b")]
    assert list(drawings.drawn_times(plans, 1)) == plans
    assert list(drawings.drawn_times(plans, 2)) == [
        ("a, draw 1", "plan a"),
        ("a, draw 2", "plan a"),
        ("b, draw 1", "plan b"),
        ("b, draw 2", "plan b"),
    ]


def test_segmentation_cli_draws_each_plan_in_several_styles(capsys):
    seen, drawn = [], []  # each drawing and its labels (painted-over furniture comes twice)

    def oracle(rendered):
        if not any(labels is rendered.labels for labels in drawn):
            drawn.append(rendered.labels)
            seen.append(rendered.image)
        return rendered.labels, None

    args = ["--synthetic", "2", "--seed", "3", "--size", "128", "--styles", "random", "--json"]
    segmentation.main([*args, "--draws", "3"], predict=oracle)
    assert _json(capsys)["n_images"] == 6 and len(seen) == 6
    assert not np.array_equal(seen[0], seen[1])  # one plan, two drawings
    first_draw = seen[0]
    seen.clear()
    drawn.clear()
    segmentation.main(args, predict=oracle)
    assert _json(capsys)["n_images"] == 2 and len(seen) == 2
    assert np.array_equal(seen[0], first_draw)  # the first draw is the drawing without --draws


@pytest.mark.parametrize(
    "extra, message",
    [(["--draws", "0"], "at least 1"), (["--draws", "2"], "needs --styles random")],
)
def test_segmentation_cli_refuses_useless_draws(capsys, extra, message):
    code = run_cli(segmentation.main, ["--synthetic", "1", *extra])
    assert code == 2 and message in capsys.readouterr().err


def test_segmentation_cli_draws_synthetic_plans_with_varied_openings(capsys):
    drawn = []

    def oracle(rendered):
        drawn.append(rendered.image)
        return rendered.labels, None

    args = ["--synthetic", "2", "--seed", "3", "--size", "128", "--json"]
    segmentation.main(args, predict=oracle)
    assert _json(capsys)["openings"] == "typical"
    segmentation.main([*args, "--openings", "varied"], predict=oracle)
    assert _json(capsys)["openings"] == "varied"
    assert not np.array_equal(drawn[0], drawn[2])  # the same layout, other door and window widths
    code = run_cli(
        segmentation.main, ["--resplan", str(resplan_sample_path()), "--openings", "varied"]
    )
    assert code == 2 and "ResPlan plan has its own" in capsys.readouterr().err


def test_segmentation_cli_refuses_training_seeds(capsys):
    with pytest.raises(InputError, match="overlap the training seeds"):
        segmentation.main(
            ["--synthetic", "10", "--seed", "999995"], predict=segmentation.oracle_predictor(0.0)
        )
    code = run_cli(segmentation.main, ["--synthetic", "1", "--seed", "1000000"])
    assert code == 2 and "training seeds" in capsys.readouterr().err
