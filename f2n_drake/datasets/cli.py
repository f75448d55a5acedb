"""Data CLI: write synthetic or ResPlan drawings with label masks, benchmark, make the figure.

    python -m f2n_drake.data generate --n 1000 --out data/train --seed 0 [--building] [--styles]
    python -m f2n_drake.data render-resplan plans.pkl --out data/real [--metres-per-unit X]
    python -m f2n_drake.data benchmark [--n 200] [--size 512] [--json]
    python -m f2n_drake.data figure --out docs/figures/data_comparison.png

Each sample ``i`` is ``{i:05d}_image.png`` (grey drawing), ``{i:05d}_label.png`` (class ids) and
``{i:05d}_plan.json`` (``FloorPlan`` in metres with ``metadata["render"]`` = the pixel grid), plus
one ``index.json``. ResPlan files are pickles, which can execute code: load trusted files only.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import sys
import time
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import cv2
import numpy as np
from tqdm import tqdm

from f2n_drake.core.classes import CLASS_NAMES, NUM_CLASSES, PALETTE
from f2n_drake.core.errors import InputError, finite_float, non_negative_int, run_cli
from f2n_drake.core.output_dir import atomic_output_dir
from f2n_drake.core.paths import resplan_sample_path
from f2n_drake.core.plan import FloorPlan
from f2n_drake.datasets.render import DrawingStyle, RenderedPlan, colorize, render
from f2n_drake.datasets.resplan import load_resplan

BUILDING_METRES_PER_PX = 0.03
MAX_BUILDING_PX = 4096
MAX_SIZE_PX = 8192
"""Largest ``--size`` [px]: a drawing this size takes about 0.7 GiB to draw (docs/robustness.md);
the segmenter reads drawings at 512 px."""


def _generator() -> Callable[..., FloorPlan]:
    try:
        from f2n_drake.datasets.generator import generate_plan
    except ImportError as exc:
        raise InputError(f"the synthetic plan generator is not available ({exc})") from exc
    return generate_plan


def render_sample(
    plan: FloorPlan,
    size_px: int,
    *,
    style: DrawingStyle | None = None,
    rng: np.random.Generator | None = None,
    building: bool = False,
) -> RenderedPlan:
    """Render a plan for the data set: square ``size_px`` images, or for buildings a fixed
    ``BUILDING_METRES_PER_PX`` scale (coarser if needed to stay within ``MAX_BUILDING_PX``)."""
    if not building:
        return render(plan, size_px, style=style, rng=rng)
    xmin, ymin, xmax, ymax = plan.bounds
    margin = 16
    extent_m = max(xmax - xmin, ymax - ymin) * 1.11  # room for a few degrees of rotation
    metres_per_px = max(BUILDING_METRES_PER_PX, extent_m / (MAX_BUILDING_PX - 2 * margin - 2))
    return render(plan, style=style, rng=rng, margin_px=margin, metres_per_px=metres_per_px)


def write_samples(
    items: Iterable[tuple[FloorPlan, RenderedPlan, dict[str, Any]]],
    out: Path,
    summary: dict[str, Any],
) -> dict[str, Any]:
    """Write rendered plans as PNG/JSON triples and ``index.json`` into ``out`` atomically."""
    entries = []
    class_px = np.zeros(NUM_CLASSES, np.int64)
    with atomic_output_dir(out) as tmp:
        for i, (plan, rendered, extra) in enumerate(items):
            stem = f"{i:05d}"
            _imwrite(tmp / f"{stem}_image.png", rendered.image)
            _imwrite(tmp / f"{stem}_label.png", rendered.labels)
            meta = dict(
                plan.metadata,
                render=rendered.grid.to_dict(),
                style=dataclasses.asdict(rendered.style),
            )
            dataclasses.replace(plan, metadata=meta).save(tmp / f"{stem}_plan.json")
            class_px += np.bincount(rendered.labels.ravel(), minlength=NUM_CLASSES)
            entries.append(
                {
                    "index": i,
                    "image": f"{stem}_image.png",
                    "label": f"{stem}_label.png",
                    "plan": f"{stem}_plan.json",
                    "shape": list(rendered.image.shape),
                    "metres_per_px": rendered.grid.metres_per_px,
                    "counts": plan.counts(),
                    **extra,
                }
            )
        summary = dict(
            summary,
            n=len(entries),
            classes=list(CLASS_NAMES),
            class_pixel_counts=class_px.tolist(),
            items=entries,
        )
        (tmp / "index.json").write_text(json.dumps(summary, indent=1))
    return summary


def _imwrite(path: Path, image: np.ndarray) -> None:
    if not cv2.imwrite(str(path), image):
        raise InputError(f"cannot write {path}")


def cmd_generate(args: argparse.Namespace) -> int:
    generate_plan = _generator()
    _check_positive(n=args.n, size=args.size)

    def items():
        for i in tqdm(range(args.n), desc="generate", unit="plan", disable=None):
            seed = args.seed + i
            plan = generate_plan(seed, building=args.building)
            rng = np.random.default_rng([seed, 1])
            style = DrawingStyle.random(rng) if args.styles else None
            rendered = render_sample(plan, args.size, style=style, rng=rng, building=args.building)
            yield plan, rendered, {"seed": seed}

    start = time.perf_counter()
    summary = write_samples(
        items(),
        Path(args.out),
        {
            "source": "synthetic",
            "seed": args.seed,
            "size_px": args.size,
            "building": args.building,
            "styles": args.styles,
        },
    )
    rate = summary["n"] / (time.perf_counter() - start)
    print(f"wrote {summary['n']} plans to {args.out} ({rate:.1f} plans/s)")
    return 0


def cmd_render_resplan(args: argparse.Namespace) -> int:
    _check_positive(size=args.size)
    plans = load_resplan(args.file, metres_per_unit=args.metres_per_unit)
    items = (
        (p, render(p, args.size), {"resplan_id": p.metadata.get("id")})
        for p in tqdm(plans, desc="render", unit="plan", disable=None)
    )
    summary = write_samples(
        items, Path(args.out), {"source": "resplan", "file": str(args.file), "size_px": args.size}
    )
    print(f"wrote {summary['n']} ResPlan plans to {args.out}")
    return 0


def cmd_benchmark(args: argparse.Namespace) -> int:
    _check_positive(n=args.n, size=args.size)
    generate_plan = _generator()
    cv2.setNumThreads(1)  # one core: OpenCV would otherwise blur/encode on several threads
    generate_plan(0)  # warm up (imports, numba)
    gen_s = render_s = 0.0
    for seed in tqdm(range(args.n), desc="benchmark", unit="plan", disable=None):
        t0 = time.perf_counter()
        plan = generate_plan(seed)
        t1 = time.perf_counter()
        rng = np.random.default_rng(seed)
        render(plan, args.size, style=DrawingStyle.random(rng) if args.styles else None, rng=rng)
        gen_s, render_s = gen_s + t1 - t0, render_s + time.perf_counter() - t1
    result = {
        "n": args.n,
        "size_px": args.size,
        "styles": args.styles,
        "plans_per_s": args.n / (gen_s + render_s),
        "generate_ms": 1000 * gen_s / args.n,
        "render_ms": 1000 * render_s / args.n,
    }
    if args.json:
        print(json.dumps(result))
    else:
        print(
            f"{result['plans_per_s']:.1f} plans/s at {args.size} px on one core "
            f"(generate {result['generate_ms']:.1f} ms + render {result['render_ms']:.1f} ms "
            f"per plan, n={args.n}, styles={'random' if args.styles else 'clean'})"
        )
    return 0


def cmd_figure(args: argparse.Namespace) -> int:
    out = Path(args.out)
    if out.is_dir():
        raise InputError(f"--out {out} is a directory; give a .png path")
    real = load_resplan(args.resplan)
    real_plan = next((p for p in real if p.metadata.get("id") == 13), real[0])
    rows = [
        (f"synthetic (generator seed {args.seed})", _generator()(args.seed)),
        (f"ResPlan plan {real_plan.metadata.get('id')} (real)", real_plan),
    ]
    rendered = [(title, render(plan, args.size)) for title, plan in rows]
    tmp = out.with_name(f".{out.stem}.{os.getpid()}.tmp.png")
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        _draw_figure(rendered, tmp)
        os.replace(tmp, out)
    except OSError as exc:
        raise InputError(f"cannot write {out}: {exc.strerror or exc}") from exc
    finally:
        tmp.unlink(missing_ok=True)
    print(f"wrote {out}")
    return 0


def _draw_figure(rendered: list[tuple[str, RenderedPlan]], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Patch

    fig, axes = plt.subplots(
        len(rendered), 2, figsize=(10, 5.2 * len(rendered)), constrained_layout=True
    )
    for row, (title, r) in zip(np.atleast_2d(axes), rendered, strict=True):
        row[0].imshow(r.image, cmap="gray", vmin=0, vmax=255, interpolation="antialiased")
        row[0].set_title(f"{title}: drawing (input)", fontsize=10)
        row[1].imshow(colorize(r.labels), interpolation="nearest")
        row[1].set_title(f"label mask ({r.grid.metres_per_px * 100:.1f} cm/px)", fontsize=10)
        for ax in row:
            ax.set_xticks([])
            ax.set_yticks([])
    handles = [
        Patch(facecolor=np.array(c) / 255, edgecolor="0.5", label=n)
        for n, c in zip(CLASS_NAMES, PALETTE, strict=True)
    ]
    fig.legend(handles=handles, loc="outside lower center", ncol=5, fontsize=9, frameon=False)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _check_positive(**values: int) -> None:
    for name, value in values.items():
        if value is None or value < 1:
            raise InputError(f"--{name} must be a positive integer, got {value}")
    if values.get("size", 64) < 64:
        raise InputError(f"--size must be at least 64 px, got {values['size']}")
    if values.get("size", 64) > MAX_SIZE_PX:
        raise InputError(
            f"--size {values['size']} px is above the {MAX_SIZE_PX} px limit (memory grows with "
            f"its square: {values['size']} px would need about "
            f"{values['size'] ** 2 * 10 / 2**30:.0f} GiB); the segmenter reads 512 px drawings"
        )


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m f2n_drake.data",
        description=__doc__.split("\n\n")[0],
        epilog="ResPlan .pkl files are pickles, which can execute code: load trusted files only.",
    )
    sub = parser.add_subparsers(dest="command", required=True)
    gen = sub.add_parser("generate", help="write N synthetic drawings with labels")
    gen.add_argument("--n", type=int, required=True, help="number of plans")
    gen.add_argument("--out", required=True, help="output directory")
    gen.add_argument("--size", type=int, default=512, help="image side [px] (default 512)")
    gen.add_argument("--seed", type=non_negative_int, default=0, help="plan i uses seed SEED + i")
    gen.add_argument(
        "--building",
        action="store_true",
        help=f"multi-unit buildings at {BUILDING_METRES_PER_PX} m/px (up to {MAX_BUILDING_PX} px)",
    )
    gen.add_argument("--styles", action="store_true", help="random drawing styles (augmentation)")
    res = sub.add_parser("render-resplan", help="render real ResPlan plans (trusted .pkl only)")
    res.add_argument("file", help="ResPlan pickle (a list of plan dicts); trusted files only")
    res.add_argument("--out", required=True, help="output directory")
    res.add_argument("--size", type=int, default=512, help="image side [px] (default 512)")
    res.add_argument(
        "--metres-per-unit",
        type=finite_float(0.0, 1e3, low_open=True),
        default=None,
        help="scale [m/unit]; default sqrt(area / inner.area) from the file",
    )
    bench = sub.add_parser("benchmark", help="plans/s of generate + render on one core")
    bench.add_argument("--n", type=int, default=200)
    bench.add_argument("--size", type=int, default=512)
    bench.add_argument("--styles", action="store_true", help="random styles instead of clean")
    bench.add_argument("--json", action="store_true", help="machine-readable output")
    fig = sub.add_parser("figure", help="synthetic vs real drawing/label figure")
    fig.add_argument("--out", default="docs/figures/data_comparison.png")
    fig.add_argument(
        "--seed", type=non_negative_int, default=0, help="generator seed of the synthetic plan"
    )
    fig.add_argument("--size", type=int, default=512)
    fig.add_argument(
        "--resplan",
        default=str(resplan_sample_path()),
        help="ResPlan pickle for the real row (trusted files only)",
    )
    return parser


COMMANDS = {
    "generate": cmd_generate,
    "render-resplan": cmd_render_resplan,
    "benchmark": cmd_benchmark,
    "figure": cmd_figure,
}


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    return COMMANDS[args.command](args)


if __name__ == "__main__":
    sys.exit(run_cli(main))
