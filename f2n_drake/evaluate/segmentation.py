"""``python -m f2n_drake.evaluate segmentation``: segmentation and instance metrics vs ground truth.

Each plan (synthetic seeds S..S+N-1, or every plan of a ResPlan pickle) is rendered, segmented,
parsed into instances and compared with the renderer's label image and the plan's own polygons.
Every score is a fraction in 0..1 (None/null when there is nothing to measure). Pixel scores are
summed over all images (one confusion matrix). Top-level pixel scores are the network's raw
prediction; ``after_vote`` repeats them after the instance majority vote. The parse runs twice, with
and without the open-passage split; ``--no-split`` only picks which one the headline
``space_recall``/``instance_accuracy`` report (``split_effect`` always shows both). Both parses
apply the front-door prior (``--front-doors``, default 1); ``front_door_effect`` compares the split
parse with and without it.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field

import cv2
import numpy as np
from tqdm import tqdm

from f2n_drake import metrics
from f2n_drake.classes import CLASS_NAMES, CONNECTOR_CLASSES, NUM_CLASSES, SPACE_CLASSES
from f2n_drake.errors import InputError, front_door_count, non_negative_int
from f2n_drake.front_doors import FRONT_DOOR, assign_front_doors
from f2n_drake.instances import SplitOptions, binarize, extract_instances, vote_corrected_labels
from f2n_drake.parsed import UNSURE_BELOW, ParsedPlan
from f2n_drake.perception import predict_labels
from f2n_drake.plan import FloorPlan
from f2n_drake.render import DrawingStyle, RenderedPlan, render

TRAINING_SEED_START = 1_000_000
"""Training uses seeds >= this; evaluation seeds must stay below."""

Predictor = Callable[[RenderedPlan], tuple[np.ndarray, np.ndarray | None]]
"""Rendered drawing (with its ground truth, which only an oracle may read) -> (H, W) labels and
(C, H, W) class probabilities, or None where the predictor has none."""


def network_predictor(segmenter) -> Predictor:
    """Labels (and probabilities, if it gives them) from a ``Segmenter``, from the image only."""
    return lambda rendered: predict_labels(segmenter, rendered.image)


def corrupt_labels(labels: np.ndarray, fraction: float, rng: np.random.Generator) -> np.ndarray:
    """Ground truth with about ``fraction`` of the pixels overwritten by random-class blobs
    (discs of radius 1..6 px), a stand-in for network errors in tests and dry runs."""
    out = labels.copy()
    if fraction <= 0:
        return out
    n_blobs = int(round(fraction * labels.size / (np.pi * 3.5**2)))
    rows = rng.integers(0, labels.shape[0], n_blobs)
    cols = rng.integers(0, labels.shape[1], n_blobs)
    radii = rng.integers(1, 7, n_blobs)
    values = rng.integers(0, NUM_CLASSES, n_blobs)
    for r, c, rad, v in zip(
        rows.tolist(), cols.tolist(), radii.tolist(), values.tolist(), strict=True
    ):
        cv2.circle(out, (c, r), rad, v, -1)
    return out


def oracle_predictor(fraction: float, seed: int = 0) -> Predictor:
    """The ground-truth labels, corrupted by ``corrupt_labels`` (no network needed)."""
    rng = np.random.default_rng(seed)
    return lambda rendered: (corrupt_labels(rendered.labels, fraction, rng), None)


@dataclass
class Totals:
    """Counts accumulated over images; ``summary()`` turns them into the JSON report."""

    cm_raw: np.ndarray = field(default_factory=lambda: np.zeros((NUM_CLASSES,) * 2, np.int64))
    cm_vote: np.ndarray = field(default_factory=lambda: np.zeros((NUM_CLASSES,) * 2, np.int64))
    instances: dict[str, list[int]] = field(
        default_factory=lambda: {"split": [0, 0], "no_split": [0, 0]}
    )
    spaces: dict[str, list[metrics.Match]] = field(
        default_factory=lambda: {"split": [], "no_split": []}
    )
    predicted_spaces: dict[str, int] = field(default_factory=lambda: {"split": 0, "no_split": 0})
    matched_spaces: dict[str, int] = field(default_factory=lambda: {"split": 0, "no_split": 0})
    connectors: list[metrics.Match] = field(default_factory=list)
    front_doors: dict[str, list[int]] = field(
        default_factory=lambda: {m: [0, 0, 0, 0, 0, 0] for m in ("prior", "no_prior")}
    )  # instances correct, instances, true front doors found, true front doors,
    #    front-door instances right, front-door instances
    confidence: dict[str, list[int]] = field(
        default_factory=lambda: {"unsure": [0, 0], "sure": [0, 0]}
    )  # instances right, instances; unsure: confidence < UNSURE_BELOW
    n_images: int = 0
    per_plan: list[dict] = field(default_factory=list)


def evaluate_plan(
    name: str,
    plan: FloorPlan,
    rendered: RenderedPlan,
    prediction: tuple[np.ndarray, np.ndarray | None],
    totals: Totals,
    *,
    front_doors: int | None = 1,
) -> None:
    """Add one segmented drawing (labels, probabilities or None) to ``totals``."""
    gt = rendered.labels
    labels, probabilities = prediction
    lines = binarize(rendered.image)
    voted = {
        mode: extract_instances(
            rendered.image,
            labels,
            grid=rendered.grid,
            lines=lines,
            split=SplitOptions() if mode == "split" else None,
            probabilities=probabilities,
        )
        for mode in ("split", "no_split")
    }
    parsed = {mode: assign_front_doors(p, front_doors) for mode, p in voted.items()}
    totals.cm_raw += metrics.confusion_matrix(gt, labels)
    totals.cm_vote += metrics.confusion_matrix(gt, vote_corrected_labels(parsed["split"]))
    rot = rendered.style.rotation_deg
    truth_spaces = metrics.rasterise_truth(
        plan, rendered.grid, gt, SPACE_CLASSES, rotation_deg=rot, valid=~lines
    )
    truth_conn = metrics.rasterise_truth(
        plan, rendered.grid, gt, CONNECTOR_CLASSES, rotation_deg=rot
    )
    space_matches = {}
    for mode, p in parsed.items():
        correct, total = metrics.instance_accuracy_counts(p, gt)
        totals.instances[mode][0] += correct
        totals.instances[mode][1] += total
        space_matches[mode] = metrics.match_truth(p, truth_spaces, by="iou")
        totals.spaces[mode] += space_matches[mode]
        totals.predicted_spaces[mode] += len(p.of_class(*SPACE_CLASSES))
        totals.matched_spaces[mode] += len({m.instance_id for m in space_matches[mode] if m.found})
    conn_matches = metrics.match_truth(parsed["split"], truth_conn, by="overlap")
    for mode, p in (("prior", parsed["split"]), ("no_prior", voted["split"])):
        _count_front_doors(p, gt, truth_conn, totals.front_doors[mode])
    truth = metrics.instance_truth(parsed["split"], gt)
    for inst in parsed["split"].instances:
        if inst.id in truth and inst.confidence is not None:
            counts = totals.confidence["unsure" if inst.confidence < UNSURE_BELOW else "sure"]
            counts[0] += inst.class_name == truth[inst.id]
            counts[1] += 1
    totals.connectors += conn_matches
    totals.n_images += 1
    m2 = rendered.grid.metres_per_px**2
    totals.per_plan.append(
        {
            "plan": name,
            "missed_spaces": [_describe(m, m2) for m in space_matches["split"] if not m.found],
            "missed_connectors": [_describe(m, m2) for m in conn_matches if not m.found],
            "n_spaces": len(truth_spaces),
            "n_connectors": len(truth_conn),
        }
    )


def _count_front_doors(
    parsed: ParsedPlan, gt: np.ndarray, truth_conn: list[metrics.TruthRegion], counts: list[int]
) -> None:
    """Add instance accuracy and front-door recall/precision counts (see ``Totals``)."""
    truth = metrics.instance_truth(parsed, gt)
    front = [r for r in truth_conn if r.class_name == FRONT_DOOR]
    predicted = [i for i in parsed.instances if i.class_name == FRONT_DOOR]
    counts[0] += sum(i.class_name == truth[i.id] for i in parsed.instances if i.id in truth)
    counts[1] += len(truth)
    counts[2] += sum(m.found for m in metrics.match_truth(parsed, front, by="overlap"))
    counts[3] += len(front)
    counts[4] += sum(truth[i.id] == FRONT_DOOR for i in predicted)
    counts[5] += len(predicted)


def _describe(match: metrics.Match, m2_per_px: float) -> dict:
    r = match.truth
    return {
        "class": r.class_name,
        "index": r.index,
        "area_m2": round(r.area_px * m2_per_px, 2),
        "iou": round(match.iou, 3),
        "overlap": round(match.overlap, 3),
        "instance_class": match.best_class,
    }


def _pixel_scores(cm: np.ndarray) -> dict:
    return {
        "mean_iou": metrics.mean_iou(cm),
        "pixel_accuracy": metrics.pixel_accuracy(cm),
        "per_class_iou": metrics.per_class_iou(cm),
    }


def summary(totals: Totals, *, split: bool) -> dict:
    """The JSON report (fractions in 0..1, None where undefined)."""
    mode = "split" if split else "no_split"
    cm = totals.cm_raw
    precision, recall = metrics.connector_precision_recall(cm)
    effect = {}
    for m in ("split", "no_split"):
        matches = totals.spaces[m]
        effect[m] = {
            "space_recall": metrics.recall(matches),
            "space_precision": metrics.fraction(
                totals.matched_spaces[m], totals.predicted_spaces[m]
            ),
            "instance_accuracy": metrics.fraction(*totals.instances[m]),
            "kitchen_recall": metrics.recall(
                [x for x in matches if x.truth.class_name == "kitchen"]
            ),
        }
    return {
        **_pixel_scores(cm),
        "instance_accuracy": effect[mode]["instance_accuracy"],
        "space_recall": effect[mode]["space_recall"],
        "space_precision": effect[mode]["space_precision"],
        "categories": metrics.category_scores(cm),
        "connector_confusion": metrics.connector_confusion(cm).tolist(),
        "connector_confusion_layout": "rows ground truth [connector, other], "
        "columns prediction [connector, other], pixels",
        "connector_precision": precision,
        "connector_recall": recall,
        "connector_instance_recall": metrics.recall(totals.connectors),
        "after_vote": _pixel_scores(totals.cm_vote),
        "split_effect": effect,
        "split": split,
        "front_door_effect": {
            mode: {
                "instance_accuracy": metrics.fraction(c[0], c[1]),
                "front_door_recall": metrics.fraction(c[2], c[3]),
                "front_door_precision": metrics.fraction(c[4], c[5]),
            }
            for mode, c in totals.front_doors.items()
        },
        "confidence_flag": {
            "threshold": UNSURE_BELOW,
            **{
                group: {"instances": c[1], "accuracy": metrics.fraction(c[0], c[1])}
                for group, c in totals.confidence.items()
            },
        },
        "n_images": totals.n_images,
        "n_instances": totals.instances[mode][1],
        "n_gt_spaces": len(totals.spaces[mode]),
        "n_gt_connectors": len(totals.connectors),
    }


def synthetic_plans(n: int, seed: int) -> Iterator[tuple[str, FloorPlan]]:
    """Synthetic evaluation plans of seeds ``seed .. seed + n - 1``, generated lazily.

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
    from f2n_drake.generator import generate_plan

    return ((f"seed {s}", generate_plan(s)) for s in range(seed, seed + n))


