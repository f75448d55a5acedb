"""``python -m f2n_drake.segmenter.soup FIRST.pt SECOND.pt --out OUT.pt [--share S]``: a model soup.

Averages the weights of two checkpoints of the same network (Wortsman et al., "Model soups",
ICML 2022): ``(1 - S) * FIRST + S * SECOND`` for every floating-point tensor, the batch-norm
statistics included. Two fine-tunings of one parent stay in one basin of the loss, so their
average often keeps what each learned. The shipped stage 19 is the even soup of stage 13 and a
fine-tuning of it on real R3D drawings mixed with generated ones (``models/MODEL_CARD.md``).
The output records both parents (path, sha256, share, training facts) under ``training``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from f2n_drake.core.errors import InputError, run_cli
from f2n_drake.segmenter.weights import Checkpoint, load_segmenter, save_segmenter


def averaged(first: Checkpoint, second: Checkpoint, share: float) -> dict:
    """The state dict ``(1 - share) * first + share * second`` (integer tensors: ``second``'s).

    Raises:
        InputError: ``share`` outside 0..1, or the two are not the same network.
    """
    if not 0.0 <= share <= 1.0:
        raise InputError(f"the second checkpoint's share must be in 0..1, got {share}")
    if first.config != second.config or first.input_size != second.input_size:
        raise InputError("the two checkpoints are different networks; only the same one averages")
    a, b = first.model.state_dict(), second.model.state_dict()
    return {
        name: (1.0 - share) * a[name] + share * b[name] if b[name].is_floating_point() else b[name]
        for name in a
    }


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m f2n_drake.segmenter.soup", description=__doc__.splitlines()[0]
    )
    p.add_argument("first", type=Path, help="checkpoint weighted 1 - SHARE")
    p.add_argument("second", type=Path, help="checkpoint weighted SHARE")
    p.add_argument("--share", type=float, default=0.5, help="the second checkpoint's share [0.5]")
    p.add_argument("--out", type=Path, required=True, help="checkpoint to write (+ .sha256)")
    return p


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    first, second = load_segmenter(args.first), load_segmenter(args.second)
    state = averaged(first, second, args.share)
    first.model.load_state_dict(state)
    parents = [
        {"path": str(path), "sha256": c.sha256, "share": share, "training": c.training}
        for path, c, share in (
            (args.first, first, 1.0 - args.share),
            (args.second, second, args.share),
        )
    ]
    digest = save_segmenter(
        first.model, args.out, input_size=first.input_size, training={"soup_of": parents}
    )
    print(
        f"wrote {args.out} (sha256 {digest[:12]}...): {1 - args.share:g} x {args.first} + "
        f"{args.share:g} x {args.second}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(run_cli(main))
