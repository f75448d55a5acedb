"""The shipped checkpoint and its model card, written by ``python -m f2n_drake.train``."""

from __future__ import annotations

import json
import time

from f2n_drake.core.classes import CLASS_NAMES, NUM_CLASSES
from f2n_drake.segmenter.network import DeepLabV3Plus, count_parameters
from f2n_drake.segmenter.weights import save_segmenter, write_model_card


def ship_checkpoint(model: DeepLabV3Plus, args, metrics: dict, training: dict, final: bool) -> None:
    """Write ``args.out`` (fp16 weights + sha256) and its MODEL_CARD.md from the run's facts."""
    save_segmenter(model, args.out, input_size=args.input_size, metrics=metrics, training=training)
    status = (
        "final" if final else (f"INTERMEDIATE (training still running at step {training['steps']})")
    )
    iou = "\n".join(f"| {k} | {v:.3f} |" for k, v in metrics.get("iou", {}).items())
    write_model_card(
        args.out,
        {
            "Status": (
                f"{status}; written by `python -m f2n_drake.train` at "
                f"{time.strftime('%Y-%m-%d %H:%M:%S')}."
            ),
            "Model": (
                f"DeepLabV3+ (Chen et al., ECCV 2018) on a MobileNetV2 encoder (width "
                f"{model.config['width']}), output stride {model.config['output_stride']}, "
                f"separable ASPP and decoder; {count_parameters(model):,} parameters, stored "
                f"fp16. Config: `{json.dumps(model.config)}`."
            ),
            "Input and output": (
                f"Grey drawing (ink = 1 - grey/255), letterboxed to "
                f"{args.input_size}x{args.input_size} px, or, for large drawings whose rooms "
                f"would come out too small (buildings), tiled at a scale that keeps rooms as "
                f"wide as in training (see `f2n_drake.segmenter.inference`). Output: "
                f"{NUM_CLASSES} classes: "
                + ", ".join(f"{i} {n}" for i, n in enumerate(CLASS_NAMES))
                + "."
            ),
            "Training data": training["data"],
            "Training": (
                f"Command: `{training['command']}`\n\n"
                f"Processes: {training['world_size']}, steps: {training['steps']}, "
                f"crops seen: {training['samples']}, batch {args.batch}x{args.crop} px per "
                f"process, optimizer {args.optimizer} lr {args.lr} -> {args.lr_min} cosine, "
                f"wall time {training['wall_minutes']:.1f} min on {training['device']}."
            ),
            "Validation": (
                f"{len(training['val_seeds'])} held-out plans "
                f"(seeds above), whole-image inference through `Segmenter.predict`: "
                f"mIoU {metrics.get('miou', float('nan')):.3f}, pixel accuracy "
                f"{metrics.get('pixel_acc', float('nan')):.3f}.\n\n"
                "| class | IoU |\n|---|---|\n" + iou
            ),
            "Notes": args.note or "none",
            "Limitations": (
                (
                    "Trained on synthetic drawings from `f2n_drake.datasets.generator` and on "
                    "R3D's real listing drawings (set-valued labels where R3D merges classes), on "
                    "CPU for a short budget; other real drawings (scans, sheets, signs) are out of "
                    "distribution."
                    if getattr(args, "r3d", None)
                    else "Trained only on synthetic drawings from `f2n_drake.datasets.generator` "
                    "on CPU for a short budget; real scans (hatching, text, furniture) are out of "
                    "distribution."
                )
                + " Room types are guessed from shape and context alone."
            ),
        },
    )
