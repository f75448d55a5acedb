"""The pipeline in one place: a drawing in, labelled instances out (``parse_drawing``).

``parse_drawing`` keeps only the plan on the sheet (``f2n_drake.perception.sheet``), runs the
segmenter (labels and probabilities, around furniture drawn against the walls), then
``f2n_drake.perception.instances.extract_instances`` (majority vote, soft scores, doorways
closed, open-passage split), then the apartment priors of ``f2n_drake.perception.priors.chain``
(one front door, no door or window wider than one can be, balconies open to the air, one
kitchen, no room without a door).
"""

from __future__ import annotations

import dataclasses
import logging

import numpy as np

from f2n_drake.core.errors import InputError
from f2n_drake.core.parsed import ParsedPlan
from f2n_drake.core.raster import PixelGrid
from f2n_drake.perception.furniture import segment_around_furniture
from f2n_drake.perception.image import (
    LabelPredictor,
    check_drawing,
    has_enclosed_region,
    predict_labels,
)
from f2n_drake.perception.ink import as_grey, binarize
from f2n_drake.perception.instances import DEFAULT_SPLIT, SplitOptions, extract_instances
from f2n_drake.perception.priors.chain import apply_priors
from f2n_drake.perception.sheet import only_the_plan

log = logging.getLogger(__name__)


def parse_drawing(
    image: np.ndarray,
    *,
    segmenter: LabelPredictor | None = None,
    metres_per_px: float | None = None,
    split: SplitOptions | None = DEFAULT_SPLIT,
    front_doors: int | None = 1,
    kitchens: int | None = 1,
    sealed_rooms: bool = True,
    balconies: bool = True,
    connector_sizes: bool = True,
    leave_out_sheet: bool = True,
) -> ParsedPlan:
    """Segment a drawing and turn it into labelled instances.

    Furniture drawn against the walls is found from a first segmentation, and the drawing is
    segmented again with its outline painted over (``perception.furniture``); its paper is no
    instance, an obstacle.

    Args:
        image: (H, W) uint8 grey (or BGR/BGRA) drawing, dark lines on light paper.
        segmenter: anything with ``predict(image) -> (H, W) uint8 labels``; default the shipped
            ``Segmenter.load()``.
        metres_per_px: scale, if known [m/px]; sets ``grid`` (``scale_source="argument"``).
        split: open-passage split options, None to disable.
        front_doors: how many front doors the plan has (1 for an apartment); the connectors most
            like one get the class (``perception.priors.front_doors``). None keeps the vote.
        kitchens: how many kitchens the plan has at most (1 for an apartment); the others are
            undone, and a plan with none gets its most kitchen-like room
            (``perception.priors.kitchens``). None keeps the plain vote.
        sealed_rooms: where a group of rooms has no door to the rest, the most door-like wall
            between them becomes a door (``perception.priors.sealed_rooms``); False keeps the
            vote.
        balconies: a balcony that touches no exterior takes its runner-up room class
            (``perception.priors.balconies``); False keeps the vote.
        connector_sizes: a door or window wider than one can be is wall
            (``perception.priors.connector_sizes``); False keeps the vote.
        leave_out_sheet: parse only the plan on the sheet, leaving out legends, title blocks
            and other plans (``perception.sheet``; ``sheet_note`` on the result says which
            part was taken); False parses the whole drawing.

    Raises:
        InputError: bad image, no enclosed regions (checked before the network runs), missing or
            corrupt segmenter weights, or a segmenter returning labels of the wrong shape.
    """
    grey = as_grey(np.asarray(image))
    check_drawing(grey)
    if metres_per_px is not None and not (np.isfinite(metres_per_px) and metres_per_px > 0):
        raise InputError(f"metres_per_px must be a positive number, got {metres_per_px}")
    lines = binarize(grey)
    grey, plan = only_the_plan(grey, lines) if leave_out_sheet else (grey, None)
    if plan is not None and plan.left_out:
        lines = binarize(grey)
    if not has_enclosed_region(lines):
        raise InputError("no enclosed regions found: the drawing has no closed outlines")
    if segmenter is None:
        from f2n_drake.segmenter.inference import Segmenter

        segmenter = Segmenter.load()
    (labels, probabilities), furniture = segment_around_furniture(
        grey,
        lines,
        lambda drawing: predict_labels(segmenter, drawing),
    )
    grid = PixelGrid.from_scale(metres_per_px, grey.shape) if metres_per_px else None
    parsed = extract_instances(
        grey,
        labels,
        grid=grid,
        split=split,
        lines=lines,
        probabilities=probabilities,
        furniture=furniture,
    )
    parsed = apply_priors(
        parsed,
        front_doors=front_doors,
        connector_sizes=connector_sizes,
        balconies=balconies,
        kitchens=kitchens,
        sealed_rooms=sealed_rooms,
    )
    if not parsed.instances:
        raise InputError("no enclosed regions found: every closed region was classed as background")
    if plan is not None and plan.left_out:
        parsed = dataclasses.replace(parsed, sheet_note=plan.describe())
    log.info("parsed %d instances", len(parsed.instances))
    return parsed
