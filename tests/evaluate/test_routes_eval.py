"""The end-to-end route check: the wall-crossing measure on a hand-made plan, routes on a drawing
parsed with ground-truth labels (and what a planner that does not bridge door outlines makes of
it), the CLI's JSON and its argument errors."""

import json

import numpy as np
from shapely.geometry import box

import f2n_drake.mapping.occupancy as planning_grid
from f2n_drake.core.plan import FloorPlan
from f2n_drake.datasets.generator import generate_plan
from f2n_drake.datasets.render import render
from f2n_drake.evaluate.__main__ import main as evaluate_main
from f2n_drake.evaluate.routes import CROSSING_TOLERANCE_M, check_routes, inside_walls_m
from f2n_drake.mapping.robots import GROUND
from f2n_drake.pipeline import parse_drawing


def test_inside_walls_is_the_length_of_the_path_within_walls():
    plan = FloorPlan(
        {
            "living": [box(0, 0, 2, 4)],
            "bedroom": [box(2.2, 0, 4, 4)],
            "wall": [box(2, 0, 2.2, 4)],
            "window": [box(0, 4, 2, 4.2)],
        },
        0.2,
        "test",
    )
    rendered = render(plan, metres_per_px=0.02)
    to_px = rendered.grid.to_px
    across = to_px(np.array([[1.0, 2.0], [3.0, 2.0]]))  # through the 0.2 m wall
    assert abs(inside_walls_m(across, rendered, plan) - 0.2) < 1e-6
    out_of_window = to_px(np.array([[1.0, 3.5], [1.0, 4.5]]))  # windows are not walls
    assert inside_walls_m(out_of_window, rendered, plan) == 0.0
    along = to_px(np.array([[0.5, 1.0], [1.5, 3.0], [0.5, 3.5]]))
    assert inside_walls_m(along, rendered, plan) == 0.0
    assert inside_walls_m(across[:1], rendered, plan) == 0.0


class _Truth:
    """A segmenter that returns the drawing's true labels."""

    def __init__(self, labels):
        self.labels = labels

    def predict(self, image):
        return self.labels


def _parsed_drawing(seed=0):
    plan = generate_plan(seed)
    rendered = render(plan, 512)
    parsed = parse_drawing(
        rendered.image,
        segmenter=_Truth(rendered.labels),
        metres_per_px=rendered.grid.metres_per_px,
    )
    return plan, rendered, parsed


def test_every_space_the_graph_reaches_is_routed_clear_of_the_true_walls():
    plan, rendered, parsed = _parsed_drawing()
    checks = check_routes(plan, rendered, parsed, GROUND)
    n_spaces = sum(len(plan[c]) for c in ("living", "bedroom", "bathroom", "kitchen", "balcony"))
    assert len(checks) >= n_spaces - 1  # an open kitchen may share the living room's instance
    assert all(c.routed for c in checks)
    assert all(c.inside_walls_m is not None for c in checks)
    assert max(c.inside_walls_m for c in checks) < CROSSING_TOLERANCE_M


def test_a_planner_that_does_not_bridge_door_outlines_fails_the_check(monkeypatch):
    plan, rendered, parsed = _parsed_drawing()
    monkeypatch.setattr(planning_grid, "bridge_px", lambda parsed: 0)
    checks = check_routes(plan, rendered, parsed, GROUND)
    behind_doors = [c for c in checks if c.goal.startswith(("bedroom", "bathroom", "balcony"))]
    assert behind_doors and not any(c.routed for c in behind_doors)


def test_cli_prints_one_json_object(capsys):
    args = ["routes", "--synthetic", "1", "--seed", "3", "--styles", "clean", "--json"]
    assert evaluate_main(args) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["n_images"] == 1 and report["styles"] == "clean"
    assert report["spaces_reached_in_graph"] >= 3
    assert report["unroutable"] == 0 and report["wall_crossings"] == 0
    assert report["routes_checked_against_walls"] == report["spaces_reached_in_graph"]


def test_cli_argument_errors_exit_with_code_2(capsys):
    assert evaluate_main(["routes", "--synthetic", "0"]) == 2
    assert evaluate_main(["routes", "--size", "10"]) == 2
    assert evaluate_main(["routes", "--seed", "999999", "--synthetic", "2"]) == 2
    assert "error" in capsys.readouterr().err
