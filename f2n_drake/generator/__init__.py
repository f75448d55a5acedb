"""Synthetic residential floor plans and buildings with exact ground truth.

``generate_plan(seed)`` is the entry point: deterministic per seed, ``source="synthetic"``,
metadata with ``seed``, ``kind`` ("residential"/"building"), ``open_kitchen`` and ``outline``.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from f2n_drake.generator.building import generate_building
from f2n_drake.generator.residential import generate_residential
from f2n_drake.generator.validate import validate_plan
from f2n_drake.plan import FloorPlan


def generate_plan(seed: int, *, building: bool = False) -> FloorPlan:
    """The synthetic plan of ``seed`` (an apartment, or a 50-300 room building), in metres."""
    rng = np.random.default_rng(seed)
    plan = generate_building(rng) if building else generate_residential(rng)
    return dataclasses.replace(plan, metadata={"seed": int(seed), **plan.metadata})


__all__ = ["generate_building", "generate_plan", "generate_residential", "validate_plan"]
