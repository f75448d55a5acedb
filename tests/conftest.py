"""Fixtures shared by several test files: the bundled example plan, the JSON a CLI printed, and
small test drawings parsed at their own size."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import pytest

from f2n_drake.core.paths import REPO_ROOT
from f2n_drake.perception import small_drawings


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


@pytest.fixture
def drawings_at_own_size(monkeypatch) -> None:
    """Drawings of any size parsed at their own size, not enlarged
    (``perception.small_drawings``): for tests whose small drawings are checked pixel by pixel,
    or whose stubs give words and labels on the drawing's own grid."""
    monkeypatch.setattr(small_drawings, "SMALL_DRAWING_PX", 0)
