"""The ``f2n`` console script: one entry point dispatching to the run, data, train and evaluate
CLIs, which keep their ``python -m`` forms."""

from __future__ import annotations

import subprocess
import sys
from importlib.metadata import entry_points

import pytest

from f2n_drake import cli
from f2n_drake.evaluate import __main__ as evaluate_cli


def test_the_console_script_is_installed():
    (script,) = entry_points(group="console_scripts", name="f2n")
    assert script.value == "f2n_drake.cli:main" and script.load() is cli.main
    assert set(cli.SUBCOMMANDS) == {"run", "data", "train", "evaluate"}


def test_run_subcommand_is_the_run_cli(example_json, tmp_path, printed_json):
    argv = [str(example_json), "--no-sim", "--json", "--out", str(tmp_path / "out")]
    assert cli.main(["run", *argv]) == 0
    summary = printed_json()
    assert summary["route"][0] == "front_door_0" and summary["simulation"] == []
    assert (tmp_path / "out" / "map.pgm").is_file()


def test_errors_are_one_line_and_exit_2(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert cli.main(["run", str(tmp_path / "missing.png")]) == 2
    assert capsys.readouterr().err.startswith("error: no such file")
    assert cli.main(["evaluate", "no-such-benchmark"]) == 2


@pytest.mark.parametrize("argv, code", [([], 2), (["fly"], 2), (["--help"], 0)])
def test_usage_lists_the_subcommands(argv, code, capsys):
    assert cli.main(argv) == code
    usage = capsys.readouterr().err
    assert all(name in usage for name in cli.SUBCOMMANDS)


@pytest.mark.parametrize("name", ["data", "train"])
def test_subcommand_help(name, capsys):
    with pytest.raises(SystemExit) as exit_:
        cli.main([name, "--help"])
    assert exit_.value.code == 0 and "usage:" in capsys.readouterr().out


@pytest.mark.parametrize("module", ["f2n_drake.cli", "f2n_drake.run", "f2n_drake.evaluate"])
def test_module_forms_keep_working(module):
    done = subprocess.run(
        [sys.executable, "-m", module, "--help"], capture_output=True, text=True, check=False
    )
    assert done.returncode == 0 and "usage:" in done.stdout + done.stderr


@pytest.mark.parametrize("name", sorted(evaluate_cli.SUBCOMMANDS))
def test_every_benchmark_prints_its_help(name, capsys):
    with pytest.raises(SystemExit) as exit_:
        evaluate_cli.main([name, "--help"])
    assert exit_.value.code == 0 and "usage:" in capsys.readouterr().out
