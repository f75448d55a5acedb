"""``python -m f2n_drake.evaluate segmentation``: segmentation and instance metrics vs ground truth.

``--r3d DIR [--split dev|train|all]`` scores the full parse of real R3D drawings in R3D's merged
classes instead (``f2n_drake.evaluate.r3d``). Otherwise each plan (synthetic seeds S..S+N-1, or
every plan of a ResPlan pickle) is rendered, segmented,
parsed into instances and compared with the renderer's label image and the plan's own polygons;
``--look`` redraws each drawing first (``looks.restyle``: a negative, grey room fills, small on a
big sheet, unevenly lit, hatched, with room names written in, furnished, on an architect's
sheet, or an evacuation sign). ``--draws K --styles random`` draws each plan K times, each in
its own random style: a few real layouts give a steadier figure than one drawing each.
Every score is a fraction in 0..1 (None/null when there is nothing to measure);
``instance_errors`` counts the wrong instances by ``"truth->voted"`` class pair. A room, door
or window whose region the parse voted background is no instance of the parse, but it is a wrong
region: ``instance_accuracy`` and ``n_instances`` count it (``"bathroom->background"``), and
``left_out`` counts these by true class (``metrics.left_out_truth``). Pixel scores are
summed over all images (one confusion matrix). Top-level pixel scores are the network's raw
prediction; ``after_vote`` repeats them, with the category and connector scores, for
``vote_corrected_labels`` given the drawing's lines (instances take their vote, so do the leftover
regions such as the outside, connector outlines follow their connector, and in a drawing of 1 px
outlines each outline takes the class painted last beside it): the labels the parse hands on.
The parse runs twice, with and without the open-passage split;
``--no-split`` only picks which one the headline ``space_recall``/``instance_accuracy`` report
(``split_effect`` always shows both). Both parses apply the front-door prior (``--front-doors``,
default 1); ``front_door_effect`` compares the split parse with and without it. Then the
connector-size prior (``f2n_drake.perception.priors.connector_sizes``) makes wall of every door or
window wider
than one can be; ``oversized_connectors_walled`` counts them and how many were right after and
before. Then the balcony
prior (``f2n_drake.perception.priors.balconies``) makes a room of every balcony with no open air;
``balconies_closed`` counts them and how many were right after and before. Then the kitchen
prior (``f2n_drake.perception.priors.kitchens``, ``--kitchens``, default 1) undoes extra kitchens
and finds a
missing one; ``kitchen_effect`` compares the split parse with and without it, ``kitchens_undone``
and ``kitchens_added`` count them.
Then the sealed-room prior (``f2n_drake.perception.priors.sealed_rooms``; ``--keep-sealed-rooms``
turns it off)
opens rooms no door reaches; ``sealed_room_doors`` counts the walls it made doors.
``--storerooms P`` (an experiment the parse does not make) votes background every bathroom more
than P background-like after the priors, as a storeroom would be.
The parse is given each drawing's true scale; ``--unknown-scale`` parses as ``run`` does without
``--scale`` (``known_scale`` in the JSON), where areas and widths are judged in pixels.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
from collections.abc import Callable, Iterable

import cv2
import numpy as np
from tqdm import tqdm

from f2n_drake.core.classes import CLASS_NAMES, NUM_CLASSES
from f2n_drake.core.errors import InputError, count_or_any
from f2n_drake.core.plan import FloorPlan
from f2n_drake.datasets.render import RenderedPlan
from f2n_drake.evaluate.drawings import add_drawing_arguments, chosen_plans, drawing
from f2n_drake.evaluate.segmentation_scores import Totals, evaluate_plan, summary
from f2n_drake.perception.floor_textures import without_floor_textures
from f2n_drake.perception.image import predict_labels
from f2n_drake.perception.instances import binarize
from f2n_drake.perception.small_drawings import SMALL_DRAWING_PX
from f2n_drake.pipeline import segment_drawing
from f2n_drake.segmenter import DEFAULT_VIEWS, VIEW_COUNTS

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


def evaluate(
    plans: Iterable[tuple[str, FloorPlan]],
    predict: Predictor,
    *,
    size_px: int = 512,
    styles: str = "clean",
    look: str = "drawn",
    seed: int = 0,
    split: bool = True,
    front_doors: int | None = 1,
    kitchens: int | None = 1,
    sealed_rooms: bool = True,
    known_scale: bool = True,
    storerooms: float | None = None,
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
        rendered = drawing(plan, k, seed=seed, size_px=size_px, styles=styles, look=look)
        if rendered.image.ndim == 2:  # as parse_drawing reads a drawing: floors plain fills
            rendered = dataclasses.replace(rendered, image=without_floor_textures(rendered.image))
        lines = binarize(rendered.image)
        segmentation = segment_drawing(
            rendered.image,
            lines,
            lambda drawing, rendered=rendered: _checked(predict, rendered, drawing),
        )
        evaluate_plan(
            name,
            plan,
            rendered,
            segmentation,
            totals,
            front_doors=front_doors,
            kitchens=kitchens,
            sealed_rooms=sealed_rooms,
            lines=lines,
            known_scale=known_scale,
            storerooms=storerooms,
        )
    return {
        **summary(totals, split=split),
        "sealed_room_prior": sealed_rooms,
        "known_scale": known_scale,
        "storerooms": storerooms,
        "per_plan": totals.per_plan,
    }


def _checked(
    predict: Predictor, rendered: RenderedPlan, drawing: np.ndarray
) -> tuple[np.ndarray, np.ndarray | None]:
    """``predict`` of ``rendered`` drawn as ``drawing`` (itself, or with its furniture painted
    over), its labels checked to be the drawing's size."""
    labels, probabilities = predict(dataclasses.replace(rendered, image=drawing))
    labels = np.asarray(labels)
    if labels.shape != rendered.labels.shape:
        raise InputError(
            f"segmenter returned {labels.shape} labels for a {rendered.labels.shape} drawing"
        )
    return labels, probabilities


