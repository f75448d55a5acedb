"""Fixtures shared by several test files: the bundled example plan, and the JSON a CLI printed."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import pytest

from f2n_drake.core.paths import REPO_ROOT


@pytest.fixture(scope="session")
def example_json() -> Path:
    """The bundled plan as vector ground truth (``examples/plan.json``)."""
    return REPO_ROOT / "examples" / "plan.json"


@pytest.fixture(scope="session")
def example_png() -> Path:
    """The bundled plan as a drawing (``examples/plan.png``)."""
    return REPO_ROOT / "examples" / "plan.png"


@pytest.fixture
def printed_json(capsys) -> Callable[[], dict]:
    """Reads what a ``--json`` CLI printed to stdout since the last read."""
    return lambda: json.loads(capsys.readouterr().out)
