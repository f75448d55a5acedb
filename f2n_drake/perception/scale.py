"""Deciding the metres-per-pixel scale of a parsed drawing.

Four sources, in this order: an explicit ``metres_per_px`` argument (the user knows best), the
grid the plan came with (ground truth from a ``FloorPlan``), the room sizes printed on the
drawing (``f2n_drake.perception.printed_sizes``), else an estimate that makes the median door
``assumed_door_width_m`` wide (doors are the one standard-size thing in a plan).

A door's instance is the paper between its jamb lines, each drawn centred on the end of the
wall, so the opening is one outline thicker than the instance (:func:`door_openings_px`); a
drawing in thick lines would otherwise measure its doors narrow and its flat large.
``python -m f2n_drake.evaluate scale`` measures the estimate against drawings of known scale.
"""

from __future__ import annotations

import dataclasses
import logging
import math

import numpy as np
from scipy import ndimage

from f2n_drake.core.errors import InputError
from f2n_drake.core.parsed import Instance, ParsedPlan
from f2n_drake.core.raster import PixelGrid
from f2n_drake.mapping.graph import clear_width_px, line_gap_px
from f2n_drake.perception.printed_sizes import printed_scale

log = logging.getLogger(__name__)

DOOR_CLASSES: tuple[str, ...] = ("door", "front_door")


def clear_widths_px(parsed: ParsedPlan, instances: list[Instance]) -> dict[int, float]:
    """Instance id -> clear width [px] (:func:`f2n_drake.mapping.graph.clear_width_px`; 0 if it has
    no
    pixels)."""
    slices = ndimage.find_objects(parsed.instance_ids)
    widths = {}
    for inst in instances:
        sl = slices[inst.id - 1] if inst.id <= len(slices) else None
        widths[inst.id] = clear_width_px(parsed.instance_ids[sl] == inst.id) if sl else 0.0
    return widths


def door_widths_px(parsed: ParsedPlan) -> list[float]:
    """Clear width [px] of every door and front door instance."""
    widths = clear_widths_px(parsed, parsed.of_class(*DOOR_CLASSES)).values()
    return [w for w in widths if w > 0]


def door_openings_px(parsed: ParsedPlan) -> list[float]:
    """Width [px] of every door and front door opening, jamb line centre to jamb line centre:
    its clear width plus the thickness of the drawn outlines
    (:func:`f2n_drake.mapping.graph.line_gap_px`,
    0 for ground truth, whose doors touch their walls)."""
    outline_px = line_gap_px(parsed)
    return [w + outline_px for w in door_widths_px(parsed)]


def opening_widths_m(
    parsed: ParsedPlan, instances: list[Instance], assumed_door_width_m: float = 0.9
) -> dict[int, float | None]:
    """Instance id -> opening [m], jamb line centre to jamb line centre (clear width plus one
    outline). Without a grid, the median interior door's opening is taken to be
    ``assumed_door_width_m`` (front doors, which the front-door prior measures with this, do not
    set the yardstick); None for all when there is neither grid nor door."""
    outline_px = line_gap_px(parsed)
    openings = {i: w + outline_px for i, w in clear_widths_px(parsed, instances).items()}
    if parsed.grid is not None:
        metres_per_px = parsed.grid.metres_per_px
    else:
        doors = [w for w in clear_widths_px(parsed, parsed.of_class("door")).values() if w > 0]
        if not doors:
            return dict.fromkeys(openings)
        metres_per_px = assumed_door_width_m / (float(np.median(doors)) + outline_px)
    return {i: w * metres_per_px for i, w in openings.items()}


def resolve_scale(
    parsed: ParsedPlan,
    *,
    metres_per_px: float | None = None,
    assumed_door_width_m: float = 0.9,
) -> ParsedPlan:
    """A copy of ``parsed`` with ``grid`` and ``scale_source`` set.

    Args:
        parsed: a parsed plan, with or without a grid.
        metres_per_px: known scale [m/px]; overrides the plan's own grid ("argument").
        assumed_door_width_m: opening a median door is taken to have when estimating [m].

    Returns:
        The plan unchanged if it has a grid and no argument is given ("input" or whatever its
        source was); else with ``PixelGrid.from_scale`` (origin at the image's top-left corner),
        from the printed room sizes when the drawing prints some ("from 6 printed room sizes,
        spread 4 %"), else from its doors.

    Raises:
        InputError: ``metres_per_px`` is not a positive number, or there is no scale and no
            door to estimate one from.
    """
    shape = tuple(int(v) for v in parsed.instance_ids.shape)
    if metres_per_px is not None:
        if not (
            isinstance(metres_per_px, (int, float))
            and math.isfinite(metres_per_px)
            and metres_per_px > 0
        ):
            raise InputError(f"metres per pixel must be a positive number, got {metres_per_px}")
        grid = PixelGrid.from_scale(float(metres_per_px), shape)
        return dataclasses.replace(parsed, grid=grid, scale_source="argument")
    if parsed.grid is not None:
        return parsed
    printed = printed_scale(parsed)
    if printed is not None:
        log.info("scale %.4f m/px %s", printed.metres_per_px, printed.describe())
        grid = PixelGrid.from_scale(printed.metres_per_px, shape)
        return dataclasses.replace(parsed, grid=grid, scale_source=printed.describe())
    widths = door_openings_px(parsed)
    if not widths:
        raise InputError(
            "cannot estimate the scale: no door found to measure; give the scale in metres per "
            "pixel (run --scale M_PER_PX, or metres_per_px)"
        )
    median_px = float(np.median(widths))
    scale = assumed_door_width_m / median_px
    log.info(
        "scale %.4f m/px from the median of %d door openings (%.1f px)",
        scale,
        len(widths),
        median_px,
    )
    source = f"door-width estimate, {assumed_door_width_m:g} m doors"
    return dataclasses.replace(parsed, grid=PixelGrid.from_scale(scale, shape), scale_source=source)
