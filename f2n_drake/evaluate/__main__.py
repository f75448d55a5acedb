"""``python -m f2n_drake.evaluate SUBCOMMAND``: segmentation, hatching, photos,
storerooms, scale, reading, routes, parse-speed, planning, navigation, replanning.

Each subcommand lives in its own module with a ``main(argv) -> int``; this only dispatches.
"""

from __future__ import annotations

import importlib
import sys

from f2n_drake.core.errors import run_cli

SUBCOMMANDS = {
    "segmentation": ("f2n_drake.evaluate.segmentation", "segmentation metrics vs ground truth"),
    "hatching": ("f2n_drake.evaluate.hatching", "on which drawings hatched walls are found"),
    "photos": (
        "f2n_drake.evaluate.photos",
        "does a drawing photographed (dimmed, at an angle) parse as it did?",
    ),
    "storerooms": (
        "f2n_drake.evaluate.storerooms",
        "how far ground truth tells storerooms from bathrooms",
    ),
    "scale": (
        "f2n_drake.evaluate.scale",
        "how far off the scale estimated from door widths is",
    ),
    "reading": (
        "f2n_drake.evaluate.reading",
        "scale from printed sizes, room names and reading time on generated drawings",
    ),
    "routes": (
        "f2n_drake.evaluate.routes",
        "drawings in, routes out: can the parsed graph be driven?",
    ),
    "parse-speed": ("f2n_drake.evaluate.parse_speed", "time the full parse of a drawing"),
    "planning": ("f2n_drake.evaluate.planning", "global A* vs hierarchical planning benchmark"),
    "navigation": ("f2n_drake.evaluate.navigation", "Drake navigation benchmark"),
    "replanning": (
        "f2n_drake.evaluate.replanning",
        "a door of the route closed: replanned round it, or stopped with a message",
    ),
}


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if not argv or argv[0] not in SUBCOMMANDS:
        lines = [f"  {name:13s} {help_}" for name, (_, help_) in SUBCOMMANDS.items()]
        print(
            "usage: python -m f2n_drake.evaluate SUBCOMMAND [options]\n" + "\n".join(lines),
            file=sys.stderr,
        )
        return 0 if argv and argv[0] in ("-h", "--help") else 2
    module = importlib.import_module(SUBCOMMANDS[argv[0]][0])
    return run_cli(module.main, argv[1:])


if __name__ == "__main__":
    sys.exit(main())
