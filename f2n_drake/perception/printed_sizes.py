"""Printed room sizes ("4.50 x 2.08m", "14'9\\" x 6'10\\"", "12.5 m²", "88 sf") and the scale
they give.

Each size is matched to the room it is written in (``TextBox.instance_id``). A room's
dimensions give metres per pixel as sqrt(printed area / drawn area), its drawn area the
room's minimum rotated rectangle; a printed area, against the room's pixels. A room's drawn
size is its paper plus half an outline on each side (the outlines are drawn centred on the wall
faces; ``f2n_drake.mapping.graph.line_gap_px`` measures their thickness). Dimensions written
where the parse found no room (a room open to its neighbours through door gaps, voted
background), or in an instance that holds the sizes of several rooms (rooms run together), are
matched to the span between the walls, windows and doors (``labels``) met going
left, right, up and down from the text's centre. The scale is the median
over rooms, its spread the median absolute deviation relative to it. A total area written
outside every room ("Approx. 1295 sq. feet (120.31 sq. metres)") is matched to the flat's
footprint, used only when no room has a size.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import cv2
import numpy as np

from f2n_drake.core.classes import CLASS_ID, CONNECTOR_CLASSES
from f2n_drake.core.parsed import Instance, ParsedPlan
from f2n_drake.core.text import TextBox
from f2n_drake.mapping.graph import line_gap_px

FOOT_M = 0.3048
INCH_M = 0.0254

_NUMBER = r"(\d+(?:[.,]\d+)?)"
_FEET = r"(\d{1,2})\s*['’′`]\s*(?:(\d{1,2})\s*(?:[\"”″]|''|’’)?)?"
_BY = r"\s*[x×X*]\s*"
_METRIC_DIMS = re.compile(_NUMBER + r"\s*(mm|cm|m)?" + _BY + _NUMBER + r"\s*(mm|cm|m)?\b")
_IMPERIAL_DIMS = re.compile(_FEET + _BY + _FEET)
_AREA_M2 = re.compile(
    _NUMBER + r"\s*(?:m2|m²|m\^2|sqm|sq\.?\s*m(?:etres|eters|etre|eter)?\b|square\s+met)",
    re.IGNORECASE,
)
_AREA_FT2 = re.compile(
    _NUMBER + r"\s*(?:sf\b|sq\.?\s*f(?:ee)?t|ft2|ft²|square\s+f(?:ee|oo)t)", re.IGNORECASE
)
_METRE_UNITS = {"mm": 0.001, "cm": 0.01, "m": 1.0}


@dataclass(frozen=True)
class PrintedSize:
    """A size printed on a drawing: ``area_m2`` [m²], and the ``sides_m`` (a, b) [m] when it is
    printed as dimensions rather than as an area."""

    area_m2: float
    sides_m: tuple[float, float] | None = None


def _number(text: str) -> float:
    return float(text.replace(",", "."))


def parse_size(text: str) -> PrintedSize | None:
    """The room size ``text`` prints, None when it prints none.

    Dimensions: "4.50 x 2.08m", "3.66 x 2.59 m", "4,5 x 3 m", "4500 x 2080 mm", "14'9\\" x
    6'10\\"" (a metric pair without a unit is read as metres when both sides are 0.5-30).
    Areas: "12.5 m²", "12.5 m2", "12.5 sq. metres", "88 sf", "88 sq ft", "1295 sq. feet".
    Metric wins where a line prints both.
    """
    text = text.replace("’", "'").replace("”", '"')
    for match in _METRIC_DIMS.finditer(text):
        a, unit_a, b, unit_b = match.groups()
        unit = unit_b or unit_a
        a_m, b_m = _number(a), _number(b)
        if unit is None and not ("." in a + b or "," in a + b):
            continue
        factor = _METRE_UNITS[unit] if unit else 1.0
        a_m, b_m = a_m * factor, b_m * factor
        if 0.5 <= a_m <= 30 and 0.5 <= b_m <= 30:
            return PrintedSize(a_m * b_m, (a_m, b_m))
    if match := _AREA_M2.search(text):
        area = _number(match.group(1))
        return PrintedSize(area) if 0.5 <= area <= 5000 else None
    if match := _IMPERIAL_DIMS.search(text):
        feet_a, inches_a, feet_b, inches_b = (int(v) if v else 0 for v in match.groups())
        if inches_a < 12 and inches_b < 12:
            a_m = feet_a * FOOT_M + inches_a * INCH_M
            b_m = feet_b * FOOT_M + inches_b * INCH_M
            if 0.5 <= a_m <= 30 and 0.5 <= b_m <= 30:
                return PrintedSize(a_m * b_m, (a_m, b_m))
    if match := _AREA_FT2.search(text):
        area = _number(match.group(1)) * FOOT_M**2
        return PrintedSize(area) if 0.5 <= area <= 5000 else None
    return None


@dataclass(frozen=True)
class PrintedScale:
    """The scale printed sizes give: ``metres_per_px`` [m/px], from ``n_rooms`` rooms (0 when
    from a total area), ``spread`` the median absolute deviation over rooms relative to it."""

    metres_per_px: float
    n_rooms: int
    spread: float

    def describe(self) -> str:
        """How the scale was found, as ``run`` prints it."""
        if self.n_rooms == 0:
            return "from the printed total area"
        rooms = f"{self.n_rooms} printed room size{'s' * (self.n_rooms > 1)}"
        return f"from {rooms}, spread {100 * self.spread:.0f} %"


def _room_estimate(inst: Instance, size: PrintedSize, outline_px: float) -> float | None:
    """Metres per pixel that make ``inst`` as large as ``size`` says."""
    if size.sides_m is not None:
        (_, _), (w, h), _ = cv2.minAreaRect(np.asarray(inst.contour_px, np.float32))
        drawn_px2 = (w + 1 + outline_px) * (h + 1 + outline_px)
    else:
        perimeter = cv2.arcLength(np.asarray(inst.contour_px, np.float32), closed=True)
        drawn_px2 = inst.area_px + perimeter * outline_px / 2
    return math.sqrt(size.area_m2 / drawn_px2) if drawn_px2 > 0 else None


_BOUNDARY_IDS = [CLASS_ID[name] for name in ("wall", "window", "door", "front_door")]
SAME_ROOM = 0.1
"""Sizes printed in one instance whose areas differ by more than this (relative) are of
different rooms: the instance is rooms the parse ran together, and each size is matched to the
walls around it instead."""
MAX_ASPECT_MISMATCH = 0.25
"""A span between walls whose proportions differ from the printed dimensions' by more than this
(relative) is not the room's (furniture or a counter stopped a ray): no estimate."""


