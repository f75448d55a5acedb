"""Reading the words on a drawing: room names and printed sizes, each placed in its instance.

Detection and recognition are RapidOCR's (``rapidocr-onnxruntime``: PaddleOCR's PP-OCRv4
detector and recogniser run by ONNX Runtime on the CPU). Its wheel holds the three ONNX models
(detection 4.7 MB, recognition 10.9 MB, orientation 0.6 MB), so nothing is downloaded when it
runs. The recogniser's alphabet is Chinese with the Latin letters, digits and the signs printed
sizes use (', ", x, /, .); accented letters come out plain or dropped, which the lexicon's
keys allow for (``perception.room_names``). Lines are read as written along the drawing's rows,
and a line running up or down it both ways (a narrow room's name is often written downward or
upward: :func:`_read_either_way`); RapidOCR's 180-degree classifier is skipped. The detector
sees the drawing shrunk to ``DETECT_SIDE_PX`` px on its long side, or to ``DETECT_SHARE`` of it
for a large drawing (a smaller one enlarged toward it, ``DETECT_MAX_ENLARGE``: its letters are
often too small), and each line it finds is recognised on a crop of the drawing itself.
Recognition is most of the time: about 30 ms of one core per line of text.
"""

from __future__ import annotations

import functools
import logging
from collections.abc import Callable, Sequence
from importlib.resources import files

import cv2
import numpy as np

from f2n_drake.core.text import TextBox
from f2n_drake.perception.room_names import room_class

log = logging.getLogger(__name__)

MIN_CONFIDENCE = 0.5
"""Lines read with less confidence than this are dropped (RapidOCR's own default)."""

DETECT_SIDE_PX = 736
"""Long side [px] a drawing is shrunk to, at least, for detection (letters 10 px high on a
1000 px drawing stay 7 px high); a smaller drawing is enlarged toward it."""
DETECT_MAX_ENLARGE = 1.25
"""Most a small drawing is enlarged for detection: a listing's 7 px letters are often too small
for the detector at their own size (on R3D's development split, mostly 500-700 px listings, 100
named rooms are matched against 95 at their own size, 101 when enlarged to ``DETECT_SIDE_PX``,
which costs twice the 15 ms this adds to a 512 px parse)."""
DETECT_SHARE = 0.75
"""A drawing whose long side is more than ``DETECT_SIDE_PX / DETECT_SHARE`` is shrunk to this
share of it for detection (its letters are drawn bigger in pixels)."""

TALL = 1.5
"""A detected line this many times as high as wide runs up or down the drawing (RapidOCR's own
rule for turning its crop)."""

THREADS = 2
"""ONNX Runtime threads per model, which wait for work asleep (its default threads spin: the
reader took 1.2 times as long with them on the quiet 2-core machine, 1.5-1.8 times with both
cores busy)."""
MODELS = ("ch_PP-OCRv4_det_infer.onnx", "ch_PP-OCRv4_rec_infer.onnx")
"""RapidOCR's detection and recognition models, in its wheel's ``models`` folder."""

TextReader = Callable[[np.ndarray], list[TextBox]]
"""Anything that reads an (H, W) uint8 grey drawing into text boxes (unplaced)."""


@functools.lru_cache(maxsize=1)
def _engine():
    import onnxruntime
    from rapidocr_onnxruntime import RapidOCR

    engine = RapidOCR()
    options = onnxruntime.SessionOptions()
    options.intra_op_num_threads = THREADS
    options.add_session_config_entry("session.intra_op.allow_spinning", "0")
    models = files("rapidocr_onnxruntime").joinpath("models")
    for model, name in zip((engine.text_det.infer, engine.text_rec.session), MODELS, strict=True):
        model.session = onnxruntime.InferenceSession(
            str(models.joinpath(name)), options, providers=["CPUExecutionProvider"]
        )
    return engine


