"""Training samples for the segmenter: synthetic plans on the fly, a generated folder, or toys.

Seeds: training plans use generator seeds ``TRAIN_SEED_BASE + i`` (i = 0, 1, ...), validation
plans ``VAL_SEED_BASE + k`` (k < 1000); the evaluation uses seeds below 1_000_000, so the three
sets are disjoint. Sample ``i`` is drawn by shard ``i % num_shards`` (one shard per DDP rank and
DataLoader worker), so every plan is used once however the work is split.

Each plan is rendered at a random size (``render_px``) in a random :class:`DrawingStyle`; with
probability ``p_letterbox`` it is then resized to the inference input size (what
``Segmenter`` does to a flat's drawing of any size), otherwise kept at its native scale (what
tiling sees). With probability ``p_look`` a plan is first redrawn in one of ``looks``
(``f2n_drake.datasets.looks``, e.g. hatched walls, which no preparation step removes), and with
probability ``p_varied_openings`` its doors and windows are drawn from the generator's
``VARIED_SIZES`` instead of its typical widths. Random crops with flips and 90-degree turns of
that image are the training samples; their labels are acceptable-class bit masks
(:func:`as_class_sets`), so set-valued labels (R3D's merged classes) and class ids mix in one batch.
:func:`class_weights` weighs the loss by how rare each class is in a set of samples.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterator
from pathlib import Path

import cv2
import numpy as np
import torch
from torch.utils.data import IterableDataset, get_worker_info

from f2n_drake.core.classes import CLASS_ID, NUM_CLASSES
from f2n_drake.core.errors import InputError

TRAIN_SEED_BASE = 1_001_000
VAL_SEED_BASE = 1_000_000

Sample = tuple[np.ndarray, np.ndarray]
"""(H,W) uint8 grey drawing (255 = paper) and (H,W) uint8 labels."""


class SyntheticPlans:
    """Plans from ``f2n_drake.datasets.generator.generate_plan(seed)`` drawn by
    ``f2n_drake.datasets.render``.

    Args:
        seed_base: generator seed of index 0.
        render_px: (min, max) side of the square render [px], drawn uniformly.
        looks: ``f2n_drake.datasets.looks.LOOKS`` a plan may be redrawn in, one drawn uniformly.
        p_look: probability a plan is redrawn in one of ``looks``.
        p_varied_openings: probability a plan's doors and windows take the generator's
            ``VARIED_SIZES`` (else ``TYPICAL_SIZES``).

    Raises:
        InputError: an unknown look, or a probability outside 0..1.
    """

    def __init__(
        self,
        seed_base: int = TRAIN_SEED_BASE,
        render_px: tuple[int, int] = (384, 1024),
        *,
        looks: tuple[str, ...] = (),
        p_look: float = 0.0,
        p_varied_openings: float = 0.0,
    ) -> None:
        from f2n_drake.datasets.looks import LOOKS

        unknown = [look for look in looks if look not in LOOKS]
        if unknown:
            raise InputError(f"unknown look {unknown[0]!r}; choose from {', '.join(LOOKS)}")
        if not 0.0 <= p_look <= 1.0:
            raise InputError(f"the look probability must be in 0..1, got {p_look}")
        if not 0.0 <= p_varied_openings <= 1.0:
            raise InputError(
                f"the varied-openings probability must be in 0..1, got {p_varied_openings}"
            )
        self.seed_base = seed_base
        self.render_px = render_px
        self.looks = tuple(looks)
        self.p_look = p_look
        self.p_varied_openings = p_varied_openings

    def seed(self, index: int) -> int:
        return self.seed_base + index

    def __call__(self, index: int) -> Sample:
        from f2n_drake.datasets.generator import OPENING_SIZES, generate_plan
        from f2n_drake.datasets.render import DrawingStyle, render

        seed = self.seed(index)
        rng = np.random.default_rng(seed)
        varied = self.p_varied_openings > 0 and rng.random() < self.p_varied_openings
        plan = generate_plan(seed, sizes=OPENING_SIZES["varied" if varied else "typical"])
        size = int(rng.integers(self.render_px[0], self.render_px[1] + 1))
        rendered = render(plan, size, style=DrawingStyle.random(rng), rng=rng)
        if self.looks and rng.random() < self.p_look:
            from f2n_drake.datasets.looks import restyle
            from f2n_drake.perception.ink import as_grey

            rendered = restyle(rendered, self.looks[int(rng.integers(len(self.looks)))], rng)
            return as_grey(rendered.image), rendered.labels
        return rendered.image, rendered.labels


class DirectoryPlans:
    """Pairs ``DIR/{i:05d}_image.png`` / ``DIR/{i:05d}_label.png`` (``python -m f2n_drake.data``).

    Args:
        root: the folder.
        indices: which of the sorted pairs to use (default all); index ``i`` wraps around.

    Raises:
        InputError: the folder holds no pairs.
    """

    def __init__(self, root: str | Path, indices: slice | None = None) -> None:
        images = sorted(Path(root).glob("*_image.png"))
        pairs = [(p, p.with_name(p.name.replace("_image.png", "_label.png"))) for p in images]
        self.pairs = [pair for pair in pairs if pair[1].is_file()][indices or slice(None)]
        if not self.pairs:
            raise InputError(f"no *_image.png / *_label.png pairs in {root}")

    def seed(self, index: int) -> int:
        return index % len(self.pairs)

    def __call__(self, index: int) -> Sample:
        image_path, label_path = self.pairs[index % len(self.pairs)]
        image = cv2.imread(str(image_path), cv2.IMREAD_GRAYSCALE)
        labels = cv2.imread(str(label_path), cv2.IMREAD_UNCHANGED)
        if image is None or labels is None or labels.ndim != 2:
            raise InputError(f"cannot read training pair {image_path.name}")
        return image, labels


class ToyPlans:
    """Random outlined rectangles with room, wall and door labels, for tests without a generator."""

    def __init__(self, seed_base: int = TRAIN_SEED_BASE, size_px: int = 128) -> None:
        self.seed_base = seed_base
        self.size_px = size_px

    def seed(self, index: int) -> int:
        return self.seed_base + index

    def __call__(self, index: int) -> Sample:
        rng = np.random.default_rng(self.seed(index))
        n = self.size_px
        image = np.full((n, n), 255, np.uint8)
        labels = np.zeros((n, n), np.uint8)
        for _ in range(int(rng.integers(1, 4))):
            x0, y0 = rng.integers(4, n // 2, size=2)
            x1, y1 = rng.integers(n // 2 + 8, n - 4, size=2)
            labels[y0:y1, x0:x1] = CLASS_ID["wall"]
            labels[y0 + 3 : y1 - 3, x0 + 3 : x1 - 3] = rng.integers(1, 5)
            labels[y0 : y0 + 3, (x0 + x1) // 2 : (x0 + x1) // 2 + 6] = CLASS_ID["door"]
            cv2.rectangle(image, (int(x0), int(y0)), (int(x1) - 1, int(y1) - 1), 0, 1)
            cv2.rectangle(image, (int(x0) + 3, int(y0) + 3), (int(x1) - 4, int(y1) - 4), 0, 1)
        return image, labels


def letterbox(image: np.ndarray, labels: np.ndarray, size_px: int) -> Sample:
    """Pad to a centred square (white, background) and resize to ``size_px`` like inference."""
    h, w = image.shape
    side = max(h, w)
    top, left = (side - h) // 2, (side - w) // 2
    square = np.full((side, side), 255, np.uint8)
    square_labels = np.zeros((side, side), labels.dtype)
    square[top : top + h, left : left + w] = image
    square_labels[top : top + h, left : left + w] = labels
    interp = cv2.INTER_AREA if side > size_px else cv2.INTER_LINEAR
    return (
        cv2.resize(square, (size_px, size_px), interpolation=interp),
        cv2.resize(square_labels, (size_px, size_px), interpolation=cv2.INTER_NEAREST),
    )


def class_weights(samples: list[Sample], input_px: int) -> torch.Tensor:
    """sqrt(median frequency / frequency) per class, clipped to [0.25, 10]; 1 for absent ones."""
    counts = np.zeros(NUM_CLASSES)
    for image, labels in samples:
        boxed = letterbox(image, labels, input_px)[1]
        counts += np.bincount(boxed.ravel(), minlength=NUM_CLASSES)
    freq = counts / counts.sum()
    present = freq > 0
    weights = np.ones(NUM_CLASSES)
    weights[present] = np.clip(np.sqrt(np.median(freq[present]) / freq[present]), 0.25, 10.0)
    return torch.tensor(weights, dtype=torch.float32)


def random_crop(
    image: np.ndarray, labels: np.ndarray, crop_px: int, rng: np.random.Generator
) -> Sample:
    """A ``crop_px`` square crop (padded white/background if smaller), random flip and turn."""
    h, w = image.shape
    if h < crop_px or w < crop_px:
        ph, pw = max(0, crop_px - h), max(0, crop_px - w)
        image = np.pad(image, ((0, ph), (0, pw)), constant_values=255)
        labels = np.pad(labels, ((0, ph), (0, pw)), constant_values=0)
        h, w = image.shape
    y, x = int(rng.integers(0, h - crop_px + 1)), int(rng.integers(0, w - crop_px + 1))
    image, labels = (
        image[y : y + crop_px, x : x + crop_px],
        labels[y : y + crop_px, x : x + crop_px],
    )
    k = int(rng.integers(4))
    image, labels = np.rot90(image, k), np.rot90(labels, k)
    if rng.random() < 0.5:
        image, labels = image[:, ::-1], labels[:, ::-1]
    return np.ascontiguousarray(image), np.ascontiguousarray(labels)


def as_class_sets(labels: np.ndarray) -> np.ndarray:
    """(H, W) int64 acceptable-class bit masks (bit c: class c is right): uint8 class ids become
    one-bit sets; uint16 labels are bit masks already (``f2n_drake.datasets.r3d.class_sets``),
    0 where nothing is known (padding), which the loss ignores."""
    if labels.dtype == np.uint16:
        return labels.astype(np.int64)
    return np.left_shift(1, labels.astype(np.int64))


class CropStream(IterableDataset):
    """Endless (image (1,c,c) float ink=1, class sets (c,c) int64, plan seed) training crops.

    Args:
        source: index -> (image, labels); must have ``seed(index)`` for logging.
        crop_px: crop side [px].
        input_px: the inference input size that letterboxed samples are resized to [px].
        p_letterbox: probability a plan is resized to ``input_px`` before cropping.
        crops_per_plan: crops taken from each rendered plan (amortises generation).
        rank, world_size: this DDP process and the number of processes.
        seed: augmentation seed (crop positions, flips).
    """

    def __init__(
        self,
        source: Callable[[int], Sample],
        crop_px: int,
        *,
        input_px: int = 512,
        p_letterbox: float = 0.7,
        crops_per_plan: int = 1,
        rank: int = 0,
        world_size: int = 1,
        seed: int = 0,
        first_index: int = 0,
    ) -> None:
        super().__init__()
        self.source, self.crop_px, self.input_px = source, crop_px, input_px
        self.p_letterbox, self.crops_per_plan = p_letterbox, crops_per_plan
        self.rank, self.world_size, self.seed = rank, world_size, seed
        self.first_index = first_index

    def __iter__(self) -> Iterator[tuple[torch.Tensor, torch.Tensor, int]]:
        info = get_worker_info()
        workers, worker = (info.num_workers, info.id) if info else (1, 0)
        shards, shard = self.world_size * workers, self.rank * workers + worker
        for k in itertools.count():
            index = self.first_index + k * shards + shard
            rng = np.random.default_rng([self.seed, index])
            image, labels = self.source(index)
            if rng.random() < self.p_letterbox:
                image, labels = letterbox(image, labels, self.input_px)
            for _ in range(self.crops_per_plan):
                crop, crop_labels = random_crop(image, labels, self.crop_px, rng)
                x = torch.from_numpy(1.0 - crop.astype(np.float32) / 255.0)[None]
                sets = torch.from_numpy(as_class_sets(crop_labels))
                yield x, sets, self.source.seed(index)
