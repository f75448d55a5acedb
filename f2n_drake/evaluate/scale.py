"""``python -m f2n_drake.evaluate scale``: how far off is the scale estimated from door widths?

Each plan (synthetic seeds S..S+N-1, or every plan of a ResPlan pickle, ``--draws`` times) is
drawn as ``evaluate segmentation`` draws it, parsed by the segmenter with no scale given, and its
scale estimated as ``python -m f2n_drake.run`` estimates it (``f2n_drake.perception.scale``: the
median door opening taken as ``--door-width`` metres). The estimate is compared with the drawing's
true metres per pixel; ``error`` is estimate / truth - 1 (positive: the flat comes out too
large). Two things make it err: the plan's doors are not as wide as assumed (``door_m``, the
median door and front door of the plan itself, tells how far), and the parse measures them
wrong (``measured_door_m``, the median opening the parse found, at the true scale; the summary's
``measure_error`` compares it with ``door_m``). ``clear_width_only`` repeats the figures for
doors measured between their jamb lines, without the outline's thickness, to show what that
correction is worth.

``--r3d DIR [--split dev|train|all]`` measures it on real drawings instead, against the scale
their printed room sizes give (``f2n_drake.evaluate.r3d_scale``).
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable, Iterable

import numpy as np
import shapely
from tqdm import tqdm

from f2n_drake import parse_drawing
from f2n_drake.core.errors import InputError
from f2n_drake.core.plan import FloorPlan
from f2n_drake.datasets.render import RenderedPlan
from f2n_drake.evaluate.drawings import add_drawing_arguments, chosen_plans, drawing
from f2n_drake.evaluate.r3d_scale import MAX_SPREAD, MIN_PRINTED_ROOMS, r3d_scale_rows
from f2n_drake.perception.image import LabelPredictor
from f2n_drake.perception.scale import DOOR_CLASSES, door_openings_px, door_widths_px

WITHIN = 0.1
"""``within_10_percent``: the share of drawings whose estimate is off by at most this."""
FAR_OFF = 0.4
"""``off_40_percent``: the share of drawings whose estimate is off by more than this."""
_TOUCH_M = 0.05  # a door touches a space this close to it [m]


def plan_door_width_m(plan: FloorPlan) -> float | None:
    """Median opening of the plan's passage doors [m]: front doors, and doors touching two
    spaces (a storeroom's door, which the parse leaves out of its yardstick as
    ``perception.scale.storage_door_ids`` does, is left out here too; every door when none is a
    passage door). Each door's opening is the long side of its minimum rotated rectangle; None
    if the plan has no door."""
    spaces = [polygon for _, polygon in plan.spaces()]
    widths, passages = [], []
    for name in DOOR_CLASSES:
        for polygon in plan[name]:
            corners = np.asarray(shapely.minimum_rotated_rectangle(polygon).exterior.coords)
            width = float(np.linalg.norm(np.diff(corners[:3], axis=0), axis=1).max())
            widths.append(width)
            touched = sum(space.distance(polygon) <= _TOUCH_M for space in spaces)
            if name == "front_door" or touched >= 2:
                passages.append(width)
    widths = passages or widths
    return float(np.median(widths)) if widths else None


def scale_estimates(
    plans: Iterable[tuple[str, FloorPlan]],
    segmenter_for: Callable[[RenderedPlan], LabelPredictor],
    *,
    door_width_m: float = 0.9,
    size_px: int = 512,
    styles: str = "clean",
    look: str = "drawn",
    seed: int = 0,
    progress: bool = True,
    total: int | None = None,
) -> list[dict]:
    """One row per drawing: its name, true and estimated metres per pixel (``estimate`` with
    the outline's thickness, ``clear_width_estimate`` without; None when no door was found), and
    the plan's median door ``door_m``. ``segmenter_for`` gives the segmenter of a drawing (the
    network, whatever the drawing; a test's oracle reads its ground truth)."""
    rows = []
    for k, (name, plan) in enumerate(
        tqdm(plans, total=total, disable=not progress, file=sys.stderr, desc="scale", unit="plan")
    ):
        rendered = drawing(plan, k, seed=seed, size_px=size_px, styles=styles, look=look)
        parsed = parse_drawing(rendered.image, segmenter=segmenter_for(rendered))
        openings, clear = door_openings_px(parsed), door_widths_px(parsed)
        true_m_per_px = rendered.grid.metres_per_px
        rows.append(
            {
                "name": name,
                "true_m_per_px": true_m_per_px,
                "estimate": door_width_m / float(np.median(openings)) if openings else None,
                "clear_width_estimate": door_width_m / float(np.median(clear)) if clear else None,
                "n_doors": len(openings),
                "door_m": plan_door_width_m(plan),
                "measured_door_m": true_m_per_px * float(np.median(openings)) if openings else None,
            }
        )
    return rows


def error_summary(rows: list[dict], key: str) -> dict:
    """Estimate errors (estimate / truth - 1) of ``rows[i][key]`` over the drawings that have
    both: median, mean and 90th percentile of the absolute error, shares within ``WITHIN`` and
    off by more than ``FAR_OFF``."""
    errors = np.array(
        [
            row[key] / row["true_m_per_px"] - 1
            for row in rows
            if row[key] is not None and row["true_m_per_px"] is not None
        ],
        float,
    )
    if errors.size == 0:
        return {"n_estimated": 0} | dict.fromkeys(
            (
                "median_error",
                "mean_abs_error",
                "p90_abs_error",
                "within_10_percent",
                "off_40_percent",
            )
        )
    return {
        "n_estimated": int(errors.size),
        "median_error": float(np.median(errors)),
        "mean_abs_error": float(np.abs(errors).mean()),
        "p90_abs_error": float(np.percentile(np.abs(errors), 90)),
        "within_10_percent": float((np.abs(errors) <= WITHIN).mean()),
        "off_40_percent": float((np.abs(errors) > FAR_OFF).mean()),
    }


def report_of(rows: list[dict], door_width_m: float) -> dict:
    doors = [row["door_m"] for row in rows if row["door_m"] is not None]
    measure_errors = [
        row["measured_door_m"] / row["door_m"] - 1
        for row in rows
        if row["measured_door_m"] is not None and row["door_m"] is not None
    ]
    return {
        "n_images": len(rows),
        "door_width_m": door_width_m,
        "plan_door_m_median": float(np.median(doors)) if doors else None,
        "measure_error_median": float(np.median(measure_errors)) if measure_errors else None,
        "measure_abs_error_mean": (
            float(np.abs(measure_errors).mean()) if measure_errors else None
        ),
        **error_summary(rows, "estimate"),
        "clear_width_only": error_summary(rows, "clear_width_estimate"),
        "per_drawing": rows,
    }


def _pct(value: float | None, signed: bool = False) -> str:
    if value is None:
        return "-"
    return f"{100 * value:+.1f} %" if signed else f"{100 * value:.1f} %"


def format_report(report: dict) -> str:
    lines = [
        f"{report['n_images']} drawings, {report['n_estimated']} with a door to measure; "
        f"doors assumed {report['door_width_m']:g} m, the plans' own median "
        f"{report['plan_door_m_median'] or 0:.2f} m; the parse measures them "
        f"{_pct(report['measure_error_median'], True)} (median), "
        f"{_pct(report['measure_abs_error_mean'])} off (mean)"
    ]
    for label, figures in (
        ("opening (shipped)", report),
        ("clear width only", report["clear_width_only"]),
    ):
        lines.append(
            f"  {label:18s} error median {_pct(figures['median_error'], True):>8s}, "
            f"|error| mean {_pct(figures['mean_abs_error']):>7s}, "
            f"90th pct {_pct(figures['p90_abs_error']):>7s}, "
            f"within 10 %: {_pct(figures['within_10_percent'])}, "
            f"off > 40 %: {_pct(figures['off_40_percent'])}"
        )
    return "\n".join(lines)


def r3d_report_of(rows: list[dict], door_width_m: float, split: str) -> dict:
    return {
        "split": split,
        "n_images": len(rows),
        "refused": sum(row["refused"] for row in rows),
        "n_printed": sum(row.get("printed_m_per_px") is not None for row in rows),
        "n_reference": sum(row["true_m_per_px"] is not None for row in rows),
        "door_width_m": door_width_m,
        **error_summary(rows, "estimate"),
        "per_drawing": rows,
    }


def format_r3d_report(report: dict) -> str:
    return (
        f"{report['n_images']} R3D drawings ({report['split']}), {report['refused']} refused; "
        f"{report['n_printed']} read a printed scale, {report['n_reference']} from >= "
        f"{MIN_PRINTED_ROOMS} room sizes within {100 * MAX_SPREAD:.0f} % of each other (the "
        f"reference)\n"
        f"  door-width estimate ({report['door_width_m']:g} m doors) on {report['n_estimated']} "
        f"of them: error median {_pct(report['median_error'], True)}, "
        f"|error| mean {_pct(report['mean_abs_error'])}, "
        f"90th pct {_pct(report['p90_abs_error'])}, "
        f"within 10 %: {_pct(report['within_10_percent'])}, "
        f"off > 40 %: {_pct(report['off_40_percent'])}"
    )


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m f2n_drake.evaluate scale", description=__doc__.splitlines()[0]
    )
    add_drawing_arguments(parser, real_drawings=True)
    parser.add_argument(
        "--door-width",
        type=float,
        default=0.9,
        metavar="M",
        help="opening a median door is assumed to have [m] (as run's estimate) [0.9]",
    )
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    return parser


