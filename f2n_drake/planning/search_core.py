"""The compiled 8-connected grid search core (numba, binary heap) behind A* and Dijkstra.

One search core serves both the global baseline and the hierarchical planner's local searches,
so their timings compare like with like. Grids are (rows, cols) arrays; cells are (row, col).

Cost model: a step to a neighbour costs its length (1 straight, ``diagonal_cost`` diagonal,
√2 by default) times the cost multiplier of the cell entered (1 when no multiplier array is
given). Diagonal steps never cut a corner: both orthogonal cells beside the step must be
passable. The heuristic is the octile distance (Chebyshev when ``diagonal_cost`` is 1) scaled by
the smallest multiplier, hence admissible and consistent (Hart, Nilsson & Raphael 1968).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

SQRT2 = math.sqrt(2.0)

NEIGHBOUR_DR = np.array([-1, 1, 0, 0, -1, -1, 1, 1], dtype=np.int64)
NEIGHBOUR_DC = np.array([0, 0, -1, 1, -1, 1, -1, 1], dtype=np.int64)


@dataclass(frozen=True)
class GridPath:
    """Result of one grid search.

    Attributes:
        cells: (N, 2) int64 (row, col) from start to goal; empty when no path.
        cost: path cost [px x multiplier]; ``inf`` when no path.
        expanded: number of cells expanded (popped and closed).
    """

    cells: np.ndarray
    cost: float
    expanded: int

    @property
    def found(self) -> bool:
        return len(self.cells) > 0


BLOCKED, OPEN, CLOSED = 0, 1, 2
"""States of a cell in the search's padded work grid."""

TIE_BREAK = 1e-6
"""Relative inflation of the heuristic: among equal-f cells the one nearer the goal is expanded
first (far fewer expansions on open octile grids); the cost found is within 1e-6 of optimal."""


@njit(cache=True, nogil=True, inline="always")
def _sift_up(heap, i, item):
    while i > 0:
        p = (i - 1) >> 1
        if heap[p] <= item:
            break
        heap[i] = heap[p]
        i = p
    heap[i] = item


@njit(cache=True, nogil=True, inline="always")
def _sift_down(heap, size, item):
    i = 0
    while True:
        child = 2 * i + 1
        if child >= size:
            break
        if child + 1 < size and heap[child + 1] < heap[child]:
            child += 1
        if heap[child] < item:
            heap[i] = heap[child]
            i = child
        else:
            break
    heap[i] = item


@njit(cache=True, nogil=True)
def trace_path(parent, cell, pcols):
    """Cells (row, col) of the unpadded grid from the root to padded flat ``cell``."""
    n = 0
    c = cell
    while c >= 0:
        n += 1
        c = parent[c]
    out = np.empty((n, 2), np.int64)
    c = cell
    for k in range(n - 1, -1, -1):
        out[k, 0] = c // pcols - 1
        out[k, 1] = c % pcols - 1
        c = parent[c]
    return out


