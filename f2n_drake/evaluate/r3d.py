"""Scores of the full parse on R3D drawings, in R3D's merged classes (set-valued labels).

For each drawing of an R3D split (``f2n_drake.datasets.r3d``), ``f2n_drake.pipeline.parse_drawing``
runs as ``run`` runs it (no scale given) and is scored against R3D's labels:

- pixel figures, from the parse's per-pixel labels (``ParsedPlan.labels``: the network's labels of
  the drawing, segmented around its furniture) and, under ``after_vote``, from the labels the
  parse hands on (``vote_corrected_labels``): a pixel is right when its label is acceptable for its
  R3D class (living or kitchen for R3D's living/kitchen/dining, door, window or front door for
  its openings, ...). ``pixel_accuracy`` is over every pixel; ``class_accuracy`` is the recall of
  each R3D class; ``mean_class_accuracy`` averages the eight classes DeepFloorplan reports (wall,
  opening, closet, bathroom, living, bedroom, hall, balcony), not background nor "other";
- rooms recovered: an R3D room is a 4-connected region of one room class (``ROOM_CLASSES``, of
  at least ``MIN_ROOM_PX``); it is recovered when one parse instance has IoU >= 0.5 with it and a
  class acceptable for it;
- doors and windows recovered: the same rule on R3D's openings (4-connected regions of at least
  ``MIN_OPENING_PX``) and the parse's door, window and front-door instances; counted apart too
  for the openings thinner than ``THIN_OPENING_PX`` (strips R3D marks a closet's front with);
- doors and windows on an opening: of the parse's door, window and front-door instances, those
  with at least ``ON_OPENING_SHARE`` of their pixels on R3D opening pixels (the precision beside
  the recall above: a parse that made a door of every gap would recover more and place worse);
- named rooms (``f2n_drake.evaluate.r3d_named_rooms``): the R3D rooms on which the parse read a
  room name, scored by the class of the instance covering most of each, with the names and on a
  parse of the drawing without reading (``reader=None``);
- drawings refused: the parse raised ``InputError``. A refused drawing's rooms and openings count
  as missed; its pixel figures use the network's labels of the plain drawing.
"""

from __future__ import annotations

import sys
from collections.abc import Iterable
from dataclasses import dataclass, field
from functools import partial

import cv2
import numpy as np
from tqdm import tqdm

from f2n_drake.core.classes import CLASS_ID, CONNECTOR_CLASSES, NUM_CLASSES
from f2n_drake.core.errors import InputError
from f2n_drake.core.parsed import ParsedPlan
from f2n_drake.datasets.r3d import (
    ACCEPTABLE_MASK,
    R3D_CLASSES,
    R3D_ID,
    ROOM_CLASSES,
    R3DPlan,
    askew,
    enlarged,
    scanned_turned,
)
from f2n_drake.evaluate.r3d_named_rooms import named_rooms_summary, score_named_rooms
from f2n_drake.perception.floor_textures import without_floor_textures
from f2n_drake.perception.image import predict_labels
from f2n_drake.perception.ink import binarize
from f2n_drake.perception.instances import vote_corrected_labels
from f2n_drake.perception.paper_grid import without_paper_grid
from f2n_drake.perception.reading import TextReader, read_words
from f2n_drake.pipeline import parse_drawing

MIN_ROOM_PX = 50
MIN_OPENING_PX = 10
IOU_RECOVERED = 0.5
ON_OPENING_SHARE = 0.5
THIN_OPENING_PX = 3.0
"""An R3D opening whose least-area rectangle is thinner than this [px] is a strip (R3D's mark for
a closet's bifold or sliding front, on the paper of its mouth): a connector as thick as the wall
beside it overlaps it by less than half, so its recovery is reported apart."""
REPORTED_CLASSES: tuple[str, ...] = (
    "wall",
    "opening",
    "closet",
    "bathroom",
    "living",
    "bedroom",
    "hall",
    "balcony",
)
"""The R3D classes DeepFloorplan reports per-class accuracy for (their mean is the headline)."""

_ACCEPTS = (ACCEPTABLE_MASK[:, None] >> np.arange(NUM_CLASSES)) & 1 == 1
"""(R3D classes, f2n_drake classes) bool: is the class acceptable for the R3D class."""


