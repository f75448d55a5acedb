"""Compiled query kernels of the hierarchical planner (numba): choosing the portal chain
(all-pairs look-ups or an A* over the portal graph), descending the distance fields into cells,
joining the pieces and shortcutting them.

Shared layout (built by :class:`~f2n_drake.planning.hierarchical.HierarchicalPlanner`):
``pinfo`` rows per portal: field offset into ``flat``, window row, col, height, width, region,
index in region, exit base; ``rtab`` rows per region: first portal, count, window row, col,
width; ``exit_cells[exit_base[p] + index of q]`` is the portal cell of q (same region as p).
"""

from __future__ import annotations

import heapq
import math

import numpy as np
from numba import njit

from f2n_drake.planning.astar import SQRT2, descend
from f2n_drake.planning.smoothing import segment_clear, string_pull_kernel


@njit(cache=True, nogil=True)
def _append_piece(buf, n, piece, m, reverse, clear, bad, nbad):
    """Append ``piece[:m]`` (reversed if asked) to ``buf[:n]``; a jump between pieces that is
    not clear on ``clear`` is recorded in ``bad``. Returns (buf, n, nbad)."""
    while n + m > buf.shape[0]:
        grown = np.empty((2 * buf.shape[0], 2), np.int64)
        grown[:n] = buf[:n]
        buf = grown
    for k in range(m):
        src = m - 1 - k if reverse else k
        r = piece[src, 0]
        c = piece[src, 1]
        if n > 0 and buf[n - 1, 0] == r and buf[n - 1, 1] == c:
            continue
        if n > 0 and k == 0 and (abs(buf[n - 1, 0] - r) > 1 or abs(buf[n - 1, 1] - c) > 1):
            if not segment_clear(clear, buf[n - 1, 0], buf[n - 1, 1], r, c):
                bad[nbad] = n
                nbad += 1
        buf[n, 0] = r
        buf[n, 1] = c
        n += 1
    return buf, n, nbad


@njit(cache=True, nogil=True)
def _owners_along(owner, pts):
    """Owner ids met along a polyline (jumps sampled every half cell), consecutive repeats
    and 0 dropped."""
    out = np.empty(64, np.int64)
    n = 0
    for k in range(pts.shape[0]):
        r1 = pts[k, 0]
        c1 = pts[k, 1]
        r0 = pts[k - 1, 0] if k > 0 else r1
        c0 = pts[k - 1, 1] if k > 0 else c1
        span = max(abs(r1 - r0), abs(c1 - c0))
        steps = 2 * span if span > 1 else 1
        for i in range(steps):
            if steps == 1:
                o = owner[r1, c1]
            else:
                t = (i + 1) / steps
                o = owner[int(r0 + t * (r1 - r0) + 0.5), int(c0 + t * (c1 - c0) + 0.5)]
            if o > 0 and (n == 0 or out[n - 1] != o):
                if n == out.shape[0]:
                    grown = np.empty(2 * n, np.int64)
                    grown[:n] = out[:n]
                    out = grown
                out[n] = o
                n += 1
    return out[:n]


@njit(cache=True, nogil=True)
def finish_query(cells, clear, owner, to_m):
    """Line-of-sight shortcut of ``cells`` (``string_pull_kernel``); returns (waypoints, their
    metres
    via the affine map ``to_m`` (3, 2): [row, col, 1] @ to_m, owner ids met, raw length,
    smoothed length [px])."""
    way = string_pull_kernel(cells, clear) if cells.shape[0] > 2 else cells.copy()
    metres = np.empty((way.shape[0], 2))
    for k in range(way.shape[0]):
        for j in range(2):
            metres[k, j] = way[k, 0] * to_m[0, j] + way[k, 1] * to_m[1, j] + to_m[2, j]
    raw = 0.0
    for k in range(cells.shape[0] - 1):
        raw += math.hypot(cells[k + 1, 0] - cells[k, 0], cells[k + 1, 1] - cells[k, 1])
    smooth = 0.0
    for k in range(way.shape[0] - 1):
        smooth += math.hypot(way[k + 1, 0] - way[k, 0], way[k + 1, 1] - way[k, 1])
    return way, metres, _owners_along(owner, cells), raw, smooth


@njit(cache=True, nogil=True)
def _field_piece(flat, pinfo, p, cost, uniform, r, c, tmp):
    off, r0, c0, h, w = pinfo[p, 0], pinfo[p, 1], pinfo[p, 2], pinfo[p, 3], pinfo[p, 4]
    field = flat[off : off + h * w].reshape(h, w)
    while True:
        m = descend(field, r0, c0, cost, uniform, r, c, tmp, 0)
        if m >= 0 or tmp.shape[0] > 4 * h * w + 8:
            return m, tmp
        tmp = np.empty((2 * tmp.shape[0], 2), np.int64)


