"""Segmentation and instance metrics: pure functions on label arrays and instance lists.

Pixel metrics start from a confusion matrix ``cm[gt, pred]`` (rows ground truth, columns
prediction) so images can be accumulated by summing matrices. Every score is a fraction in 0..1;
a score with nothing to measure is None (``null`` in JSON), never a made-up 0 or 1.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from f2n_drake.core.classes import (
    CLASS_ID,
    CLASS_NAMES,
    CONNECTOR_CLASSES,
    NUM_CLASSES,
    OPENING,
    SPACE_CLASSES,
)
from f2n_drake.core.parsed import ParsedPlan
from f2n_drake.core.plan import FloorPlan, polygons_of
from f2n_drake.core.raster import PixelGrid

CATEGORIES: dict[str, tuple[str, ...]] = {
    "functional_spaces": SPACE_CLASSES,
    "connectors": CONNECTOR_CLASSES,
    "wall": ("wall",),
    "background": ("background",),
}
"""Class groups scored by macro precision / recall / F1 over their classes."""

_SHIFT = 4  # fractional bits of the fixed-point polygon coordinates given to cv2.fillPoly


def fraction(num: float, den: float) -> float | None:
    """num / den, or None when den is 0."""
    return float(num) / float(den) if den else None


# -- pixel metrics --------------------------------------------------------------------------
def confusion_matrix(
    gt: np.ndarray, pred: np.ndarray, num_classes: int = NUM_CLASSES
) -> np.ndarray:
    """(C, C) int64 pixel counts, ``cm[g, p]`` = pixels with ground truth g predicted p."""
    gt = np.asarray(gt, dtype=np.int64).ravel()
    pred = np.asarray(pred, dtype=np.int64).ravel()
    if gt.shape != pred.shape:
        raise ValueError(f"ground truth has {gt.size} pixels, prediction {pred.size}")
    counts = np.bincount(gt * num_classes + pred, minlength=num_classes * num_classes)
    return counts[: num_classes * num_classes].reshape(num_classes, num_classes)


def present_classes(cm: np.ndarray) -> np.ndarray:
    """Bool per class: it occurs in the ground truth or in the prediction."""
    return (cm.sum(axis=0) + cm.sum(axis=1)) > 0


def per_class_iou(cm: np.ndarray) -> dict[str, float | None]:
    """Class name -> TP / (TP + FP + FN); None for a class absent from both images."""
    tp = np.diag(cm)
    union = cm.sum(axis=0) + cm.sum(axis=1) - tp
    return {CLASS_NAMES[c]: fraction(tp[c], union[c]) for c in range(len(tp))}


def mean_iou(cm: np.ndarray) -> float | None:
    """Mean IoU over the classes present in the ground truth or the prediction."""
    values = [v for v in per_class_iou(cm).values() if v is not None]
    return float(np.mean(values)) if values else None


def pixel_accuracy(cm: np.ndarray) -> float | None:
    return fraction(np.trace(cm), cm.sum())


def class_scores(cm: np.ndarray, c: int) -> tuple[float, float, float]:
    """(precision, recall, F1) of class ``c``; a zero denominator counts as 0."""
    tp = cm[c, c]
    precision = fraction(tp, cm[:, c].sum()) or 0.0
    recall = fraction(tp, cm[c, :].sum()) or 0.0
    f1 = 2 * precision * recall / (precision + recall) if precision + recall else 0.0
    return precision, recall, f1


def category_scores(cm: np.ndarray) -> dict[str, dict[str, float] | None]:
    """Category -> macro ``{"precision", "recall", "f1"}`` over its classes that are present
    (in ground truth or prediction); None when none is."""
    present = present_classes(cm)
    out: dict[str, dict[str, float] | None] = {}
    for category, names in CATEGORIES.items():
        ids = [CLASS_ID[n] for n in names if present[CLASS_ID[n]]]
        if not ids:
            out[category] = None
            continue
        scores = np.array([class_scores(cm, c) for c in ids])
        out[category] = dict(
            zip(("precision", "recall", "f1"), scores.mean(axis=0).tolist(), strict=True)
        )
    return out


def connector_confusion(cm: np.ndarray) -> np.ndarray:
    """2x2 pixel counts, rows ground truth (connector, other), columns prediction (same order).

    A pixel is a connector when its class is door, window or front door (any of them: a door
    predicted as window still counts as a connector here).
    """
    conn = np.zeros(cm.shape[0], dtype=bool)
    conn[[CLASS_ID[n] for n in CONNECTOR_CLASSES]] = True
    return np.array(
        [
            [cm[np.ix_(conn, conn)].sum(), cm[np.ix_(conn, ~conn)].sum()],
            [cm[np.ix_(~conn, conn)].sum(), cm[np.ix_(~conn, ~conn)].sum()],
        ],
        dtype=np.int64,
    )


def connector_precision_recall(cm: np.ndarray) -> tuple[float | None, float | None]:
    """(precision, recall) of connector-vs-other pixels."""
    (tp, fn), (fp, _) = connector_confusion(cm)
    return fraction(tp, tp + fp), fraction(tp, tp + fn)


# -- instance metrics -----------------------------------------------------------------------
def instance_truth(parsed: ParsedPlan, gt_labels: np.ndarray) -> dict[int, str]:
    """Instance id -> the ground-truth majority class of its pixels (openings left out)."""
    instances = [i for i in parsed.instances if i.class_name != OPENING]
    if not instances:
        return {}
    n = max(i.id for i in parsed.instances) + 1
    votes = np.bincount(
        (parsed.instance_ids.astype(np.int64) * NUM_CLASSES + gt_labels).ravel(),
        minlength=n * NUM_CLASSES,
    ).reshape(n, NUM_CLASSES)
    majority = votes.argmax(axis=1)
    return {i.id: CLASS_NAMES[majority[i.id]] for i in instances}


def instance_accuracy_counts(
    parsed: ParsedPlan, gt_labels: np.ndarray, truth: dict[int, str] | None = None
) -> tuple[int, int]:
    """(correct, total) over instances other than openings: correct when the instance's class is
    the ground-truth majority label of its pixels (``truth``: ``instance_truth``, if known)."""
    truth = instance_truth(parsed, gt_labels) if truth is None else truth
    correct = sum(i.class_name == truth[i.id] for i in parsed.instances if i.id in truth)
    return int(correct), len(truth)


def left_out_truth(
    parsed: ParsedPlan, components: np.ndarray, enclosed: np.ndarray, gt_labels: np.ndarray
) -> list[str]:
    """Ground-truth classes of the rooms and connectors the parse left out.

    An instance candidate (``enclosed`` components of ``components``, as
    :func:`f2n_drake.perception.instances.enclosed_regions` gives them) is left out when at most
    half of it
    belongs to an instance (it was voted background). It counts when the ground-truth majority of
    its pixels is a space or connector class: a room, door or window the parse dropped.
    :func:`instance_accuracy_counts` scores the parse's instances only, so the evaluation adds
    these as wrong instances: a rule that votes ambiguous rooms background pays for the real
    rooms it drops.
    """
    n = len(enclosed)
    flat = components.ravel()
    area = np.bincount(flat, minlength=n)
    covered = np.bincount(flat, weights=(parsed.instance_ids.ravel() > 0), minlength=n)
    votes = np.bincount(
        flat.astype(np.int64) * NUM_CLASSES + gt_labels.ravel(), minlength=n * NUM_CLASSES
    ).reshape(n, NUM_CLASSES)
    majority = votes.argmax(axis=1)
    wanted = np.isin(majority, [CLASS_ID[c] for c in (*SPACE_CLASSES, *CONNECTOR_CLASSES)])
    left_out = enclosed & (covered <= area / 2) & wanted
    return [CLASS_NAMES[majority[k]] for k in np.flatnonzero(left_out)]


@dataclass(frozen=True)
class TruthRegion:
    """One ground-truth polygon rasterised: class, index within its class, bool mask (trimmed
    to the valid pixels) and the untrimmed mask."""

    class_name: str
    index: int
    mask: np.ndarray
    full: np.ndarray | None = None

    @property
    def area_px(self) -> int:
        return int(self.mask.sum())


def rasterise_truth(
    plan: FloorPlan,
    grid: PixelGrid,
    gt_labels: np.ndarray,
    classes: tuple[str, ...],
    *,
    rotation_deg: float = 0.0,
    valid: np.ndarray | None = None,
) -> list[TruthRegion]:
    """Each polygon of ``classes`` as its own mask, kept only where ``gt_labels`` has its class
    (so paint order matches the label image); a polygon repeating an earlier one of its class
    (mask IoU >= 0.9) is left out. An open kitchen is its own region here even though
    the drawing merges it with the living room. ``rotation_deg`` as in ``RenderedPlan``: pixels
    turned counter-clockwise (as seen) about the image centre. ``valid`` (e.g. the non-ink pixels)
    trims the masks after empty polygons are left out, so a region lost under ink still counts."""
    t = math.radians(rotation_deg)
    rot = np.array([[math.cos(t), math.sin(t)], [-math.sin(t), math.cos(t)]])
    centre = np.array([(grid.shape[1] - 1) / 2, (grid.shape[0] - 1) / 2])
    out = []
    for name in classes:
        for index, poly in enumerate(p for g in plan[name] for p in polygons_of(g)):
            rings = []
            for ring in (poly.exterior, *poly.interiors):
                px = grid.to_px(np.asarray(ring.coords)[:-1])
                if rotation_deg:
                    px = (px - centre) @ rot.T + centre
                rings.append(np.round(px * (1 << _SHIFT)).astype(np.int32))
            mask = np.zeros(grid.shape, np.uint8)
            cv2.fillPoly(mask, rings, 1, cv2.LINE_8, _SHIFT)
            mask = mask.astype(bool) & (gt_labels == CLASS_ID[name])
            if not mask.any() or any(_same(mask, r.full) for r in out if r.class_name == name):
                continue  # painted over, or a duplicate polygon (ResPlan has some)
            out.append(TruthRegion(name, index, mask if valid is None else mask & valid, mask))
    return out


def _same(a: np.ndarray, b: np.ndarray, min_iou: float = 0.9) -> bool:
    inter = np.count_nonzero(a & b)
    return inter >= min_iou * (np.count_nonzero(a) + np.count_nonzero(b) - inter)


@dataclass(frozen=True)
class Match:
    """How a ground-truth region was recovered: the best same-class instance and its scores."""

    truth: TruthRegion
    instance_id: int | None
    iou: float
    overlap: float  # intersection / min(area truth, area instance)
    found: bool
    best_class: str | None  # class of the instance covering most of the region (any class)


def match_truth(
    parsed: ParsedPlan, truth: list[TruthRegion], *, by: str = "iou", threshold: float = 0.5
) -> list[Match]:
    """Match every ground-truth region to its best predicted instance of the same class.

    ``by="iou"`` (spaces): found when IoU >= threshold. ``by="overlap"`` (connectors, whose thin
    regions lose a large share to the outline pixels): found when intersection / min(areas) >=
    threshold.
    """
    if by not in ("iou", "overlap"):
        raise ValueError(f"by must be 'iou' or 'overlap', got {by!r}")
    areas = {i.id: i.area_px for i in parsed.instances}
    classes = {i.id: i.class_name for i in parsed.instances}
    out = []
    for region in truth:
        ids, inter = np.unique(parsed.instance_ids[region.mask], return_counts=True)
        keep = ids > 0
        ids, inter = ids[keep], inter[keep]
        best_class = classes[int(ids[np.argmax(inter)])] if ids.size else None
        best_id, best_iou, best_overlap, best_score = None, 0.0, 0.0, -1.0
        for iid, n in zip(ids.tolist(), inter.tolist(), strict=True):
            if classes[iid] != region.class_name:
                continue
            iou = n / (region.area_px + areas[iid] - n)
            overlap = n / min(region.area_px, areas[iid])
            score = overlap if by == "overlap" else iou
            if score > best_score:
                best_id, best_iou, best_overlap, best_score = iid, iou, overlap, score
        found = best_score >= threshold
        out.append(Match(region, best_id, best_iou, best_overlap, found, best_class))
    return out


def recall(matches: list[Match]) -> float | None:
    return fraction(sum(m.found for m in matches), len(matches))