def resplan_plans(path: str) -> list[tuple[str, FloorPlan]]:
    from f2n_drake.resplan import load_resplan

    plans = load_resplan(path)
    if not plans:
        raise InputError(f"{path} holds no plans")
    return [(f"resplan {p.metadata.get('id', i)}", p) for i, p in enumerate(plans)]


def evaluate(
    plans: Iterable[tuple[str, FloorPlan]],
    predict: Predictor,
    *,
    size_px: int = 512,
    styles: str = "clean",
    seed: int = 0,
    split: bool = True,
    front_doors: int | None = 1,
    progress: bool = True,
    total: int | None = None,
) -> dict:
    """Render, segment and score every plan; returns ``summary()`` plus ``per_plan``."""
    totals = Totals()
    for k, (name, plan) in enumerate(
        tqdm(
            plans,
            total=total,
            disable=not progress,
            file=sys.stderr,
            desc="segmentation",
            unit="plan",
        )
    ):
        rng = np.random.default_rng([seed, k])
        style = DrawingStyle.random(rng) if styles == "random" else DrawingStyle()
        rendered = render(plan, size_px, style=style, rng=rng)
        labels, probabilities = predict(rendered)
        labels = np.asarray(labels)
        if labels.shape != rendered.labels.shape:
            raise InputError(
                f"segmenter returned {labels.shape} labels for a {rendered.labels.shape} drawing"
            )
        evaluate_plan(
            name, plan, rendered, (labels, probabilities), totals, front_doors=front_doors
        )
    return {**summary(totals, split=split), "per_plan": totals.per_plan}