def main(
    argv: list[str] | None = None,
    *,
    segmenter_for: Callable[[RenderedPlan], LabelPredictor] | None = None,
) -> int:
    args = build_parser().parse_args(argv)
    if not (np.isfinite(args.door_width) and args.door_width > 0):
        raise InputError(f"--door-width must be a positive number of metres, got {args.door_width}")
    if args.r3d:
        return _main_r3d(args)
    plans, total = chosen_plans(args)
    if segmenter_for is None:
        from f2n_drake.segmenter.inference import Segmenter

        segmenter = Segmenter.load()  # as run loads it by default
        segmenter_for = lambda _rendered: segmenter  # noqa: E731
    rows = scale_estimates(
        plans,
        segmenter_for,
        door_width_m=args.door_width,
        size_px=args.size,
        styles=args.styles,
        look=args.look,
        seed=args.seed,
        total=total,
    )
    report = report_of(rows, args.door_width)
    if args.json:
        print(json.dumps(report))
    else:
        print(format_report(report))
    return 0


def _main_r3d(args: argparse.Namespace) -> int:
    """``--r3d DIR``: the door-width scale of R3D's drawings against their printed sizes."""
    from f2n_drake.datasets.r3d import load_r3d_plan, split_names
    from f2n_drake.segmenter.inference import Segmenter

    names = split_names(args.r3d, args.split)[: args.plans]
    plans = (load_r3d_plan(args.r3d, name) for name in names)
    rows = r3d_scale_rows(plans, Segmenter.load(), door_width_m=args.door_width, total=len(names))
    report = r3d_report_of(rows, args.door_width, args.split)
    print(json.dumps(report) if args.json else format_r3d_report(report))
    return 0
