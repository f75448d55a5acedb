"""The semantic classes of a floor plan, in the label order used everywhere.

Label ids follow FloorPlan2Nav: 0 background, 1 living, 2 bedroom, 3 bathroom, 4 kitchen,
5 balcony, 6 wall, 7 door, 8 window, 9 front door. ``opening`` is not a pixel class: it is the
connector recorded where two spaces meet with no wall between them (an open kitchen).
"""

from __future__ import annotations

CLASS_NAMES: tuple[str, ...] = (
    "background",
    "living",
    "bedroom",
    "bathroom",
    "kitchen",
    "balcony",
    "wall",
    "door",
    "window",
    "front_door",
)
NUM_CLASSES = len(CLASS_NAMES)
CLASS_ID: dict[str, int] = {name: i for i, name in enumerate(CLASS_NAMES)}

SPACE_CLASSES: tuple[str, ...] = ("living", "bedroom", "bathroom", "kitchen", "balcony")
"""Functional spaces: graph nodes a robot can be in."""

CONNECTOR_CLASSES: tuple[str, ...] = ("door", "window", "front_door")
"""Connector pixel classes; the graph adds ``opening`` for wall-less passages."""

OPENING = "opening"

PAINT_ORDER: tuple[str, ...] = (
    "living",
    "bedroom",
    "bathroom",
    "kitchen",
    "balcony",
    "wall",
    "window",
    "door",
    "front_door",
)
"""Classes in the order they are rasterised; the last one painted owns a pixel (label masks and
ground-truth instances alike)."""

PLAN_CLASSES: tuple[str, ...] = CLASS_NAMES[1:]
"""Keys a FloorPlan always has (every labelled class but background)."""

EXTRA_PLAN_KEYS: tuple[str, ...] = (
    "storage",
    "stair",
    "garden",
    "pool",
    "parking",
    "veranda",
    "inner",
    "land",
    "neighbor",
)
"""Optional ResPlan keys kept by FloorPlan but not labelled (they render as background)."""

# RGB colours for figures, one per label id.
PALETTE: tuple[tuple[int, int, int], ...] = (
    (255, 255, 255),  # background
    (244, 208, 63),  # living
    (93, 173, 226),  # bedroom
    (72, 201, 176),  # bathroom
    (235, 152, 78),  # kitchen
    (165, 105, 189),  # balcony
    (40, 40, 40),  # wall
    (231, 76, 60),  # door
    (0, 220, 230),  # window
    (30, 160, 30),  # front door
)
