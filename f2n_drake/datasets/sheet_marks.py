"""What is drawn round and on a plan on a sheet: an architect's dimension chains, scale bar and
title block, an evacuation sign's routes, arrows, extinguishers and legend in colour (the
``sheet`` and ``evacuation`` looks of :func:`f2n_drake.datasets.looks.restyle`), on paper added
round the
drawing (:func:`padded`)."""

from __future__ import annotations

import dataclasses

import cv2
import numpy as np

from f2n_drake.core.classes import CLASS_ID, SPACE_CLASSES
from f2n_drake.core.raster import PixelGrid
from f2n_drake.datasets.listing_marks import inscribed_rooms
from f2n_drake.datasets.render import RenderedPlan


def padded(rendered: RenderedPlan, pad: tuple[tuple[int, int], tuple[int, int]]) -> RenderedPlan:
    """``rendered`` with white paper added, ``pad`` = ((top, bottom), (left, right)) [px]:
    labels background there, the grid moved with the drawing."""
    (top, bottom), (left, right) = pad
    grid = rendered.grid
    return dataclasses.replace(
        rendered,
        image=np.pad(rendered.image, pad, constant_values=255),
        labels=np.pad(rendered.labels, pad, constant_values=0),
        grid=PixelGrid(
            grid.metres_per_px,
            (
                grid.origin_m[0] - left * grid.metres_per_px,
                grid.origin_m[1] + top * grid.metres_per_px,
            ),
            (grid.shape[0] + top + bottom, grid.shape[1] + left + right),
        ),
    )


def on_sheet(rendered: RenderedPlan, rng: np.random.Generator) -> RenderedPlan:
    """``rendered`` on an architect's sheet: a dimension chain 0.6-1.2 m below and one left of
    the plan (extension lines stopping short of the walls, ticks, lengths in cm), a title block
    (a box of three cells with words) in the sheet's bottom-right corner and a scale bar of four
    1 m cells in its bottom-left one, all in the drawing's ink, none touching the plan."""
    side = max(rendered.image.shape)
    far, near = round(0.3 * side), round(0.12 * side)
    sheet = padded(rendered, ((near, far), (near, far)))
    image, grid = sheet.image.copy(), sheet.grid
    ink = int(rng.integers(0, 60))
    font = cv2.FONT_HERSHEY_SIMPLEX
    darkest, paper = int(image.min()), int(np.median(image))
    rows, cols = np.nonzero(image < (darkest + paper) / 2)  # the plan's ink, faint lines too
    top, bottom, left, right = rows.min(), rows.max(), cols.min(), cols.max()
    tick, text_px = grid.length_px(0.12), grid.length_px(0.25)
    text_scale = text_px / cv2.getTextSize("0", font, 1.0, 1)[0][1]
    for axis in (0, 1):  # 0: a chain below the plan (along x), 1: left of it (along y)
        lo, hi = (left, right) if axis == 0 else (top, bottom)
        offset = grid.length_px(rng.uniform(0.6, 1.2))
        at = bottom + offset if axis == 0 else left - offset
        stops = np.sort(np.concatenate([[lo, hi], rng.integers(lo + 1, hi, 3)]))
        points = [(s, at) if axis == 0 else (at, s) for s in stops]
        cv2.line(image, _pt(points[0]), _pt(points[-1]), ink, 1, cv2.LINE_AA)
        for x, y in points:
            ext = (0, 2 * tick) if axis == 0 else (2 * tick, 0)
            cv2.line(
                image, _pt((x - ext[0], y - ext[1])), _pt((x + ext[0] / 2, y + ext[1] / 2)), ink, 1
            )
            cv2.line(image, _pt((x - tick, y + tick)), _pt((x + tick, y - tick)), ink, 1)
        for a, b in zip(stops[:-1], stops[1:], strict=True):
            if b - a < 3 * text_px:
                continue
            label = f"{(b - a) * grid.metres_per_px * 100:.0f}"
            mid = (a + b) / 2
            xy = (mid - text_px, at - tick) if axis == 0 else (at - 4 * text_px, mid)
            cv2.putText(image, label, _pt(xy), font, text_scale, ink, 1, cv2.LINE_AA)
    h, w = image.shape
    margin = round(0.02 * side)
    x0, y0, x1, y1 = round(w - 0.45 * side), round(h - 0.16 * side), w - margin, h - margin
    cv2.rectangle(image, (x0, y0), (x1, y1), ink, 2)
    ym, xm = (y0 + y1) // 2, (x0 + x1) // 2
    cv2.line(image, (x0, ym), (x1, ym), ink, 1)
    cv2.line(image, (xm, ym), (xm, y1), ink, 1)
    pad = round(0.2 * (ym - y0))
    for word, (x, y) in (
        ("FLOOR PLAN", (x0 + pad, ym - pad)),
        ("1:100", (x0 + pad, y1 - pad)),
        ("A-101", (xm + pad, y1 - pad)),
    ):
        cv2.putText(image, word, (x, y), font, text_scale, ink, 1, cv2.LINE_AA)
    cell, bar_h = grid.length_px(1.0), max(3, grid.length_px(0.15))
    bx, by = margin, h - margin - bar_h
    for k in range(4):
        corner = (_pt((bx + k * cell, by)), _pt((bx + (k + 1) * cell, by + bar_h)))
        cv2.rectangle(image, *corner, ink, -1 if k % 2 == 0 else 1)
    return dataclasses.replace(sheet, image=image)


