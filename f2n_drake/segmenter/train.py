"""Train the DeepLabV3+ segmenter: ``python -m f2n_drake.train [--synthetic | --data DIR]``.

SGD (momentum 0.9) with a cosine learning-rate decay from ``--lr`` to ``--lr-min`` after a short
linear warm-up, as in DeepLabV3+ (which uses SGD with a poly decay); class-weighted cross entropy
(square-root median-frequency weights, so thin doors and windows count), set-valued where a
dataset merges classes (``segmenter.losses``). ``--r3d DIR`` mixes R3D's training plans (never its
development split) with the generated ones (``--p-r3d``); ``--r3d-emphasised closet --emphasis 4``
makes the loss of R3D's closet pixels count four times. Training runs until
``--steps`` or ``--max-minutes``, whichever ends first; the schedule follows whichever is further
along. Data parallel with ``torchrun --nproc_per_node=N -m f2n_drake.train ...`` (gloo on CPU,
nccl on CUDA); each rank draws its own plans (see ``segmenter.dataset``).

Writes ``--out`` (fp16 checkpoint), its ``.sha256`` record and ``MODEL_CARD.md`` beside it at
every validation and at the end, and logs config, seeds and metrics to ``runs/NAME/``.
"""

from __future__ import annotations

import argparse
import json
import logging
import math
import os
import shlex
import shutil
import sys
import time

import cv2
import numpy as np
import torch
import torch.distributed as dist
from torch.utils.data import DataLoader
from tqdm import tqdm

from f2n_drake.core.classes import CLASS_NAMES, NUM_CLASSES
from f2n_drake.core.errors import (
    InputError,
    run_cli,
)
from f2n_drake.core.output_dir import check_writable_file
from f2n_drake.segmenter import DEFAULT_VIEWS
from f2n_drake.segmenter import dataset as ds
from f2n_drake.segmenter.inference import Segmenter
from f2n_drake.segmenter.losses import distillation_loss, set_cross_entropy
from f2n_drake.segmenter.model_card import ship_checkpoint
from f2n_drake.segmenter.network import DeepLabV3Plus, count_parameters
from f2n_drake.segmenter.training_setup import build_parser, training_sources
from f2n_drake.segmenter.weights import load_segmenter

log = logging.getLogger("f2n_drake.segmenter.train")


def evaluate_segmenter(segmenter: Segmenter, samples: list[ds.Sample]) -> dict:
    """Pixel accuracy, per-class IoU and mIoU (over classes present in labels or predictions)."""
    confusion = np.zeros((NUM_CLASSES, NUM_CLASSES), np.int64)
    for image, labels in samples:
        pred = segmenter.predict(image)
        pairs = labels.ravel().astype(np.int64) * NUM_CLASSES + pred.ravel()
        confusion += np.bincount(pairs, minlength=NUM_CLASSES**2).reshape(confusion.shape)
    tp = np.diag(confusion)
    union = confusion.sum(0) + confusion.sum(1) - tp
    iou = {CLASS_NAMES[c]: float(tp[c] / union[c]) for c in range(NUM_CLASSES) if union[c]}
    return {
        "miou": float(np.mean(list(iou.values()))),
        "pixel_acc": float(tp.sum() / confusion.sum()),
        "iou": {k: round(v, 4) for k, v in iou.items()},
    }


def _learning_rate(args: argparse.Namespace, progress: float) -> float:
    if progress < args.warmup:
        return args.lr * max(progress / args.warmup, 0.01)
    t = (progress - args.warmup) / max(1e-9, 1 - args.warmup)
    return args.lr_min + 0.5 * (args.lr - args.lr_min) * (1 + math.cos(math.pi * min(t, 1.0)))


