"""f2n_drake: floor plan images in, robot navigation out.

The pipeline (``f2n_drake.pipeline``)::

    from f2n_drake import build_graph, parse_drawing, plan_route, simulate

Names are imported on first use, so ``import f2n_drake`` stays fast.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

_EXPORTS = {
    "parse_drawing": "f2n_drake.pipeline",
    "build_graph": "f2n_drake.pipeline",
    "plan_route": "f2n_drake.pipeline",
    "simulate": "f2n_drake.pipeline",
    "PlanMap": "f2n_drake.pipeline",
    "Segmentation": "f2n_drake.pipeline",
    "CLASS_ID": "f2n_drake.core.classes",
    "CLASS_NAMES": "f2n_drake.core.classes",
    "NUM_CLASSES": "f2n_drake.core.classes",
    "F2NError": "f2n_drake.core.errors",
    "InputError": "f2n_drake.core.errors",
    "PlanningError": "f2n_drake.core.errors",
    "FloorPlan": "f2n_drake.core.plan",
    "ParsedPlan": "f2n_drake.core.parsed",
    "PixelGrid": "f2n_drake.core.raster",
    "GROUND": "f2n_drake.mapping.robots",
    "UAV": "f2n_drake.mapping.robots",
    "RobotProfile": "f2n_drake.mapping.robots",
    "Route": "f2n_drake.planning.route",
    "Segmenter": "f2n_drake.segmenter.inference",
    "HierarchicalPlanner": "f2n_drake.planning.hierarchical",
    "traversable_subgraph": "f2n_drake.mapping.robots",
    "PlanGeometry": "f2n_drake.mapping.walls",
    "class_legend": "f2n_drake.outputs.figures",
    "colorize": "f2n_drake.outputs.figures",
    "plot_drift": "f2n_drake.outputs.figures",
    "plot_graph": "f2n_drake.outputs.figures",
    "plot_segmentation": "f2n_drake.outputs.figures",
    "model_path": "f2n_drake.models",
}

__all__ = [
    "CLASS_ID",
    "CLASS_NAMES",
    "F2NError",
    "FloorPlan",
    "GROUND",
    "HierarchicalPlanner",
    "InputError",
    "NUM_CLASSES",
    "ParsedPlan",
    "PixelGrid",
    "PlanGeometry",
    "PlanMap",
    "PlanningError",
    "RobotProfile",
    "Route",
    "Segmentation",
    "Segmenter",
    "UAV",
    "build_graph",
    "class_legend",
    "colorize",
    "model_path",
    "parse_drawing",
    "plan_route",
    "plot_drift",
    "plot_graph",
    "plot_segmentation",
    "simulate",
    "traversable_subgraph",
]
__version__ = "0.1.0"

if TYPE_CHECKING:
    from f2n_drake.core.classes import CLASS_ID, CLASS_NAMES, NUM_CLASSES
    from f2n_drake.core.errors import F2NError, InputError, PlanningError
    from f2n_drake.core.parsed import ParsedPlan
    from f2n_drake.core.plan import FloorPlan
    from f2n_drake.core.raster import PixelGrid
    from f2n_drake.mapping.robots import GROUND, UAV, RobotProfile, traversable_subgraph
    from f2n_drake.mapping.walls import PlanGeometry
    from f2n_drake.models import model_path
    from f2n_drake.outputs.figures import (
        class_legend,
        colorize,
        plot_drift,
        plot_graph,
        plot_segmentation,
    )
    from f2n_drake.pipeline import (
        PlanMap,
        Segmentation,
        build_graph,
        parse_drawing,
        plan_route,
        simulate,
    )
    from f2n_drake.planning.hierarchical import HierarchicalPlanner
    from f2n_drake.planning.route import Route
    from f2n_drake.segmenter.inference import Segmenter


def __getattr__(name: str) -> Any:
    if name not in _EXPORTS:
        raise AttributeError(f"module 'f2n_drake' has no attribute {name!r}")
    value = getattr(importlib.import_module(_EXPORTS[name]), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_EXPORTS})