def _pt(xy: tuple[float, float]) -> tuple[int, int]:
    return int(round(xy[0])), int(round(xy[1]))


GREEN, RED = (40, 150, 0), (30, 30, 210)  # BGR: escape routes and exits; fire fighting, you


def evacuation_sign(rendered: RenderedPlan, rng: np.random.Generator) -> RenderedPlan:
    """``rendered`` as an evacuation sign, a BGR image: in each room a green arrow (0.5-1 m,
    within the room) pointing to its nearest door, red extinguishers (0.18 m discs) against
    the living room's walls, a red "you are here" dot and ring in it, and beside the plan a
    legend (a black box with each symbol and its words); labels background and grid moved
    there, as for ``wide-margins``."""
    side = max(rendered.image.shape)
    sign = padded(rendered, ((0, 0), (0, round(0.45 * side))))
    labels, grid = sign.labels, sign.grid
    image = cv2.cvtColor(sign.image, cv2.COLOR_GRAY2BGR)
    ways_out = np.isin(labels, [CLASS_ID["door"], CLASS_ID["front_door"]])
    if not ways_out.any():
        return dataclasses.replace(sign, image=image)
    to_door = cv2.distanceTransform((~ways_out).astype(np.uint8), cv2.DIST_L2, 5)
    for _, _, depth, (row, col) in inscribed_rooms(labels):
        length = min(grid.length_px(rng.uniform(0.5, 1.0)), 1.6 * depth[row, col])
        if length < 8:
            continue
        step = np.array(
            [
                to_door[row, col + 1] - to_door[row, col - 1],
                to_door[row + 1, col] - to_door[row - 1, col],
            ]
        )
        if np.linalg.norm(step) < 1e-6:
            continue
        tip = np.array([col, row]) - 0.5 * length * step / np.linalg.norm(step)
        tail = 2 * np.array([col, row]) - tip
        _arrow(image, tail, tip, max(2, round(grid.length_px(0.1))), GREEN)
    living = (labels == CLASS_ID["living"]).astype(np.uint8)
    depth = cv2.distanceTransform(living, cv2.DIST_L2, 3)
    radius = max(2, round(grid.length_px(0.18)))
    at_wall = np.argwhere((depth > radius - 1) & (depth <= radius))  # the disc touches the wall
    for row, col in at_wall[rng.permutation(len(at_wall))[:2]]:
        cv2.circle(image, (int(col), int(row)), int(radius), RED, -1, cv2.LINE_AA)
    free = np.argwhere(depth >= grid.length_px(0.5))
    if len(free):
        row, col = free[rng.integers(len(free))]
        _escape_route(image, labels, grid, (int(row), int(col)))
        cv2.circle(image, (int(col), int(row)), max(2, round(grid.length_px(0.12))), RED, -1)
        cv2.circle(
            image, (int(col), int(row)), max(4, round(grid.length_px(0.3))), RED, 1, cv2.LINE_AA
        )
    _legend(image, rendered.image.shape[1] + round(0.08 * side), round(0.1 * side), side)
    return dataclasses.replace(sign, image=image)