@dataclass
class R3DTotals:
    """Counts summed over drawings: confusion (R3D class x f2n_drake class) of the network's
    and the voted labels, regions found and recovered per R3D class, the parse's connectors and
    those on an R3D opening, refused drawings."""

    confusion: np.ndarray = field(default_factory=lambda: np.zeros((len(R3D_CLASSES), NUM_CLASSES)))
    confusion_voted: np.ndarray = field(
        default_factory=lambda: np.zeros((len(R3D_CLASSES), NUM_CLASSES))
    )
    regions: np.ndarray = field(default_factory=lambda: np.zeros(len(R3D_CLASSES), np.int64))
    recovered: np.ndarray = field(default_factory=lambda: np.zeros(len(R3D_CLASSES), np.int64))
    thin_openings: int = 0
    thin_openings_recovered: int = 0
    connectors: int = 0
    connectors_on_openings: int = 0
    refused: list[str] = field(default_factory=list)
    per_plan: list[dict] = field(default_factory=list)
    named_rooms: list[dict] = field(default_factory=list)


def confusion(r3d_labels: np.ndarray, labels: np.ndarray) -> np.ndarray:
    """(R3D classes, f2n_drake classes) pixel counts."""
    pairs = r3d_labels.astype(np.int64).ravel() * NUM_CLASSES + labels.ravel()
    return np.bincount(pairs, minlength=len(R3D_CLASSES) * NUM_CLASSES).reshape(-1, NUM_CLASSES)


def region_matches(
    r3d_labels: np.ndarray, parsed: ParsedPlan | None, r3d_class: str, min_px: int
) -> list[tuple[np.ndarray, bool]]:
    """Per 4-connected region of one R3D class of at least ``min_px``: its (N, 2) pixels (x, y)
    and whether one parse instance matches it with IoU >= 0.5 and an acceptable class."""
    r = R3D_ID[r3d_class]
    n, regions, stats, _ = cv2.connectedComponentsWithStats(
        (r3d_labels == r).astype(np.uint8), connectivity=4
    )
    kept = [k for k in range(1, n) if stats[k, cv2.CC_STAT_AREA] >= min_px]
    if parsed is not None and kept:
        ids = parsed.instance_ids
        instance_px = np.bincount(ids.ravel())
        accepted = {
            inst.id
            for inst in parsed.instances
            if inst.class_name in CLASS_ID and _ACCEPTS[r, CLASS_ID[inst.class_name]]
        }
    matches = []
    for k in kept:
        where = regions == k
        ys, xs = np.nonzero(where)
        hit = False
        if parsed is not None:
            inside = ids[where]
            overlap = np.bincount(inside[inside > 0])
            area = stats[k, cv2.CC_STAT_AREA]
            hit = any(
                overlap[i] / (area + instance_px[i] - overlap[i]) >= IOU_RECOVERED
                for i in np.flatnonzero(overlap)
                if i in accepted
            )
        matches.append((np.stack([xs, ys], axis=1), bool(hit)))
    return matches


def thickness_px(pixels: np.ndarray) -> float:
    """The short side of the least-area rectangle holding (N, 2) pixel positions [px], a pixel
    wide line 1 px."""
    (_, _), (w, h), _ = cv2.minAreaRect(pixels.astype(np.float32))
    return float(min(w, h)) + 1.0


def connectors_on_openings(r3d_labels: np.ndarray, parsed: ParsedPlan | None) -> tuple[int, int]:
    """(connectors, on openings): the parse's door, window and front-door instances, and how many
    of them have at least ``ON_OPENING_SHARE`` of their pixels on R3D opening pixels."""
    if parsed is None:
        return 0, 0
    ids = [i.id for i in parsed.instances if i.class_name in CONNECTOR_CLASSES]
    if not ids:
        return 0, 0
    lut = np.zeros(int(parsed.instance_ids.max()) + 1, np.int64)
    lut[ids] = np.arange(1, len(ids) + 1)
    index = lut[parsed.instance_ids]
    size = np.bincount(index.ravel(), minlength=len(ids) + 1)[1:]
    on = np.bincount(index[r3d_labels == R3D_ID["opening"]], minlength=len(ids) + 1)[1:]
    return len(ids), int(np.count_nonzero(on >= ON_OPENING_SHARE * size))


def _parse_or_none(
    plan: R3DPlan, segmenter, reader: TextReader | None, enlarge_small: bool = True
) -> ParsedPlan | None:
    try:
        return parse_drawing(
            plan.image, segmenter=segmenter, reader=reader, enlarge_small=enlarge_small
        )
    except InputError:
        return None


