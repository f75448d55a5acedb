"""The closed-door benchmark: extra doors make loops; the CLI's JSON."""

from __future__ import annotations

import json

import networkx as nx
import numpy as np

from f2n_drake.datasets.generator import generate_plan, validate_plan
from f2n_drake.evaluate.__main__ import main as evaluate_main
from f2n_drake.evaluate.replanning import with_extra_doors


def _room_loops(plan) -> list:
    from f2n_drake import build_graph
    from f2n_drake.datasets.ground_truth import parse_ground_truth

    graph = build_graph(parse_ground_truth(plan, size_px=512), planning_cell_m=None).graph
    inside = [
        k
        for k, d in graph.nodes(data=True)
        if (d.get("kind") == "space" and d.get("class_name") != "balcony")
        or d.get("class_name") in ("door", "opening")
    ]
    return nx.cycle_basis(nx.Graph(graph.subgraph(inside)))


def test_extra_doors_make_a_loop_of_rooms():
    plan = generate_plan(1)
    more = with_extra_doors(plan, np.random.default_rng(0), 2)
    assert len(more["door"]) == len(plan["door"]) + 2 and validate_plan(more) == []
    assert not _room_loops(plan) and _room_loops(more)


def test_one_task_json(capsys):
    argv = ["replanning", "--plans", "1", "--tasks", "1", "--seed", "1", "--no-baseline"]
    assert evaluate_main([*argv, "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["tasks"] == 1 and report["extra_doors"] == 2
    way, no_way = report["other_way"], report["no_other_way"]
    assert way["tasks"] + no_way["tasks"] == 1
    assert way["collisions"] + no_way["collisions"] == 0
    if way["tasks"]:
        assert way["success_rate"] == 1.0
    else:
        assert no_way["message_rate"] == 1.0
    assert report["realtime_factor"]["closed_door"] > 1.0


def test_navigation_benchmark_with_the_replanner(capsys):
    argv = ["navigation", "--plans", "1", "--tasks", "1", "--seed", "3", "--modes", "continuous"]
    assert evaluate_main([*argv, "--replan", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["replan"] is True
    stats = report["modes"]["continuous"]
    assert stats["success_rate"] == 1.0 and stats["replans"] == 0  # nothing in the way
