"""``python -m f2n_drake.evaluate hatching``: on which drawings are hatched walls found?

Each plan (synthetic seeds S..S+N-1, or every plan of a ResPlan pickle, ``--draws`` times) is
rendered and restyled as in ``evaluate segmentation``, shrunk as ``f2n_drake.hatching`` shrinks
it, and the diagonal asymmetry of its wall bands is measured. Hatched walls are found where it
is at least ``hatching.MIN_ASYMMETRY``: the threshold should sit between the drawn and the
hatched looks. No network runs.
"""

from __future__ import annotations

import argparse
import json
import sys

import cv2
import numpy as np
from tqdm import tqdm

from f2n_drake.binarize import as_grey, binarize, ink_is_dark
from f2n_drake.errors import InputError, non_negative_int
from f2n_drake.evaluate.segmentation import drawn_times, resplan_plans, synthetic_plans
from f2n_drake.hatching import MIN_ASYMMETRY, detection_scale, diagonal_asymmetry, wall_bands
from f2n_drake.looks import LOOKS, restyle
from f2n_drake.render import DrawingStyle, render


def asymmetry(image: np.ndarray) -> float:
    """The diagonal asymmetry of a drawing's wall bands, measured as hatching is looked for."""
    grey = as_grey(image)
    if not ink_is_dark(grey):
        grey = 255 - grey
    scale = detection_scale(grey.shape)
    if scale < 1:
        size = (max(1, round(grey.shape[1] * scale)), max(1, round(grey.shape[0] * scale)))
        grey = cv2.resize(grey, size, interpolation=cv2.INTER_AREA)
    return diagonal_asymmetry(grey, wall_bands(binarize(grey)))


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m f2n_drake.evaluate hatching", description=__doc__.splitlines()[0]
    )
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument("--synthetic", type=int, metavar="N", help="N synthetic plans")
    source.add_argument("--resplan", metavar="FILE.pkl", help="every plan of a pickle")
    parser.add_argument("--seed", type=non_negative_int, default=0, help="first synthetic seed")
    parser.add_argument("--size", type=int, default=512, help="drawing side [px]")
    parser.add_argument("--styles", choices=("clean", "random"), default="clean")
    parser.add_argument("--draws", type=int, default=1, metavar="K", help="draw each plan K times")
    parser.add_argument("--look", choices=LOOKS, default="drawn")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    if args.size < 64:
        raise InputError(f"--size must be at least 64 px, got {args.size}")
    if args.draws < 1:
        raise InputError(f"--draws must be at least 1, got {args.draws}")
    if args.resplan:
        plans = resplan_plans(args.resplan)
        total = len(plans)
    else:
        plans, total = synthetic_plans(args.synthetic, args.seed), args.synthetic
    values = []
    for k, (_, plan) in enumerate(
        tqdm(drawn_times(plans, args.draws), total=total * args.draws, file=sys.stderr)
    ):
        rng = np.random.default_rng([args.seed, k])  # as evaluate segmentation draws it
        style = DrawingStyle.random(rng) if args.styles == "random" else DrawingStyle()
        values.append(
            asymmetry(restyle(render(plan, args.size, style=style, rng=rng), args.look, rng).image)
        )
    values = np.array(values)
    report = {
        "look": args.look,
        "n_images": int(values.size),
        "hatching_found": int((values >= MIN_ASYMMETRY).sum()),
        "threshold": MIN_ASYMMETRY,
        "asymmetry_min": float(values.min()),
        "asymmetry_median": float(np.median(values)),
        "asymmetry_max": float(values.max()),
    }
    if args.json:
        print(json.dumps(report))
    else:
        print(
            f"look {report['look']}: hatched walls found on {report['hatching_found']} of "
            f"{report['n_images']} drawings; wall-band diagonal asymmetry "
            f"{report['asymmetry_min']:.3f} .. {report['asymmetry_median']:.3f} (median) .. "
            f"{report['asymmetry_max']:.3f}, threshold {MIN_ASYMMETRY}"
        )
    return 0