def score_plan(
    plan: R3DPlan,
    segmenter,
    totals: R3DTotals,
    reader: TextReader | None = read_words,
    zoom: float = 1.0,
    enlarge_small: bool = True,
) -> None:
    """Parse one drawing (reading its words with ``reader``) and add its scores to
    ``totals``; ``zoom``: the drawing was enlarged that many times (smallest regions scored
    grown with it); ``enlarge_small``: as ``parse_drawing``'s."""
    try:
        parsed = parse_drawing(
            plan.image, segmenter=segmenter, reader=reader, enlarge_small=enlarge_small
        )
        labels = parsed.labels
        # the lines the parse read: a floor's texture or the paper's grid is no line
        # (perception.floor_textures, perception.paper_grid)
        plain = without_floor_textures(without_paper_grid(plan.image))
        voted = vote_corrected_labels(parsed, binarize(plain))
    except InputError:
        parsed = None
        labels = voted = predict_labels(segmenter, plan.image)[0]
        totals.refused.append(plan.name)
    cm = confusion(plan.labels, labels)
    totals.confusion += cm
    totals.confusion_voted += confusion(plan.labels, voted)
    entry = {"plan": plan.name, "refused": parsed is None}
    for name in (*ROOM_CLASSES, "opening"):
        min_px = (MIN_OPENING_PX if name == "opening" else MIN_ROOM_PX) * zoom**2
        matches = region_matches(plan.labels, parsed, name, min_px)
        found = sum(hit for _, hit in matches)
        totals.regions[R3D_ID[name]] += len(matches)
        totals.recovered[R3D_ID[name]] += found
        entry[name] = [found, len(matches)]
        if name == "opening":
            thin = [hit for px, hit in matches if thickness_px(px) < THIN_OPENING_PX * zoom]
            totals.thin_openings += len(thin)
            totals.thin_openings_recovered += sum(thin)
    n, on = connectors_on_openings(plan.labels, parsed)
    totals.connectors += n
    totals.connectors_on_openings += on
    entry["connectors_on_openings"] = [on, n]
    entry["pixel_accuracy"] = round(float((cm * _ACCEPTS).sum() / cm.sum()), 4)
    named = score_named_rooms(
        plan.labels,
        parsed,
        partial(_parse_or_none, plan, segmenter, None, enlarge_small),
        MIN_ROOM_PX * zoom**2,
    )
    entry["named_rooms"] = [sum(r["right"] for r in named), len(named)]
    entry["named_rooms_without_names"] = [sum(r["right_without_names"] for r in named), len(named)]
    totals.named_rooms += [{"plan": plan.name, **r} for r in named]
    totals.per_plan.append(entry)


def _pixel_scores(cm: np.ndarray) -> dict:
    right = (cm * _ACCEPTS).sum(axis=1)
    per_class = {
        name: (float(right[r] / cm[r].sum()) if cm[r].sum() else None)
        for r, name in enumerate(R3D_CLASSES)
    }
    reported = [per_class[name] for name in REPORTED_CLASSES if per_class[name] is not None]
    return {
        "pixel_accuracy": float(right.sum() / cm.sum()),
        "mean_class_accuracy": float(np.mean(reported)) if reported else None,
        "class_accuracy": per_class,
    }


def _fraction(found: int, n: int) -> dict:
    return {"recovered": int(found), "total": int(n), "fraction": found / n if n else None}


def summary(totals: R3DTotals) -> dict:
    rooms = [R3D_ID[name] for name in ROOM_CLASSES]
    opening = R3D_ID["opening"]
    return {
        "n_drawings": len(totals.per_plan),
        "pixel_labels": "parse (network labels of the drawing, segmented around its furniture)",
        **_pixel_scores(totals.confusion),
        "after_vote": _pixel_scores(totals.confusion_voted),
        "rooms_recovered": _fraction(totals.recovered[rooms].sum(), totals.regions[rooms].sum()),
        "rooms_recovered_by_class": {
            name: _fraction(totals.recovered[R3D_ID[name]], totals.regions[R3D_ID[name]])
            for name in ROOM_CLASSES
        },
        "openings_recovered": _fraction(totals.recovered[opening], totals.regions[opening]),
        "openings_recovered_by_thickness": {
            f"under_{THIN_OPENING_PX:g}_px": _fraction(
                totals.thin_openings_recovered, totals.thin_openings
            ),
            f"{THIN_OPENING_PX:g}_px_or_more": _fraction(
                totals.recovered[opening] - totals.thin_openings_recovered,
                totals.regions[opening] - totals.thin_openings,
            ),
        },
        "connectors_on_openings": {
            "on_openings": totals.connectors_on_openings,
            "total": totals.connectors,
            "fraction": (
                totals.connectors_on_openings / totals.connectors if totals.connectors else None
            ),
        },
        "named_rooms": named_rooms_summary(totals.named_rooms),
        "named_room_misses": [r for r in totals.named_rooms if not r["right"]],
        "refused": len(totals.refused),
        "refused_plans": totals.refused,
        "per_plan": totals.per_plan,
    }


