"""Error types and the one place CLIs turn them into a one-line message and exit code 2."""

from __future__ import annotations

import argparse
import contextlib
import logging
import os
import shutil
import sys
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path


class F2NError(ValueError):
    """Base class of every error f2n_drake raises on purpose (bad input, no route, ...)."""


class InputError(F2NError):
    """A file, image or argument the user gave cannot be used."""


class PlanningError(F2NError):
    """No route exists for this robot, or a start/goal is invalid."""


EXIT_BAD_INPUT = 2


def non_negative_int(text: str) -> int:
    """argparse ``type`` for seeds and counts: an integer >= 0 (argparse exits 2 otherwise)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be >= 0, got {value}")
    return value


def probability(text: str) -> float:
    """argparse ``type`` for probabilities: a number in 0..1 (argparse exits 2 otherwise)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not 0.0 <= value <= 1.0:
        raise argparse.ArgumentTypeError(f"must be in 0..1, got {value}")
    return value


def count_or_any(text: str) -> int | None:
    """argparse ``type`` of ``--front-doors`` and ``--kitchens``: an integer >= 0, or "any"
    (None: no prior)."""
    return None if text.strip().lower() == "any" else non_negative_int(text)


def run_cli(main: Callable[[list[str] | None], int], argv: list[str] | None = None) -> int:
    """Run a CLI ``main``; expected errors become one ``error: ...`` line on stderr and exit 2."""
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    try:
        return main(argv)
    except F2NError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print("error: interrupted", file=sys.stderr)
        return 130


@contextlib.contextmanager
def atomic_output_dir(out: str | os.PathLike) -> Iterator[Path]:
    """Yield a scratch directory that replaces ``out`` only if the block succeeds.

    Files already in ``out`` are kept unless the block writes the same names. On any exception
    the scratch directory is removed and ``out`` is left as it was: nothing half-written.

    Raises:
        InputError: ``out`` exists and is not a directory, or its parent cannot be written.
    """
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise InputError(f"output path {out} exists and is not a directory")
    parent = out.resolve().parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
        scratch = Path(tempfile.mkdtemp(prefix=f".{out.name}.", dir=parent))
    except OSError as exc:
        raise InputError(f"cannot write to {parent}: {exc.strerror}") from exc
    try:
        yield scratch
        out.mkdir(exist_ok=True)
        for item in scratch.iterdir():
            target = out / item.name
            if target.is_dir() and not target.is_symlink():
                shutil.rmtree(target)
            os.replace(item, target)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