def _detection_input(grey: np.ndarray) -> np.ndarray:
    """(1, 3, h, w) float32 input of the detector: ``grey`` scaled (``DETECT_SIDE_PX``,
    ``DETECT_SHARE``) to sides that are multiples of 32, in -1..1, its grey in all three
    channels."""
    h, w = grey.shape
    long_px = max(h, w)
    if long_px < DETECT_SIDE_PX:
        factor = min(DETECT_SIDE_PX / long_px, DETECT_MAX_ENLARGE)
    else:
        factor = max(DETECT_SIDE_PX, DETECT_SHARE * long_px) / long_px
    size = (max(32, round(w * factor / 32) * 32), max(32, round(h * factor / 32) * 32))
    small = cv2.resize(grey, size, interpolation=cv2.INTER_AREA if factor < 1 else cv2.INTER_LINEAR)
    x = small.astype(np.float32) / np.float32(127.5) - np.float32(1.0)
    return np.broadcast_to(x, (1, 3, *x.shape)).copy()


def read_words(grey: np.ndarray, min_confidence: float = MIN_CONFIDENCE) -> list[TextBox]:
    """Every line of text RapidOCR reads on ``grey`` ((H, W) uint8, dark ink on light paper),
    with at least ``min_confidence``, its box the axis-aligned bounds of the detected quad
    [px]; ``instance_id`` unset (:func:`place_texts`). Lines are detected on the drawing
    shrunk (:func:`_detection_input`) and recognised on crops of the drawing itself."""
    h, w = grey.shape
    quads = detected_lines(grey)
    if not quads:
        return []
    lines = _read_either_way(line_crops(grey, quads), [is_tall(quad) for quad in quads])
    texts = []
    for quad, (text, confidence) in zip(quads, lines, strict=True):
        quad = np.clip(np.asarray(quad, float), 0, (w, h))
        c0, r0 = np.floor(quad.min(axis=0)).astype(int)
        c1, r1 = np.ceil(quad.max(axis=0)).astype(int)
        box = (int(c0), int(r0), int(c1), int(r1))
        if float(confidence) >= min_confidence and text.strip() and c1 > c0 and r1 > r0:
            texts.append(TextBox(text.strip(), float(confidence), box))
    texts = joined_lines(texts)
    log.info("read %d lines of text", len(texts))
    return texts


def detected_lines(grey: np.ndarray) -> list[np.ndarray]:
    """The (4, 2) quads [px] of the lines of text the detector finds on ``grey`` ((H, W) uint8,
    dark ink on light paper), in reading order (top to bottom, left to right)."""
    engine = _engine()
    h, w = grey.shape
    detector = engine.text_det
    found, _ = detector.postprocess_op(detector.infer(_detection_input(grey))[0], (h, w))
    quads = detector.filter_tag_det_res(found, (h, w))
    return list(engine.sorted_boxes(quads)) if len(quads) else []


def line_crops(grey: np.ndarray, quads: Sequence[np.ndarray]) -> list[np.ndarray]:
    """Each line's crop of ``grey``, squared to its quad and, for a tall line, turned a
    quarter turn to the left (:func:`is_tall`), as the recogniser reads it."""
    return _engine().get_crop_img_list(cv2.cvtColor(grey, cv2.COLOR_GRAY2BGR), list(quads))


def recognised(crops: Sequence[np.ndarray]) -> list[tuple[str, float]]:
    """(text, confidence) of each crop, read as it lies."""
    lines, _ = _engine().text_rec(list(crops))
    return [(text, float(confidence)) for text, confidence in lines]


def is_tall(quad: np.ndarray) -> bool:
    """Whether a detected line runs up or down the drawing (RapidOCR turns its crop a quarter
    turn to the left before reading it: the crop of a quad at least ``TALL`` times as high as
    wide)."""
    p = np.asarray(quad, np.float64)
    width = max(np.linalg.norm(p[0] - p[1]), np.linalg.norm(p[2] - p[3]))
    height = max(np.linalg.norm(p[0] - p[3]), np.linalg.norm(p[1] - p[2]))
    return height >= TALL * width