def evaluate_r3d(
    plans: Iterable[R3DPlan],
    segmenter,
    *,
    total: int | None = None,
    reader: TextReader | None = read_words,
    zoom: float = 1.0,
    askew_deg: float = 0.0,
    quarter_turns: int = 0,
    enlarge_small: bool = True,
) -> dict:
    """Parse (reading with ``reader``) and score every plan, each enlarged ``zoom`` times first
    (:func:`~f2n_drake.datasets.r3d.enlarged`: the same listings scanned finer, or shrunk below
    1), laid ``askew_deg`` degrees askew (:func:`~f2n_drake.datasets.r3d.askew`, with the skew
    step as ``run`` runs it) and turned ``quarter_turns`` quarter turns counter-clockwise
    (:func:`~f2n_drake.datasets.r3d.scanned_turned`, with the orientation step as ``run`` runs
    it); ``enlarge_small`` False parses small drawings at their own size
    (``perception.small_drawings``); progress bar on stderr; returns :func:`summary`."""
    totals = R3DTotals()
    for plan in tqdm(plans, total=total, file=sys.stderr, desc="r3d", unit="plan"):
        drawing = scanned_turned(askew(enlarged(plan, zoom), askew_deg), quarter_turns)
        score_plan(drawing, segmenter, totals, reader, zoom, enlarge_small)
    return summary(totals)


def _pct(value: float | None) -> str:
    return "   -  " if value is None else f"{100 * value:5.1f}%"


def format_r3d_table(report: dict) -> str:
    """A human summary of :func:`summary`."""
    voted = report["after_vote"]
    lines = [
        f"{report['n_drawings']} R3D drawings, {report['refused']} refused; pixel figures from "
        "the parse's labels (after the vote beside them)",
        f"{'R3D class':12s} {'accuracy':>9s} {'after vote':>11s}",
    ]
    for name in R3D_CLASSES:
        lines.append(
            f"{name:12s} {_pct(report['class_accuracy'][name]):>9s} "
            f"{_pct(voted['class_accuracy'][name]):>11s}"
        )
    for key, label in (("mean_class_accuracy", "mean class"), ("pixel_accuracy", "pixel acc.")):
        lines.append(f"{label:12s} {_pct(report[key]):>9s} {_pct(voted[key]):>11s}")
    rooms, openings = report["rooms_recovered"], report["openings_recovered"]
    by_class = ", ".join(
        f"{name} {r['recovered']}/{r['total']}"
        for name, r in report["rooms_recovered_by_class"].items()
    )
    lines.append(
        f"rooms recovered {rooms['recovered']}/{rooms['total']} ({_pct(rooms['fraction'])}): "
        + by_class
    )
    placed = report["connectors_on_openings"]
    lines.append(
        f"doors and windows recovered {openings['recovered']}/{openings['total']} "
        f"({_pct(openings['fraction'])}); of the {placed['total']} the parse found, "
        f"{placed['on_openings']} ({_pct(placed['fraction'])}) lie on an R3D opening"
    )
    by_thickness = report["openings_recovered_by_thickness"]
    thin = by_thickness[f"under_{THIN_OPENING_PX:g}_px"]
    thick = by_thickness[f"{THIN_OPENING_PX:g}_px_or_more"]
    lines.append(
        f"  openings at least {THIN_OPENING_PX:g} px thick {thick['recovered']}/{thick['total']} "
        f"({_pct(thick['fraction'])}), thinner strips (closet fronts) "
        f"{thin['recovered']}/{thin['total']}"
    )
    named = report["named_rooms"]
    lines.append(
        f"rooms whose name is read {named['count']}: type right {_pct(named['accuracy'])} "
        f"with the names, {_pct(named['accuracy_without_names'])} without (network, vote and "
        "priors alone)"
    )
    if report["refused_plans"]:
        lines.append("refused: " + ", ".join(report["refused_plans"]))
    return "\n".join(lines)
