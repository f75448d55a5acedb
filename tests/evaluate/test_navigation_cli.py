"""The navigation benchmark CLI: JSON structure, value ranges, bad arguments."""

from __future__ import annotations

import json

import pytest

from f2n_drake.evaluate import navigation
from f2n_drake.evaluate.__main__ import main as evaluate_main

MODE_KEYS = {"success_rate", "mean_error_m", "max_error_m", "collisions"}


def test_one_plan_one_task_json(capsys):
    assert (
        evaluate_main(["navigation", "--plans", "1", "--tasks", "1", "--seed", "3", "--json"]) == 0
    )
    report = json.loads(capsys.readouterr().out)
    assert report["tasks"] == 1
    assert set(report["modes"]) == {"off", "paper", "continuous"}
    for stats in report["modes"].values():
        assert MODE_KEYS <= set(stats)
        assert 0.0 <= stats["success_rate"] <= 1.0
        assert 0.0 <= stats["mean_error_m"] <= stats["max_error_m"] < 5.0
        assert stats["collisions"] in (0, 1)
    assert report["modes"]["continuous"]["mean_error_m"] < 0.1
    assert report["realtime_factor"] > 1.0
    run = report["runs"]["continuous"][0]  # one line per task and mode
    assert (run["plan"], run["task"]) == (0, 0) and " -> " in run["route"]
    assert run["message"] in ("route done", "collision") or run["message"].startswith("time")


def test_only_runs_the_chosen_task(capsys):
    argv = ["navigation", "--plans", "1", "--tasks", "2", "--seed", "3", "--modes", "continuous"]
    assert evaluate_main([*argv, "--only", "0:1", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["tasks"] == 1
    assert [(r["plan"], r["task"]) for r in report["runs"]["continuous"]] == [(0, 1)]


def test_unknown_start_reports_global_localization(capsys):
    argv = ["navigation", "--plans", "1", "--tasks", "1", "--seed", "3", "--modes", "continuous"]
    assert evaluate_main([*argv, "--unknown-start", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["unknown_start"] is True
    assert set(report["modes"]) == {"continuous"}
    stats = report["global_localization"]["continuous"]
    assert stats["converged_rate"] == stats["converged_within_10cm_rate"] == 1.0
    assert 0.0 < stats["mean_time_to_converge_s"] <= stats["max_time_to_converge_s"] < 20.0
    assert stats["wrong_convergences"] == stats["collisions_before_converged"] == 0


@pytest.mark.parametrize(
    "argv",
    [
        ["--modes", "off,teleport"],
        ["--plans", "0"],
        ["--tasks", "0"],
        ["--sigma", "-1"],
        ["--spacing", "0"],
        ["--only", "3"],
    ],
)
def test_bad_arguments_exit_2(argv, capsys):
    assert evaluate_main(["navigation", *argv]) == 2
    assert "error:" in capsys.readouterr().err


def test_rotate_plan_keeps_areas():
    from shapely.geometry import box

    from f2n_drake.core.plan import FloorPlan

    plan = FloorPlan({"wall": [box(0, 0, 4, 0.2)], "bedroom": [box(0, 0.2, 4, 3)]}, 0.2, "t")
    turned = navigation.rotate_plan(plan, 20.0)
    assert turned.metadata["rotation_deg"] == 20.0
    assert turned["wall"][0].area == pytest.approx(plan["wall"][0].area)
    assert turned.bounds != plan.bounds


def test_world_options_are_reported_beside_the_modes(capsys):
    argv = ["navigation", "--plans", "1", "--tasks", "1", "--seed", "3", "--modes", "continuous"]
    world = ["--clutter", "0.1", "--people", "2", "--closed-doors", "1", "--deviation", "0.05"]
    assert evaluate_main([*argv, *world, "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["world"] == {
        "clutter_fraction": 0.1,
        "people": 2,
        "closed_doors": 1,
        "deviation_m": 0.05,
    }
    (stats,) = report["modes"].values()
    assert MODE_KEYS | {"person_collisions", "no_way"} <= set(stats)
    assert stats["no_way"] in (0, 1) and stats["person_collisions"] >= 0


@pytest.mark.parametrize(
    "argv", [["--clutter", "0.9"], ["--people", "-1"], ["--deviation", "nan"], ["--people", "99"]]
)
def test_bad_world_options_exit_2(argv, capsys):
    assert evaluate_main(["navigation", *argv]) == 2
    assert "error:" in capsys.readouterr().err
