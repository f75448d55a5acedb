"""What a training run is told and what it reads: the options of ``python -m f2n_drake.train``
and the plans they choose (generated, from a folder, toy rectangles, or mixed with R3D's training
split), with the validation plans and a description for the model card."""

from __future__ import annotations

import argparse
from pathlib import Path

from f2n_drake.core.errors import (
    ArgumentParser,
    InputError,
    finite_float,
    non_negative_int,
    probability,
)
from f2n_drake.datasets.looks import LOOKS
from f2n_drake.datasets.r3d import R3D_CLASSES
from f2n_drake.segmenter import DEFAULT_VIEWS, VIEW_COUNTS
from f2n_drake.segmenter import dataset as ds


def build_parser() -> argparse.ArgumentParser:
    p = ArgumentParser(
        prog="python -m f2n_drake.train",
        description="Train the DeepLabV3+ segmenter on generated, folder or R3D plans.",
    )
    src = p.add_mutually_exclusive_group()
    src.add_argument("--synthetic", action="store_true", help="generate plans on the fly (default)")
    src.add_argument("--data", type=Path, help="folder of NNNNN_image.png / NNNNN_label.png pairs")
    src.add_argument("--toy", action="store_true", help="random rectangles (tests, smoke runs)")
    p.add_argument("--steps", type=int, default=20000, help="optimizer steps (upper bound)")
    p.add_argument(
        "--max-minutes",
        type=finite_float(0.0, 1e6, low_open=True),
        default=None,
        help="wall-clock budget [min]",
    )
    p.add_argument("--batch", type=int, default=8, help="crops per step per process")
    p.add_argument("--crop", type=int, default=256, help="crop side [px]")
    p.add_argument("--input-size", type=int, default=512, help="inference input side [px]")
    p.add_argument("--render-min", type=int, default=384, help="smallest synthetic render [px]")
    p.add_argument("--render-max", type=int, default=1024, help="largest synthetic render [px]")
    p.add_argument(
        "--p-letterbox",
        type=probability,
        default=0.8,
        help="probability a plan is resized to --input-size before cropping",
    )
    p.add_argument(
        "--looks",
        nargs="+",
        default=[],
        choices=LOOKS,
        metavar="LOOK",
        help="looks (f2n_drake.datasets.looks) a synthetic training plan may be redrawn in",
    )
    p.add_argument(
        "--p-look", type=probability, default=0.0, help="share of training plans in one of --looks"
    )
    p.add_argument(
        "--p-varied-openings",
        type=probability,
        default=0.0,
        help="share of training plans with the generator's varied door and window widths",
    )
    p.add_argument(
        "--r3d",
        type=Path,
        default=None,
        help="R3D folder (DeepFloorplan layout): mix its training split with generated plans",
    )
    p.add_argument(
        "--p-r3d", type=probability, default=0.5, help="share of training plans taken from --r3d"
    )
    p.add_argument(
        "--r3d-emphasised",
        nargs="+",
        default=[],
        choices=R3D_CLASSES,
        metavar="CLASS",
        help="R3D classes whose pixels' loss counts --emphasis times (e.g. closet)",
    )
    p.add_argument(
        "--emphasis",
        type=finite_float(1.0, 100.0),
        default=1.0,
        help="factor on the loss of --r3d-emphasised pixels",
    )
    p.add_argument("--crops-per-plan", type=int, default=1, help="crops from each rendered plan")
    p.add_argument("--optimizer", choices=("sgd", "adamw"), default="sgd")
    p.add_argument("--lr", type=finite_float(0.0, 10.0, low_open=True), default=7e-3)
    p.add_argument("--lr-min", type=finite_float(0.0, 10.0), default=7e-5)
    p.add_argument("--weight-decay", type=finite_float(0.0, 1.0), default=4e-5)
    p.add_argument(
        "--warmup",
        type=finite_float(0.0, 1.0),
        default=0.02,
        help="warm-up fraction of the schedule",
    )
    p.add_argument(
        "--width", type=finite_float(0.0, 4.0, low_open=True), default=0.5, help="encoder width"
    )
    p.add_argument("--output-stride", type=int, choices=(8, 16), default=16)
    p.add_argument("--seed", type=non_negative_int, default=0, help="init and augmentation seed")
    p.add_argument("--val-plans", type=int, default=16, help="held-out plans for val mIoU")
    p.add_argument(
        "--val-minutes",
        type=finite_float(0.0, 1e6, low_open=True),
        default=5.0,
        help="validate every M minutes",
    )
    p.add_argument("--out", type=Path, default=Path("models/segmenter.pt"))
    p.add_argument("--name", default=None, help="run name: logs go to RUNS/NAME (default: time)")
    p.add_argument("--runs", type=Path, default=Path("runs"), help="folder of run logs")
    p.add_argument("--workers", type=int, default=1, help="DataLoader workers per process")
    p.add_argument("--threads", type=int, default=None, help="torch threads per process")
    p.add_argument("--device", choices=("cpu", "cuda"), default="cpu")
    p.add_argument("--log-every", type=int, default=20, help="log a metrics line every N steps")
    p.add_argument("--note", default="", help="markdown added to the model card's Notes")
    p.add_argument(
        "--init",
        type=Path,
        default=None,
        help="start from this checkpoint's weights (fine-tuning / continuing a run)",
    )
    p.add_argument(
        "--teacher",
        default=None,
        metavar="WEIGHTS",
        help="distil this segmenter's answers (its test-time views averaged); 'shipped': the "
        "shipped segmenter with its storage network",
    )
    p.add_argument(
        "--teacher-views",
        type=int,
        choices=VIEW_COUNTS,
        default=DEFAULT_VIEWS,
        help=f"test-time views the teacher averages [{DEFAULT_VIEWS}]",
    )
    p.add_argument(
        "--distill",
        type=finite_float(0.0, 1.0),
        default=1.0,
        help="with --teacher: the loss is (1 - D) x cross entropy + D x divergence from the "
        "teacher [1]",
    )
    p.add_argument(
        "--first-plan",
        type=int,
        default=0,
        help="index of the first training plan (continue on plans not yet seen)",
    )
    return p


