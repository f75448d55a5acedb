"""``evaluate scale --r3d DIR``: the door-width scale on real drawings, against their printed sizes.

R3D's listings print most rooms' sizes ("12'2\\" x 10'6\\""). Each drawing is parsed as ``run``
parses it (words read, no scale given). Where the printed sizes the parse reads give a scale
resting on at least ``MIN_PRINTED_ROOMS`` rooms that agree within ``MAX_SPREAD``
(:class:`~f2n_drake.perception.printed_sizes.PrintedScale`: the median absolute deviation of the
rooms' scales, relative to their median), that scale is the reference; the estimate is the one
``run`` falls back on when nothing is printed, the median plausible door opening taken to be
``door_width_m`` wide (:func:`~f2n_drake.perception.scale.door_openings_px`). A printed scale is
itself read by the parse (text read, rooms matched), so the comparison measures the two
estimates' disagreement: a bound on the door estimate's error, not the error itself.
"""

from __future__ import annotations

import sys
from collections.abc import Iterable

import numpy as np
from tqdm import tqdm

from f2n_drake.core.errors import InputError
from f2n_drake.datasets.r3d import R3DPlan
from f2n_drake.perception.image import LabelPredictor
from f2n_drake.perception.printed_sizes import printed_scale
from f2n_drake.perception.reading import TextReader, read_words
from f2n_drake.perception.scale import door_openings_px
from f2n_drake.pipeline import parse_drawing

MIN_PRINTED_ROOMS = 3
"""A printed scale is a reference when this many room sizes give it ..."""
MAX_SPREAD = 0.1
"""... and they agree this closely (median absolute deviation relative to their median)."""


def r3d_scale_rows(
    plans: Iterable[R3DPlan],
    segmenter: LabelPredictor,
    *,
    reader: TextReader | None = read_words,
    door_width_m: float = 0.9,
    total: int | None = None,
    progress: bool = True,
) -> list[dict]:
    """One row per drawing: its name, whether the parse refused it, the printed scale it reads
    (``printed_m_per_px``, from ``printed_rooms`` rooms with ``printed_spread``; None when
    nothing printed is read), the reference (``true_m_per_px``: the printed scale when it is
    one, else None), the door-width ``estimate`` (None without a door) and ``n_doors``."""
    rows = []
    for plan in tqdm(
        plans, total=total, disable=not progress, file=sys.stderr, desc="r3d scale", unit="plan"
    ):
        row: dict = {"name": plan.name, "refused": False}
        try:
            parsed = parse_drawing(plan.image, segmenter=segmenter, reader=reader)
        except InputError:
            rows.append(row | {"refused": True, "true_m_per_px": None, "estimate": None})
            continue
        printed = printed_scale(parsed)
        openings = door_openings_px(parsed)
        is_reference = (
            printed is not None
            and printed.n_rooms >= MIN_PRINTED_ROOMS
            and printed.spread <= MAX_SPREAD
        )
        rows.append(
            row
            | {
                "printed_m_per_px": printed.metres_per_px if printed else None,
                "printed_rooms": printed.n_rooms if printed else 0,
                "printed_spread": printed.spread if printed else None,
                "true_m_per_px": printed.metres_per_px if is_reference else None,
                "estimate": door_width_m / float(np.median(openings)) if openings else None,
                "n_doors": len(openings),
            }
        )
    return rows
