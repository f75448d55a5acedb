"""Finding data files: one resolver, with an environment-variable override."""

from __future__ import annotations

import os
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[2]


def resplan_sample_path() -> Path:
    """The two-plan ResPlan sample: ``$F2N_DRAKE_RESPLAN_SAMPLE`` or ``../shared/data/...``."""
    env = os.environ.get("F2N_DRAKE_RESPLAN_SAMPLE")
    if env:
        return Path(env)
    return REPO_ROOT.parent / "shared" / "data" / "resplan_sample" / "resplan_sample.pkl"


def example_plan_path() -> Path:
    """The drawing bundled in ``examples/`` for the README's first command."""
    return REPO_ROOT / "examples" / "plan.png"
