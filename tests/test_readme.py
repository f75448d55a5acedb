"""The README's Python example runs as printed (the product page must not drift from the API)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def python_blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", (ROOT / "README.md").read_text(), flags=re.S)


def test_readme_has_one_python_example_using_the_public_api():
    blocks = python_blocks()
    assert len(blocks) == 1
    assert "from f2n_drake import" in blocks[0]


@pytest.mark.slow
def test_readme_python_example_runs(monkeypatch, capsys):
    monkeypatch.chdir(ROOT)
    exec(compile(python_blocks()[0], "README.md", "exec"), {})
    printed = capsys.readouterr().out
    assert re.fullmatch(r"\d+\.\d\d m, mean error \d+\.\d cm\n", printed), printed
