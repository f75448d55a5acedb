"""Error types, argument checks, and the one place CLIs turn errors into a one-line message and
an exit code.

Exit codes of every ``python -m f2n_drake.*`` command:

====  ==========================================================================================
0     done
1     a bug: an unexpected exception (its traceback is printed)
2     bad input: a file, image, option or robot profile that cannot be used (``InputError``)
3     no route: the parse succeeded but no route can be planned for the robot
      (``PlanningError``); ``run`` still writes the parse to ``--out``
4     the simulated robot did not reach its goal (``run``; with ``--correction all``, any mode)
130   interrupted (SIGINT, Ctrl-C); nothing half-written is left
143   terminated (SIGTERM); nothing half-written is left
====  ==========================================================================================
"""

from __future__ import annotations

import argparse
import logging
import math
import signal
import sys
import threading
from collections.abc import Callable


class F2NError(ValueError):
    """Base class of every error f2n_drake raises on purpose (bad input, no route, ...)."""


class InputError(F2NError):
    """A file, image or argument the user gave cannot be used."""


class PlanningError(F2NError):
    """No route exists for this robot, or a start/goal is where the robot cannot be."""


class Terminated(BaseException):
    """SIGTERM arrived: raised where the program is, so ``finally`` blocks clean up."""


EXIT_OK = 0
EXIT_BAD_INPUT = 2
EXIT_NO_ROUTE = 3
EXIT_GOAL_NOT_REACHED = 4
EXIT_INTERRUPTED = 130
EXIT_TERMINATED = 143


class ArgumentParser(argparse.ArgumentParser):
    """``argparse.ArgumentParser`` whose usage errors are ``InputError``: one ``error:`` line and
    exit 2 under ``run_cli``, like every other bad input (plain argparse prints its usage too)."""

    def error(self, message: str):
        raise InputError(f"{message} (see {self.prog} --help)")


def positive_int(text: str) -> int:
    """argparse ``type`` for 1-based numbers (a PDF's page): an integer >= 1."""
    value = non_negative_int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be >= 1, got {value}")
    return value


def paper_scale(text: str) -> float:
    """argparse ``type`` for a drawing's paper scale, ``1:N`` or ``N`` (1 <= N <= 100000): N."""
    denominator = text.strip().removeprefix("1:")
    try:
        value = float(denominator)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is no paper scale (say 1:100)") from None
    if not (math.isfinite(value) and 1.0 <= value <= 100_000.0):
        raise argparse.ArgumentTypeError(f"a paper scale is 1:1 to 1:100000, got {text!r}")
    return value


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


def finite_float(
    low: float = -math.inf,
    high: float = math.inf,
    *,
    low_open: bool = False,
) -> Callable[[str], float]:
    """argparse ``type`` for a finite number in ``[low, high]`` (``(low, high]`` with
    ``low_open``); nan, inf and values outside exit 2 with the range in the message."""
    bracket = "(" if low_open else "["

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
        too_low = value <= low if low_open else value < low
        if not math.isfinite(value) or too_low or value > high:
            raise argparse.ArgumentTypeError(
                f"must be a finite number in {bracket}{low:g}, {high:g}], got {text}"
            )
        return value

    parse.__name__ = "number"  # argparse names the type in its messages
    return parse


def count_or_any(text: str) -> int | None:
    """argparse ``type`` of ``--front-doors`` and ``--kitchens``: an integer >= 0, or "any"
    (None: no prior)."""
    return None if text.strip().lower() == "any" else non_negative_int(text)


def run_cli(main: Callable[[list[str] | None], int], argv: list[str] | None = None) -> int:
    """Run a CLI ``main``; expected errors become one ``error: ...`` line on stderr and their
    exit code (see the module docstring). SIGTERM is turned into ``Terminated`` while ``main``
    runs, so scratch files are removed as on Ctrl-C."""
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    for stream in (sys.stdout, sys.stderr):  # a file name that is not UTF-8 still prints
        if hasattr(stream, "reconfigure"):
            stream.reconfigure(errors="backslashreplace")
    previous = None
    if threading.current_thread() is threading.main_thread():
        previous = signal.signal(signal.SIGTERM, _raise_terminated)
    try:
        return main(argv)
    except PlanningError as exc:
        print(f"error: {_one_line(exc)}", file=sys.stderr)
        return EXIT_NO_ROUTE
    except F2NError as exc:
        print(f"error: {_one_line(exc)}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print("error: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except Terminated:
        print("error: terminated", file=sys.stderr)
        return EXIT_TERMINATED
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


def _raise_terminated(signum, frame) -> None:
    raise Terminated()


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split())
