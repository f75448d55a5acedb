"""``ParsedPlan``: labelled instances with exact geometry, the hand-off from perception.

Perception (``f2n_drake.perception.instances``) makes one from a drawing;
``f2n_drake.datasets.ground_truth`` makes one
from a ``FloorPlan``. Everything downstream (graph, planning, exports, simulation) reads only this.
"""

from __future__ import annotations

from collections.abc import Callable, Collection, Hashable
from dataclasses import dataclass, field, replace
from typing import Any, TypeVar

import cv2
import numpy as np
from scipy import ndimage
from shapely.geometry import Polygon, box

from f2n_drake.core.classes import CLASS_ID, CLASS_NAMES, NUM_CLASSES
from f2n_drake.core.raster import PixelGrid
from f2n_drake.core.text import TextBox

T = TypeVar("T")

UNSURE_BELOW = 0.8
"""An instance whose ``confidence`` is below this is flagged as unsure (the CLI lists them; the
segmentation evaluation reports how often flagged and unflagged instances are right)."""


def outer_contour(mask: np.ndarray, offset: tuple[int, int]) -> np.ndarray:
    """(N, 2) float outer contour (col, row) of the largest blob of a bool crop ``mask`` whose
    top-left pixel is ``offset`` (col, row) in the image."""
    contours, _ = cv2.findContours(
        np.pad(mask, 1).astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE
    )
    if not contours:
        return np.zeros((0, 2))
    best = max(contours, key=lambda c: (cv2.contourArea(c), len(c)))
    return best.reshape(-1, 2).astype(float) + (offset[0] - 1, offset[1] - 1)


@dataclass
class Instance:
    """One enclosed region of the drawing (or a recorded opening cut).

    Attributes:
        id: instance id, > 0; pixels with this value in ``ParsedPlan.instance_ids`` belong to it.
        class_name: one of ``CLASS_NAMES`` (not background for spaces/connectors) or ``"opening"``.
        contour_px: (N, 2) float outer contour, pixel-centre coordinates (col, row).
        area_px: number of pixels.
        centroid_px: (col, row) mean of the pixels.
        votes: label id -> pixel count inside the region (empty for ground truth).
        scores: label id -> mean class probability over the region (a soft vote, in 0..1;
            empty when the segmenter gave no probabilities).
        name: the room's printed name ("Kitchen / Diner"), None when none was read.
    """

    id: int
    class_name: str
    contour_px: np.ndarray
    area_px: int
    centroid_px: tuple[float, float]
    votes: dict[int, int] = field(default_factory=dict)
    scores: dict[int, float] = field(default_factory=dict)
    name: str | None = None

    @property
    def confidence(self) -> float | None:
        """Mean probability of the instance's own class, None without ``scores`` (ground truth,
        openings, label-only segmenters)."""
        class_id = CLASS_ID.get(self.class_name)
        return self.scores.get(class_id) if class_id is not None else None

    def evidence(self, class_id: int) -> float:
        """How much the instance looks like class ``class_id``, in 0..1: its mean probability
        (``scores``), else its share of the pixel votes (0 with neither)."""
        if self.scores:
            return float(self.scores.get(class_id, 0.0))
        total = sum(self.votes.values())
        return self.votes.get(class_id, 0) / total if total else 0.0

    def best_class(self, among: Collection[int], default: str) -> str:
        """Name of the class of ``among`` the instance looks most like (scores, else votes);
        ``default`` when it has evidence for none of them."""
        evidence = self.scores or self.votes
        candidates = {c: v for c, v in evidence.items() if c in among}
        return CLASS_NAMES[max(candidates, key=candidates.get)] if candidates else default

    def contour_m(self, grid: PixelGrid) -> np.ndarray:
        """(N, 2) contour in metres."""
        return grid.to_m(self.contour_px)

    def polygon_m(self, grid: PixelGrid) -> Polygon:
        """The contour as a shapely polygon in metres (made valid); an instance a pixel or two
        thin, whose contour is under three corners, is the box of its pixels."""
        corners = self.contour_m(grid).reshape(-1, 2)
        if len(corners) == 0:
            return Polygon()
        if len(np.unique(corners, axis=0)) < 3:
            half = grid.metres_per_px / 2
            (x0, y0), (x1, y1) = corners.min(axis=0) - half, corners.max(axis=0) + half
            return box(x0, y0, x1, y1)
        poly = Polygon(corners)
        return poly if poly.is_valid else poly.buffer(0)

    def area_m2(self, grid: PixelGrid) -> float:
        return grid.area_m2(self.area_px)

    def centroid_m(self, grid: PixelGrid) -> np.ndarray:
        return grid.to_m(np.asarray(self.centroid_px))


