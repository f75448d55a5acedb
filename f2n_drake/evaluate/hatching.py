"""``python -m f2n_drake.evaluate hatching``: on which drawings are hatched walls found?

Each plan (synthetic seeds S..S+N-1, or every plan of a ResPlan pickle, ``--draws`` times) is
rendered and restyled as in ``evaluate segmentation``, shrunk as ``f2n_drake.perception.hatching``
shrinks
it, and the diagonal asymmetry of its wall bands is measured (on its binarisation, whose
hatching cells are already filled where hatching was found: the value of a drawing found
hatched can differ a little from the one that found it). Hatched walls are found where it is at
least ``hatching.MIN_ASYMMETRY``: the threshold should sit between the drawn and the hatched
looks. No network runs.
"""

from __future__ import annotations

import argparse
import json
import sys

import cv2
import numpy as np
from tqdm import tqdm

from f2n_drake.evaluate.drawings import add_drawing_arguments, chosen_plans, drawing
from f2n_drake.perception.hatching import (
    MIN_ASYMMETRY,
    detection_scale,
    diagonal_asymmetry,
    wall_bands,
)
from f2n_drake.perception.ink import as_grey, binarize, ink_is_dark


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
    add_drawing_arguments(parser)
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    plans, total = chosen_plans(args)
    values = np.array(
        [
            asymmetry(
                drawing(
                    plan, k, seed=args.seed, size_px=args.size, styles=args.styles, look=args.look
                ).image
            )
            for k, (_, plan) in enumerate(tqdm(plans, total=total, file=sys.stderr))
        ]
    )
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
