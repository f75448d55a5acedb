"""``f2n SUBCOMMAND``: the project's command line, one entry point for its four programs.

``f2n run PLAN`` is ``python -m f2n_drake.run PLAN``, and so on for ``data``, ``train`` and
``evaluate``; each subcommand's own ``--help`` lists its options. This only dispatches.
"""

from __future__ import annotations

import importlib
import sys

from f2n_drake.core.errors import run_cli

SUBCOMMANDS = {
    "run": ("f2n_drake.run", "floor plan in, route and simulated drive out"),
    "data": ("f2n_drake.datasets.cli", "generate or render training drawings"),
    "train": ("f2n_drake.segmenter.train", "train the segmenter"),
    "evaluate": ("f2n_drake.evaluate.__main__", "segmentation, planning and navigation benchmarks"),
}


def usage() -> str:
    lines = [f"  {name:9s} {help_}" for name, (_, help_) in SUBCOMMANDS.items()]
    return "usage: f2n {run,data,train,evaluate} [options]\n" + "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """Run subcommand ``argv[0]`` with the rest of ``argv`` (default ``sys.argv[1:]``)."""
    argv = sys.argv[1:] if argv is None else list(argv)
    if not argv or argv[0] not in SUBCOMMANDS:
        print(usage(), file=sys.stderr)
        return 0 if argv and argv[0] in ("-h", "--help") else 2
    name, rest = argv[0], argv[1:]
    module = importlib.import_module(SUBCOMMANDS[name][0])
    if name == "evaluate":  # a dispatcher itself, with its own error handling
        return module.main(rest)
    return run_cli(module.main, rest)


if __name__ == "__main__":
    sys.exit(main())
