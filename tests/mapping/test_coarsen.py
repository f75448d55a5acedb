"""Coarsening a parsed plan for planning: walls stay closed, doors stay open, metres stay put."""

from __future__ import annotations

import numpy as np
import pytest

from f2n_drake.core.parsed import Instance, ParsedPlan
from f2n_drake.core.raster import PixelGrid
from f2n_drake.datasets.generator import generate_plan
from f2n_drake.datasets.ground_truth import parse_ground_truth
from f2n_drake.mapping.graph import build_connectivity_graph
from f2n_drake.mapping.resolution import at_planning_resolution, coarsened, planning_factor
from f2n_drake.planning.hierarchical import plan_route


def _parsed(ids: np.ndarray, classes: dict[int, str], metres_per_px: float = 0.01) -> ParsedPlan:
    instances = [
        Instance(
            i, c, np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]), int((ids == i).sum()), (0, 0)
        )
        for i, c in classes.items()
    ]
    grid = PixelGrid.from_scale(metres_per_px, ids.shape)
    return ParsedPlan(ids.astype(np.int32), np.zeros(ids.shape, np.uint8), instances, grid)


def _touch(ids: np.ndarray, a: int, b: int) -> bool:
    """Whether instances a and b are 4-neighbours anywhere."""
    pairs = [(ids[:, :-1], ids[:, 1:]), (ids[:-1], ids[1:])]
    return any((((x == a) & (y == b)) | ((x == b) & (y == a))).any() for x, y in pairs)


@pytest.mark.parametrize("offset", [0, 1, 2])
def test_a_one_pixel_wall_keeps_two_rooms_apart_and_a_thin_door_stays(offset):
    ids = np.zeros((60, 61), np.int32)
    wall = 30 + offset  # a 1 px line, anywhere in a 3 px block
    ids[:, :wall] = 1
    ids[:, wall + 1 :] = 2
    ids[24:36, wall] = 3  # a door one pixel thick, in the line
    ids[0, :] = ids[-1, :] = 0
    parsed = _parsed(ids, {1: "living", 2: "bedroom", 3: "door"})
    coarse = coarsened(parsed, 3)
    assert coarse.instance_ids.shape == (20, 21)
    assert not _touch(coarse.instance_ids, 1, 2)  # the line still parts the rooms
    assert _touch(coarse.instance_ids, 1, 3) and _touch(coarse.instance_ids, 2, 3)
    assert {i.id for i in coarse.instances} == {1, 2, 3}
    assert coarse.grid.metres_per_px == pytest.approx(0.03)
    assert coarse.grid.origin_m == parsed.grid.origin_m


def test_instances_keep_their_place_in_metres_and_lose_what_no_cell_keeps():
    ids = np.zeros((90, 90), np.int32)
    ids[10:70, 20:80] = 1
    ids[80, 5] = 2  # a one-pixel speck amid line pixels: no cell keeps it
    parsed = _parsed(ids, {1: "kitchen", 2: "bedroom"})
    fine = Instance(
        1, "kitchen", np.array([[20.0, 10.0], [79.0, 10.0], [79.0, 69.0]]), 3600, (49.5, 39.5)
    )
    parsed = ParsedPlan(
        parsed.instance_ids, parsed.labels, [fine, parsed.instances[1]], parsed.grid
    )
    coarse = coarsened(parsed, 3)
    (kitchen,) = [i for i in coarse.instances if i.id == 1]
    np.testing.assert_allclose(
        kitchen.centroid_m(coarse.grid), fine.centroid_m(parsed.grid), atol=0.015
    )
    np.testing.assert_allclose(kitchen.contour_m(coarse.grid), fine.contour_m(parsed.grid))
    # the outline's cells go to the lines: a 0.6 m room loses up to a cell along each side
    assert (
        0.8 * fine.area_m2(parsed.grid) < kitchen.area_m2(coarse.grid) <= fine.area_m2(parsed.grid)
    )
    assert 2 not in {i.id for i in coarse.instances}


def test_planning_factor_keeps_cells_at_most_the_planning_cell():
    grid = lambda m: PixelGrid.from_scale(m, (10, 10))  # noqa: E731
    assert planning_factor(grid(0.0243)) == 1  # the bundled example: as drawn
    assert planning_factor(grid(0.008)) == 2
    assert planning_factor(grid(0.005)) == 4
    assert planning_factor(None) == 1
    with pytest.raises(ValueError):
        coarsened(_parsed(np.ones((4, 4), np.int32), {1: "living"}), 0)


def test_a_high_resolution_plan_routes_like_the_drawing_and_faster():
    parsed = parse_ground_truth(generate_plan(3), size_px=1800)
    assert planning_factor(parsed.grid) >= 2
    coarse = at_planning_resolution(parsed)
    assert coarse.instance_ids.size * 4 <= parsed.instance_ids.size
    routes = []
    for p in (parsed, coarse):
        graph = build_connectivity_graph(p)
        assert sorted(graph.edges) == sorted(build_connectivity_graph(parsed).edges)
        goal = max(
            (n for n, d in graph.nodes(data=True) if d.get("kind") == "space"),
            key=lambda n: graph.nodes[n]["area_m2"],
        )
        routes.append(plan_route(p, graph, "ground", "front_door_0", goal))
    fine, rough = routes
    assert rough.sequence == fine.sequence
    assert rough.length_m == pytest.approx(fine.length_m, rel=0.05)
    assert rough.timings["precompute"] < fine.timings["precompute"]
