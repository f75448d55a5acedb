"""``python -m f2n_drake.evaluate parse-speed``: how long the full parse of one drawing takes.

A synthetic plan (seed 0, evaluation range) is rendered at ``--size`` px and parsed ``--repeats``
times by ``parse_drawing`` after one warm-up: the network's calls (labels and probabilities) and
the rest (binarize, marks, the furniture check, regions, vote, open-passage split, front-door,
kitchen and sealed-room priors) are timed separately. Times are wall-clock milliseconds; the
total's median is held against ``TARGET_MEDIAN_MS`` (300 ms at 512 px, 1.5 s at 1000 px).
"""

from __future__ import annotations

import argparse
import json
import sys
import time

import numpy as np
from tqdm import tqdm

from f2n_drake import parse_drawing
from f2n_drake.core.errors import InputError, non_negative_int
from f2n_drake.perception.image import LabelPredictor, predict_labels
from f2n_drake.segmenter import DEFAULT_VIEWS, VIEW_COUNTS

TARGET_MEDIAN_MS = {512: 300.0, 1000: 1500.0}
"""Median targets by drawing side [px] (the network's own input size; a 1000 px drawing, the real
drawings' goal); other sizes have none."""


class _Timed:
    """A segmenter whose calls are timed (milliseconds, one entry per parse)."""

    def __init__(self, segmenter: LabelPredictor) -> None:
        self.segmenter, self.ms = segmenter, 0.0

    def predict_with_probabilities(self, image: np.ndarray):
        t0 = time.perf_counter()
        labels, probabilities = predict_labels(self.segmenter, image)
        self.ms += 1000 * (time.perf_counter() - t0)
        return labels, probabilities


def time_parse(
    image: np.ndarray, segmenter: LabelPredictor, *, repeats: int = 20, progress: bool = True
) -> dict[str, list[float]]:
    """Per-repeat milliseconds of ``parse_drawing`` (``total``), of its network calls
    (``network``) and of the rest (``instances``), after one warm-up."""
    timed = _Timed(segmenter)
    parse_drawing(image, segmenter=timed)  # warm-up: lazy init, allocator, caches
    times: dict[str, list[float]] = {"network": [], "instances": [], "total": []}
    for _ in tqdm(range(repeats), disable=not progress, file=sys.stderr, desc="parse", unit="run"):
        timed.ms = 0.0
        t0 = time.perf_counter()
        parse_drawing(image, segmenter=timed)
        total = 1000 * (time.perf_counter() - t0)
        times["network"].append(timed.ms)
        times["instances"].append(total - timed.ms)
        times["total"].append(total)
    return times


def summarise(times: dict[str, list[float]]) -> dict[str, dict[str, float]]:
    return {
        k: {"median_ms": float(np.median(v)), "p90_ms": float(np.percentile(v, 90))}
        for k, v in times.items()
    }


def main(argv: list[str] | None = None, *, segmenter: LabelPredictor | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m f2n_drake.evaluate parse-speed", description=__doc__.splitlines()[0]
    )
    parser.add_argument("--size", type=int, default=512, help="drawing side [px]")
    parser.add_argument("--repeats", type=int, default=20)
    parser.add_argument(
        "--seed", type=non_negative_int, default=0, help="synthetic plan seed (< 1000000)"
    )
    parser.add_argument(
        "--weights",
        default=None,
        help="segmenter checkpoint, run alone (default: the shipped one with its storage network)",
    )
    parser.add_argument("--device", default="cpu")
    parser.add_argument(
        "--views",
        type=int,
        choices=VIEW_COUNTS,
        default=DEFAULT_VIEWS,
        help=f"test-time views averaged; 1 is the network alone [{DEFAULT_VIEWS}]",
    )
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    args = parser.parse_args(argv)
    if args.repeats < 1:
        raise InputError(f"--repeats must be at least 1, got {args.repeats}")
    if args.size < 64:
        raise InputError(f"--size must be at least 64 px, got {args.size}")
    if not 0 <= args.seed < 1_000_000:
        raise InputError(f"--seed must be in 0..999999 (training uses >= 1000000), got {args.seed}")
    from f2n_drake.datasets.generator import generate_plan
    from f2n_drake.datasets.render import render

    image = render(generate_plan(args.seed), args.size).image
    if segmenter is None:
        from f2n_drake.segmenter.inference import Segmenter

        segmenter = Segmenter.load(args.weights, device=args.device, views=args.views)
        device = str(segmenter.device)
    else:
        device = "injected"
    stats = summarise(time_parse(image, segmenter, repeats=args.repeats))
    target = TARGET_MEDIAN_MS.get(args.size)
    report = {
        "size_px": args.size,
        "repeats": args.repeats,
        "device": device,
        "views": args.views if device != "injected" else None,
        **stats,
        "target_median_ms": target,
        "meets_target": None if target is None else stats["total"]["median_ms"] <= target,
    }
    if args.json:
        print(json.dumps(report))
    else:
        views = f", {args.views} view(s)" if device != "injected" else ""
        print(
            f"parse of a {args.size}x{args.size} drawing, {args.repeats} runs on {device}{views}:"
        )
        for k in ("network", "instances", "total"):
            print(
                f"  {k:9s} median {stats[k]['median_ms']:7.1f} ms   p90 "
                f"{stats[k]['p90_ms']:7.1f} ms"
            )
        if target is not None:
            verdict = "meets" if report["meets_target"] else "MISSES"
            print(f"  {verdict} the {target:.0f} ms median target for a {args.size} px drawing")
    return 0
