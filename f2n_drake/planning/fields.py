"""Multi-source Dijkstra: nearest cell of each target label, distance fields, their descent.

Exhaustive distance fields are kept for lookups and path tracing; :func:`descend` walks down one
to its source inside compiled (numba) code.

Same cost model as A* (see :mod:`f2n_drake.planning.search_core`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from f2n_drake.planning.search_core import (
    NEIGHBOUR_DC,
    NEIGHBOUR_DR,
    SQRT2,
    GridPath,
    grid_search,
    prepare_search,
    trace_path,
)


def dijkstra_to_labels(
    passable: np.ndarray,
    sources: np.ndarray,
    labels: np.ndarray,
    n_labels: int,
    *,
    cost: np.ndarray | None = None,
    source_cost: np.ndarray | None = None,
    diagonal_cost: float = SQRT2,
) -> tuple[list[GridPath], int]:
    """Multi-source Dijkstra to the nearest cell of each target label.

    Args:
        passable: (H, W) bool grid (already masked).
        sources: (K, 2) int (row, col) source cells, all passable.
        labels: (H, W) int32, target label 0..n_labels-1 per cell, -1 elsewhere.
        source_cost: optional (K,) initial cost of each source (0 by default).

    Returns one :class:`GridPath` per label (empty when unreachable; ``expanded`` is 0 in
    each) and the total number of cells expanded. The search stops once every label is reached.
    """
    passable, cost_arr, uniform, _ = prepare_search(passable, cost, None)
    sources = np.asarray(sources, np.int64).reshape(-1, 2)
    flat = sources[:, 0] * passable.shape[1] + sources[:, 1]
    src_g = np.zeros(len(flat)) if source_cost is None else np.asarray(source_cost, np.float64)
    labels = np.ascontiguousarray(labels, np.int32)
    parent, best, best_g, expanded, _ = grid_search(
        passable,
        cost_arr,
        uniform,
        flat,
        src_g,
        -1,
        labels,
        int(n_labels),
        float(diagonal_cost),
        1.0,
    )
    cols = passable.shape[1] + 2
    paths = []
    for k in range(n_labels):
        if best[k] < 0:
            paths.append(GridPath(np.empty((0, 2), np.int64), math.inf, 0))
        else:
            paths.append(GridPath(trace_path(parent, best[k], cols), float(best_g[k]), 0))
    return paths, int(expanded)


@dataclass(frozen=True)
class DistanceField:
    """Exhaustive multi-source Dijkstra over a grid, kept for lookups and path tracing.

    Attributes:
        cost: ((H+2)*(W+2),) float32 cost from the nearest source to each cell of the grid
            padded by one cell on every side [px x multiplier]; inf where unreachable.
        parent: ((H+2)*(W+2),) int32 padded index of each cell's predecessor, -1 at sources.
        shape: (H, W) of the unpadded grid.
        expanded: cells expanded to build it.
    """

    cost: np.ndarray
    parent: np.ndarray
    shape: tuple[int, int]
    expanded: int

    def index(self, cell: tuple[int, int]) -> int:
        return (int(cell[0]) + 1) * (self.shape[1] + 2) + int(cell[1]) + 1

    def cost_at(self, cell: tuple[int, int]) -> float:
        return float(self.cost[self.index(cell)])

    def path_from(self, cell: tuple[int, int]) -> np.ndarray:
        """(N, 2) cells (row, col) from ``cell`` back to its nearest source; empty if
        unreachable."""
        idx = self.index(cell)
        if not np.isfinite(self.cost[idx]):
            return np.empty((0, 2), np.int64)
        return trace_path(self.parent, idx, self.shape[1] + 2)[::-1]


def distance_field(
    passable: np.ndarray,
    sources: np.ndarray,
    *,
    cost: np.ndarray | None = None,
    diagonal_cost: float = SQRT2,
) -> DistanceField:
    """Dijkstra from all ``sources`` (K, 2) (row, col) over the whole passable component."""
    passable, cost_arr, uniform, _ = prepare_search(passable, cost, None)
    sources = np.asarray(sources, np.int64).reshape(-1, 2)
    flat = sources[:, 0] * passable.shape[1] + sources[:, 1]
    parent, _, _, expanded, g = grid_search(
        passable,
        cost_arr,
        uniform,
        flat,
        np.zeros(len(flat)),
        -1,
        np.full((1, 1), -1, np.int32),
        0,
        float(diagonal_cost),
        1.0,
    )
    return DistanceField(g.astype(np.float32), parent, passable.shape, int(expanded))


@njit(cache=True, nogil=True)
def descend(field, r0, c0, cost, uniform, r, c, out, n):
    """Append to ``out[n:]`` the cells (row, col) from (r, c) down a distance field to its
    source (field 0) and return the new count (-1 when (r, c) is unreachable or ``out`` full).

    ``field`` is an (h, w) float32 window whose top-left is cell (r0, c0) of the (H, W) grid
    ``cost`` (ignored when ``uniform``); it was built with :func:`grid_search`'s step model, so
    each step goes to the neighbour p minimising field[p] + step length x cost of the cell
    left (strictly decreasing: it ends at a source); among equal choices (within 1e-4) it
    keeps the previous direction, so paths in open space have few turns."""
    h, w = field.shape
    prev = -1
    lr = r - r0
    lc = c - c0
    if lr < 0 or lr >= h or lc < 0 or lc >= w or not np.isfinite(field[lr, lc]):
        return -1
    while True:
        if n >= out.shape[0]:
            return -1
        out[n, 0] = lr + r0
        out[n, 1] = lc + c0
        n += 1
        here = field[lr, lc]
        if here <= 0.0:
            return n
        cx = 1.0 if uniform else cost[lr + r0, lc + c0]
        best = np.inf
        br = -1
        bc = -1
        bk = -1
        for kk in range(9):
            k = prev if kk == 0 else kk - 1
            if k < 0 or (kk > 0 and k == prev):
                continue
            nr = lr + NEIGHBOUR_DR[k]
            nc = lc + NEIGHBOUR_DC[k]
            if nr < 0 or nr >= h or nc < 0 or nc >= w:
                continue
            v = field[nr, nc]
            if not v < here:  # also skips inf
                continue
            step = 1.0
            if k >= 4:
                if not (np.isfinite(field[nr, lc]) and np.isfinite(field[lr, nc])):
                    continue
                step = SQRT2
            v = v + step * cx
            if v < best - 1e-4:
                best = v
                br = nr
                bc = nc
                bk = k
        if br < 0:
            return -1
        lr = br
        lc = bc
        prev = bk
