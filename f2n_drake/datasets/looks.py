"""How a finished drawing may look: the renderer's drawings redrawn as users bring them.

:func:`restyle` turns a :class:`~f2n_drake.datasets.render.RenderedPlan` into a negative, a drawing
with
grey room fills, a small plan on a big sheet, an unevenly lit page, a listing with room names or
with furniture, an architect's sheet or an evacuation sign, keeping its labels (``python -m
f2n_drake.evaluate segmentation --look``). They measure how the parse copes with drawings unlike
the training ones; none is used in training.
"""

from __future__ import annotations

import dataclasses
import math

import cv2
import numpy as np

from f2n_drake.core.classes import CLASS_ID, NUM_CLASSES, SPACE_CLASSES
from f2n_drake.core.errors import InputError
from f2n_drake.datasets.listing_marks import draw_furniture, fit_furniture, write_room_names
from f2n_drake.datasets.render import RenderedPlan
from f2n_drake.datasets.sheet_marks import evacuation_sign, on_sheet, padded

LOOKS: tuple[str, ...] = (
    "drawn",
    "negative",
    "room-fills",
    "wide-margins",
    "shaded",
    "hatched",
    "labelled",
    "furnished",
    "fitted",
    "sheet",
    "evacuation",
    "textured-floors",
    "light-lines",
)
"""How a finished drawing may look: as drawn, as a negative (light lines on dark paper, as a
blueprint reads in grey), with every room filled with a light grey per room class (as
real-estate listings colour their rooms), small in the middle of a big sheet, lit unevenly
(a photographed or scanned page), with its walls hatched, with each room's name and area
written in it, with furniture standing in the rooms or drawn against their walls, on an
architect's sheet with dimension chains, a scale bar and a title block, as an evacuation
sign in colour, with its floors painted with planks and tiles (as rendered listings paint
them), or in light grey lines with black room names (as CAD exports print)."""
WOOD_GREYS = (204, 190, 168)
"""Greys of the woods :func:`painted_floors` lays: light oak, oak, a darker wood."""
TILE_GREYS = (235, 223, 207)
"""Greys of its tiles."""
LIGHT_LINE_GREYS = (190, 230)
"""Range of the grey black ink becomes in a ``light-lines`` drawing."""


def restyle(rendered: RenderedPlan, look: str, rng: np.random.Generator) -> RenderedPlan:
    """``rendered`` with its image given ``look`` (labels and grid unchanged but for
    ``wide-margins``).

    ``room-fills`` draws rooms of each space class in one grey of 170-235 (ink stays as dark as
    it was); ``negative`` inverts the image; ``wide-margins`` adds white paper 0.75 times the
    drawing's long side wide on every side (labels background, grid moved with it), so the
    drawing spans 40 % of the sheet; ``shaded`` dims the image linearly from full light on one
    side to 60-70 % on the opposite one (the side drawn at random); ``hatched`` hatches the
    walls with 45-degree lines 6-10 cm apart, as architects draw cut walls. What a listing draws
    (``f2n_drake.datasets.listing_marks``): ``labelled`` writes each room's name and area,
    ``furnished``
    stands a piece of furniture in rooms, ``fitted`` draws one against a wall. What a sheet
    draws (``f2n_drake.datasets.sheet_marks``): ``sheet`` puts the drawing on an architect's sheet,
    ``evacuation`` makes it an evacuation sign, a BGR colour image (both: labels background and
    grid moved with the added paper, as for ``wide-margins``). ``textured-floors`` lays planks
    0.12-0.3 m wide in the living rooms and bedrooms and tiles 0.2-0.45 m in the kitchens and
    bathrooms (:func:`painted_floors`). ``light-lines`` lightens the ink so that black becomes a
    grey of ``LIGHT_LINE_GREYS`` and writes the room names in black over it (``labelled``).
    """
    if look not in LOOKS:
        raise InputError(f"unknown look {look!r}; choose from {', '.join(LOOKS)}")
    image = rendered.image
    if look == "negative":
        image = 255 - image
    elif look == "room-fills":
        fills = np.full(NUM_CLASSES, 255, np.uint8)
        space_ids = [CLASS_ID[n] for n in SPACE_CLASSES]
        fills[space_ids] = rng.integers(170, 236, len(space_ids))
        image = np.minimum(image, fills[rendered.labels])
    elif look == "shaded":
        h, w = image.shape
        angle = rng.uniform(0, 2 * math.pi)
        rows, cols = np.mgrid[0:h, 0:w]
        along = np.cos(angle) * cols / max(w - 1, 1) + np.sin(angle) * rows / max(h - 1, 1)
        along = (along - along.min()) / max(float(np.ptp(along)), 1e-9)
        light = 1.0 - rng.uniform(0.3, 0.4) * along
        image = np.clip(image * light, 0, 255).astype(np.uint8)
    elif look == "hatched":
        step = max(3, round(rendered.grid.length_px(rng.uniform(0.06, 0.1))))
        h, w = image.shape
        hatching = np.full((h, w), 255, np.uint8)
        for col in range(-h, w, step):
            cv2.line(hatching, (col, 0), (col + h, h), 0, 1, cv2.LINE_AA)
        walls = rendered.labels == CLASS_ID["wall"]
        image = np.where(walls, np.minimum(image, hatching), image)
    elif look == "light-lines":
        grey = rng.uniform(*LIGHT_LINE_GREYS)
        lightened = 255.0 - (255.0 - image) * (255.0 - grey) / 255.0
        image = write_room_names(lightened.astype(np.uint8), rendered.labels, rendered.grid, rng)
    elif look == "labelled":
        image = write_room_names(image, rendered.labels, rendered.grid, rng)
    elif look == "furnished":
        image = draw_furniture(image, rendered.labels, rendered.grid, rng)
    elif look == "fitted":
        image = fit_furniture(image, rendered.labels, rendered.grid, rng)
    elif look == "wide-margins":
        pad = round(0.75 * max(image.shape))
        return padded(rendered, ((pad, pad), (pad, pad)))
    elif look == "sheet":
        return on_sheet(rendered, rng)
    elif look == "evacuation":
        return evacuation_sign(rendered, rng)
    elif look == "textured-floors":
        floors = [
            (
                rendered.labels == CLASS_ID[name],
                "tiles" if name in ("kitchen", "bathroom") else "planks",
            )
            for name in ("living", "bedroom", "kitchen", "bathroom")
        ]
        plank_px, tile_px = (
            (round(rendered.grid.length_px(lo)), round(rendered.grid.length_px(hi)) + 1)
            for lo, hi in ((0.12, 0.3), (0.2, 0.45))
        )
        image = painted_floors(image, floors, rng, plank_px=plank_px, tile_px=tile_px)
    return dataclasses.replace(rendered, image=image)