def _read_either_way(crops: list[np.ndarray], tall: list[bool]) -> list[tuple[str, float]]:
    """(text, confidence) of each crop; a tall line's crop, turned to read upward, is read
    turned the other way too (a name written downward), and the more confident reading kept."""
    lines = recognised(crops)
    turned = [k for k, up_or_down in enumerate(tall) if up_or_down]
    if turned:
        others = recognised([np.rot90(crops[k], 2) for k in turned])
        for k, (text, confidence) in zip(turned, others, strict=True):
            if confidence > lines[k][1]:
                lines[k] = (text, confidence)
    return lines


_JOINS = "/&+"


def _below(upper: TextBox, lower: TextBox) -> bool:
    """Whether ``lower`` is the line right below ``upper``: both written along the rows,
    overlapping across, starting under its middle and at most a line's height beneath it."""
    (a0, b0, a1, b1), (c0, d0, c1, d1) = upper.box_px, lower.box_px
    if b1 - b0 >= TALL * (a1 - a0) or d1 - d0 >= TALL * (c1 - c0):  # a line up or down the page
        return False
    height = max(b1 - b0, d1 - d0)
    return min(a1, c1) > max(a0, c0) and d0 > (b0 + b1) / 2 and d0 - b1 <= height


def joined_lines(texts: Sequence[TextBox]) -> list[TextBox]:
    """``texts`` with each name written on two lines read as one ("Reception Room /" over
    "Kitchen" is "Reception Room / Kitchen"): a line ending in "/", "&" or "+" is joined to the
    line right below it, a line beginning with one to the line above, and so are two lines
    that are both room names ("Reception Room" over "Kitchen": one room's name, which a
    room would otherwise be parted between; the lowest confidence of the two, the box round
    both). Lines with digits are not joined: they are sizes ("+ wardrobe" under
    "15'10 x 12'4")."""
    texts = list(texts)
    for upper in sorted(texts, key=lambda t: t.box_px[1]):
        if upper not in texts:
            continue
        for lower in sorted(texts, key=lambda t: t.box_px[1]):
            if lower is upper or not _below(upper, lower):
                continue
            joins = upper.text[-1] in _JOINS or lower.text[0] in _JOINS
            joins = joins or (
                room_class(upper.text) is not None and room_class(lower.text) is not None
            )
            if joins and not any(c.isdigit() for c in upper.text + lower.text):
                (a0, b0, a1, b1), (c0, d0, c1, d1) = upper.box_px, lower.box_px
                joined = TextBox(
                    f"{upper.text} {lower.text}",
                    min(upper.confidence, lower.confidence),
                    (min(a0, c0), min(b0, d0), max(a1, c1), max(b1, d1)),
                )
                texts[texts.index(upper)] = joined
                texts.remove(lower)
                break
    return texts


def place_texts(texts: Sequence[TextBox], instance_ids: np.ndarray) -> list[TextBox]:
    """``texts`` each with ``instance_id`` set to the instance holding most of its box's pixels
    (None when the box lies on no instance)."""
    placed = []
    for text in texts:
        c0, r0, c1, r1 = text.box_px
        ids = instance_ids[r0:r1, c0:c1]
        ids = ids[ids > 0]
        instance_id = int(np.bincount(ids).argmax()) if ids.size else None
        placed.append(TextBox(text.text, text.confidence, text.box_px, instance_id))
    return placed


def text_ink(lines: np.ndarray, texts: Sequence[TextBox], margin_px: int = 1) -> np.ndarray:
    """(H, W) bool: the ink of ``lines`` that is text, every connected stroke lying wholly in the
    text boxes (grown by ``margin_px``; a stroke joining two lines of a name lies in both). A
    wall or a door swing a box overlaps runs out of it and stays ink."""
    if not texts:
        return np.zeros(lines.shape, bool)
    boxes = np.zeros(lines.shape, bool)
    for text in texts:
        c0, r0, c1, r1 = text.box_px
        boxes[max(r0 - margin_px, 0) : r1 + margin_px, max(c0 - margin_px, 0) : c1 + margin_px] = 1
    n, cc = cv2.connectedComponents(lines.astype(np.uint8), connectivity=8)
    inside = np.bincount(cc[boxes], minlength=n) > 0
    inside &= np.bincount(cc[~boxes], minlength=n) == 0
    inside[0] = False
    return inside[cc]