def _escape_route(
    image: np.ndarray, labels: np.ndarray, grid: PixelGrid, start: tuple[int, int]
) -> None:
    """A green line 0.08 m wide from ``start`` (row, col) through the rooms and doors (0.2 m
    clear of walls) and out of the front door, 0.5 m beyond it, ending in an arrowhead; drawn
    over the doors' outlines, as signs draw their routes."""
    from f2n_drake.planning.astar import astar

    front = np.argwhere(labels == CLASS_ID["front_door"])
    walk = np.isin(labels, [CLASS_ID[n] for n in (*SPACE_CLASSES, "door", "front_door")])
    clear = cv2.distanceTransform(walk.astype(np.uint8), cv2.DIST_L2, 3) > grid.length_px(0.2)
    if not len(front) or not clear[start]:
        return
    door = front.mean(axis=0)
    inside = np.argwhere(clear)
    goal = inside[np.argmin(np.linalg.norm(inside - door, axis=1))]
    path = astar(clear, start, (int(goal[0]), int(goal[1])))
    if not path.found:
        return
    out = (door - goal) / max(float(np.linalg.norm(door - goal)), 1e-9)
    points = np.vstack([path.cells, door, door + grid.length_px(0.5) * out])[:, ::-1]
    points = cv2.approxPolyDP(points.astype(np.float32)[:, None], 2.0, False)[:, 0]
    width = max(2, round(grid.length_px(0.08)))
    cv2.polylines(image, [np.round(points[:-1]).astype(np.int32)], False, GREEN, width, cv2.LINE_AA)
    _arrow(image, points[-2], points[-1], width, GREEN)


def _arrow(image: np.ndarray, tail: np.ndarray, tip: np.ndarray, width: int, colour) -> None:
    """A filled arrow from ``tail`` to ``tip`` [px (x, y)], shaft ``width`` px thick."""
    along = (tip - tail) / max(float(np.linalg.norm(tip - tail)), 1e-9)
    across = np.array([-along[1], along[0]])
    head = tip - 2.5 * width * along
    cv2.line(image, _pt(tail), _pt(head), colour, width, cv2.LINE_AA)
    corners = [tip, head + 1.5 * width * across, head - 1.5 * width * across]
    cv2.fillPoly(image, [np.round(corners).astype(np.int32)], colour, cv2.LINE_AA)


def _legend(image: np.ndarray, x0: int, y0: int, side: int) -> None:
    """A black legend box at (``x0``, ``y0``) [px]: each symbol of the sign and its words."""
    font, unit = cv2.FONT_HERSHEY_SIMPLEX, round(0.05 * side)
    scale = 0.4 * unit / cv2.getTextSize("M", font, 1.0, 1)[0][1]
    rows = ("ESCAPE ROUTE", "EXTINGUISHER", "YOU ARE HERE")
    cv2.rectangle(image, (x0, y0), (x0 + 7 * unit, y0 + (len(rows) + 1) * unit), (0, 0, 0), 1)
    for i, words in enumerate(rows):
        cy = y0 + (i + 1) * unit
        mark = np.array([x0 + unit, cy], float)
        if i == 0:
            _arrow(image, mark - (0.4 * unit, 0), mark + (0.4 * unit, 0), max(2, unit // 6), GREEN)
        else:
            cv2.circle(image, _pt(mark), max(2, unit // 4), RED, -1, cv2.LINE_AA)
        cv2.putText(
            image, words, (x0 + 2 * unit, cy + unit // 5), font, scale, (0, 0, 0), 1, cv2.LINE_AA
        )
