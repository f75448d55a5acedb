"""Segmenter checkpoints: save with a sha256 record, load with verification.

A checkpoint is a ``torch.save``d dict::

    {"format": "f2n_drake.segmenter/1", "state_dict": {name: fp16/fp32 tensor},
     "config": DeepLabV3Plus constructor kwargs, "classes": CLASS_NAMES, "input_size": 512,
     "metrics": {...}, "training": {...}}

The shipped file is ``models/segmenter.pt``; its sha256 is written next to it in
``segmenter.sha256`` (``<hex>  segmenter.pt``) and quoted in ``MODEL_CARD.md``.
"""

from __future__ import annotations

import hashlib
import io
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import torch

from f2n_drake.core.classes import CLASS_NAMES
from f2n_drake.core.errors import InputError
from f2n_drake.models import model_path
from f2n_drake.segmenter.network import DeepLabV3Plus

FORMAT = "f2n_drake.segmenter/1"
DEFAULT_NAME = "segmenter.pt"


@dataclass
class Checkpoint:
    """A loaded segmenter with the metadata stored beside its weights."""

    model: DeepLabV3Plus
    config: dict[str, Any]
    classes: tuple[str, ...]
    input_size: int
    metrics: dict[str, Any] = field(default_factory=dict)
    training: dict[str, Any] = field(default_factory=dict)
    sha256: str = ""


def sha256_of(path: str | os.PathLike) -> str:
    """Hex sha256 of a file's bytes."""
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            digest.update(chunk)
    return digest.hexdigest()


def sha256_path(weights: str | os.PathLike) -> Path:
    """Where the sha256 record of ``weights`` lives: same folder, suffix ``.sha256``."""
    return Path(weights).with_suffix(".sha256")


def save_segmenter(
    model: DeepLabV3Plus,
    path: str | os.PathLike,
    *,
    input_size: int,
    metrics: dict[str, Any] | None = None,
    training: dict[str, Any] | None = None,
    half: bool = True,
) -> str:
    """Write ``model`` to ``path`` (fp16 floats if ``half``) plus its ``.sha256`` record.

    Both files are written to temporaries and renamed, so a reader never sees half a file.
    Returns the sha256 hex digest.

    Raises:
        InputError: a weight is not finite (a diverged training run ships nothing).
    """
    bad = [
        k for k, v in model.state_dict().items() if v.is_floating_point() and not v.isfinite().all()
    ]
    if bad:
        raise InputError(f"not saving {path}: weights {', '.join(bad[:3])} are not finite")
    state = {
        k: (v.detach().cpu().half() if half and v.is_floating_point() else v.detach().cpu())
        for k, v in model.state_dict().items()
    }
    blob = {
        "format": FORMAT,
        "state_dict": state,
        "config": dict(model.config),
        "classes": list(CLASS_NAMES),
        "input_size": int(input_size),
        "metrics": metrics or {},
        "training": training or {},
    }
    buffer = io.BytesIO()
    torch.save(blob, buffer)
    data = buffer.getvalue()
    digest = hashlib.sha256(data).hexdigest()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    _write_atomic(path, data)
    _write_atomic(sha256_path(path), f"{digest}  {path.name}\n".encode())
    return digest


def _write_atomic(path: Path, data: bytes) -> None:
    tmp = path.with_name(f".{path.name}.tmp{os.getpid()}")
    try:
        tmp.write_bytes(data)
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


def expected_sha256(path: str | os.PathLike) -> str:
    """The sha256 recorded for ``path`` in its ``.sha256`` file.

    Raises:
        InputError: the record is missing or malformed.
    """
    record = sha256_path(path)
    try:
        text = record.read_text().split()
    except OSError as exc:
        raise InputError(
            f"segmenter sha256 record {record} cannot be read: {exc.strerror}"
        ) from exc
    if not text or len(text[0]) != 64:
        raise InputError(f"segmenter sha256 record {record} is malformed")
    return text[0].lower()


def load_segmenter(
    path: str | os.PathLike | None = None,
    *,
    verify: bool = True,
    device: str | torch.device = "cpu",
) -> Checkpoint:
    """Load a checkpoint (default: the shipped ``models/segmenter.pt``) in eval mode, fp32.

    Args:
        path: checkpoint file; ``None`` means ``f2n_drake.models.model_path("segmenter.pt")``.
        verify: check the file's sha256 against its ``.sha256`` record first.
        device: torch device to put the model on.

    Raises:
        InputError: the file is missing, its sha256 does not match, or it cannot be loaded.
    """
    path = Path(path) if path is not None else model_path(DEFAULT_NAME)
    if not path.is_file():
        raise InputError(f"segmenter weights not found: {path}")
    digest = sha256_of(path)
    if verify and digest != expected_sha256(path):
        raise InputError(f"segmenter weights {path} fail the sha256 check (corrupt or replaced)")
    try:
        blob = torch.load(path, map_location="cpu", weights_only=True)
        if not isinstance(blob, dict) or blob.get("format") != FORMAT:
            raise ValueError("not an f2n_drake segmenter checkpoint")
        model = DeepLabV3Plus(**blob["config"])
        state = {
            k: v.float() if v.is_floating_point() else v for k, v in blob["state_dict"].items()
        }
        model.load_state_dict(state)
    except Exception as exc:  # noqa: BLE001 - any unpickling/shape error means a bad file
        message = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise InputError(f"segmenter weights {path} cannot be loaded: {message}") from exc
    model.to(device).eval()
    return Checkpoint(
        model=model,
        config=dict(blob["config"]),
        classes=tuple(blob["classes"]),
        input_size=int(blob["input_size"]),
        metrics=dict(blob.get("metrics", {})),
        training=dict(blob.get("training", {})),
        sha256=digest,
    )


def write_model_card(weights: str | os.PathLike, text_sections: dict[str, str]) -> Path:
    """Write ``MODEL_CARD.md`` beside ``weights`` quoting its sha256; returns the card path.

    ``text_sections`` maps a section title to its markdown body, in order.
    """
    weights = Path(weights)
    digest = sha256_of(weights)
    lines = [
        "# f2n_drake segmenter: DeepLabV3+ (MobileNetV2 encoder)",
        "",
        f"- File: `{weights.name}` ({weights.stat().st_size / 1e6:.2f} MB)",
        f"- sha256: `{digest}` (also in `{sha256_path(weights).name}`; checked on load)",
        "",
    ]
    for title, body in text_sections.items():
        lines += [f"## {title}", "", body.rstrip(), ""]
    card = weights.with_name("MODEL_CARD.md")
    _write_atomic(card, "\n".join(lines).encode())
    return card
