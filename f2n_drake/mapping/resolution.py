"""A parsed plan on a coarser raster, so a high-resolution scan plans as fast as a small drawing.

Perception reads a drawing at its own resolution, but the graph, the planner, the Nav2 map and the
simulated walls need no more than about ``PLANNING_CELL_M`` per cell: a scan at 0.8 cm/px would
otherwise give the planner nine times the cells, and its precompute grows faster than that.
:func:`at_planning_resolution` merges ``factor`` x ``factor`` blocks of pixels into one cell
(:func:`coarsened`) whenever that keeps cells at most ``PLANNING_CELL_M`` wide.

A cell keeps what matters for navigation: any connector or opening pixel in the block makes it
that connector (a door never closes), else any line pixel makes it a line (two rooms never
merge), else it takes the instance at the block's centre. Doors therefore grow by up to one
cell into their outlines and lines thicken to one cell: both well under the robot's size.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from f2n_drake.core.classes import CONNECTOR_CLASSES, OPENING
from f2n_drake.core.parsed import Instance, ParsedPlan
from f2n_drake.core.raster import PixelGrid

PLANNING_CELL_M = 0.02
"""Widest planning cell [m] a drawing is coarsened to: the synthetic drawings' own scale
(1.6-4 cm/px), a tenth of the TurtleBot3's diameter."""


def planning_factor(grid: PixelGrid | None, cell_m: float = PLANNING_CELL_M) -> int:
    """Pixels per planning cell side: the largest integer keeping cells at most ``cell_m``."""
    if grid is None:
        return 1
    return max(1, int(cell_m / grid.metres_per_px + 1e-9))


def at_planning_resolution(parsed: ParsedPlan, cell_m: float = PLANNING_CELL_M) -> ParsedPlan:
    """``parsed`` coarsened by ``planning_factor`` (``parsed`` itself when that is 1)."""
    factor = planning_factor(parsed.grid, cell_m)
    return parsed if factor == 1 else coarsened(parsed, factor)


def coarsened(parsed: ParsedPlan, factor: int) -> ParsedPlan:
    """``parsed`` with ``factor`` x ``factor`` pixel blocks merged into one cell.

    The image is padded with empty pixels (id 0, background) to a multiple of ``factor``.
    Instances keep their ids, classes, votes and scores; their contours are scaled (their
    precision is kept), their areas and centroids recounted, and an instance that no cell keeps
    is dropped. Raises ValueError for a factor below 1.
    """
    if factor < 1:
        raise ValueError(f"factor must be >= 1, got {factor}")
    if factor == 1:
        return parsed
    ids = parsed.instance_ids
    h, w = ids.shape
    hc, wc = -(-h // factor), -(-w // factor)
    pad = ((0, hc * factor - h), (0, wc * factor - w))
    blocks = _blocks(np.pad(ids, pad), factor)
    labels = _blocks(np.pad(parsed.labels, pad), factor)
    n = int(ids.max()) + 1
    is_connector = np.zeros(n, bool)
    for inst in parsed.instances:
        is_connector[inst.id] = inst.class_name in (*CONNECTOR_CLASSES, OPENING)
    connector = np.where(is_connector[blocks], blocks, 0).max(-1)
    centre = blocks[..., (factor // 2) * factor + factor // 2]
    coarse = np.where(connector > 0, connector, np.where((blocks == 0).any(-1), 0, centre))
    coarse = coarse.astype(np.int32)

    area = np.bincount(coarse.ravel(), minlength=n)
    rows, cols = np.indices(coarse.shape)
    sum_r = np.bincount(coarse.ravel(), weights=rows.ravel(), minlength=n)
    sum_c = np.bincount(coarse.ravel(), weights=cols.ravel(), minlength=n)
    instances: list[Instance] = []
    for inst in parsed.instances:
        if area[inst.id] == 0:
            continue
        instances.append(
            dataclasses.replace(
                inst,
                contour_px=(np.asarray(inst.contour_px, float) + 0.5) / factor - 0.5,
                area_px=int(area[inst.id]),
                centroid_px=(sum_c[inst.id] / area[inst.id], sum_r[inst.id] / area[inst.id]),
            )
        )
    grid = parsed.grid
    if grid is not None:
        grid = PixelGrid(grid.metres_per_px * factor, grid.origin_m, (hc, wc))
    return ParsedPlan(
        coarse,
        labels[..., (factor // 2) * factor + factor // 2],
        instances,
        grid,
        parsed.scale_source,
        [text.scaled(factor) for text in parsed.texts],
        parsed.sheet_note,
        plans=parsed.plans,
        drawing_notes=parsed.drawing_notes,
    )


def _blocks(image: np.ndarray, factor: int) -> np.ndarray:
    """(H, W) with H, W multiples of ``factor`` -> (H/f, W/f, f*f) the pixels of each block."""
    h, w = image.shape
    return (
        image.reshape(h // factor, factor, w // factor, factor)
        .transpose(0, 2, 1, 3)
        .reshape(h // factor, w // factor, factor * factor)
    )
