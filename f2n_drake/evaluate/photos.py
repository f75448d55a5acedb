"""``python -m f2n_drake.evaluate photos DRAWING...``: does a drawing photographed, or saved
small or as JPEG, parse as it did?

Each drawing is parsed as given, then made into pictures a phone would take of it, or a user
would save of it, and parsed again, with the steps that undo it and without:

- ``dimmed 60 %`` and ``dimmed 40 %``: lit fully at its top-left corner and down to that share of
  the light at its bottom-right one (:func:`dimmed`); undone by ``perception.lighting``;
- ``photographed``: the drawing on a page with a white margin, seen at an angle on a darker
  table, dimmed to 60 % and slightly blurred (:func:`photographed`); undone by
  ``perception.page`` (squaring the page) and ``perception.lighting``;
- ``JPEG 60`` and ``half size``: saved as JPEG at quality 60, shrunk to half its size (area
  resampling); where their lines fade so far that no outline is closed, the parse reads the
  faint strokes as ink (``parse_drawing(faint_lines=True)``).

Reported per drawing and picture, a photographed parse carried back onto the drawing's grid:
``labels kept``, the share of the pixels either parse labels (not background after the vote)
whose label is the one the drawing as given gets (two near-tied room classes swapping count
against it); ``rooms kept``, the share of the drawing's rooms that one room of the picture's
parse covers with intersection over union at least 0.5, whatever the classes; the parses
refused.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import cv2
import numpy as np
from tqdm import tqdm

from f2n_drake.core.errors import InputError
from f2n_drake.perception.image import load_image
from f2n_drake.perception.ink import as_grey, binarize
from f2n_drake.perception.instances import vote_corrected_labels
from f2n_drake.perception.lighting import evenly_lit
from f2n_drake.perception.page import squared_page

PICTURES: tuple[str, ...] = ("dimmed 60 %", "dimmed 40 %", "photographed", "JPEG 60", "half size")
TABLE_GREY = 90
"""The table's grey under a photographed page."""


def dimmed(image: np.ndarray, darkest: float) -> np.ndarray:
    """``image`` (grey or colour) lit fully at its top-left corner, ``darkest`` of that at its
    bottom-right one, linearly along the diagonal."""
    h, w = image.shape[:2]
    along = np.add.outer(np.arange(h) / max(h - 1, 1), np.arange(w) / max(w - 1, 1)) / 2
    light = 1.0 - (1.0 - darkest) * along
    if image.ndim == 3:
        light = light[..., None]
    return np.clip(image * light, 0, 255).astype(np.uint8)


