"""Scores of segmented drawings against their ground truth, accumulated over many plans.

``evaluate_plan`` parses one segmented drawing with the parse's own steps
(``f2n_drake.pipeline.parse_steps``: instances, then each prior), with and without the
open-passage split, and again without the front-door and kitchen priors, and adds its counts to
``Totals``; ``summary`` turns the totals into the JSON report of ``python -m
f2n_drake.evaluate segmentation`` (fractions in 0..1, None where undefined; pixel scores from one
confusion matrix over all images).
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field

import numpy as np

from f2n_drake.core.classes import CONNECTOR_CLASSES, NUM_CLASSES, SPACE_CLASSES
from f2n_drake.core.parsed import UNSURE_BELOW, ParsedPlan
from f2n_drake.core.plan import FloorPlan
from f2n_drake.datasets.render import RenderedPlan
from f2n_drake.evaluate import metrics
from f2n_drake.evaluate.storerooms import vote_storerooms
from f2n_drake.perception.instances import (
    EnclosedRegions,
    SplitOptions,
    binarize,
    enclosed_regions,
    vote_corrected_labels,
)
from f2n_drake.perception.priors.chain import apply_priors
from f2n_drake.perception.priors.front_doors import FRONT_DOOR
from f2n_drake.pipeline import PARSE_STEPS, Segmentation, parse_steps


@dataclass
class Totals:
    """Counts accumulated over images; ``summary()`` turns them into the JSON report."""

    cm_raw: np.ndarray = field(default_factory=lambda: np.zeros((NUM_CLASSES,) * 2, np.int64))
    cm_vote: np.ndarray = field(default_factory=lambda: np.zeros((NUM_CLASSES,) * 2, np.int64))
    instances: dict[str, list[int]] = field(
        default_factory=lambda: {"split": [0, 0], "no_split": [0, 0]}
    )
    instance_errors: dict[str, Counter] = field(
        default_factory=lambda: {"split": Counter(), "no_split": Counter()}
    )  # "truth->voted" -> wrong instances
    left_out: dict[str, Counter] = field(
        default_factory=lambda: {"split": Counter(), "no_split": Counter()}
    )  # truth class -> rooms and connectors voted background (no instance), as left_out_truth
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
    sealed_room_doors: int = 0  # walls the sealed-room prior made doors (split parse)
    balconies_closed: list[int] = field(
        default_factory=lambda: [0, 0, 0]
    )  # balconies the balcony prior made rooms, of them right after, right before (split parse)
    oversized_walled: list[int] = field(
        default_factory=lambda: [0, 0, 0]
    )  # doors and windows the connector-size prior made wall, right after, right before (split)
    kitchens: dict[str, list[int]] = field(
        default_factory=lambda: {m: [0, 0] for m in ("prior", "no_prior")}
    )  # instances right, instances (split parse, with and without the kitchen prior)
    kitchens_undone: int = 0  # kitchens the kitchen prior undid (split parse)
    kitchens_added: int = 0  # rooms the kitchen prior made the missing kitchen (split parse)
    n_images: int = 0
    per_plan: list[dict] = field(default_factory=list)


def evaluate_plan(
    name: str,
    plan: FloorPlan,
    rendered: RenderedPlan,
    segmentation: Segmentation,
    totals: Totals,
    *,
    front_doors: int | None = 1,
    kitchens: int | None = 1,
    sealed_rooms: bool = True,
    lines: np.ndarray | None = None,
    known_scale: bool = True,
    storerooms: float | None = None,
) -> None:
    """Add one segmented drawing (``pipeline.segment_drawing``'s result) to ``totals``; both
    parses get the front-door prior (``front_doors``) and, with ``sealed_rooms``, the
    sealed-room prior; ``lines``: ``binarize(rendered.image)`` if already known;
    ``known_scale``: the parse is given the drawing's true scale, else none (as ``run`` without
    ``--scale`` parses); ``storerooms``: after the priors, bathrooms more background-like than
    this are voted background (``storerooms.vote_storerooms``, an experiment; None: not)."""
    gt = rendered.labels
    labels, furniture = segmentation.labels, segmentation.furniture
    lines = binarize(rendered.image) if lines is None else lines
    switches = {"front_doors": front_doors, "kitchens": kitchens, "sealed_rooms": sealed_rooms}
    steps = {
        mode: parse_steps(
            rendered.image,
            segmentation,
            lines=lines,
            grid=rendered.grid if known_scale else None,
            split=SplitOptions() if mode == "split" else None,
            **switches,
        )
        for mode in ("split", "no_split")
    }
    voted = {mode: s["instances"] for mode, s in steps.items()}
    stages = steps["split"]
    _count_changed(stages["front_doors"], stages["connector_sizes"], gt, totals.oversized_walled)
    _count_changed(stages["connector_sizes"], stages["balconies"], gt, totals.balconies_closed)
    change = len(stages["kitchens"].of_class("kitchen")) - len(
        stages["balconies"].of_class("kitchen")
    )
    totals.kitchens_undone += max(0, -change)
    totals.kitchens_added += max(0, change)
    totals.sealed_room_doors += sum(
        a.class_name != b.class_name
        for a, b in zip(stages["kitchens"].instances, stages["sealed_rooms"].instances, strict=True)
    )
    parsed = {mode: s[PARSE_STEPS[-1]] for mode, s in steps.items()}
    if storerooms is not None:
        parsed = {mode: vote_storerooms(p, storerooms) for mode, p in parsed.items()}
    totals.cm_raw += metrics.confusion_matrix(gt, labels)
    totals.cm_vote += metrics.confusion_matrix(gt, vote_corrected_labels(parsed["split"], lines))
    rot = rendered.style.rotation_deg
    truth_spaces = metrics.rasterise_truth(
        plan, rendered.grid, gt, SPACE_CLASSES, rotation_deg=rot, valid=~lines
    )
    truth_conn = metrics.rasterise_truth(
        plan, rendered.grid, gt, CONNECTOR_CLASSES, rotation_deg=rot
    )
    space_matches = {}
    truth = {mode: metrics.instance_truth(p, gt) for mode, p in parsed.items()}
    regions = enclosed_regions(lines, furniture=furniture)
    for mode, p in parsed.items():
        correct, total, left_out = _region_counts(p, gt, regions, truth[mode])
        totals.instances[mode][0] += correct
        totals.instances[mode][1] += total
        totals.instance_errors[mode].update(
            f"{truth[mode][i.id]}->{i.class_name}"
            for i in p.instances
            if i.id in truth[mode] and i.class_name != truth[mode][i.id]
        )
        totals.instance_errors[mode].update(f"{name}->background" for name in left_out)
        totals.left_out[mode].update(left_out)
        space_matches[mode] = metrics.match_truth(p, truth_spaces, by="iou")
        totals.spaces[mode] += space_matches[mode]
        totals.predicted_spaces[mode] += len(p.of_class(*SPACE_CLASSES))
        totals.matched_spaces[mode] += len({m.instance_id for m in space_matches[mode] if m.found})
    conn_matches = metrics.match_truth(parsed["split"], truth_conn, by="overlap")
    _count_front_doors(
        parsed["split"], gt, truth["split"], truth_conn, regions, totals.front_doors["prior"]
    )
    no_prior = apply_priors(voted["split"], **{**switches, "front_doors": None})
    no_prior_truth = metrics.instance_truth(no_prior, gt)
    _count_front_doors(
        no_prior, gt, no_prior_truth, truth_conn, regions, totals.front_doors["no_prior"]
    )
    no_kitchen_prior = apply_priors(voted["split"], **{**switches, "kitchens": None})
    for counts, p, t in (
        (totals.kitchens["prior"], parsed["split"], truth["split"]),
        (totals.kitchens["no_prior"], no_kitchen_prior, None),
    ):
        correct, total, _ = _region_counts(p, gt, regions, t)
        counts[0] += correct
        counts[1] += total
    for inst in parsed["split"].instances:
        if inst.id in truth["split"] and inst.confidence is not None:
            counts = totals.confidence["unsure" if inst.confidence < UNSURE_BELOW else "sure"]
            counts[0] += inst.class_name == truth["split"][inst.id]
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


def _region_counts(
    parsed: ParsedPlan,
    gt: np.ndarray,
    regions: EnclosedRegions,
    truth: dict[int, str] | None = None,
) -> tuple[int, int, list[str]]:
    """(right, regions, left out): ``metrics.instance_accuracy_counts`` of the parse's
    instances, plus the rooms, doors and windows it voted background, each a wrong region
    (``metrics.left_out_truth``: no instance, but a region the parse got wrong)."""
    left_out = metrics.left_out_truth(parsed, regions.components, regions.enclosed, gt)
    correct, total = metrics.instance_accuracy_counts(parsed, gt, truth)
    return correct, total + len(left_out), left_out


def _count_front_doors(
    parsed: ParsedPlan,
    gt: np.ndarray,
    truth: dict[int, str],
    truth_conn: list[metrics.TruthRegion],
    regions: EnclosedRegions,
    counts: list[int],
) -> None:
    """Add instance accuracy and front-door recall/precision counts (see ``Totals``); ``truth``
    is ``metrics.instance_truth`` of ``parsed``, ``regions`` the drawing's instance candidates."""
    front = [r for r in truth_conn if r.class_name == FRONT_DOOR]
    predicted = [i for i in parsed.instances if i.class_name == FRONT_DOOR]
    correct, total, _ = _region_counts(parsed, gt, regions, truth)
    counts[0] += correct
    counts[1] += total
    counts[2] += sum(m.found for m in metrics.match_truth(parsed, front, by="overlap"))
    counts[3] += len(front)
    counts[4] += sum(truth[i.id] == FRONT_DOOR for i in predicted)
    counts[5] += len(predicted)


