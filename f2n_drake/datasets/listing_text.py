"""Room names and sizes printed as listings print them, with their exact truth: what
``python -m f2n_drake.evaluate reading`` measures the reading of words against.

Each room gets a name (``PRINTED_NAMES``: English, German, French, Spanish, Italian, Dutch,
Swedish and Finnish names and abbreviations; OpenCV's Hershey fonts have no accents, so
"Kuche", "Sejour") and, below it, its size: dimensions in metres ("4.50 x 2.08m", "4,50 x 2,08
m") or feet and inches ("14'9\\" x 6'10\\""), or its area ("12.5 m2", "88 sf"). One font, letter
height (0.2-0.35 m) and size format per drawing; the lines centred on the room's most
inscribed point or set in its upper-left part, never touching its outlines.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from f2n_drake.core.raster import PixelGrid
from f2n_drake.datasets.listing_marks import inscribed_rooms

PRINTED_NAMES: dict[str, tuple[str, ...]] = {
    "living": ("LIVING ROOM", "Lounge", "Wohnzimmer", "Sejour", "Salon", "Soggiorno",
               "Woonkamer", "Vardagsrum", "OH", "Living/Dining"),
    "bedroom": ("BEDROOM", "Bedroom 2", "Schlafzimmer", "Chambre", "Dormitorio", "Camera",
                "Slaapkamer", "Sovrum", "MH", "BR"),
    "bathroom": ("BATH", "Bathroom", "WC", "En-suite", "Bad", "SDB", "Bano", "Bagno",
                 "Badkamer", "Badrum", "KH"),
    "kitchen": ("KITCHEN", "Kitchen/Diner", "Kuche", "Cuisine", "Cocina", "Cucina", "Keuken",
                "Kok", "Keittio"),
    "balcony": ("BALCONY", "Terrace", "Balkon", "Balcon", "Terraza", "Balcone", "Balkong",
                "Parveke"),
}  # fmt: skip
"""Names (and abbreviations) a room of each space class may be printed with."""

SIZE_FORMATS = ("metres", "metres-comma", "feet", "square-metres", "square-feet")
FONTS = (cv2.FONT_HERSHEY_SIMPLEX, cv2.FONT_HERSHEY_DUPLEX, cv2.FONT_HERSHEY_PLAIN)
FOOT_M = 0.3048


@dataclass(frozen=True)
class PrintedRoom:
    """What was printed in one room: its ``class_name``, ``name`` and ``size`` lines, its true
    ``sides_m`` (bounding box of its label pixels [m]) and ``area_m2``, and the (col, row)
    ``centre_px`` of the text."""

    class_name: str
    name: str
    size: str
    sides_m: tuple[float, float]
    area_m2: float
    centre_px: tuple[int, int]


def _feet(metres: float) -> str:
    inches = round(metres / FOOT_M * 12)
    return f"{inches // 12}'{inches % 12}\""


def size_line(sides_m: tuple[float, float], area_m2: float, size_format: str) -> str:
    """A room's size as ``size_format`` prints it."""
    a, b = sorted(sides_m, reverse=True)
    if size_format == "metres":
        return f"{a:.2f} x {b:.2f}m"
    if size_format == "metres-comma":
        return f"{a:.2f} x {b:.2f} m".replace(".", ",")
    if size_format == "feet":
        return f"{_feet(a)} x {_feet(b)}"
    if size_format == "square-metres":
        return f"{area_m2:.1f} m2"
    if size_format == "square-feet":
        return f"{area_m2 / FOOT_M**2:.0f} sf"
    raise ValueError(f"unknown size format {size_format!r}; choose from {SIZE_FORMATS}")


def print_room_text(
    image: np.ndarray, labels: np.ndarray, grid: PixelGrid, rng: np.random.Generator
) -> tuple[np.ndarray, list[PrintedRoom]]:
    """``image`` with each room's name and size printed in it, and what was printed where.
    Rooms too narrow for letters 6 px high are left blank."""
    out = image.copy()
    font = FONTS[int(rng.integers(len(FONTS)))]
    size_format = SIZE_FORMATS[int(rng.integers(len(SIZE_FORMATS)))]
    height_px = grid.length_px(rng.uniform(0.2, 0.35))
    centred = rng.random() < 0.6
    (_, unit_h), _ = cv2.getTextSize("M", font, 1.0, 1)
    ink = int(rng.integers(0, 60))
    printed = []
    for class_name, room, depth, (row, col) in inscribed_rooms(labels):
        rows, cols = np.nonzero(room)
        sides_m = (
            (cols.max() - cols.min() + 1) * grid.metres_per_px,
            (rows.max() - rows.min() + 1) * grid.metres_per_px,
        )
        area_m2 = float(room.sum() * grid.metres_per_px**2)
        names = PRINTED_NAMES[class_name]
        words = (names[int(rng.integers(len(names)))], size_line(sides_m, area_m2, size_format))
        scale = height_px / unit_h
        thickness = max(1, round(height_px / 12))
        (w, h), _ = cv2.getTextSize(max(words, key=len), font, scale, thickness)
        fit = min(1.0, 1.4 * depth[row, col] / max(w, 1), 0.8 * depth[row, col] / max(h, 1))
        scale, h, w = scale * fit, h * fit, w * fit
        if h < 6:
            continue
        if not centred:  # up and left, as far as the text's own size allows
            row = int(row - 0.5 * (depth[row, col] - 1.6 * h))
            col = int(col - 0.5 * (depth[row, col] - w / 1.4))
        for line, word in enumerate(words):
            (lw, _), _ = cv2.getTextSize(word, font, scale, thickness)
            y = int(round(row + (line - 0.5) * 1.6 * h + h / 2))
            cv2.putText(out, word, (int(col - lw / 2), y), font, scale, ink, thickness, cv2.LINE_AA)
        printed.append(PrintedRoom(class_name, *words, sides_m, area_m2, (int(col), int(row))))
    return out, printed