def photographed(image: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``image`` as a phone photo of its page, and the (3, 3) homography from the drawing's
    pixels to the photo's: the drawing on a page with a white margin (8 % of its long side), its
    corners moved in by 5-12 % of the picture as a photo taken at an angle shows them, on a
    ``TABLE_GREY`` table 30 % wider and taller, dimmed to 60 % and blurred (sigma 1 px)."""
    grey = as_grey(image)
    h, w = grey.shape
    pad = round(0.08 * max(h, w))
    page = cv2.copyMakeBorder(grey, pad, pad, pad, pad, cv2.BORDER_CONSTANT, value=255)
    ph, pw = page.shape
    out_w, out_h = round(1.3 * pw), round(1.3 * ph)
    src = np.float32([[0, 0], [pw, 0], [pw, ph], [0, ph]])
    corners = [[0.12, 0.10], [0.86, 0.05], [0.95, 0.93], [0.05, 0.88]]
    dst = (np.array(corners) * [out_w, out_h]).astype(np.float32)
    to_photo = cv2.getPerspectiveTransform(src, dst)
    table = np.full((out_h, out_w), TABLE_GREY, np.uint8)
    photo = cv2.warpPerspective(
        page, to_photo, (out_w, out_h), dst=table, borderMode=cv2.BORDER_TRANSPARENT
    )
    photo = cv2.GaussianBlur(dimmed(photo, 0.6), (0, 0), 1.0)
    shift = np.array([[1, 0, pad], [0, 1, pad], [0, 0, 1]], np.float64)  # drawing -> page
    return photo, to_photo @ shift


def read(image: np.ndarray, segmenter, *, undo: bool) -> tuple[np.ndarray, np.ndarray] | None:
    """The parse of ``image`` as two (H, W) maps on the drawing's grid: its labels after the vote,
    and the id of its room (space instance) per pixel, 0 elsewhere; None when it was refused.
    With ``undo``, a photographed page is squared first and the light evened
    (``perception.page``, ``perception.lighting``), a drawing whose ink closes no outline is
    read with its faint strokes, textured floors are made plain fills
    (``perception.floor_textures``), and the maps are carried back from the squared page."""
    from f2n_drake.core.classes import SPACE_CLASSES
    from f2n_drake.pipeline import parse_drawing

    to_grid = np.eye(3)
    if undo:
        image, page = squared_page(image)
        if page is not None:
            width, height = page.size
            corners = np.float32([[0, 0], [width - 1, 0], [width - 1, height - 1], [0, height - 1]])
            to_grid = cv2.getPerspectiveTransform(page.corners.astype(np.float32), corners)
    try:
        parsed = parse_drawing(
            image, segmenter=segmenter, even_lighting=undo, faint_lines=undo, floor_textures=undo
        )
    except InputError:
        return None
    grey = as_grey(image)
    labels = vote_corrected_labels(parsed, binarize(evenly_lit(grey) if undo else grey))
    # ids need not run 1..n (a prior may leave a gap): one entry per id, float: warped exactly
    top = max([int(parsed.instance_ids.max()), *(inst.id for inst in parsed.instances)])
    rooms = np.zeros(top + 1, np.float32)
    for inst in parsed.instances:
        if inst.class_name in SPACE_CLASSES:
            rooms[inst.id] = inst.id
    return labels, rooms[parsed.instance_ids], to_grid


def carried_back(reading, to_picture: np.ndarray, shape: tuple[int, int]):
    """A ``read`` of a picture, on the drawing's grid (``to_picture``: drawing -> picture)."""
    if reading is None:
        return None
    labels, rooms, to_grid = reading
    warp = to_grid @ to_picture
    if np.allclose(warp, np.eye(3)):
        return labels, rooms
    h, w = shape
    flags = cv2.INTER_NEAREST | cv2.WARP_INVERSE_MAP
    back = [
        cv2.warpPerspective(m, warp, (w, h), flags=flags, borderValue=0) for m in (labels, rooms)
    ]
    return back[0], back[1]


def agreement(labels: np.ndarray | None, reference: np.ndarray | None) -> float:
    """Share of the pixels labelled by either (not background) with the same label; 0 when
    either parse was refused."""
    if labels is None or reference is None:
        return 0.0
    labelled = (labels > 0) | (reference > 0)
    return float((labels == reference)[labelled].mean()) if labelled.any() else 1.0


def rooms_kept(rooms: np.ndarray | None, reference: np.ndarray | None) -> float:
    """Share of the rooms of ``reference`` (room id maps) that one room of ``rooms`` covers with
    intersection over union at least 0.5, whatever their classes; 0 when either was refused."""
    if rooms is None or reference is None:
        return 0.0
    ids = np.unique(reference[reference > 0])
    if ids.size == 0:
        return 1.0
    kept = 0
    for r in ids:
        mine = reference == r
        others, overlap = np.unique(rooms[mine & (rooms > 0)], return_counts=True)
        kept += any(
            n / (mine.sum() + np.count_nonzero(rooms == o) - n) >= 0.5
            for o, n in zip(others, overlap, strict=True)
        )
    return kept / ids.size


def picture(image: np.ndarray, name: str) -> tuple[np.ndarray, np.ndarray]:
    """The picture ``name`` (``PICTURES``) of ``image`` and the homography drawing -> picture."""
    if name == "photographed":
        return photographed(image)
    if name == "JPEG 60":
        _, data = cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_QUALITY, 60])
        return cv2.imdecode(data, cv2.IMREAD_UNCHANGED), np.eye(3)
    if name == "half size":
        h, w = image.shape[:2]
        small = cv2.resize(image, (round(w / 2), round(h / 2)), interpolation=cv2.INTER_AREA)
        return small, np.diag([small.shape[1] / w, small.shape[0] / h, 1.0])
    return dimmed(image, float(name.split()[1]) / 100), np.eye(3)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m f2n_drake.evaluate photos",
        description=" ".join(__doc__.split("\n\n")[0].split()),
    )
    parser.add_argument("drawings", nargs="+", type=Path, help="drawings (images)")
    parser.add_argument(
        "--pictures",
        nargs="+",
        choices=PICTURES,
        default=list(PICTURES),
        metavar="PICTURE",
        help=f"which pictures of each drawing: {', '.join(map(repr, PICTURES))} [all]".replace(
            "%", "%%"
        ),
    )
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    return parser


def main(argv: list[str] | None = None) -> int:
    from f2n_drake.segmenter.inference import Segmenter

    args = build_parser().parse_args(argv)
    segmenter = Segmenter.load()
    rows = []
    for path in tqdm(args.drawings, file=sys.stderr, desc="photos", unit="drawing"):
        image = load_image(path)
        shape = image.shape[:2]
        reference = carried_back(read(image, segmenter, undo=True), np.eye(3), shape)
        for name in args.pictures:
            shot, to_shot = picture(image, name)
            row = {"drawing": path.name, "picture": name, "refused": []}
            for undo, key in ((True, "undone"), (False, "as_taken")):
                back = carried_back(read(shot, segmenter, undo=undo), to_shot, shape)
                if back is None:
                    row["refused"].append(key)
                pairs = zip(back or (None, None), reference or (None, None), strict=True)
                (labels, ref_labels), (rooms, ref_rooms) = pairs
                row[f"labels_{key}"] = round(agreement(labels, ref_labels), 4)
                row[f"rooms_{key}"] = round(rooms_kept(rooms, ref_rooms), 4)
            rows.append(row)
    figures = [f"{kind}_{key}" for kind in ("labels", "rooms") for key in ("undone", "as_taken")]
    report = {
        "drawings": len(args.drawings),
        **{f"mean_{f}": round(float(np.mean([r[f] for r in rows])), 4) for f in figures},
        "per_drawing": rows,
    }
    if args.json:
        print(json.dumps(report))
        return 0
    print(f"{'drawing':28s} {'picture':13s}  labels kept (undone, as taken)  rooms kept  refused")
    for r in rows:
        print(
            f"{r['drawing'][:28]:28s} {r['picture']:13s}  {100 * r['labels_undone']:10.1f}% "
            f"{100 * r['labels_as_taken']:5.1f}%  {100 * r['rooms_undone']:16.1f}% "
            f"{100 * r['rooms_as_taken']:5.1f}%  {', '.join(r['refused']) or '-'}"
        )
    print(
        "mean, undone / as taken: labels kept "
        f"{100 * report['mean_labels_undone']:.1f} / {100 * report['mean_labels_as_taken']:.1f} %, "
        f"rooms kept {100 * report['mean_rooms_undone']:.1f} / "
        f"{100 * report['mean_rooms_as_taken']:.1f} %"
    )
    return 0
