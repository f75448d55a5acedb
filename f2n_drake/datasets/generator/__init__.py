"""Synthetic residential floor plans and buildings with exact ground truth.

``generate_plan(seed)`` is the entry point: deterministic per seed, ``source="synthetic"``,
metadata with ``seed``, ``kind`` ("residential"/"building"), ``open_kitchen`` and ``outline``;
an apartment's also ``opening_sizes`` (``"typical"``, or ``"varied"`` for training).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from f2n_drake.core.plan import FloorPlan
from f2n_drake.datasets.generator.building import generate_building
from f2n_drake.datasets.generator.openings import OPENING_SIZES, TYPICAL_SIZES, OpeningSizes
from f2n_drake.datasets.generator.residential import generate_residential
from f2n_drake.datasets.generator.validate import validate_plan


def generate_plan(
    seed: int, *, building: bool = False, sizes: OpeningSizes = TYPICAL_SIZES
) -> FloorPlan:
    """The synthetic plan of ``seed`` (an apartment, or a 50-300 room building), in metres.

    ``sizes`` are the apartment's door and window widths (buildings keep their own)."""
    rng = np.random.default_rng(seed)
    plan = generate_building(rng) if building else generate_residential(rng, sizes)
    return dataclasses.replace(plan, metadata={"seed": int(seed), **plan.metadata})


__all__ = [
    "OPENING_SIZES",
    "TYPICAL_SIZES",
    "OpeningSizes",
    "generate_building",
    "generate_plan",
    "generate_residential",
    "validate_plan",
]