@njit(cache=True, nogil=True)
def _assemble(chain, sr, sc, gr, gc, flat, pinfo, exit_cells, cost, uniform, clear):
    """Cells from (sr, sc) through the portal ``chain`` to (gr, gc): fields descended, pieces
    joined. ``pinfo`` rows: field offset, window row, col, height, width, region, index in
    region, exit base. Returns (cells, bad joins (indices into cells), number of bad joins,
    ok)."""
    buf = np.empty((1024, 2), np.int64)
    tmp = np.empty((1024, 2), np.int64)
    bad = np.empty(2 * chain.shape[0] + 2, np.int64)
    n = 0
    nbad = 0
    m, tmp = _field_piece(flat, pinfo, chain[0], cost, uniform, sr, sc, tmp)
    if m < 0:
        return buf[:0], bad, 0, False
    buf, n, nbad = _append_piece(buf, n, tmp, m, False, clear, bad, nbad)
    for t in range(chain.shape[0] - 1):
        p = chain[t]
        q = chain[t + 1]
        if pinfo[p, 5] != pinfo[q, 5]:
            continue  # crossing connector p == q: the next piece starts inside it
        e = pinfo[p, 7] + pinfo[q, 6]
        m, tmp = _field_piece(
            flat, pinfo, p, cost, uniform, exit_cells[e, 0], exit_cells[e, 1], tmp
        )
        if m < 0:
            return buf[:0], bad, 0, False
        buf, n, nbad = _append_piece(buf, n, tmp, m, True, clear, bad, nbad)
    p = chain[chain.shape[0] - 1]
    m, tmp = _field_piece(flat, pinfo, p, cost, uniform, gr, gc, tmp)
    if m < 0:
        return buf[:0], bad, 0, False
    buf, n, nbad = _append_piece(buf, n, tmp, m, True, clear, bad, nbad)
    return buf[:n].copy(), bad, nbad, True


@njit(cache=True, nogil=True)
def _choose(sr, sc, gr, gc, rs, rg, rtab, flat, pinfo, dist, pred):
    """Cheapest d_s[i] + D[i, j] + d_g[j] over the portals i of region ``rs`` and j of ``rg``
    (``rtab`` rows: first portal, count, window row, col, width; ``dist``, ``pred`` from
    :func:`portal_costs`); returns (cost, chain of portals from i to j) or (inf, empty)."""
    fs, ks, s0, s1, sw = rtab[rs, 0], rtab[rs, 1], rtab[rs, 2], rtab[rs, 3], rtab[rs, 4]
    fg, kg, g0, g1, gw = rtab[rg, 0], rtab[rg, 1], rtab[rg, 2], rtab[rg, 3], rtab[rg, 4]
    at_s = (sr - s0) * sw + sc - s1
    at_g = (gr - g0) * gw + gc - g1
    best = np.inf
    bi = -1
    bj = -1
    for j in range(kg):
        dg = flat[pinfo[fg + j, 0] + at_g]
        if not dg < np.inf:
            continue
        for i in range(ks):
            v = flat[pinfo[fs + i, 0] + at_s] + dist[fs + i, fg + j] + dg
            if v < best:
                best = v
                bi = fs + i
                bj = fg + j
    if bi < 0:
        return np.inf, np.empty(0, np.int64)
    return best, _chain(pred[bi], bi, bj)


@njit(cache=True, nogil=True)
def _chain(parent, first, last):
    """Portals from ``first`` to ``last`` following ``parent`` links back from ``last``."""
    n = 1
    p = last
    while p != first:
        p = parent[p]
        n += 1
    chain = np.empty(n, np.int64)
    p = last
    for k in range(n - 1, -1, -1):
        chain[k] = p
        if k > 0:
            p = parent[p]
    return chain


@njit(cache=True, nogil=True)
def _search_portals(
    sr, sc, gr, gc, rs, rg, rtab, flat, pinfo, indptr, indices, weights, pcell, h_scale
):
    """Like :func:`_choose` without all-pairs costs: A* over the portal graph (CSR) from the
    start region's portals (initial cost d_s) to the goal region's (final cost d_g), heuristic
    the octile distance of a portal cell to the goal x ``h_scale``. Returns (cost, chain,
    portals expanded)."""
    n = pinfo.shape[0]
    fs, ks, s0, s1, sw = rtab[rs, 0], rtab[rs, 1], rtab[rs, 2], rtab[rs, 3], rtab[rs, 4]
    fg, kg, g0, g1, gw = rtab[rg, 0], rtab[rg, 1], rtab[rg, 2], rtab[rg, 3], rtab[rg, 4]
    at_s = (sr - s0) * sw + sc - s1
    at_g = (gr - g0) * gw + gc - g1
    g = np.full(n, np.inf)
    parent = np.full(n, -1, np.int64)
    closed = np.zeros(n, np.bool_)
    to_goal = np.full(n, np.inf)
    for j in range(kg):
        to_goal[fg + j] = flat[pinfo[fg + j, 0] + at_g]
    heap = [(0.0, np.int64(0))]
    heap.pop()
    for i in range(ks):
        d = flat[pinfo[fs + i, 0] + at_s]
        p = fs + i
        if d < g[p]:
            g[p] = d
            dr = abs(pcell[p, 0] - gr)
            dc = abs(pcell[p, 1] - gc)
            heapq.heappush(heap, (d + h_scale * (max(dr, dc) + (SQRT2 - 1) * min(dr, dc)), p))
    best = np.inf
    bj = -1
    expanded = 0
    while len(heap) > 0:
        f, p = heapq.heappop(heap)
        if f >= best:
            break
        if closed[p]:
            continue
        closed[p] = True
        expanded += 1
        if g[p] + to_goal[p] < best:
            best = g[p] + to_goal[p]
            bj = p
        for e in range(indptr[p], indptr[p + 1]):
            q = indices[e]
            ng = g[p] + weights[e]
            if ng < g[q]:
                g[q] = ng
                parent[q] = p
                dr = abs(pcell[q, 0] - gr)
                dc = abs(pcell[q, 1] - gc)
                heapq.heappush(heap, (ng + h_scale * (max(dr, dc) + (SQRT2 - 1) * min(dr, dc)), q))
    if bj < 0:
        return np.inf, np.empty(0, np.int64), expanded
    first = bj
    while parent[first] >= 0:
        first = parent[first]
    return best, _chain(parent, first, bj), expanded


