"""Datasets: the plan generator, the renderer and its looks, readers of real datasets."""

from f2n_drake.core.paths import resplan_sample_path
from f2n_drake.datasets.generator import generate_building, generate_plan
from f2n_drake.datasets.ground_truth import parse_ground_truth
from f2n_drake.datasets.render import DrawingStyle, RenderedPlan, render
from f2n_drake.datasets.resplan import load_resplan

__all__ = [
    "DrawingStyle",
    "RenderedPlan",
    "generate_building",
    "generate_plan",
    "load_resplan",
    "parse_ground_truth",
    "render",
    "resplan_sample_path",
]
