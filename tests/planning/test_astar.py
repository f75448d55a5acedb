"""Compiled grid A*, Dijkstra fields and line-of-sight smoothing on small hand-made grids."""

import math

import numpy as np
import pytest

from f2n_drake.core.errors import PlanningError
from f2n_drake.planning.astar import (
    SQRT2,
    astar,
    descend,
    dijkstra_to_labels,
    distance_field,
    path_length,
)
from f2n_drake.planning.smoothing import polyline_clear, segment_clear, shortcut, string_pull


def test_open_grid_costs_use_diagonals():
    free = np.ones((5, 5), bool)
    assert astar(free, (0, 0), (4, 4)).cost == pytest.approx(4 * SQRT2, rel=1e-6)
    found = astar(free, (0, 0), (2, 4))
    assert found.cost == pytest.approx(2 * SQRT2 + 2, rel=1e-6)
    assert tuple(found.cells[0]) == (0, 0) and tuple(found.cells[-1]) == (2, 4)
    assert np.abs(np.diff(found.cells, axis=0)).max() == 1  # 8-connected steps
    assert astar(free, (0, 0), (4, 4), diagonal_cost=1.0).cost == pytest.approx(4, rel=1e-6)


def test_no_corner_cutting():
    free = np.ones((3, 3), bool)
    free[0, 1] = False
    found = astar(free, (0, 0), (1, 1))
    assert found.cost == pytest.approx(2.0, rel=1e-6)  # via (1, 0), not diagonally past (0, 1)
    free[1, 0] = False
    assert not astar(free, (0, 0), (1, 1)).found  # only a corner-cutting step would remain


def test_unreachable_goal_and_blocked_endpoints():
    free = np.ones((6, 6), bool)
    free[:, 3] = False
    found = astar(free, (0, 0), (0, 5))
    assert not found.found and math.isinf(found.cost) and found.expanded > 0
    with pytest.raises(PlanningError, match="blocked"):
        astar(free, (0, 3), (0, 5))
    with pytest.raises(PlanningError, match="outside"):
        astar(free, (0, 0), (9, 9))


def test_optimal_and_heuristic_admissible_on_random_grids():
    rng = np.random.default_rng(3)
    for _ in range(20):
        free = rng.random((30, 40)) > 0.3
        cells = np.argwhere(free)
        s, g = (tuple(cells[k]) for k in rng.integers(len(cells), size=2))
        field = distance_field(free, np.array([g]))
        exact = field.cost_at(s)
        found = astar(free, s, g)
        if math.isinf(exact):
            assert not found.found
            continue
        assert found.cost == pytest.approx(exact, rel=1e-5, abs=1e-5)
        assert path_length(found.cells) == pytest.approx(found.cost, rel=1e-6)
        # octile distance never exceeds the true cost to the goal
        reach = np.argwhere(free)
        true = np.array([field.cost_at(tuple(c)) for c in reach])
        d = np.abs(reach - np.array(g))
        octile = d.max(1) + (SQRT2 - 1) * d.min(1)
        ok = np.isfinite(true)
        assert np.all(octile[ok] <= true[ok] + 1e-4)


def test_mask_restricts_search_and_cost_multipliers_steer():
    free = np.ones((7, 7), bool)
    mask = np.ones((7, 7), bool)
    mask[1:6, 3] = False  # a wall only in the mask
    assert astar(free, (3, 0), (3, 6)).cost == pytest.approx(6, rel=1e-6)
    assert astar(free, (3, 0), (3, 6), mask=mask).cost > 6.5
    with pytest.raises(PlanningError):
        astar(free, (3, 0), (3, 3), mask=mask)
    cost = np.ones((7, 7))
    cost[:, 3] = 10.0
    cost[0, 3] = 1.0  # a cheap crossing at the top row
    found = astar(free, (3, 0), (3, 6), cost=cost)
    assert (0, 3) in {tuple(c) for c in found.cells}


