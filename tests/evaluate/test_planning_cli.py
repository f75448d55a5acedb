"""The planning benchmark CLI: JSON figures on a couple of generated plans, argument errors."""

import json

from f2n_drake.evaluate.__main__ import main as evaluate_main


def test_planning_benchmark_json(capsys):
    assert evaluate_main(["planning", "--plans", "2", "--pairs", "4", "--seed", "3", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    for key in (
        "tasks",
        "global_ms_median",
        "hierarchical_ms_median",
        "hierarchical_precompute_ms_median",
        "speedup",
        "global_nodes_mean",
        "hierarchical_nodes_mean",
        "cost_ratio_mean",
        "failures",
        "cost_ratio_over_1",
        "hierarchical_precompute_expanded_median",
    ):
        assert key in out
    assert out["tasks"] == 8
    assert out["failures"] == 0
    assert out["cost_ratio_mean"] <= 1.0 + 1e-6
    assert out["cost_ratio_over_1"] == 0


def test_planning_benchmark_uav_json(capsys):
    argv = ["planning", "--plans", "1", "--pairs", "4", "--seed", "1", "--robot", "uav", "--json"]
    assert evaluate_main(argv) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["robot"] == "uav" and out["tasks"] == 4 and out["failures"] == 0


def test_planning_benchmark_rejects_bad_arguments(capsys):
    assert evaluate_main(["planning", "--plans", "0"]) == 2
    assert "error:" in capsys.readouterr().err