def on_squared_paper(grey: np.ndarray, spacing_px: int, level: int = 200) -> np.ndarray:
    """``grey`` printed on squared paper: a grid of lines one pixel wide, ``spacing_px`` apart
    and ``level`` grey, under the drawing (each pixel the darker of the two)."""
    grid = np.full(grey.shape, 255, np.uint8)
    grid[::spacing_px] = level
    grid[:, ::spacing_px] = level
    return np.minimum(grey, grid)


def painted_floors(
    image: np.ndarray,
    floors: list[tuple[np.ndarray, str]],
    rng: np.random.Generator,
    *,
    plank_px: tuple[int, int],
    tile_px: tuple[int, int],
) -> np.ndarray:
    """(H, W) uint8 grey ``image`` with each floor (a mask and ``"planks"`` or ``"tiles"``)
    painted as a rendered listing paints it, the drawing's lines on top (the floor times the
    drawing's grey over white). Planks are of one wood of ``WOOD_GREYS`` for the drawing, their
    edges every ``plank_px`` (low, high: a range of integers) px along the rows or the columns,
    10-25 % darker than the wood, with grain of up to 12 grey levels; tiles of one of
    ``TILE_GREYS`` per floor, joints every ``tile_px`` px, 10-20 % darker."""
    h, w = image.shape
    drawn = image.astype(np.float32)
    out = drawn.copy()
    wood = float(rng.choice(WOOD_GREYS))
    grain = rng.uniform(0.0, 12.0)
    for floor, kind in floors:
        if not floor.any():
            continue
        if kind == "tiles":
            grey, spacing = float(rng.choice(TILE_GREYS)), max(2, int(rng.integers(*tile_px)))
            joints = np.zeros((h, w), bool)
            joints[::spacing] = True
            joints[:, ::spacing] = True
            texture = np.where(joints, grey * rng.uniform(0.8, 0.9), grey)
        else:
            spacing = max(2, int(rng.integers(*plank_px)))
            edge = wood * rng.uniform(0.75, 0.9)
            along = np.arange(w if rng.random() < 0.5 else h) % spacing == 0
            edges = np.broadcast_to(along, (h, w)) if along.size == w else along[:, None]
            texture = np.where(edges, edge, wood) + rng.normal(0.0, grain, (h, w))
        out[floor] = np.broadcast_to(texture, (h, w))[floor] * drawn[floor] / 255.0
    return np.clip(out, 0, 255).round().astype(np.uint8)
