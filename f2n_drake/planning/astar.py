"""Compiled 8-connected grid A* and multi-source/multi-target Dijkstra (numba, binary heap).

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

from f2n_drake.errors import PlanningError

SQRT2 = math.sqrt(2.0)

_DR = np.array([-1, 1, 0, 0, -1, -1, 1, 1], dtype=np.int64)
_DC = np.array([0, 0, -1, 1, -1, 1, -1, 1], dtype=np.int64)


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
def _trace(parent, cell, pcols):
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
def _search(passable, cost, uniform, src, src_g, goal, label, n_labels, diag, h_scale):
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
        offsets[k] = _DR[k] * pcols + _DC[k]
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
                if free[cur + _DR[k] * pcols] == BLOCKED or free[cur + _DC[k]] == BLOCKED:
                    continue
                step = diag
            nr = r + _DR[k]
            nc = c + _DC[k]
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


def _prepare(
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
    passable, cost_arr, uniform, h_scale = _prepare(free, cost, mask)
    s = _check_cell(passable, start, "start")
    t = _check_cell(passable, goal, "goal")
    label = np.zeros((1, 1), np.int32)
    parent, best, best_g, expanded, _ = _search(
        passable, cost_arr, uniform, np.array([s], np.int64), np.zeros(1), t, label, 1,
        float(diagonal_cost), h_scale)
    if best[0] < 0:
        return GridPath(np.empty((0, 2), np.int64), math.inf, int(expanded))
    return GridPath(_trace(parent, best[0], passable.shape[1] + 2), float(best_g[0]), int(expanded))


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
    passable, cost_arr, uniform, _ = _prepare(passable, cost, None)
    sources = np.asarray(sources, np.int64).reshape(-1, 2)
    flat = sources[:, 0] * passable.shape[1] + sources[:, 1]
    src_g = np.zeros(len(flat)) if source_cost is None else np.asarray(source_cost, np.float64)
    labels = np.ascontiguousarray(labels, np.int32)
    parent, best, best_g, expanded, _ = _search(
        passable, cost_arr, uniform, flat, src_g, -1, labels, int(n_labels),
        float(diagonal_cost), 1.0)
    cols = passable.shape[1] + 2
    paths = []
    for k in range(n_labels):
        if best[k] < 0:
            paths.append(GridPath(np.empty((0, 2), np.int64), math.inf, 0))
        else:
            paths.append(GridPath(_trace(parent, best[k], cols), float(best_g[k]), 0))
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
        return _trace(self.parent, idx, self.shape[1] + 2)[::-1]


def distance_field(
    passable: np.ndarray,
    sources: np.ndarray,
    *,
    cost: np.ndarray | None = None,
    diagonal_cost: float = SQRT2,
) -> DistanceField:
    """Dijkstra from all ``sources`` (K, 2) (row, col) over the whole passable component."""
    passable, cost_arr, uniform, _ = _prepare(passable, cost, None)
    sources = np.asarray(sources, np.int64).reshape(-1, 2)
    flat = sources[:, 0] * passable.shape[1] + sources[:, 1]
    parent, _, _, expanded, g = _search(
        passable, cost_arr, uniform, flat, np.zeros(len(flat)), -1,
        np.full((1, 1), -1, np.int32), 0, float(diagonal_cost), 1.0)
    return DistanceField(g.astype(np.float32), parent, passable.shape, int(expanded))


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


@njit(cache=True, nogil=True)
def descend(field, r0, c0, cost, uniform, r, c, out, n):
    """Append to ``out[n:]`` the cells (row, col) from (r, c) down a distance field to its
    source (field 0) and return the new count (-1 when (r, c) is unreachable or ``out`` full).

    ``field`` is an (h, w) float32 window whose top-left is cell (r0, c0) of the (H, W) grid
    ``cost`` (ignored when ``uniform``); it was built with :func:`_search`'s step model, so
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
            nr = lr + _DR[k]
            nc = lc + _DC[k]
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