def training_sources(args: argparse.Namespace):
    """(training source, validation samples, description of the data).

    Raises:
        InputError: ``--r3d-emphasised`` without ``--r3d``, or ``--emphasis`` without classes.
    """
    if args.r3d_emphasised and args.r3d is None:
        raise InputError("--r3d-emphasised needs --r3d (the R3D plans whose pixels it weighs)")
    if args.emphasis != 1.0 and not args.r3d_emphasised:
        raise InputError("--emphasis weighs the --r3d-emphasised classes: name them too")
    if args.data is not None:
        val = ds.DirectoryPlans(args.data, slice(0, args.val_plans))
        train = ds.DirectoryPlans(args.data, slice(args.val_plans, None))
        return (
            train,
            [val(i) for i in range(len(val.pairs))],
            (f"folder {args.data}: first {args.val_plans} pairs for validation, the rest training"),
        )
    looks = ""
    if args.toy:
        kind = ds.ToyPlans
        make = lambda base, **_: ds.ToyPlans(base, size_px=max(args.crop, 64))
    else:
        kind = ds.SyntheticPlans
        make = lambda base, **redrawn: ds.SyntheticPlans(
            base, (args.render_min, args.render_max), **redrawn
        )
        if args.looks:
            looks = f", {args.p_look:.0%} of training plans redrawn as {' or '.join(args.looks)}"
        if args.p_varied_openings:
            looks += f", {args.p_varied_openings:.0%} with varied door and window widths"
    val = make(ds.VAL_SEED_BASE)  # validation plans as drawn, comparable across stages
    train = make(
        ds.TRAIN_SEED_BASE,
        looks=tuple(args.looks),
        p_look=args.p_look,
        p_varied_openings=args.p_varied_openings,
    )
    if args.r3d is not None:
        from f2n_drake.datasets.r3d import split_names
        from f2n_drake.segmenter.real_plans import MixedPlans, R3DPlans

        names = split_names(args.r3d, "train")
        r3d = R3DPlans(
            args.r3d,
            names,
            seed=args.seed,
            input_px=args.input_size,
            emphasised=tuple(args.r3d_emphasised),
        )
        train = MixedPlans(train, r3d, args.p_r3d)
        looks += (
            f"; {args.p_r3d:.0%} of training plans are views of the {len(names)} R3D training "
            f"plans of {args.r3d} (random windows and margins; set-valued labels)"
        )
        if args.r3d_emphasised and args.emphasis != 1.0:
            looks += (
                f"; the loss of R3D {' and '.join(args.r3d_emphasised)} pixels counts "
                f"{args.emphasis:g} times"
            )
    return (
        train,
        [val(i) for i in range(args.val_plans)],
        (
            f"{kind.__name__} on the fly: training generator seeds {ds.TRAIN_SEED_BASE} upward "
            f"(plan index i uses seed {ds.TRAIN_SEED_BASE}+i), validation seeds "
            f"{ds.VAL_SEED_BASE}..{ds.VAL_SEED_BASE + args.val_plans - 1}; evaluation uses seeds "
            f"< 1000000, so all three are disjoint. Render sizes "
            f"{args.render_min}-{args.render_max} px, DrawingStyle.random, "
            f"{args.p_letterbox:.0%} letterboxed to {args.input_size} px, {args.crop} px crops "
            f"with flips and 90-degree turns{looks}"
        ),
    )