@njit(cache=True, nogil=True)
def _straight(sr, sc, gr, gc):
    cells = np.empty((2, 2), np.int64)
    cells[0, 0] = sr
    cells[0, 1] = sc
    cells[1, 0] = gr
    cells[1, 1] = gc
    return cells


@njit(cache=True, nogil=True)
def _complete(
    best, chain, bound, sr, sc, gr, gc, flat, pinfo, exit_cells, cost, uniform, clear, owner, to_m
):
    """Descend, join and shortcut ``chain`` unless ``best`` is not under ``bound``. Returns
    (kind: 1 via portals, 2 nothing cheaper than ``bound``, 3 a field could not be descended;
    cost, cells, bad joins, n bad, waypoints, metres, owners, raw length, smoothed length)."""
    empty = np.empty((0, 2), np.int64)
    if not best < bound:
        return 2, best, empty, empty[:, 0], 0, empty, np.empty((0, 2)), empty[:, 0], 0.0, 0.0
    cells, bad, nbad, ok = _assemble(
        chain, sr, sc, gr, gc, flat, pinfo, exit_cells, cost, uniform, clear
    )
    kind = 1 if ok else 3
    if nbad > 0 or not ok:
        return kind, best, cells, bad, nbad, empty, np.empty((0, 2)), empty[:, 0], 0.0, 0.0
    way, metres, owners, raw, smooth = finish_query(cells, clear, owner, to_m)
    return kind, best, cells, bad, nbad, way, metres, owners, raw, smooth


@njit(cache=True, nogil=True)
def portal_query(
    sr,
    sc,
    gr,
    gc,
    rs,
    rg,
    bound,
    rtab,
    flat,
    pinfo,
    dist,
    pred,
    exit_cells,
    cost,
    uniform,
    clear,
    owner,
    to_m,
):
    """The compiled query with all-pairs portal costs: straight line if clear (kind 0), else
    :func:`_choose` then :func:`_complete` (same returns)."""
    if segment_clear(clear, sr, sc, gr, gc):
        cells = _straight(sr, sc, gr, gc)
        way, metres, owners, raw, smooth = finish_query(cells, clear, owner, to_m)
        return 0, np.nan, cells, cells[:0, 0], 0, way, metres, owners, raw, smooth
    best, chain = _choose(sr, sc, gr, gc, rs, rg, rtab, flat, pinfo, dist, pred)
    return _complete(
        best,
        chain,
        bound,
        sr,
        sc,
        gr,
        gc,
        flat,
        pinfo,
        exit_cells,
        cost,
        uniform,
        clear,
        owner,
        to_m,
    )


@njit(cache=True, nogil=True)
def portal_query_search(
    sr,
    sc,
    gr,
    gc,
    rs,
    rg,
    bound,
    rtab,
    flat,
    pinfo,
    indptr,
    indices,
    weights,
    pcell,
    h_scale,
    exit_cells,
    cost,
    uniform,
    clear,
    owner,
    to_m,
):
    """As :func:`portal_query` with a portal-graph A* (:func:`_search_portals`) instead of all-pairs
    costs; also returns the portals expanded."""
    if segment_clear(clear, sr, sc, gr, gc):
        cells = _straight(sr, sc, gr, gc)
        way, metres, owners, raw, smooth = finish_query(cells, clear, owner, to_m)
        return 0, np.nan, cells, cells[:0, 0], 0, way, metres, owners, raw, smooth, 0
    best, chain, expanded = _search_portals(
        sr, sc, gr, gc, rs, rg, rtab, flat, pinfo, indptr, indices, weights, pcell, h_scale
    )
    kind, best, cells, bad, nbad, way, metres, owners, raw, smooth = _complete(
        best,
        chain,
        bound,
        sr,
        sc,
        gr,
        gc,
        flat,
        pinfo,
        exit_cells,
        cost,
        uniform,
        clear,
        owner,
        to_m,
    )
    return kind, best, cells, bad, nbad, way, metres, owners, raw, smooth, expanded
