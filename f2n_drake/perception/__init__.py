"""Perception: a drawing in, labelled instances (a ``ParsedPlan``) out."""

from f2n_drake.perception.instances import (
    DEFAULT_SPLIT,
    SplitOptions,
    binarize,
    enclosed_regions,
    extract_instances,
    vote_corrected_labels,
)

__all__ = [
    "DEFAULT_SPLIT",
    "SplitOptions",
    "binarize",
    "enclosed_regions",
    "extract_instances",
    "vote_corrected_labels",
]
