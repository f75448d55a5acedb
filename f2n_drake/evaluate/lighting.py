"""``python -m f2n_drake.evaluate lighting DRAWING...``: does a dimmed drawing parse as it did?

Each drawing is parsed as given, then dimmed from its top-left corner to its bottom-right one
(down to each ``--darkest`` share of its light, as a phone photo dims a page) and parsed again,
with ``perception.lighting`` lighting it evenly first and without. Reported per drawing and
dimming: the share of the pixels either parse labels (not background after the vote) whose label
is the one the drawing as given gets, and the parses refused. A drawing whose lighting is left
alone gives the same figure twice.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
from tqdm import tqdm

from f2n_drake.core.errors import InputError
from f2n_drake.perception.image import load_image
from f2n_drake.perception.ink import as_grey, binarize
from f2n_drake.perception.instances import vote_corrected_labels
from f2n_drake.perception.lighting import evenly_lit

DARKEST: tuple[float, ...] = (0.6, 0.4)


def dimmed(image: np.ndarray, darkest: float) -> np.ndarray:
    """``image`` (grey or colour) lit fully at its top-left corner, ``darkest`` of that at its
    bottom-right one, linearly along the diagonal."""
    h, w = image.shape[:2]
    along = np.add.outer(np.arange(h) / max(h - 1, 1), np.arange(w) / max(w - 1, 1)) / 2
    light = 1.0 - (1.0 - darkest) * along
    if image.ndim == 3:
        light = light[..., None]
    return np.clip(image * light, 0, 255).astype(np.uint8)


def voted_labels(image: np.ndarray, segmenter, *, even_lighting: bool) -> np.ndarray | None:
    """The labels after the vote of the parse of ``image`` (None: refused)."""
    from f2n_drake.pipeline import parse_drawing

    try:
        parsed = parse_drawing(image, segmenter=segmenter, even_lighting=even_lighting)
    except InputError:
        return None
    grey = as_grey(image)
    return vote_corrected_labels(parsed, binarize(evenly_lit(grey) if even_lighting else grey))


def agreement(labels: np.ndarray | None, reference: np.ndarray | None) -> float:
    """Share of the pixels labelled by either (not background) with the same label; 0 when
    either parse was refused."""
    if labels is None or reference is None:
        return 0.0
    labelled = (labels > 0) | (reference > 0)
    return float((labels == reference)[labelled].mean()) if labelled.any() else 1.0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m f2n_drake.evaluate lighting", description=__doc__.splitlines()[0]
    )
    parser.add_argument("drawings", nargs="+", type=Path, help="drawings (images)")
    parser.add_argument(
        "--darkest",
        type=float,
        nargs="+",
        default=list(DARKEST),
        help="share of the light left at the darkest corner [0.6 0.4]",
    )
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    return parser


def main(argv: list[str] | None = None) -> int:
    from f2n_drake.segmenter.inference import Segmenter

    args = build_parser().parse_args(argv)
    if not all(0.0 < d < 1.0 for d in args.darkest):
        raise InputError("--darkest must lie between 0 and 1")
    segmenter = Segmenter.load()
    rows = []
    for path in tqdm(args.drawings, file=sys.stderr, desc="lighting", unit="drawing"):
        image = load_image(path)
        reference = voted_labels(image, segmenter, even_lighting=True)
        for darkest in args.darkest:
            dim = dimmed(image, darkest)
            lit = voted_labels(dim, segmenter, even_lighting=True)
            as_dimmed = voted_labels(dim, segmenter, even_lighting=False)
            rows.append(
                {
                    "drawing": path.name,
                    "darkest": darkest,
                    "agreement_lit": round(agreement(lit, reference), 4),
                    "agreement_as_dimmed": round(agreement(as_dimmed, reference), 4),
                    "refused": [
                        name
                        for name, labels in (("as given", reference), ("lit", lit))
                        + (("as dimmed", as_dimmed),)
                        if labels is None
                    ],
                }
            )
    report = {
        "drawings": len(args.drawings),
        "mean_agreement_lit": round(float(np.mean([r["agreement_lit"] for r in rows])), 4),
        "mean_agreement_as_dimmed": round(
            float(np.mean([r["agreement_as_dimmed"] for r in rows])), 4
        ),
        "per_drawing": rows,
    }
    if args.json:
        print(json.dumps(report))
        return 0
    print(f"{'drawing':32s} darkest  lit evenly  as dimmed  refused")
    for r in rows:
        print(
            f"{r['drawing'][:32]:32s} {r['darkest']:7.2f}  {100 * r['agreement_lit']:9.1f}%"
            f"  {100 * r['agreement_as_dimmed']:8.1f}%  {', '.join(r['refused']) or '-'}"
        )
    print(
        f"mean agreement with the drawing as given: lit evenly "
        f"{100 * report['mean_agreement_lit']:.1f}%, as dimmed "
        f"{100 * report['mean_agreement_as_dimmed']:.1f}%"
    )
    return 0