def _fmt(value: float | None) -> str:
    return "   -  " if value is None else f"{100 * value:5.1f}%"


def format_table(report: dict, *, list_misses: bool) -> str:
    lines = [
        f"{report['n_images']} images, {report['n_instances']} instances, "
        f"{report['n_gt_spaces']} ground-truth spaces (split={report['split']}"
        + (f", views={report['views']}" if report.get("views") else "")
        + (", storage network" if report.get("storage_network") else "")
        + ("" if report.get("known_scale", True) else ", scale unknown")
        + ")",
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
    voted = report["after_vote"]
    lines.append(f"{'':18s} {'network':^24s}   {'after vote':^24s}")
    for cat, s in report["categories"].items():
        v = voted["categories"][cat]
        if s and v:
            lines.append(
                f"{cat:18s} P {_fmt(s['precision'])}  R {_fmt(s['recall'])}  F1 {_fmt(s['f1'])}"
                f"   P {_fmt(v['precision'])}  R {_fmt(v['recall'])}  F1 {_fmt(v['f1'])}"
            )
    lines.append(
        f"{'connector pixels':18s} P {_fmt(report['connector_precision'])}  "
        f"R {_fmt(report['connector_recall'])}{'':11s}"
        f"   P {_fmt(voted['connector_precision'])}  R {_fmt(voted['connector_recall'])}"
    )
    lines.append(f"connector instances found {_fmt(report['connector_instance_recall'])}")
    lines.append(f"instance accuracy {_fmt(report['instance_accuracy'])}")
    errors = list(report["instance_errors"].items())
    if errors:
        shown = ", ".join(f"{pair} {n}" for pair, n in errors[:6])
        more = f" (+{sum(n for _, n in errors[6:])} more)" if errors[6:] else ""
        lines.append(f"wrong instances (truth->voted): {shown}{more}")
    left_out = report["left_out"]
    lines.append(
        "left out (voted background): "
        + (", ".join(f"{name} {n}" for name, n in left_out.items()) if left_out else "none")
    )
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
    walled = report["oversized_connectors_walled"]
    if walled["instances"]:
        lines.append(
            f"connector-size prior: {walled['instances']} doors and windows too wide made wall, "
            f"{walled['right_after']} right (before: {walled['right_before']})"
        )
    closed = report["balconies_closed"]
    if closed["instances"]:
        lines.append(
            f"balcony prior: {closed['instances']} balconies with no open air made rooms, "
            f"{closed['right_after']} right (before: {closed['right_before']})"
        )
    if report["sealed_room_doors"]:
        lines.append(f"sealed-room prior: {report['sealed_room_doors']} walls made doors")
    kitchen = report["kitchen_effect"]
    lines.append(
        f"kitchen prior: {report['kitchens_undone']} kitchens undone, "
        f"{report['kitchens_added']} missing ones found, instance accuracy "
        f"{_fmt(kitchen['no_prior']['instance_accuracy'])} -> "
        f"{_fmt(kitchen['prior']['instance_accuracy'])}"
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
                    + (f"in {m['instance_class']})" if m["instance_class"] else "in no instance)")
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
    add_drawing_arguments(parser, real_drawings=True)
    parser.add_argument(
        "--no-split", action="store_true", help="headline figures without the open-passage split"
    )
    parser.add_argument(
        "--front-doors",
        type=count_or_any,
        default=1,
        metavar="N|any",
        help="front-door prior for the headline figures: N per plan, or 'any' for none [1]",
    )
    parser.add_argument(
        "--kitchens",
        type=count_or_any,
        default=1,
        metavar="N|any",
        help="kitchen prior: at most N kitchens per plan (and one where none was found), "
        "or 'any' for none [1]",
    )
    parser.add_argument(
        "--keep-sealed-rooms",
        action="store_true",
        help="no sealed-room prior: walls stay walls even where a room has no door",
    )
    parser.add_argument(
        "--unknown-scale",
        action="store_true",
        help="parse each drawing without its scale, as run does without --scale (the priors "
        "then measure widths against the drawing's doors)",
    )
    parser.add_argument(
        "--storerooms",
        type=float,
        default=None,
        metavar="P",
        help="experiment, not the parse: after the priors, vote background every bathroom whose "
        "mean background probability is above P (a storeroom in the ground truth); the real "
        "bathrooms it drops count as wrong instances and in left_out",
    )
    parser.add_argument(
        "--weights",
        default=None,
        help="segmenter checkpoint, run alone (default: the shipped one with its storage network)",
    )
    parser.add_argument("--device", default="cpu")
    parser.add_argument(
        "--zoom",
        type=float,
        default=1.0,
        metavar="F",
        help="R3D: enlarge each drawing and its labels F times first, as a finer scan of the "
        "same listing, or shrink them below 1, as a thumbnail (rooms and openings scored at "
        "F^2 times the smallest size) [1]",
    )
    parser.add_argument(
        "--at-own-size",
        action="store_true",
        help=f"R3D: parse drawings under {SMALL_DRAWING_PX} px at their own size, not enlarged "
        "(perception.small_drawings)",
    )
    parser.add_argument(
        "--askew",
        type=float,
        default=0.0,
        metavar="DEG",
        help="R3D: lay each drawing and its labels DEG degrees askew first, as a page scanned "
        "crooked, and run the skew step on it as run does [0]",
    )
    parser.add_argument(
        "--quarter-turns",
        type=int,
        default=0,
        choices=(0, 1, 2, 3),
        metavar="K",
        help="R3D: turn each drawing and its labels K quarter turns counter-clockwise first, as "
        "a page scanned on its side or upside down, and run the orientation step on it as run "
        "does [0]",
    )
    parser.add_argument(
        "--textured-floors",
        action="store_true",
        help="R3D: paint each drawing's floors with planks and its bathrooms with tiles first "
        "(grey, seeded by --seed), as a rendered listing paints them",
    )
    parser.add_argument(
        "--squared-paper",
        type=int,
        default=0,
        metavar="PX",
        help="R3D: print each drawing on squared paper first, grid lines PX px apart (0: none) [0]",
    )
    parser.add_argument(
        "--squared-paper-grey",
        type=int,
        default=200,
        metavar="G",
        help="R3D: the grey of the squared paper's lines, 0-255 [200]",
    )
    parser.add_argument(
        "--coarse-scan",
        type=int,
        default=0,
        metavar="Q",
        help="R3D: each drawing as a coarse scan first: shrunk to half, saved as JPEG at quality "
        "Q, enlarged back (0: as drawn) [0]",
    )
    parser.add_argument(
        "--views",
        type=int,
        choices=VIEW_COUNTS,
        default=DEFAULT_VIEWS,
        help=f"test-time views of each drawing averaged; 1 is the network alone [{DEFAULT_VIEWS}]",
    )
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
    if args.oracle is not None and not 0 <= args.oracle <= 1:
        raise InputError(f"--oracle must be a fraction in 0..1, got {args.oracle}")
    if args.storerooms is not None and not 0 <= args.storerooms <= 1:
        raise InputError(f"--storerooms must be a probability in 0..1, got {args.storerooms}")
    if not 0.25 <= args.zoom <= 8:
        raise InputError(f"--zoom must be a factor in 0.25..8, got {args.zoom}")
    if not -45 <= args.askew <= 45:
        raise InputError(f"--askew must be in -45..45 degrees, got {args.askew}")
    if not 0 <= args.coarse_scan <= 100:
        raise InputError(
            f"--coarse-scan must be a JPEG quality in 1-100 (0: none), got {args.coarse_scan}"
        )
    r3d_only = {
        "--zoom": args.zoom != 1,
        "--at-own-size": args.at_own_size,
        "--askew": args.askew != 0,
        "--quarter-turns": args.quarter_turns != 0,
        "--textured-floors": args.textured_floors,
        "--squared-paper": args.squared_paper,
        "--coarse-scan": args.coarse_scan,
    }
    for flag, given in r3d_only.items():
        if given and not args.r3d:
            raise InputError(
                f"{flag} changes R3D drawings before they are parsed; use it with --r3d"
            )
    if args.r3d:
        return _main_r3d(args)
    plans, total = chosen_plans(args)
    if predict is None and args.oracle is not None:
        predict = oracle_predictor(args.oracle, args.seed)
    views = None  # test-time views of the segmenter; None for an injected or oracle predictor
    storage = None  # whether a storage network reads closets beside it
    if predict is None:
        from f2n_drake.segmenter.inference import Segmenter

        views = args.views
        segmenter = Segmenter.load(args.weights, device=args.device, views=views)
        storage = getattr(segmenter, "storage_model", None) is not None
        predict = network_predictor(segmenter)
    report = evaluate(
        plans,
        predict,
        size_px=args.size,
        styles=args.styles,
        look=args.look,
        seed=args.seed,
        split=not args.no_split,
        front_doors=args.front_doors,
        kitchens=args.kitchens,
        sealed_rooms=not args.keep_sealed_rooms,
        known_scale=not args.unknown_scale,
        storerooms=args.storerooms,
        total=total,
    )
    report["views"] = views
    report["storage_network"] = storage
    report["look"] = args.look
    if not args.resplan:
        report["openings"] = args.openings
        report.pop("per_plan")
    if args.json:
        print(json.dumps(report))
    else:
        print(format_table(report, list_misses=bool(args.resplan)))
    return 0


def _main_r3d(args: argparse.Namespace) -> int:
    """``--r3d DIR``: the full parse of R3D's drawings, scored in its merged classes."""
    from f2n_drake.datasets.r3d import (
        coarse_scan,
        load_r3d_plan,
        on_squared_paper,
        split_names,
        textured_floors,
    )
    from f2n_drake.evaluate.r3d import evaluate_r3d, format_r3d_table
    from f2n_drake.segmenter.inference import Segmenter

    if args.oracle is not None:
        raise InputError("--oracle needs drawn plans; R3D drawings are scored with the network")
    names = split_names(args.r3d, args.split)[: args.plans]
    segmenter = Segmenter.load(args.weights, device=args.device, views=args.views)
    plans = (load_r3d_plan(args.r3d, name) for name in names)
    if args.textured_floors:
        plans = (textured_floors(plan, args.seed) for plan in plans)
    if args.squared_paper:
        grid = (args.squared_paper, args.squared_paper_grey)
        plans = (on_squared_paper(plan, *grid) for plan in plans)
    if args.coarse_scan:
        plans = (coarse_scan(plan, args.coarse_scan) for plan in plans)
    report = evaluate_r3d(
        plans,
        segmenter,
        total=len(names),
        zoom=args.zoom,
        askew_deg=args.askew,
        quarter_turns=args.quarter_turns,
        enlarge_small=not args.at_own_size,
    )
    report.update(
        split=args.split,
        zoom=args.zoom,
        at_own_size=args.at_own_size,
        askew=args.askew,
        quarter_turns=args.quarter_turns,
        textured_floors=args.textured_floors,
        squared_paper=args.squared_paper,
        squared_paper_grey=args.squared_paper_grey if args.squared_paper else None,
        coarse_scan=args.coarse_scan or None,
        views=args.views,
        weights=args.weights or "shipped",
        storage_network=getattr(segmenter, "storage_model", None) is not None,
    )
    print(json.dumps(report) if args.json else format_r3d_table(report))
    return 0
