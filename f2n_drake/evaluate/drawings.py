"""The drawings an evaluation draws: which plans (synthetic seeds or a ResPlan pickle), how
often each (``--draws``), and how each is drawn (size, clean or random style, look), with the
command-line options that choose them. ``evaluate segmentation`` and ``evaluate hatching`` draw
the same drawings from the same options.
"""

from __future__ import annotations

import argparse
from collections.abc import Iterable, Iterator

import numpy as np

from f2n_drake.core.errors import InputError, non_negative_int
from f2n_drake.core.plan import FloorPlan
from f2n_drake.datasets.generator.openings import OPENING_SIZES
from f2n_drake.datasets.looks import LOOKS, restyle
from f2n_drake.datasets.r3d import SPLITS
from f2n_drake.datasets.render import DrawingStyle, RenderedPlan, render

TRAINING_SEED_START = 1_000_000
"""Training uses seeds >= this; evaluation seeds must stay below."""


def synthetic_plans(
    n: int, seed: int, openings: str = "typical"
) -> Iterator[tuple[str, FloorPlan]]:
    """Synthetic evaluation plans of seeds ``seed .. seed + n - 1``, generated lazily, their
    doors and windows as wide as the generator's ``OPENING_SIZES[openings]``.

    Raises (at once, not on first use):
        InputError: n < 1, or the seeds are negative or reach the training seeds (>= 1000000).
    """
    if n < 1:
        raise InputError(f"--synthetic needs at least 1 plan, got {n}")
    if seed < 0 or seed + n > TRAINING_SEED_START:
        raise InputError(
            f"evaluation seeds {seed}..{seed + n - 1} overlap the training seeds "
            f"(>= {TRAINING_SEED_START}) or are negative; pick seeds in "
            f"0..{TRAINING_SEED_START - 1}"
        )
    from f2n_drake.datasets.generator import generate_plan

    sizes = OPENING_SIZES[openings]
    return ((f"seed {s}", generate_plan(s, sizes=sizes)) for s in range(seed, seed + n))


def resplan_plans(path: str) -> list[tuple[str, FloorPlan]]:
    from f2n_drake.datasets.resplan import load_resplan

    plans = load_resplan(path)
    if not plans:
        raise InputError(f"{path} holds no plans")
    return [(f"resplan {p.metadata.get('id', i)}", p) for i, p in enumerate(plans)]


def drawn_times(
    plans: Iterable[tuple[str, FloorPlan]], draws: int
) -> Iterator[tuple[str, FloorPlan]]:
    """Each plan ``draws`` times in a row (named ``"<plan>, draw d"`` when more than once), so
    that ``evaluate`` draws it in as many random styles: one layout, many drawings."""
    for name, plan in plans:
        if draws == 1:
            yield name, plan
        else:
            yield from ((f"{name}, draw {d + 1}", plan) for d in range(draws))


def drawing(
    plan: FloorPlan, k: int, *, seed: int, size_px: int, styles: str, look: str
) -> RenderedPlan:
    """The ``k``-th drawing of an evaluation: ``plan`` rendered ``size_px`` wide in a clean or
    random style and restyled to ``look``, all drawn from the random generator of ``[seed, k]``."""
    rng = np.random.default_rng([seed, k])
    style = DrawingStyle.random(rng) if styles == "random" else DrawingStyle()
    return restyle(render(plan, size_px, style=style, rng=rng), look, rng)


def add_drawing_arguments(parser: argparse.ArgumentParser, *, real_drawings: bool = False) -> None:
    """The options that choose the plans and draw them (read back by :func:`chosen_plans`);
    ``real_drawings`` adds ``--r3d DIR`` and ``--split`` (drawings with labels, no plan to draw:
    the caller reads them)."""
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument("--synthetic", type=int, metavar="N", help="N synthetic plans")
    source.add_argument("--resplan", metavar="FILE.pkl", help="every plan of a pickle")
    if real_drawings:
        source.add_argument(
            "--r3d", metavar="DIR", help="R3D drawings (DeepFloorplan layout) with their labels"
        )
        parser.add_argument(
            "--split",
            choices=SPLITS,
            default="dev",
            help="which R3D plans: the fixed development split, the others, or all [dev]",
        )
        parser.add_argument(
            "--plans",
            type=non_negative_int,
            default=None,
            metavar="N",
            help="only the first N R3D plans of the split (sorted names) [all]",
        )
    parser.add_argument(
        "--seed", type=non_negative_int, default=0, help="first synthetic seed (< 1000000)"
    )
    parser.add_argument(
        "--openings",
        choices=tuple(OPENING_SIZES),
        default="typical",
        help="synthetic plans' door and window widths: typical (the test set's), or the wider, "
        "overlapping ranges of training's --p-varied-openings",
    )
    parser.add_argument("--size", type=int, default=512, help="drawing side [px]")
    parser.add_argument("--styles", choices=("clean", "random"), default="clean")
    parser.add_argument(
        "--draws",
        type=int,
        default=1,
        metavar="K",
        help="draw each plan K times, each in its own random style (needs --styles random) [1]",
    )
    parser.add_argument(
        "--look",
        choices=LOOKS,
        default="drawn",
        help="the drawings as drawn, as negatives, with grey room fills, small on a big sheet, "
        "unevenly lit, with hatched walls, with each room's name and area written in it, with "
        "furniture standing in rooms or against walls, on an architect's sheet, or as an "
        "evacuation sign in colour, or in light grey lines with black room names",
    )


def chosen_plans(args: argparse.Namespace) -> tuple[Iterator[tuple[str, FloorPlan]], int]:
    """The plans :func:`add_drawing_arguments`' options name, each repeated ``--draws`` times,
    and how many drawings that makes.

    Raises:
        InputError: a size under 64 px, fewer than 1 draw, several draws of clean drawings,
            ``--openings`` with a ResPlan pickle, or a bad source (see :func:`synthetic_plans`,
            :func:`resplan_plans`).
    """
    if args.size < 64:
        raise InputError(f"--size must be at least 64 px, got {args.size}")
    if args.draws < 1:
        raise InputError(f"--draws must be at least 1, got {args.draws}")
    if args.draws > 1 and args.styles != "random":
        raise InputError("--draws needs --styles random: clean drawings of a plan are all alike")
    if args.resplan and args.openings != "typical":
        raise InputError("--openings chooses synthetic plans' widths; a ResPlan plan has its own")
    if args.resplan:
        plans = resplan_plans(args.resplan)
        total = len(plans)
    else:
        plans = synthetic_plans(args.synthetic, args.seed, args.openings)
        total = args.synthetic
    return drawn_times(plans, args.draws), total * args.draws
