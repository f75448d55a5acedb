"""Every tutorial runs top to bottom in test mode; notebooks are committed with outputs cleared.

Notebooks are exported to Python and run in a subprocess (no kernel, no port clashes) with
``F2N_DRAKE_TEST_MODE=1`` (the notebooks' one flag that shortens durations), Drake deprecation
warnings as errors and matplotlib headless.
"""

from __future__ import annotations

import ast
import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import nbformat
import pytest

TUTORIALS = sorted((Path(__file__).resolve().parents[2] / "tutorials").glob("*.ipynb"))
PRELUDE = """\
import warnings
from pydrake.common.deprecation import DrakeDeprecationWarning
warnings.simplefilter("error", DrakeDeprecationWarning)
import matplotlib
matplotlib.use("Agg")
"""


def notebook_as_script(path: Path) -> str:
    nb = nbformat.read(path, as_version=4)
    cells = []
    for cell in nb.cells:
        if cell.cell_type != "code":
            continue
        # IPython magics and shell escapes have no meaning in a plain script.
        lines = [ln for ln in cell.source.splitlines() if not ln.lstrip().startswith(("%", "!"))]
        cells.append("\n".join(lines))
    return PRELUDE + "\n\n".join(cells) + "\n"


def test_tutorials_exist():
    names = {p.name for p in TUTORIALS}
    assert {
        "01_parse_floor_plan.ipynb",
        "02_graph_and_planning.ipynb",
        "03_drake_navigation.ipynb",
        "04_train_segmenter.ipynb",
    } <= names


@pytest.mark.parametrize("path", TUTORIALS, ids=[p.stem for p in TUTORIALS])
def test_outputs_cleared(path):
    nb = nbformat.read(path, as_version=4)
    for cell in nb.cells:
        if cell.cell_type == "code":
            assert not cell.outputs, f"{path.name}: a code cell has outputs; clear them"
            assert cell.execution_count is None, f"{path.name}: execution counts committed"


@pytest.mark.parametrize("path", TUTORIALS, ids=[p.stem for p in TUTORIALS])
def test_tutorials_use_the_package_and_at_most_two_subpackages(path):
    tree = ast.parse(notebook_as_script(path))
    modules = {
        node.module
        for node in ast.walk(tree)
        if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("f2n_drake")
    }
    assert "f2n_drake" in modules, f"{path.name} does not use the public API"
    subpackages = {
        ".".join(m.split(".")[:2])
        for m in modules
        if m.count(".") >= 1
        and importlib.util.find_spec(".".join(m.split(".")[:2])).submodule_search_locations
    }
    assert len(subpackages) <= 2, f"{path.name} imports from {sorted(subpackages)}"


@pytest.mark.notebook
@pytest.mark.slow
@pytest.mark.parametrize("path", TUTORIALS, ids=[p.stem for p in TUTORIALS])
def test_notebook_runs(path, tmp_path):
    script = tmp_path / f"{path.stem}.py"
    script.write_text(notebook_as_script(path))
    env = {
        **os.environ,
        "F2N_DRAKE_TEST_MODE": "1",
        "MPLBACKEND": "Agg",
        "DRAKE_ALLOW_NETWORK": "meshcat",
        "PYTHONUNBUFFERED": "1",
    }
    proc = subprocess.run(
        [sys.executable, str(script)],
        cwd=path.parent,
        env=env,
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert proc.returncode == 0, (
        f"{path.name} failed:\n{proc.stdout[-3000:]}\n{proc.stderr[-5000:]}"
    )
