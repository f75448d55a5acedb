"""The public API: parse_drawing, build_graph, plan_route, simulate, and the one parse that the
segmentation evaluation measures."""

from __future__ import annotations

import dataclasses
import subprocess
import sys

import numpy as np
import pytest
from helpers import Oracle, two_rooms

import f2n_drake
from f2n_drake import build_graph, parse_drawing, plan_route, simulate
from f2n_drake.core.errors import InputError
from f2n_drake.core.plan import FloorPlan
from f2n_drake.datasets.ground_truth import parse_ground_truth
from f2n_drake.evaluate import segmentation, segmentation_scores
from f2n_drake.mapping.graph import line_gap_px
from f2n_drake.mapping.occupancy import build_grids, occupancy_map
from f2n_drake.mapping.robots import GROUND, UAV
from f2n_drake.perception.ink import binarize
from f2n_drake.pipeline import PARSE_STEPS, PlanMap, parse_steps, segment_drawing
from f2n_drake.planning.hierarchical import HierarchicalPlanner


@pytest.fixture(scope="module")
def example_map(example_json) -> PlanMap:
    """The bundled plan's ground truth and graph on its own 256 px raster."""
    return build_graph(
        parse_ground_truth(FloorPlan.load(example_json), size_px=256), planning_cell_m=None
    )


def test_import_is_light_and_names_load_on_use():
    code = (
        "import sys, f2n_drake; "
        "heavy = {'torch', 'pydrake', 'cv2', 'f2n_drake.pipeline'} & set(sys.modules); "
        "assert not heavy, heavy; "
        "assert callable(f2n_drake.parse_drawing) and 'f2n_drake.pipeline' in sys.modules"
    )
    subprocess.run([sys.executable, "-c", code], check=True)
    for name in f2n_drake.__all__:
        assert getattr(f2n_drake, name) is not None
    with pytest.raises(AttributeError):
        f2n_drake.no_such_name  # noqa: B018


@pytest.mark.usefixtures("drawings_at_own_size")
def test_parse_drawing_is_the_last_parse_step():
    img, lab = two_rooms()
    lines = binarize(img)
    steps = parse_steps(img, segment_drawing(img, lines, lambda d: (lab, None)), lines=lines)
    assert tuple(steps) == PARSE_STEPS and PARSE_STEPS[0] == "instances"
    told = []
    parsed = parse_drawing(img, segmenter=Oracle(lab), progress=told.append)
    assert told == [
        "preparing the drawing",
        "reading the words",
        "segmenting the drawing",
        "closing rooms at their doorways, voting their classes",
    ]
    expected = steps[PARSE_STEPS[-1]]
    assert [i.class_name for i in parsed.instances] == [i.class_name for i in expected.instances]
    np.testing.assert_array_equal(parsed.instance_ids, expected.instance_ids)


def test_segmentation_evaluation_parses_with_the_parse_steps(monkeypatch, capsys):
    calls = []

    def recorded(*args, **kwargs):
        calls.append(kwargs["split"] is not None)
        return parse_steps(*args, **kwargs)

    monkeypatch.setattr(segmentation_scores, "parse_steps", recorded)
    code = segmentation.main(
        ["--synthetic", "1", "--seed", "0", "--json", "--size", "256"],
        predict=segmentation.oracle_predictor(0.0),
    )
    assert code == 0 and sorted(calls) == [False, True]  # with and without the split
    capsys.readouterr()


def test_plan_route_defaults_and_names(example_map):
    route = plan_route(example_map)
    assert route.sequence[0] == "front_door_0"
    planner = HierarchicalPlanner(example_map.parsed, example_map.graph, GROUND)
    same = planner.plan("front_door_0", route.sequence[-1])
    np.testing.assert_allclose(route.waypoints_m, same.waypoints_m)
    kitchen = plan_route(example_map, robot="uav", start="front_door", goal="kitchen")
    assert kitchen.sequence[0] == "front_door_0" and kitchen.sequence[-1] == "kitchen_0"
    with pytest.raises(InputError, match="no room"):
        plan_route(example_map, goal="garage")


def test_build_graph_plans_at_planning_resolution(example_json):
    fine = parse_ground_truth(FloorPlan.load(example_json), size_px=2048)
    plan_map = build_graph(fine)
    assert plan_map.parsed.instance_ids.shape[0] < fine.instance_ids.shape[0]
    assert build_graph(fine, planning_cell_m=None).parsed is fine


def test_one_occupancy_map_per_plan(example_map):
    free = example_map.occupancy("ground")
    assert (
        free
        is example_map.occupancy(GROUND)
        is occupancy_map(example_map.parsed, ["door", "front_door", "opening"])
    )
    assert not free.flags.writeable
    grids = build_grids(example_map.parsed, GROUND, example_map.graph)
    assert grids.free is free  # every door is wide enough: the planner searches the same map
    assert example_map.occupancy(UAV) is not free


def test_line_gap_is_measured_once_per_plan():
    img, lab = two_rooms()
    parsed = parse_drawing(img, segmenter=Oracle(lab))
    gap = line_gap_px(parsed)
    assert gap > 0 and parsed.derived(("line_gap_px", 16.0), lambda: -1.0) == gap
    copy = dataclasses.replace(parsed)  # a new plan: nothing derived yet
    assert copy.derived(("line_gap_px", 16.0), lambda: -1.0) == -1.0


def test_simulate_drives_a_plan_map(example_map):
    route = plan_route(example_map)
    result = simulate(example_map, route, correction="off", time_limit_s=1.0)
    assert result.time_s == pytest.approx(1.0) and not result.collided
    assert result.correction == "off" and len(result.true_path) >= 10


def test_build_graph_estimates_a_missing_scale_from_the_doors():
    img, lab = two_rooms()
    parsed = parse_drawing(img, segmenter=Oracle(lab))
    assert parsed.grid is None
    plan_map = build_graph(parsed)
    assert plan_map.parsed.scale_source.startswith("door-width estimate")
    assert plan_map.graph.graph["metres_per_px"] == plan_map.parsed.grid.metres_per_px


def test_plan_route_goes_to_the_next_farthest_room_it_can_reach(example_map, monkeypatch):
    from f2n_drake.core.errors import PlanningError
    from f2n_drake.planning.endpoints import default_start, goal_candidates

    start = default_start(example_map.graph, GROUND)
    farthest, runner_up = goal_candidates(example_map.graph, GROUND, start)[:2]
    plan = HierarchicalPlanner.plan

    def blocked(self, start, goal):  # the graph joins the farthest room; no path does
        if goal == farthest:
            raise PlanningError(f"no route to {goal}")
        return plan(self, start, goal)

    monkeypatch.setattr(HierarchicalPlanner, "plan", blocked)
    assert plan_route(example_map).sequence[-1] == runner_up
    with pytest.raises(PlanningError, match=farthest):  # a goal given is not swapped
        plan_route(example_map, goal=farthest)
