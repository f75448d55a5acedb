"""Small drawings read enlarged: a listing's thumbnail parsed at the size the parse works best at.

The parse's geometry is made for drawings a few hundred pixels and more across (R3D's listings
are 600 px on their long side): at 360 px a partition is a one-pixel line, a door's gap a few
pixels, a window's lines merge, and rooms, doors and their names are lost. A drawing whose longer
side is under ``SMALL_DRAWING_PX`` is therefore enlarged by a whole factor (:func:`enlargement`,
bicubic) to at least ``READ_SIDE_PX`` and parsed there; the network reads it at its own size
(:func:`read_at_drawing_size`: its input is resized to the network's anyway), and the parse is
brought back onto the drawing's own grid (:func:`on_drawing_grid`), so its labels and instances
lie on the pixels the user handed over. Nothing is added to what the drawing holds: the enlarged
strokes give the geometry room, they do not make lost names readable.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

import cv2
import numpy as np

from f2n_drake.core.parsed import ParsedPlan
from f2n_drake.mapping.resolution import coarsened
from f2n_drake.perception.image import Prediction

SMALL_DRAWING_PX = 400
"""A drawing whose longer side is shorter than this [px] is parsed enlarged."""
READ_SIDE_PX = 600
"""The longer side [px] a small drawing is enlarged to at least."""


def enlargement(shape: tuple[int, ...]) -> int:
    """The whole factor a drawing of ``shape`` is parsed enlarged by: 1 when its longer side is
    at least ``SMALL_DRAWING_PX``, else the least factor, at least 2, taking it to
    ``READ_SIDE_PX``."""
    side = max(shape[:2])
    if side >= SMALL_DRAWING_PX:
        return 1
    return max(2, math.ceil(READ_SIDE_PX / side))


def enlarged(grey: np.ndarray, factor: int) -> np.ndarray:
    """``grey`` enlarged ``factor`` times (bicubic), each pixel a ``factor`` square."""
    return cv2.resize(grey, None, fx=factor, fy=factor, interpolation=cv2.INTER_CUBIC)


def read_at_drawing_size(
    predict: Callable[[np.ndarray], Prediction], factor: int
) -> Callable[[np.ndarray], Prediction]:
    """``predict`` for an enlarged drawing, asking the network about it at the drawing's own
    size (shrunk ``factor`` times back, by area): its labels enlarged as nearest pixels, its
    probabilities bilinearly."""

    def read(drawing: np.ndarray) -> Prediction:
        height, width = drawing.shape[:2]
        small = cv2.resize(
            drawing, (width // factor, height // factor), interpolation=cv2.INTER_AREA
        )
        labels, probabilities = predict(small)
        labels = np.asarray(labels)  # class ids: each fits a byte, which OpenCV resizes
        grown = cv2.resize(
            labels.astype(np.uint8), (width, height), interpolation=cv2.INTER_NEAREST
        )
        labels = grown.astype(labels.dtype)
        if probabilities is not None:
            channels = np.moveaxis(np.asarray(probabilities, np.float32), 0, -1)
            grown = cv2.resize(channels, (width, height), interpolation=cv2.INTER_LINEAR)
            probabilities = np.moveaxis(grown.reshape(height, width, -1), -1, 0)
        return labels, probabilities

    return read


def on_drawing_grid(parsed: ParsedPlan, factor: int) -> ParsedPlan:
    """A plan parsed on its drawing enlarged ``factor`` times, brought back onto the drawing's
    grid (``mapping.resolution.coarsened``: a door or window pixel in a block makes it that
    connector, a line pixel a line, else the block takes its centre's instance); lengths in
    pixels shrink with it."""
    if factor == 1:
        return parsed
    back = coarsened(parsed, factor)
    return dataclasses.replace(
        back,
        door_outline_px=parsed.door_outline_px / factor,
        scale_source=parsed.scale_source,
    )
