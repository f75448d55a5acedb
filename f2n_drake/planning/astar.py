"""Compiled 8-connected grid A* (numba, binary heap) from a start cell to a goal cell.

The search core and its cost model live in :mod:`f2n_drake.planning.search_core`; multi-source
Dijkstra, distance fields and their descent in :mod:`f2n_drake.planning.fields`. Both are
re-exported here.
"""

from __future__ import annotations

import math

import numpy as np

from f2n_drake.core.errors import PlanningError
from f2n_drake.planning.fields import DistanceField, descend, dijkstra_to_labels, distance_field
from f2n_drake.planning.search_core import (
    BLOCKED,
    CLOSED,
    OPEN,
    SQRT2,
    TIE_BREAK,
    GridPath,
    grid_search,
    prepare_search,
    trace_path,
)

__all__ = [
    "BLOCKED",
    "CLOSED",
    "OPEN",
    "SQRT2",
    "TIE_BREAK",
    "DistanceField",
    "GridPath",
    "astar",
    "descend",
    "dijkstra_to_labels",
    "distance_field",
    "path_length",
    "warm_up",
]


def _check_cell(passable: np.ndarray, cell: tuple[int, int], what: str) -> int:
    r, c = int(cell[0]), int(cell[1])
    rows, cols = passable.shape
    if not (0 <= r < rows and 0 <= c < cols):
        raise PlanningError(f"{what} cell {(r, c)} lies outside the {rows}x{cols} grid")
    if not passable[r, c]:
        raise PlanningError(f"{what} cell {(r, c)} is blocked")
    return r * cols + c


def astar(
    free: np.ndarray,
    start: tuple[int, int],
    goal: tuple[int, int],
    *,
    cost: np.ndarray | None = None,
    mask: np.ndarray | None = None,
    diagonal_cost: float = SQRT2,
) -> GridPath:
    """Shortest 8-connected path from ``start`` to ``goal`` (row, col) on a boolean grid.

    Args:
        free: (H, W) bool, True where the robot centre may be.
        cost: optional (H, W) positive multiplier of the cost of entering each cell.
        mask: optional (H, W) bool restricting the search (cells outside are blocked).
        diagonal_cost: length of a diagonal step, √2 (octile) or 1 (Chebyshev).

    Returns a :class:`GridPath`; ``found`` is False when the goal is unreachable.
    Raises PlanningError when start or goal is outside the grid or blocked.
    """
    passable, cost_arr, uniform, h_scale = prepare_search(free, cost, mask)
    s = _check_cell(passable, start, "start")
    t = _check_cell(passable, goal, "goal")
    label = np.zeros((1, 1), np.int32)
    parent, best, best_g, expanded, _ = grid_search(
        passable,
        cost_arr,
        uniform,
        np.array([s], np.int64),
        np.zeros(1),
        t,
        label,
        1,
        float(diagonal_cost),
        h_scale,
    )
    if best[0] < 0:
        return GridPath(np.empty((0, 2), np.int64), math.inf, int(expanded))
    return GridPath(
        trace_path(parent, best[0], passable.shape[1] + 2), float(best_g[0]), int(expanded)
    )


def path_length(cells: np.ndarray) -> float:
    """Euclidean length of a polyline of (row, col) cells [px]."""
    cells = np.asarray(cells, dtype=float)
    if len(cells) < 2:
        return 0.0
    return float(np.hypot(*np.diff(cells, axis=0).T).sum())


def warm_up() -> None:
    """Compile (or load from cache) the search kernels on a tiny grid."""
    grid = np.ones((4, 4), bool)
    astar(grid, (0, 0), (3, 3))
    astar(grid, (0, 0), (3, 3), cost=np.ones((4, 4)))
    lab = np.full((4, 4), -1, np.int32)
    lab[3, 3] = 0
    dijkstra_to_labels(grid, np.array([[0, 0]]), lab, 1)
    distance_field(grid, np.array([[0, 0]])).path_from((3, 3))
    from f2n_drake.planning.smoothing import polyline_clear, shortcut

    path = np.array([[0, 0], [1, 1], [2, 2], [3, 3]])
    shortcut(path, grid)
    polyline_clear(path, grid)