def train(args: argparse.Namespace, command: str) -> dict:
    """Run training as configured by ``args``; returns the final validation metrics."""
    world = int(os.environ.get("WORLD_SIZE", "1"))
    rank = int(os.environ.get("RANK", "0"))
    if args.device == "cuda" and not torch.cuda.is_available():
        raise InputError("--device cuda but no CUDA device is available")
    local_rank = int(os.environ.get("LOCAL_RANK", "0"))
    device = torch.device(f"cuda:{local_rank}" if args.device == "cuda" else "cpu")
    if world > 1:
        dist.init_process_group("nccl" if args.device == "cuda" else "gloo")
    if device.type == "cuda":
        torch.backends.cudnn.benchmark = True  # fixed crop size: let cuDNN pick its kernels once
    if args.threads:
        torch.set_num_threads(args.threads)
    cv2.setNumThreads(1)  # OpenCV's pool would compete with torch's threads for the CPU
    name = [args.name or time.strftime("%Y%m%d-%H%M%S")]
    if world > 1:
        dist.broadcast_object_list(name, src=0)
    run_dir = args.runs / name[0]

    torch.manual_seed(args.seed)
    if args.init is not None:
        model = load_segmenter(args.init).model.to(device).train()
    else:
        model = DeepLabV3Plus(
            num_classes=NUM_CLASSES, output_stride=args.output_stride, width=args.width
        ).to(device)
    train_source, val_samples, data_desc = training_sources(args)
    weights = ds.class_weights(val_samples, args.input_size).to(device)
    teacher = None
    if args.teacher is not None:
        shipped = args.teacher == "shipped"
        teacher = Segmenter.load(
            None if shipped else args.teacher, device=str(device), views=args.teacher_views
        )
        data_desc += (
            f"; distilled from {'the shipped segmenter' if shipped else args.teacher} "
            f"({args.teacher_views} views averaged), loss {1 - args.distill:g} x cross entropy "
            f"+ {args.distill:g} x divergence from it"
        )
    net = torch.nn.parallel.DistributedDataParallel(model) if world > 1 else model
    if args.optimizer == "sgd":
        optimizer = torch.optim.SGD(
            net.parameters(), lr=args.lr, momentum=0.9, weight_decay=args.weight_decay
        )
    else:
        optimizer = torch.optim.AdamW(net.parameters(), lr=args.lr, weight_decay=args.weight_decay)
    stream = ds.CropStream(
        train_source,
        args.crop,
        input_px=args.input_size,
        p_letterbox=args.p_letterbox,
        crops_per_plan=args.crops_per_plan,
        rank=rank,
        world_size=world,
        seed=args.seed,
        first_index=args.first_plan,
    )
    loader = DataLoader(
        stream,
        batch_size=args.batch,
        num_workers=args.workers,
        persistent_workers=args.workers > 0,
        prefetch_factor=4 if args.workers > 0 else None,
    )
    config = {
        **vars(args),
        "out": str(args.out),
        "runs": str(args.runs),
        "data": str(args.data) if args.data else None,
        "world_size": world,
        "init": str(args.init) if args.init else None,
        "r3d": str(args.r3d) if args.r3d else None,
        "model": model.config,
        "parameters": count_parameters(model),
        "class_weights": [round(w, 4) for w in weights.tolist()],
        "command": command,
        "data_description": data_desc,
        "torch_threads": torch.get_num_threads(),
    }
    new_run_dir = not run_dir.exists()  # created only now, once the data and model are ready
    run_dir.mkdir(parents=True, exist_ok=True)
    handler = None
    if rank == 0:
        handler = logging.FileHandler(run_dir / "train.log")
        handler.setFormatter(logging.Formatter("%(asctime)s %(message)s"))
        log.addHandler(handler)
        log.setLevel(logging.INFO)
        (run_dir / "config.json").write_text(json.dumps(config, indent=2))
        log.info(
            "run %s: %d parameters, class weights %s",
            run_dir,
            config["parameters"],
            config["class_weights"],
        )
    seeds_file = open(run_dir / f"seeds_rank{rank}.txt", "a")
    metrics_file = open(run_dir / "metrics.jsonl", "a") if rank == 0 else None
    max_s = args.max_minutes * 60 if args.max_minutes else math.inf
    start = last_val = time.monotonic()
    metrics: dict = {}
    step, samples, progress, last_seed, shipped = 0, 0, 0.0, None, False
    bar = tqdm(
        total=args.steps,
        disable=rank != 0,
        mininterval=5 if sys.stderr.isatty() else 60,
        desc="train",
    )

    def training_info() -> dict:
        return {
            "command": command,
            "steps": step,
            "samples": samples * world,
            "world_size": world,
            "wall_minutes": (time.monotonic() - start) / 60,
            "device": str(device),
            "data": data_desc,
            "val_seeds": list(range(ds.VAL_SEED_BASE, ds.VAL_SEED_BASE + len(val_samples))),
            "run_dir": str(run_dir),
            "seed": args.seed,
        }

    def validate(final: bool) -> None:
        nonlocal metrics, last_val, shipped
        metrics = evaluate_segmenter(
            Segmenter(model, input_size=args.input_size, device=device, views=1), val_samples
        )
        model.train()
        last_val = time.monotonic()
        info = training_info()
        log.info(
            "val step %d: mIoU %.4f acc %.4f %s",
            step,
            metrics["miou"],
            metrics["pixel_acc"],
            metrics["iou"],
        )
        metrics_file.write(json.dumps({"step": step, "val": metrics, **info}) + "\n")
        metrics_file.flush()
        ship_checkpoint(model, args, metrics, info, final)
        shipped = True

    model.train()
    running = []
    for images, labels, seeds in loader:
        if rank == 0:
            progress = max(step / args.steps, (time.monotonic() - start) / max_s)
        if world > 1:
            flag = torch.tensor([progress], dtype=torch.float64)
            dist.broadcast(flag, src=0)
            progress = float(flag)
        if progress >= 1.0:
            break
        lr = _learning_rate(args, progress)
        for group in optimizer.param_groups:
            group["lr"] = lr
        images, labels = images.to(device), labels.to(device)
        logits = net(images)
        if teacher is None:
            loss = set_cross_entropy(logits, labels, weight=weights, emphasis=args.emphasis)
        else:
            answer = teacher.logits(images).clone()  # a normal tensor: autograd may keep it
            loss = args.distill * distillation_loss(logits, answer, weights)
            if args.distill < 1.0:
                ce = set_cross_entropy(logits, labels, weight=weights, emphasis=args.emphasis)
                loss = loss + (1 - args.distill) * ce
        if not torch.isfinite(loss):
            bar.close()
            for file in (seeds_file, metrics_file):
                if file is not None:
                    file.close()
            _close_log(handler)
            if new_run_dir and not shipped:
                shutil.rmtree(run_dir, ignore_errors=True)
            kept = f"; the logs of the run are in {run_dir}" if shipped else "; nothing was written"
            raise InputError(
                f"training diverged: the loss is {loss.item()} at step {step + 1} (learning rate "
                f"{lr:.3g}); lower --lr{kept}"
            )
        optimizer.zero_grad(set_to_none=True)
        loss.backward()
        optimizer.step()
        step += 1
        samples += len(images)
        running.append(loss.item())
        batch_seeds = [int(s) for s in seeds if int(s) != last_seed]
        seeds_file.write("".join(f"{s}\n" for s in dict.fromkeys(batch_seeds)))
        last_seed = int(seeds[-1])
        bar.update(1)
        if rank == 0 and step % args.log_every == 0:
            elapsed = time.monotonic() - start
            entry = {
                "step": step,
                "loss": float(np.mean(running)),
                "lr": lr,
                "elapsed_s": round(elapsed, 1),
                "crops_per_s": round(samples * world / elapsed, 2),
            }
            running = []
            bar.set_postfix(loss=f"{entry['loss']:.3f}", lr=f"{lr:.2e}")
            log.info(
                "step %d loss %.4f lr %.2e %.2f crops/s",
                step,
                entry["loss"],
                lr,
                entry["crops_per_s"],
            )
            metrics_file.write(json.dumps(entry) + "\n")
            metrics_file.flush()
        if rank == 0 and time.monotonic() - last_val > args.val_minutes * 60:
            validate(final=False)
    bar.close()
    seeds_file.close()
    if rank == 0:
        validate(final=True)
        metrics_file.close()
    _close_log(handler)
    if world > 1:
        dist.barrier()
        dist.destroy_process_group()
    return metrics


