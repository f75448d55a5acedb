"""f2n_drake: floor plan images in, robot navigation out."""

from f2n_drake.core.classes import CLASS_ID, CLASS_NAMES, NUM_CLASSES
from f2n_drake.core.errors import F2NError, InputError, PlanningError
from f2n_drake.core.plan import FloorPlan
from f2n_drake.core.raster import PixelGrid

__all__ = [
    "CLASS_ID",
    "CLASS_NAMES",
    "NUM_CLASSES",
    "F2NError",
    "FloorPlan",
    "InputError",
    "PixelGrid",
    "PlanningError",
]
__version__ = "0.1.0"
