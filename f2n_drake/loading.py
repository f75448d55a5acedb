"""Reading the input of a run: a drawing (an image or a PDF page, parsed by perception), a ResPlan
.pkl or a plan JSON (ground truth), with the checks made before the work (scale, size, memory; see
``f2n_drake.core.limits``)."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from f2n_drake.core.errors import InputError
from f2n_drake.core.limits import MAX_PLAN_M as MAX_PLAN_EXTENT_M
from f2n_drake.core.limits import MIN_PLAN_M as MIN_PLAN_EXTENT_M
from f2n_drake.core.limits import check_plan_extent, check_render_size
from f2n_drake.segmenter import DEFAULT_VIEWS

IMAGE_SUFFIXES = {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".webp", ".gif"}
MAX_RENDER_PX = 8192
"""Largest side [px] a vector plan is drawn on at ``--scale``."""


@dataclass
class LoadedPlan:
    """What the pipeline knows about the input once it is parsed."""

    parsed: object  # ParsedPlan
    image: np.ndarray  # the drawing (rendered for vector inputs)
    floorplan: object | None  # FloorPlan when the input was vector ground truth
    perception: str
    notes: list[str] = field(default_factory=list)
    squared: bool = False  # ``image`` is not the input's grid: a photographed page squared
    # (``perception.page``) or a drawing turned upright (``perception.skew``,
    # ``perception.orientation``)


def load_plan(
    path: Path,
    *,
    metres_per_px: float | None,
    plan_index: int = 0,
    page: int = 1,
    paper_scale: float | None = None,
    front_doors: int | None = 1,
    kitchens: int | None = 1,
    views: int = DEFAULT_VIEWS,
    progress: Callable[[str], None] | None = None,
) -> LoadedPlan:
    """Read a drawing (an image, or page ``page``, from 1, of a PDF drawn at 1:``paper_scale``
    if given; perception, expecting ``front_doors`` front doors and at most ``kitchens``
    kitchens: see ``f2n_drake.perception.priors.front_doors``,
    ``f2n_drake.perception.priors.kitchens``; the segmenter averages ``views`` views of it), a
    ResPlan .pkl or a plan JSON (ground truth). ``progress`` is told each step of a drawing's
    parse as it starts."""
    from f2n_drake.datasets.ground_truth import parse_ground_truth
    from f2n_drake.datasets.render import render

    if not path.exists():
        raise InputError(f"no such file: {path}")
    suffix = path.suffix.lower()
    notes: list[str] = []
    if suffix in IMAGE_SUFFIXES or suffix == ".pdf":
        from f2n_drake import parse_drawing
        from f2n_drake.perception.image import load_image, plain_grey
        from f2n_drake.perception.orientation import quarter_turns, turned
        from f2n_drake.perception.page import squared_page
        from f2n_drake.perception.pdf_pages import PAGE_LONG_SIDE_PX, load_pdf_page
        from f2n_drake.perception.scale import resolve_scale
        from f2n_drake.perception.skew import skew_deg, upright
        from f2n_drake.segmenter.inference import Segmenter

        if paper_scale is not None and metres_per_px is not None:
            raise InputError("give --scale or --paper-scale, not both")
        scale_source, photo = None, None
        if suffix == ".pdf":
            sheet = load_pdf_page(path, page=page - 1)
            image = sheet.image
            taken = f"page {page} of {sheet.pages}"
            taken += " (--page chooses another)" * (sheet.pages > 1)
            notes.append(f"{path.name}: {taken} drawn {PAGE_LONG_SIDE_PX} px on its long side")
            if paper_scale is not None:
                metres_per_px = paper_scale * sheet.paper_metres_per_px
                scale_source = f"paper scale 1:{paper_scale:g} of the PDF page"
        else:
            if paper_scale is not None:
                raise InputError(
                    f"--paper-scale needs a PDF (its page size is known); {path.name} is an "
                    "image: give --scale in metres per pixel"
                )
            image = load_image(path)  # grey, coloured marks made paper
            image, photo = squared_page(image, luminance=plain_grey(path, image.shape))
            if photo is not None:
                width, height = photo.size
                notes.append(
                    f"{path.name}: a page photographed at an angle, squared to {width}x{height} "
                    "px; the outputs lie on the squared page (page.png)"
                )
        skew = 0.0 if photo is not None else skew_deg(image)
        if skew:
            image = upright(image, skew)
            notes.append(
                f"{path.name}: drawn {abs(skew):.1f} degrees off square, turned upright; the "
                "outputs lie on the turned drawing (page.png)"
            )
        turns = quarter_turns(image)
        if turns:
            image = turned(image, turns)
            how = {
                1: "run down the page, turned a quarter turn counter-clockwise",
                2: "read upside down, turned a half turn",
                3: "run up the page, turned a quarter turn clockwise",
            }[turns]
            notes.append(
                f"{path.name}: its words {how}; the outputs lie on the turned drawing (page.png)"
            )
        if metres_per_px is not None:
            given = scale_source or f"--scale {metres_per_px:g}"
            check_plan_extent(image.shape, metres_per_px, source=given)
        parsed = parse_drawing(
            image,
            segmenter=Segmenter.load(views=views),
            metres_per_px=metres_per_px,
            front_doors=front_doors,
            kitchens=kitchens,
            progress=progress,
        )
        parsed = resolve_scale(parsed, metres_per_px=metres_per_px)
        if scale_source is not None:
            parsed = dataclasses.replace(parsed, scale_source=scale_source)
        if metres_per_px is None:
            check_plan_extent(
                image.shape,
                parsed.grid.metres_per_px,
                source=f"the scale read from the drawing ({parsed.scale_source}; give --scale "
                "to override)",
            )
        perception = f"segmenter, {views} view{'s' * (views > 1)}"
        squared = photo is not None or skew != 0.0 or turns != 0
        return LoadedPlan(parsed, image, None, perception, notes, squared=squared)
    if suffix == ".pkl":
        from f2n_drake.datasets.resplan import load_resplan

        plans = load_resplan(path)
        if not 0 <= plan_index < len(plans):
            raise InputError(
                f"{path} holds {len(plans)} plans; --plan-index {plan_index} is out of range"
            )
        plan = plans[plan_index]
        if len(plans) > 1:
            notes.append(
                f"{path.name} holds {len(plans)} plans; plan {plan_index} was taken "
                "(--plan-index chooses another)"
            )
    elif suffix == ".json":
        from f2n_drake.core.plan import FloorPlan

        plan = FloorPlan.load(path)
    elif suffix in (".svg", ".dwg", ".dxf"):
        raise InputError(
            f"{path}: a {suffix[1:].upper()} file is not read; export the plan as a PDF or PNG "
            "first (a PNG about 1000 px across)"
        )
    else:
        raise InputError(f"{path}: expected an image, a PDF, a ResPlan .pkl or a plan .json")
    # Vector input: the planning grid is 512 px across, or as fine as --scale asks.
    xmin, ymin, xmax, ymax = plan.bounds
    extent_m = max(xmax - xmin, ymax - ymin)
    if not MIN_PLAN_EXTENT_M <= extent_m <= MAX_PLAN_EXTENT_M:
        raise InputError(
            f"{path}: the plan is {extent_m:g} m across; a building is {MIN_PLAN_EXTENT_M:g} m "
            f"to {MAX_PLAN_EXTENT_M / 1000:g} km (are its units metres?)"
        )
    if metres_per_px is not None:
        check_render_size(extent_m, metres_per_px, max_side_px=MAX_RENDER_PX)
    rendered = (
        render(plan, 512) if metres_per_px is None else render(plan, metres_per_px=metres_per_px)
    )
    parsed = parse_ground_truth(plan, rendered.grid)
    return LoadedPlan(parsed, rendered.image, plan, "ground truth (vector input)", notes)
