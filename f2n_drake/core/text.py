"""``TextBox``: one run of words read on a drawing (a room name, a printed size), in pixels.

Perception reads them (``f2n_drake.perception.reading``) and places each in the instance it lies
in; the room-name prior and the printed-size scale read them from ``ParsedPlan.texts``. Text is
never a wall, a room boundary or an obstacle: it is the paper of the room it is written in.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np


@dataclass(frozen=True)
class TextBox:
    """One line of text on a drawing.

    Attributes:
        text: the string read.
        confidence: the recogniser's confidence, in 0..1.
        box_px: (col0, row0, col1, row1) axis-aligned bounds [px], col1/row1 exclusive.
        instance_id: id of the instance the box lies in (most of its pixels), None outside
            every instance.
    """

    text: str
    confidence: float
    box_px: tuple[int, int, int, int]
    instance_id: int | None = None

    @property
    def centre_px(self) -> tuple[float, float]:
        """(col, row) centre of the box [px]."""
        c0, r0, c1, r1 = self.box_px
        return (c0 + c1) / 2, (r0 + r1) / 2

    @property
    def height_px(self) -> int:
        return self.box_px[3] - self.box_px[1]

    def scaled(self, factor: float) -> TextBox:
        """The box on a drawing ``factor`` times smaller (a planning grid ``factor`` px per
        cell)."""
        c0, r0, c1, r1 = self.box_px
        box = (
            int(c0 // factor),
            int(r0 // factor),
            int(np.ceil(c1 / factor)),
            int(np.ceil(r1 / factor)),
        )
        return replace(self, box_px=box)
