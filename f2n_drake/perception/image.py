"""A drawing as perception takes it: read and checked (``load_image``, ``check_drawing``), and
labelled per pixel by any ``LabelPredictor`` (``predict_labels``).
"""

from __future__ import annotations

import contextlib
import os
import sys
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import Protocol

import cv2
import numpy as np

from f2n_drake.core.errors import InputError
from f2n_drake.core.limits import check_parse_memory
from f2n_drake.perception.ink import as_grey

MAX_PIXELS = 100_000_000
"""Largest drawing accepted [px], checked from the file header before decoding."""
MIN_SIDE_PX = 16


Prediction = tuple[np.ndarray, np.ndarray | None]
"""(H, W) uint8 labels and (C, H, W) class probabilities (None from a label-only segmenter)."""


class LabelPredictor(Protocol):
    """Per-pixel class ids for a drawing. A predictor that also has
    ``predict_with_probabilities(image) -> (labels, (C, H, W) probabilities)`` (the shipped
    ``Segmenter``) is called through that, so instances get soft scores."""

    def predict(self, image: np.ndarray) -> np.ndarray: ...


def _header_size(path: Path) -> tuple[int, int] | None:
    """(width, height) from the image header without decoding the pixels; None if Pillow cannot
    tell. Raises InputError when Pillow flags the file as a decompression bomb."""
    try:
        from PIL import Image
    except ImportError:  # pragma: no cover - Pillow comes with matplotlib
        return None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)
            with Image.open(path) as im:
                return im.size
    except Image.DecompressionBombError as exc:
        message = f"{path} is too large to decode safely ({exc}); downscale it first"
        raise InputError(message) from exc
    except Exception:  # noqa: BLE001 - any other failure: let OpenCV decide
        return None


def plain_grey(path: str | os.PathLike, shape: tuple[int, int]) -> np.ndarray | None:
    """The image file at ``path`` (read by :func:`load_image` as ``shape``) as plain luminance,
    colours kept as their grey (``load_image`` makes strongly coloured marks paper); None when it
    decodes to another size."""
    with _quiet_stderr():
        grey = cv2.imdecode(np.fromfile(path, dtype=np.uint8), cv2.IMREAD_GRAYSCALE)
    return grey if grey is not None and grey.shape == tuple(shape) else None


def load_image(path: str | os.PathLike, *, max_pixels: int = MAX_PIXELS) -> np.ndarray:
    """Read a drawing as (H, W) uint8 grey (alpha composited on white, 16-bit scaled down).

    Raises:
        InputError: missing or unreadable file, empty file, not an image, more than
            ``max_pixels`` pixels (checked before decoding), a side under 16 px, or a uniform
            image with no lines (all white, all black).
    """
    path = Path(path)
    if not path.exists():
        raise InputError(f"image not found: {path}")
    if not path.is_file():
        raise InputError(f"{path} is not a file")
    try:
        size = path.stat().st_size
    except OSError as exc:
        raise InputError(f"cannot read {path}: {exc.strerror}") from exc
    if size == 0:
        raise InputError(f"{path} is empty")
    header = _header_size(path)
    if header is not None and header[0] * header[1] > max_pixels:
        raise InputError(
            f"{path} is {header[0]}x{header[1]} px, larger than the "
            f"{max_pixels / 1e6:.0f} megapixel limit; downscale it first"
        )
    if header is not None:
        check_parse_memory((header[1], header[0]), name=str(path))
    try:
        data = np.fromfile(path, dtype=np.uint8)
    except OSError as exc:
        raise InputError(f"cannot read {path}: {exc.strerror}") from exc
    with _quiet_stderr():  # libpng prints warnings of a damaged file itself
        image = cv2.imdecode(data, cv2.IMREAD_UNCHANGED)
    if image is None or image.size == 0:
        raise InputError(f"{path} is not an image OpenCV can read (PNG, JPEG, TIFF, BMP, ...)")
    if image.shape[0] * image.shape[1] > max_pixels:
        raise InputError(
            f"{path} is {image.shape[1]}x{image.shape[0]} px, larger than the "
            f"{max_pixels / 1e6:.0f} megapixel limit; downscale it first"
        )
    if image.dtype == np.uint16:
        image = (image >> 8).astype(np.uint8)
    elif image.dtype != np.uint8:
        raise InputError(f"{path} has unsupported pixel type {image.dtype}")
    grey = as_grey(image)
    check_drawing(grey, name=str(path))
    return grey


@contextlib.contextmanager
def _quiet_stderr() -> Iterator[None]:
    """Send file descriptor 2 to /dev/null in the block (C libraries' own warnings)."""
    try:
        sys.stderr.flush()
        saved = os.dup(2)
    except (OSError, ValueError):
        yield
        return
    try:
        with open(os.devnull, "wb") as null:
            os.dup2(null.fileno(), 2)
            yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)


def check_drawing(grey: np.ndarray, *, name: str = "image") -> None:
    """Raise InputError if ``grey`` is too small or has no lines (uniform)."""
    if grey.ndim != 2 or min(grey.shape) < MIN_SIDE_PX:
        raise InputError(
            f"{name} is too small ({grey.shape[1] if grey.ndim > 1 else 0}x"
            f"{grey.shape[0]} px, need at least {MIN_SIDE_PX} px a side)"
        )
    lo, hi = int(grey.min()), int(grey.max())
    if hi - lo < 40:
        tone = "white" if lo > 200 else "black" if hi < 56 else "uniform grey"
        raise InputError(f"{name} is blank ({tone}, grey levels {lo}..{hi}): no lines to read")


def predict_labels(segmenter: LabelPredictor, image: np.ndarray) -> Prediction:
    """(H, W) labels and, if the segmenter gives them, (C, H, W) probabilities of a drawing.

    Raises:
        InputError: the segmenter returned labels of another shape than the drawing.
    """
    probabilities = None
    if hasattr(segmenter, "predict_with_probabilities"):
        labels, probabilities = segmenter.predict_with_probabilities(image)
    else:
        labels = segmenter.predict(image)
    labels = np.asarray(labels)
    if labels.shape != image.shape[:2]:
        raise InputError(
            f"segmenter returned labels of shape {labels.shape} for a {image.shape[:2]} drawing"
        )
    return labels, probabilities


def has_enclosed_region(lines: np.ndarray, min_area_px: int = 12) -> bool:
    """True when some non-line region of at least ``min_area_px`` misses the image border."""
    n, _, stats, _ = cv2.connectedComponentsWithStats((~lines).astype(np.uint8), connectivity=4)
    h, w = lines.shape
    x, y, ww, hh, area = (stats[1:, i] for i in range(5))
    inner = (x > 0) & (y > 0) & (x + ww < w) & (y + hh < h) & (area >= min_area_px)
    return bool(inner.any())