def test_multi_target_dijkstra_matches_astar():
    rng = np.random.default_rng(0)
    free = rng.random((25, 25)) > 0.25
    free[12, 12] = True
    labels = np.full(free.shape, -1, np.int32)
    targets = [tuple(c) for c in np.argwhere(free)[[5, 100, 300]]]
    for k, t in enumerate(targets):
        labels[t] = k
    paths, expanded = dijkstra_to_labels(free, np.array([[12, 12]]), labels, 3)
    assert expanded > 0
    for t, p in zip(targets, paths, strict=True):
        ref = astar(free, (12, 12), t)
        assert p.found == ref.found
        if ref.found:
            assert p.cost == pytest.approx(ref.cost, rel=1e-5)
            assert tuple(p.cells[-1]) == t


def test_line_of_sight_and_smoothing():
    free = np.ones((10, 10), bool)
    free[2:8, 5] = False
    assert segment_clear(free, 0, 0, 0, 9)
    assert not segment_clear(free, 4, 0, 4, 9)
    assert not segment_clear(np.array([[True, False], [False, True]]), 0, 0, 1, 1)  # corner
    path = astar(free, (4, 0), (4, 9)).cells
    smooth = shortcut(path, free)
    assert len(smooth) < len(path)
    assert polyline_clear(smooth, free)
    assert path_length(smooth) <= path_length(path) + 1e-9
    assert not polyline_clear(np.array([[4, 0], [4, 9]]), free)


def test_descending_a_field_gives_a_shortest_path_with_few_turns():
    rng = np.random.default_rng(1)
    free = rng.random((30, 40)) > 0.2
    free[0:3, 0:3] = True
    fld = distance_field(free, np.array([[1, 1]]))
    field = fld.cost.reshape(32, 42)[1:-1, 1:-1].copy()
    ok = 0
    for r, c in np.argwhere(np.isfinite(field))[::37]:
        out = np.empty((field.size, 2), np.int64)
        n = descend(field, 0, 0, np.ones((1, 1)), True, int(r), int(c), out, 0)
        cells = out[:n]
        assert tuple(cells[0]) == (r, c) and tuple(cells[-1]) == (1, 1)
        assert np.abs(np.diff(cells, axis=0)).max() <= 1
        assert path_length(cells) == pytest.approx(field[r, c], rel=1e-5, abs=1e-4)
        assert polyline_clear(cells, free)
        ok += 1
    assert ok > 5
    assert (
        descend(field, 0, 0, np.ones((1, 1)), True, 29, 39, np.empty((0, 2), np.int64), 0) == -1
    )  # no room in the output
    open_field = distance_field(np.ones((20, 20), bool), np.array([[0, 0]]))
    field = open_field.cost.reshape(22, 22)[1:-1, 1:-1].copy()
    out = np.empty((400, 2), np.int64)
    cells = out[: descend(field, 0, 0, np.ones((1, 1)), True, 19, 10, out, 0)]
    turns = np.abs(np.diff(np.diff(cells, axis=0), axis=0)).sum(1) > 0
    assert turns.sum() == 1  # one straight run and one diagonal run, not a staircase


def test_string_pull_is_clear_and_as_short_as_shortcut():
    rng = np.random.default_rng(4)
    for _ in range(10):
        free = np.ones((40, 60), bool)
        for _ in range(6):
            r, c = rng.integers(0, 36), rng.integers(0, 56)
            free[r : r + 4, c : c + 4] = False
        free[0, 0] = free[39, 59] = True
        path = astar(free, (0, 0), (39, 59)).cells
        if len(path) == 0:
            continue
        pulled = string_pull(path, free)
        assert tuple(pulled[0]) == (0, 0) and tuple(pulled[-1]) == (39, 59)
        assert polyline_clear(pulled, free)
        assert path_length(pulled) <= path_length(shortcut(path, free)) + 1.0
        assert path_length(pulled) <= path_length(path) + 1e-9