def _span_estimate(
    labels: np.ndarray, centre_px: tuple[float, float], size: PrintedSize
) -> tuple[float, tuple[int, ...]] | None:
    """Metres per pixel from the walls around a dimensions text centred at ``centre_px``, and
    the walls' positions (the same for every text of one room)."""
    col, row = int(centre_px[0]), int(centre_px[1])
    boundary = np.isin(labels, _BOUNDARY_IDS)
    spans, walls = [], []
    for line, at in ((boundary[row, :], col), (boundary[:, col], row)):
        before, after = np.flatnonzero(line[:at]), np.flatnonzero(line[at:])
        if not (before.size and after.size):
            return None
        spans.append(float(after[0] + at - before[-1] - 1))
        walls += [int(before[-1]), int(after[0] + at)]
    a, b = sorted(size.sides_m)
    p, q = sorted(spans)
    if p <= 0 or abs((b / a) / (q / p) - 1) > MAX_ASPECT_MISMATCH:
        return None
    return math.sqrt(size.area_m2 / (p * q)), tuple(walls)


def _merged_rooms(read: list[tuple[TextBox, PrintedSize]]) -> set[int]:
    """Instances holding the sizes of more than one room (rooms the parse ran together): two
    printed areas more than ``SAME_ROOM`` apart."""
    areas: dict[int, list[float]] = {}
    for text, size in read:
        if text.instance_id is not None:
            areas.setdefault(text.instance_id, []).append(size.area_m2)
    return {i for i, a in areas.items() if max(a) > (1 + SAME_ROOM) * min(a)}


def footprint_px(parsed: ParsedPlan) -> int:
    """Pixels inside the flat's outer outline: every instance and the lines between them."""
    inside = (parsed.instance_ids > 0).astype(np.uint8)
    inside = cv2.morphologyEx(inside, cv2.MORPH_CLOSE, np.ones((7, 7), np.uint8))
    contours, _ = cv2.findContours(inside, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
    filled = np.zeros_like(inside)
    cv2.drawContours(filled, contours, -1, 1, cv2.FILLED)
    return int(filled.sum())


def printed_scale(parsed: ParsedPlan) -> PrintedScale | None:
    """The scale the sizes printed in ``parsed.texts`` give, None when none is printed."""
    rooms = {inst.id: inst for inst in parsed.instances if inst.class_name not in CONNECTOR_CLASSES}
    if not any(parse_size(t.text) for t in parsed.texts):
        return None
    outline_px = line_gap_px(parsed)
    per_room: dict[int | tuple[int, ...], list[float]] = {}
    totals = []
    read = [(t, size) for t in parsed.texts if (size := parse_size(t.text)) is not None]
    merged = _merged_rooms(read)
    for text, size in read:
        if text.instance_id in rooms and text.instance_id not in merged:
            estimate = _room_estimate(rooms[text.instance_id], size, outline_px)
            if estimate is not None:
                per_room.setdefault(text.instance_id, []).append(estimate)
        elif (text.instance_id is None or text.instance_id in merged) and size.sides_m:
            found = _span_estimate(parsed.labels, text.centre_px, size)
            if found is not None:  # a room keyed by its walls
                per_room.setdefault(found[1], []).append(found[0])
        elif text.instance_id is None:
            totals.append(size.area_m2)
    if per_room:
        estimates = np.array([np.median(v) for v in per_room.values()])
        scale = float(np.median(estimates))
        spread = float(np.median(np.abs(estimates - scale)) / scale)
        return PrintedScale(scale, len(estimates), spread)
    footprint = footprint_px(parsed)
    if totals and footprint:
        return PrintedScale(math.sqrt(max(totals) / footprint), 0, 0.0)
    return None