@njit(cache=True, nogil=True)
def grid_search(passable, cost, uniform, src, src_g, goal, label, n_labels, diag, h_scale):
    """Shared core, binary heap with lazy deletion, on a copy of the grid padded by one
    blocked cell so the inner loop needs no bounds checks. ``src``/``goal`` are (row, col)
    flat indices of the unpadded grid. ``goal >= 0``: A* to that cell (``label`` ignored).
    ``goal < 0``: Dijkstra until one cell of every label 0..n_labels-1 of ``label`` settles.

    Returns (parent over the padded grid, best padded cell per label, its cost, expanded,
    g over the padded grid)."""
    rows, cols = passable.shape
    pcols = cols + 2
    n = (rows + 2) * pcols
    free = np.zeros(n, np.uint8)
    for r in range(rows):
        base = (r + 1) * pcols + 1
        for c in range(cols):
            free[base + c] = passable[r, c]
    offsets = np.empty(8, np.int64)
    for k in range(8):
        offsets[k] = NEIGHBOUR_DR[k] * pcols + NEIGHBOUR_DC[k]
    g = np.full(n, np.inf)
    parent = np.full(n, -1, np.int32)
    best = np.full(max(n_labels, 1), -1, np.int64)
    best_g = np.full(max(n_labels, 1), np.inf)
    cap = max(4096, 2 * src.shape[0])
    heap = np.empty(cap, np.int64)
    size = 0
    # Heap items pack (fixed-point key << idx_bits) | cell into one int64: one compare per
    # level. The key resolution is 1/kscale px (about 1e-5 px on 512^2, 4e-4 px on 4096^2).
    idx_bits = 1
    while (1 << idx_bits) < n:
        idx_bits += 1
    idx_mask = (1 << idx_bits) - 1
    cost_max = 1.0 if uniform else max(1.0, cost.max())
    key_max = 2.0 * n * max(diag, 1.0) * cost_max * (1.0 + TIE_BREAK) + 1.0
    kscale = float(1 << (62 - idx_bits)) / key_max
    has_goal = goal >= 0
    gr = goal // cols + 1 if has_goal else 0
    gc = goal % cols + 1 if has_goal else 0
    pgoal = gr * pcols + gc if has_goal else -1
    h_weight = h_scale * (1.0 + TIE_BREAK)
    for k in range(src.shape[0]):
        sr = src[k] // cols + 1
        sc = src[k] % cols + 1
        s = sr * pcols + sc
        if src_g[k] < g[s]:
            g[s] = src_g[k]
            h = 0.0
            if has_goal:
                dr = abs(sr - gr)
                dc = abs(sc - gc)
                h = h_weight * (max(dr, dc) + (diag - 1.0) * min(dr, dc))
            _sift_up(heap, size, (np.int64((src_g[k] + h) * kscale) << idx_bits) | s)
            size += 1
    expanded = 0
    remaining = n_labels
    while size > 0:
        cur = heap[0] & idx_mask
        size -= 1
        if size > 0:
            _sift_down(heap, size, heap[size])
        if free[cur] == CLOSED:
            continue
        free[cur] = CLOSED
        expanded += 1
        gcur = g[cur]
        r = cur // pcols
        c = cur - r * pcols
        if has_goal:
            if cur == pgoal:
                best[0] = cur
                best_g[0] = gcur
                break
        elif n_labels > 0:
            lab = label[r - 1, c - 1]
            if lab >= 0 and best[lab] < 0:
                best[lab] = cur
                best_g[lab] = gcur
                remaining -= 1
                if remaining == 0:
                    break
        for k in range(8):
            nxt = cur + offsets[k]
            if free[nxt] != OPEN:
                continue
            step = 1.0
            if k >= 4:
                if (
                    free[cur + NEIGHBOUR_DR[k] * pcols] == BLOCKED
                    or free[cur + NEIGHBOUR_DC[k]] == BLOCKED
                ):
                    continue
                step = diag
            nr = r + NEIGHBOUR_DR[k]
            nc = c + NEIGHBOUR_DC[k]
            ng = gcur + (step if uniform else step * cost[nr - 1, nc - 1])
            if ng < g[nxt]:
                g[nxt] = ng
                parent[nxt] = cur
                key = ng
                if has_goal:
                    dr = abs(nr - gr)
                    dc = abs(nc - gc)
                    key += h_weight * (max(dr, dc) + (diag - 1.0) * min(dr, dc))
                if size == cap:
                    cap *= 2
                    heap2 = np.empty(cap, np.int64)
                    heap2[:size] = heap[:size]
                    heap = heap2
                _sift_up(heap, size, (np.int64(key * kscale) << idx_bits) | nxt)
                size += 1
    return parent, best, best_g, expanded, g


def prepare_search(
    free: np.ndarray, cost: np.ndarray | None, mask: np.ndarray | None
) -> tuple[np.ndarray, np.ndarray, bool, float]:
    passable = np.asarray(free, dtype=bool)
    if mask is not None:
        if mask.shape != passable.shape:
            raise ValueError(f"mask shape {mask.shape} != grid shape {passable.shape}")
        passable = passable & mask
    if cost is None:
        return np.ascontiguousarray(passable), np.ones((1, 1)), True, 1.0
    if cost.shape != passable.shape:
        raise ValueError(f"cost shape {cost.shape} != grid shape {passable.shape}")
    h_scale = float(cost[passable].min()) if passable.any() else 1.0
    if not h_scale > 0:
        raise ValueError("cost multipliers must be positive on passable cells")
    return np.ascontiguousarray(passable), np.ascontiguousarray(cost, np.float64), False, h_scale
