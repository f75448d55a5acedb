"""``python -m f2n_drake.evaluate reading``: reading the words on generated drawings.

Each synthetic plan is drawn (``evaluate segmentation``'s drawings, ``--size`` px) with every
room's name and size printed in it (``f2n_drake.datasets.listing_text``: names in eight
languages and abbreviations, sizes as dimensions in metres or feet or as areas, one font and
format per drawing), so what is read is checked against exact truth:

- ``scale_error``: the scale from printed sizes (``f2n_drake.perception.printed_sizes``) /
  truth - 1, per drawing; the target is within 5 %;
- ``names_read``: share of printed names read as their room's class by the lexicon;
- ``room_type_accuracy``: share of named rooms whose parsed instance (the one under the text)
  has the true class, with reading and with the network alone (``reader=None``);
- ``read_s_per_megapixel``: time of :func:`~f2n_drake.perception.reading.read_words` per
  million pixels, i.e. per 1000 x 1000 px drawing (target <= 0.5 s on the 2-core CPU), and
  ``read_cpu_s_per_megapixel`` the CPU time it took, all threads together (what a busy machine
  does not inflate).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Callable

import numpy as np
from tqdm import tqdm

from f2n_drake.core.parsed import ParsedPlan
from f2n_drake.datasets.listing_text import PrintedRoom, print_room_text
from f2n_drake.datasets.render import RenderedPlan
from f2n_drake.evaluate.drawings import drawing, synthetic_plans
from f2n_drake.perception.image import LabelPredictor
from f2n_drake.perception.printed_sizes import printed_scale
from f2n_drake.perception.reading import read_words
from f2n_drake.perception.room_names import room_class
from f2n_drake.pipeline import parse_drawing

TARGET_SCALE_ERROR = 0.05


def _class_under(parsed: ParsedPlan, room: PrintedRoom) -> str | None:
    col, row = room.centre_px
    instance_id = int(parsed.instance_ids[row, col])
    inst = parsed.by_id().get(instance_id)
    return inst.class_name if inst else None


def evaluate_reading(
    n_plans: int,
    *,
    seed: int = 0,
    size_px: int = 1000,
    segmenter_for: Callable[[RenderedPlan], LabelPredictor] | None = None,
    progress: bool = True,
) -> dict:
    """Per-drawing rows and a summary (see the module doc). ``segmenter_for`` gives the
    segmenter of a drawing (default the shipped network for all; a test's oracle reads its
    ground truth)."""
    if segmenter_for is None:
        from f2n_drake.segmenter.inference import Segmenter

        network = Segmenter.load()
        segmenter_for = lambda _rendered: network  # noqa: E731
    rows = []
    plans = synthetic_plans(n_plans, seed)
    for k, (name, plan) in enumerate(
        tqdm(plans, total=n_plans, disable=not progress, file=sys.stderr, desc="reading")
    ):
        rendered = drawing(plan, k, seed=seed, size_px=size_px, styles="clean", look="drawn")
        rng = np.random.default_rng([seed, k, 33])
        image, printed = print_room_text(rendered.image, rendered.labels, rendered.grid, rng)
        read_words(image[:64, :64])  # the models load once, outside the timing
        t0, c0 = time.perf_counter(), time.process_time()
        texts = read_words(image)
        read_s, read_cpu_s = time.perf_counter() - t0, time.process_time() - c0
        segmenter = segmenter_for(rendered)
        parsed = parse_drawing(image, segmenter=segmenter, reader=lambda _grey: texts)  # noqa: B023
        unread = parse_drawing(image, segmenter=segmenter, reader=None)
        scale = printed_scale(parsed)
        truth = rendered.grid.metres_per_px
        read_classes = [room_class(t.text) for t in texts]
        rows.append(
            {
                "name": name,
                "size_px": list(image.shape),
                "read_s": read_s,
                "read_s_per_megapixel": read_s / (image.size / 1e6),
                "read_cpu_s_per_megapixel": read_cpu_s / (image.size / 1e6),
                "n_printed": len(printed),
                "names_read": sum(read_classes.count(room.class_name) > 0 for room in printed),
                "scale_error": scale.metres_per_px / truth - 1 if scale else None,
                "scale_rooms": scale.n_rooms if scale else 0,
                "right_with_names": sum(_class_under(parsed, r) == r.class_name for r in printed),
                "right_network_alone": sum(
                    _class_under(unread, r) == r.class_name for r in printed
                ),
            }
        )
    return {"summary": summary_of(rows), "per_drawing": rows}


def summary_of(rows: list[dict]) -> dict:
    errors = np.array([r["scale_error"] for r in rows if r["scale_error"] is not None], float)
    printed = sum(r["n_printed"] for r in rows)
    return {
        "n_drawings": len(rows),
        "n_with_scale": int(errors.size),
        "scale_error_median": float(np.median(errors)) if errors.size else None,
        "scale_abs_error_mean": float(np.abs(errors).mean()) if errors.size else None,
        "scale_abs_error_max": float(np.abs(errors).max()) if errors.size else None,
        "within_5_percent": (
            float((np.abs(errors) <= TARGET_SCALE_ERROR).mean()) if errors.size else None
        ),
        "names_read": sum(r["names_read"] for r in rows) / printed if printed else None,
        "room_type_accuracy": sum(r["right_with_names"] for r in rows) / printed
        if printed
        else None,
        "room_type_accuracy_network_alone": (
            sum(r["right_network_alone"] for r in rows) / printed if printed else None
        ),
        "read_s_per_megapixel_median": float(np.median([r["read_s_per_megapixel"] for r in rows])),
        "read_cpu_s_per_megapixel_median": float(
            np.median([r["read_cpu_s_per_megapixel"] for r in rows])
        ),
    }


def format_summary(summary: dict) -> str:
    pct = lambda v: "-" if v is None else f"{100 * v:.1f} %"  # noqa: E731
    return "\n".join(
        [
            f"{summary['n_drawings']} drawings, "
            f"{summary['n_with_scale']} scaled from printed sizes",
            f"  scale error   median {pct(summary['scale_error_median'])}, |error| mean "
            f"{pct(summary['scale_abs_error_mean'])}, max {pct(summary['scale_abs_error_max'])}, "
            f"within 5 %: {pct(summary['within_5_percent'])}",
            f"  names read    {pct(summary['names_read'])} of printed names give their class",
            f"  room types    {pct(summary['room_type_accuracy'])} right with names, "
            f"{pct(summary['room_type_accuracy_network_alone'])} with the network alone",
            f"  reading       {summary['read_s_per_megapixel_median']:.2f} s per 1000 x 1000 px "
            f"(median; {summary['read_cpu_s_per_megapixel_median']:.2f} s of CPU, all threads)",
        ]
    )


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m f2n_drake.evaluate reading", description=__doc__.splitlines()[0]
    )
    parser.add_argument("--synthetic", type=int, default=10, metavar="N", help="plans [10]")
    parser.add_argument("--seed", type=int, default=0, help="first plan seed [0]")
    parser.add_argument("--size", type=int, default=1000, help="drawing size [px] [1000]")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    return parser


def main(
    argv: list[str] | None = None,
    *,
    segmenter_for: Callable[[RenderedPlan], LabelPredictor] | None = None,
) -> int:
    args = build_parser().parse_args(argv)
    report = evaluate_reading(
        args.synthetic, seed=args.seed, size_px=args.size, segmenter_for=segmenter_for
    )
    print(json.dumps(report) if args.json else format_summary(report["summary"]))
    return 0