def _fmt(value: float | None) -> str:
    return "   -  " if value is None else f"{100 * value:5.1f}%"


def format_table(report: dict, *, list_misses: bool) -> str:
    lines = [
        f"{report['n_images']} images, {report['n_instances']} instances, "
        f"{report['n_gt_spaces']} ground-truth spaces (split={report['split']})",
        f"{'class':12s} {'IoU':>7s} {'IoU after vote':>15s}",
    ]
    for name in CLASS_NAMES:
        lines.append(
            f"{name:12s} {_fmt(report['per_class_iou'][name]):>7s} "
            f"{_fmt(report['after_vote']['per_class_iou'][name]):>15s}"
        )
    lines.append(
        f"{'mean IoU':12s} {_fmt(report['mean_iou']):>7s} "
        f"{_fmt(report['after_vote']['mean_iou']):>15s}"
    )
    lines.append(
        f"{'pixel acc.':12s} {_fmt(report['pixel_accuracy']):>7s} "
        f"{_fmt(report['after_vote']['pixel_accuracy']):>15s}"
    )
    for cat, s in report["categories"].items():
        if s:
            lines.append(
                f"{cat:18s} P {_fmt(s['precision'])}  R {_fmt(s['recall'])}  F1 {_fmt(s['f1'])}"
            )
    lines.append(
        f"connector pixels   P {_fmt(report['connector_precision'])}  "
        f"R {_fmt(report['connector_recall'])}; connector instances found "
        f"{_fmt(report['connector_instance_recall'])}"
    )
    lines.append(f"instance accuracy {_fmt(report['instance_accuracy'])}")
    for mode, e in report["split_effect"].items():
        lines.append(
            f"{mode:8s}: space recall {_fmt(e['space_recall'])}, space precision "
            f"{_fmt(e['space_precision'])}, kitchen recall {_fmt(e['kitchen_recall'])}"
        )
    flag = report["confidence_flag"]
    if flag["unsure"]["instances"] or flag["sure"]["instances"]:
        lines.append(
            f"confidence < {100 * flag['threshold']:.0f} %: {flag['unsure']['instances']} "
            f"instances, {_fmt(flag['unsure']['accuracy'])} right; the other "
            f"{flag['sure']['instances']}: {_fmt(flag['sure']['accuracy'])} right"
        )
    for mode, e in report["front_door_effect"].items():
        lines.append(
            f"{mode:8s}: instance accuracy {_fmt(e['instance_accuracy'])}, front doors found "
            f"{_fmt(e['front_door_recall'])}, front-door precision "
            f"{_fmt(e['front_door_precision'])}"
        )
    if list_misses:
        for plan in report["per_plan"]:
            missed = plan["missed_spaces"] + plan["missed_connectors"]
            text = (
                ", ".join(
                    f"{m['class']}#{m['index']} ({m['area_m2']} m², IoU {m['iou']:.2f}, "
                    f"in {m['instance_class']})"
                    for m in missed
                )
                or "none"
            )
            lines.append(f"{plan['plan']}: missed {text}")
    return "\n".join(lines)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m f2n_drake.evaluate segmentation", description=__doc__.splitlines()[0]
    )
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument("--synthetic", type=int, metavar="N", help="evaluate N synthetic plans")
    source.add_argument("--resplan", metavar="FILE.pkl", help="evaluate every plan of a pickle")
    parser.add_argument(
        "--seed", type=non_negative_int, default=0, help="first synthetic seed (< 1000000)"
    )
    parser.add_argument("--size", type=int, default=512, help="drawing side [px]")
    parser.add_argument("--styles", choices=("clean", "random"), default="clean")
    parser.add_argument(
        "--no-split", action="store_true", help="headline figures without the open-passage split"
    )
    parser.add_argument(
        "--front-doors",
        type=front_door_count,
        default=1,
        metavar="N|any",
        help="front-door prior for the headline figures: N per plan, or 'any' for none [1]",
    )
    parser.add_argument("--weights", default=None, help="segmenter checkpoint (default: shipped)")
    parser.add_argument("--device", default="cpu")
    parser.add_argument(
        "--oracle",
        type=float,
        default=None,
        metavar="FRACTION",
        help="use ground truth with FRACTION of pixels corrupted, not the network",
    )
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    return parser


def main(argv: list[str] | None = None, *, predict: Predictor | None = None) -> int:
    args = build_parser().parse_args(argv)
    if args.size < 64:
        raise InputError(f"--size must be at least 64 px, got {args.size}")
    if args.oracle is not None and not 0 <= args.oracle <= 1:
        raise InputError(f"--oracle must be a fraction in 0..1, got {args.oracle}")
    if args.resplan:
        plans = resplan_plans(args.resplan)
        total = len(plans)
    else:
        plans, total = synthetic_plans(args.synthetic, args.seed), args.synthetic
    if predict is None and args.oracle is not None:
        predict = oracle_predictor(args.oracle, args.seed)
    if predict is None:
        from f2n_drake.segmenter.inference import Segmenter

        predict = network_predictor(Segmenter.load(args.weights, device=args.device))
    report = evaluate(
        plans,
        predict,
        size_px=args.size,
        styles=args.styles,
        seed=args.seed,
        split=not args.no_split,
        front_doors=args.front_doors,
        total=total,
    )
    if not args.resplan:
        report.pop("per_plan")
    if args.json:
        print(json.dumps(report))
    else:
        print(format_table(report, list_misses=bool(args.resplan)))
    return 0