def _count_changed(
    before: ParsedPlan, after: ParsedPlan, gt: np.ndarray, counts: list[int]
) -> None:
    """Add the instances a prior changed, those right after, those right before."""
    changed = [
        (a, b)
        for a, b in zip(before.instances, after.instances, strict=True)
        if a.class_name != b.class_name
    ]
    if not changed:
        return
    truth = metrics.instance_truth(before, gt)
    counts[0] += len(changed)
    counts[1] += sum(truth.get(b.id) == b.class_name for _, b in changed)
    counts[2] += sum(truth.get(a.id) == a.class_name for a, _ in changed)


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


def _voted_scores(cm: np.ndarray) -> dict:
    """Pixel, category and connector scores of the after-vote labels (the parse's output)."""
    precision, recall = metrics.connector_precision_recall(cm)
    return {
        **_pixel_scores(cm),
        "categories": metrics.category_scores(cm),
        "connector_precision": precision,
        "connector_recall": recall,
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
        "instance_errors": dict(totals.instance_errors[mode].most_common()),
        "left_out": dict(totals.left_out[mode].most_common()),
        "space_recall": effect[mode]["space_recall"],
        "space_precision": effect[mode]["space_precision"],
        "categories": metrics.category_scores(cm),
        "connector_confusion": metrics.connector_confusion(cm).tolist(),
        "connector_confusion_layout": "rows ground truth [connector, other], "
        "columns prediction [connector, other], pixels",
        "connector_precision": precision,
        "connector_recall": recall,
        "connector_instance_recall": metrics.recall(totals.connectors),
        "after_vote": _voted_scores(totals.cm_vote),
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
        "sealed_room_doors": totals.sealed_room_doors,
        "oversized_connectors_walled": dict(
            zip(("instances", "right_after", "right_before"), totals.oversized_walled, strict=True)
        ),
        "balconies_closed": dict(
            zip(("instances", "right_after", "right_before"), totals.balconies_closed, strict=True)
        ),
        "kitchen_effect": {
            mode: {"instance_accuracy": metrics.fraction(*c)} for mode, c in totals.kitchens.items()
        },
        "kitchens_undone": totals.kitchens_undone,
        "kitchens_added": totals.kitchens_added,
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