def _close_log(handler: logging.Handler | None) -> None:
    if handler is not None:
        log.removeHandler(handler)
        handler.close()


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    if args.steps < 1 or args.batch < 1 or args.crop < 32 or args.crop % 16:
        raise InputError("--steps and --batch must be >= 1 and --crop a multiple of 16 >= 32")
    if args.input_size % 16 or args.val_plans < 1:
        raise InputError("--input-size must be a multiple of 16 and --val-plans >= 1")
    if args.p_look > 0 and not args.looks:
        raise InputError("--p-look above 0 needs --looks")
    if args.teacher is None and (args.distill != 1.0 or args.teacher_views != DEFAULT_VIEWS):
        raise InputError("--distill and --teacher-views set how the --teacher is learnt: name it")
    check_writable_file(args.out, option="--out")
    if args.runs.exists() and not args.runs.is_dir():
        raise InputError(f"--runs {args.runs} is not a folder")
    raw = sys.argv[1:] if argv is None else argv
    launcher = (
        "torchrun ... -m f2n_drake.train"
        if "WORLD_SIZE" in os.environ
        else "python -m f2n_drake.train"
    )
    command = f"{launcher} {shlex.join(raw)}"
    metrics = train(args, command)
    if int(os.environ.get("RANK", "0")) == 0:
        print(f"wrote {args.out}: val mIoU {metrics.get('miou', float('nan')):.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(run_cli(main))