def instance_from_mask(
    iid: int,
    class_name: str,
    mask: np.ndarray,
    labels: np.ndarray,
    probabilities: np.ndarray | None = None,
    offset: tuple[int, int] = (0, 0),
) -> Instance:
    """The Instance of the bool ``mask`` (not empty): its outline, area and centroid, the votes
    of ``labels`` on it and, given (NUM_CLASSES, h, w) ``probabilities``, its scores. ``labels``
    and ``probabilities`` cover the same window as ``mask``, whose top-left pixel is ``offset``
    (col, row) in the image (a crop; (0, 0) for the whole image)."""
    rows, cols = np.nonzero(mask)
    r0, c0 = rows.min(), cols.min()
    votes = np.bincount(labels[rows, cols], minlength=NUM_CLASSES)
    scores = {}
    if probabilities is not None:
        mean = probabilities[:, rows, cols].mean(axis=1, dtype=np.float32)
        scores = {int(c): round(float(p), 4) for c, p in enumerate(mean)}
    corner = (c0 + offset[0], r0 + offset[1])
    return Instance(
        id=iid,
        class_name=class_name,
        contour_px=outer_contour(mask[r0 : rows.max() + 1, c0 : cols.max() + 1], corner),
        area_px=int(rows.size),
        centroid_px=(float(cols.mean() + offset[0]), float(rows.mean() + offset[1])),
        votes={int(c): int(v) for c, v in enumerate(votes) if v},
        scores=scores,
    )


@dataclass
class ParsedPlan:
    """Instances of a drawing plus the images they came from.

    Attributes:
        instance_ids: (H, W) int32, instance id per pixel, 0 where no instance (line pixels,
            outside background).
        labels: (H, W) uint8 semantic label per pixel (network prediction, or ground truth).
        instances: the instances, ``instances[k].id`` unique and > 0.
        grid: pixel <-> metre mapping, None when the scale is unknown.
        scale_source: how ``grid`` was obtained: "input", "argument", "door-width estimate",
            "printed room sizes" (with their count and spread), or "unknown".
        texts: the words read on the drawing (``TextBox``), each placed in its instance; empty
            when nothing was read.
        sheet_note: which part of the sheet was parsed, when not all of it (legends left
            out), or that it holds several plans; empty otherwise.
        drawing_notes: what was done to the drawing before it was read (lit evenly, its
            squared paper's grid painted out, textured floors made plain fills, faint strokes
            read as ink), one line each; empty when it was read as it came.
        door_outline_px: thickness of the lines along the sides of the doors drawn as boxes
            across thick walls [px]: such a door's instance is the whole strip between the
            wall's faces, lines included, so no unlabelled outline lies between it and its rooms
            to measure the jamb lines by (``mapping.graph.line_gap_px``); 0 when there is none.
        plans: how many plans of the sheet the parse holds (the floors of a house drawn side
            by side, ``perception.sheet``); no route joins two.

    A plan is not changed in place once made (each step returns a new one, e.g. with
    ``dataclasses.replace``), so what is derived from it is computed once (``derived``).
    """

    instance_ids: np.ndarray
    labels: np.ndarray
    instances: list[Instance]
    grid: PixelGrid | None = None
    scale_source: str = "unknown"
    texts: list[TextBox] = field(default_factory=list)
    sheet_note: str = ""
    door_outline_px: float = 0.0
    plans: int = 1
    drawing_notes: tuple[str, ...] = ()
    _derived: dict[Hashable, Any] = field(
        default_factory=dict, init=False, repr=False, compare=False
    )

    def derived(self, key: Hashable, compute: Callable[[], T]) -> T:
        """``compute()``, computed on the first call with ``key`` and kept with the plan (the line
        gap, the occupancy maps: values every later stage reads). A copy made with
        ``dataclasses.replace`` starts with none."""
        if key not in self._derived:
            self._derived[key] = compute()
        return self._derived[key]

    def boxes(self) -> list[tuple[slice, slice] | None]:
        """Bounding box of each instance id (at index ``id - 1``; None where no pixel holds it),
        ``scipy.ndimage.find_objects`` of ``instance_ids``, found once per plan."""
        return self.derived("boxes", lambda: ndimage.find_objects(self.instance_ids))

    def mask(self, instance_id: int) -> np.ndarray:
        """(H, W) bool mask of one instance."""
        return self.instance_ids == instance_id

    def by_id(self) -> dict[int, Instance]:
        return {inst.id: inst for inst in self.instances}

    def of_class(self, *names: str) -> list[Instance]:
        return [inst for inst in self.instances if inst.class_name in names]


def joined_instances(
    parsed: ParsedPlan,
    into: dict[int, int],
    class_of: Callable[[Instance, np.ndarray], str],
    probabilities: np.ndarray | None = None,
) -> ParsedPlan:
    """``parsed`` with each instance of ``into`` (id -> the id of the kept instance it joins)
    made part of that one, instance ids renumbered 1..K in their order. A kept instance that
    grew is remade from its pixels, of class ``class_of(instance, mask)``, keeping its name;
    ``probabilities`` give its scores."""
    size = max([int(parsed.instance_ids.max()), *(i.id for i in parsed.instances)]) + 1
    lut = np.arange(size)
    for piece, kept_id in into.items():
        lut[piece] = kept_id
    kept = [inst for inst in parsed.instances if inst.id not in into]
    renumber = np.zeros(size, np.int32)
    for new_id, inst in enumerate(kept, start=1):
        renumber[inst.id] = new_id
    ids = renumber[lut[parsed.instance_ids]]
    grown = set(into.values())
    instances = []
    for inst in kept:
        new_id = int(renumber[inst.id])
        if inst.id not in grown:
            instances.append(replace(inst, id=new_id))
            continue
        mask = ids == new_id
        whole = instance_from_mask(new_id, class_of(inst, mask), mask, parsed.labels, probabilities)
        instances.append(replace(whole, name=inst.name))
    return replace(parsed, instance_ids=ids, instances=instances)
