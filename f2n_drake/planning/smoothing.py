"""Line-of-sight path smoothing on a boolean grid (compiled).

A segment between two cell centres is clear when every cell of its *supercover* (each cell the
segment touches, both cells when it passes exactly through a corner) is True. Checked on the
inflated free grid this keeps the robot's clearance; checked on the un-inflated free grid it
tells whether a path crosses a wall. Shortcutting keeps from each waypoint the farthest later
point it sees, so the result is never longer than its input.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def segment_clear(grid, r0, c0, r1, c1):
    """True if the supercover of the segment (r0, c0)-(r1, c1) (cell centres) is all True."""
    rows, cols = grid.shape
    dr = r1 - r0
    dc = c1 - c0
    nr = abs(dr)
    nc = abs(dc)
    sr = 1 if dr > 0 else -1
    sc = 1 if dc > 0 else -1
    r = r0
    c = c0
    if r < 0 or r >= rows or c < 0 or c >= cols or not grid[r, c]:
        return False
    ir = 0
    ic = 0
    while ir < nr or ic < nc:
        # compare (0.5 + ic) / nc with (0.5 + ir) / nr without division
        decision = (1 + 2 * ic) * nr - (1 + 2 * ir) * nc
        if decision == 0:  # through a corner: both side cells are touched
            if not grid[r + sr, c] or not grid[r, c + sc]:
                return False
            r += sr
            c += sc
            ir += 1
            ic += 1
        elif decision < 0:  # horizontal step first
            c += sc
            ic += 1
        else:
            r += sr
            ir += 1
        if r < 0 or r >= rows or c < 0 or c >= cols or not grid[r, c]:
            return False
    return True


@njit(cache=True, nogil=True)
def _shortcut(points, grid, lookahead):
    n = points.shape[0]
    keep = np.zeros(n, np.bool_)
    keep[0] = True
    i = 0
    while i < n - 1:
        k = min(n - 1, i + lookahead)
        while k > i + 1 and not segment_clear(
            grid, points[i, 0], points[i, 1], points[k, 0], points[k, 1]
        ):
            k -= 1
        keep[k] = True
        i = k
    return points[keep]


def shortcut(points: np.ndarray, clear: np.ndarray, lookahead: int = 512) -> np.ndarray:
    """Line-of-sight shortcut of a polyline of (row, col) cells on the bool grid ``clear``.

    From each kept point, jumps to the farthest of the next ``lookahead`` points it sees (so
    a sight line lost and regained around a corner still shortens the path); returns the kept
    (M, 2) int64 waypoints, first and last included. Consecutive input points must see each
    other (true for grid A* paths), so the result is never longer than the input.
    """
    points = np.ascontiguousarray(points, np.int64).reshape(-1, 2)
    if len(points) <= 2:
        return points.copy()
    return _shortcut(points, np.ascontiguousarray(clear, np.bool_), int(max(lookahead, 2)))


@njit(cache=True, nogil=True)
def _all_clear(points, grid):
    for k in range(points.shape[0] - 1):
        if not segment_clear(grid, points[k, 0], points[k, 1], points[k + 1, 0], points[k + 1, 1]):
            return False
    return True


def polyline_clear(points: np.ndarray, free: np.ndarray) -> bool:
    """True if every segment of the (row, col) polyline stays on True cells of ``free``."""
    points = np.ascontiguousarray(points, np.int64).reshape(-1, 2)
    if len(points) == 0:
        return False
    if len(points) == 1:
        r, c = points[0]
        return bool(0 <= r < free.shape[0] and 0 <= c < free.shape[1] and free[r, c])
    return bool(_all_clear(points, np.ascontiguousarray(free, np.bool_)))


@njit(cache=True, nogil=True)
def string_pull_kernel(points, grid):
    n = points.shape[0]
    keep = np.zeros(n, np.bool_)
    keep[0] = True
    keep[n - 1] = True
    i = 0
    while i < n - 1:
        if segment_clear(grid, points[i, 0], points[i, 1], points[n - 1, 0], points[n - 1, 1]):
            break
        lo = i + 1  # consecutive points see each other
        probe = i + 2
        while probe < n - 1 and segment_clear(
            grid, points[i, 0], points[i, 1], points[probe, 0], points[probe, 1]
        ):
            lo = probe
            probe = i + 2 * (probe - i)
        hi = min(probe, n - 1)
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if segment_clear(grid, points[i, 0], points[i, 1], points[mid, 0], points[mid, 1]):
                lo = mid
            else:
                hi = mid
        keep[lo] = True
        i = lo
    return _relax(_shortcut(points[keep], grid, 512), grid)


@njit(cache=True, nogil=True)
def _relax(way, grid):
    """Pull each interior waypoint a few cells down the gradient of the length of its two
    segments while both stay clear (at most 3 passes); never lengthens the path."""
    way = way.copy()
    n = way.shape[0]
    for _ in range(3):
        moved = False
        for k in range(1, n - 1):
            pr, pc = way[k - 1, 0], way[k - 1, 1]
            qr, qc = way[k + 1, 0], way[k + 1, 1]
            xr, xc = way[k, 0], way[k, 1]
            a = math.hypot(xr - pr, xc - pc)
            b = math.hypot(xr - qr, xc - qc)
            if a == 0.0 or b == 0.0:
                continue
            gr = (xr - pr) / a + (xr - qr) / b
            gc = (xc - pc) / a + (xc - qc) / b
            norm = math.hypot(gr, gc)
            if norm < 1e-9:
                continue
            best = a + b - 1e-9
            br, bc = xr, xc
            for step in (5.0, 2.0, 1.0):
                for turn in (0.0, 0.7, -0.7, 1.4, -1.4):
                    dr = -gr / norm
                    dc = -gc / norm
                    ur = dr * math.cos(turn) - dc * math.sin(turn)
                    uc = dr * math.sin(turn) + dc * math.cos(turn)
                    cr = xr + int(round(step * ur))
                    cc = xc + int(round(step * uc))
                    length = math.hypot(cr - pr, cc - pc) + math.hypot(cr - qr, cc - qc)
                    # walks start at the candidate: a blocked one fails within a few cells
                    if (
                        length < best
                        and segment_clear(grid, cr, cc, pr, pc)
                        and segment_clear(grid, cr, cc, qr, qc)
                    ):
                        best = length
                        br, bc = cr, cc
            if br != xr or bc != xc:
                way[k, 0] = br
                way[k, 1] = bc
                moved = True
        if not moved:
            break
    return way


def string_pull(points: np.ndarray, clear: np.ndarray) -> np.ndarray:
    """Fast line-of-sight shortcut of a dense polyline of (row, col) cells on ``clear``.

    From each kept point, gallops then bisects along the path to the last point it sees before
    losing sight (O(log N) sight checks per kept point), then runs :func:`shortcut` over the
    few kept points, and pulls each remaining corner a few cells towards the straight line of
    its neighbours while both segments stay clear. Consecutive input points must see each
    other; the result is never longer than the input and every segment is clear.
    """
    points = np.ascontiguousarray(points, np.int64).reshape(-1, 2)
    if len(points) <= 2:
        return points.copy()
    return string_pull_kernel(points, np.ascontiguousarray(clear, np.bool_))
