"""Real drawings for training: R3D plans with set-valued labels, mixed with generated ones.

:class:`R3DPlans` shows the network each plan as inference does (on white paper, without room
names and furniture, cut to the drawing: ``inference.network_drawing``) and draws a new view of
one of them per index: with probability ``p_window``
a random window of 60-100 % of each side (what letterboxing then shows larger), else with
probability ``p_margin`` the plan set on paper up to 30 % wider (shown smaller); ``CropStream``
then adds the flips and quarter turns. Its labels are uint16 acceptable-class bit masks
(``f2n_drake.datasets.r3d.class_sets``), with ``losses.EMPHASIS_BIT`` on the pixels of the
``emphasised`` R3D classes. :class:`MixedPlans` takes each index from one of two
sources, the second with probability ``p_second``.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from f2n_drake.core.errors import InputError
from f2n_drake.datasets.r3d import ACCEPTABLE_MASK, R3D_ID, load_r3d_plan
from f2n_drake.perception.preparation import visible_strokes
from f2n_drake.segmenter.inference import network_drawing
from f2n_drake.segmenter.losses import EMPHASIS_BIT

Sample = tuple[np.ndarray, np.ndarray]


class R3DPlans:
    """Augmented views of R3D plans (never the development split: pass training names).

    Args:
        root: folder of the R3D plans.
        names: the plans to draw from; index ``i`` views plan ``names[i % len(names)]``.
        seed: augmentation seed.
        p_window: probability of a random window of the plan.
        p_margin: probability (when no window is taken) of white margins around it.
        input_px: the network's input side [px] (thin strokes are thickened for it).
        emphasised: R3D classes whose pixels carry ``EMPHASIS_BIT`` (their loss counts more).

    Raises:
        InputError: no names, or an emphasised class R3D does not have.
    """

    def __init__(
        self,
        root: str | Path,
        names: list[str],
        *,
        seed: int = 0,
        p_window: float = 0.5,
        p_margin: float = 0.3,
        input_px: int = 512,
        emphasised: tuple[str, ...] = (),
    ) -> None:
        if not names:
            raise InputError("R3DPlans needs at least one plan name")
        unknown = sorted(set(emphasised) - set(R3D_ID))
        if unknown:
            raise InputError(f"R3D has no class {', '.join(unknown)}; its classes: {list(R3D_ID)}")
        self.emphasised_ids = np.array([R3D_ID[c] for c in emphasised], np.uint8)
        self.root, self.names, self.seed_value = Path(root), list(names), seed
        self.p_window, self.p_margin, self.input_px = p_window, p_margin, input_px
        self._cache: dict[str, tuple[np.ndarray, np.ndarray]] = {}

    def seed(self, index: int) -> int:
        return index

    def _plan(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """The plan as inference shows it to the network (``network_drawing``, strokes kept
        visible at the input size), and its class sets cut to the same box."""
        if name not in self._cache:
            plan = load_r3d_plan(self.root, name)
            image, (r0, r1, c0, c1), stroke = network_drawing(plan.image)
            image = visible_strokes(image, stroke, self.input_px / max(image.shape))
            sets = plan.class_sets[r0:r1, c0:c1].copy()
            sets[np.isin(plan.labels[r0:r1, c0:c1], self.emphasised_ids)] |= EMPHASIS_BIT
            self._cache[name] = (image, sets)
        return self._cache[name]

    def __call__(self, index: int) -> Sample:
        image, sets = self._plan(self.names[index % len(self.names)])
        rng = np.random.default_rng([self.seed_value, index])
        h, w = image.shape
        if rng.random() < self.p_window:
            wh, ww = (int(s * rng.uniform(0.6, 1.0)) for s in (h, w))
            y, x = int(rng.integers(0, h - wh + 1)), int(rng.integers(0, w - ww + 1))
            return image[y : y + wh, x : x + ww], sets[y : y + wh, x : x + ww]
        if rng.random() < self.p_margin:
            pad = [(int(s * rng.uniform(0, 0.15)),) * 2 for s in (h, w)]
            outside = ACCEPTABLE_MASK[R3D_ID["background"]]
            return (
                np.pad(image, pad, constant_values=255),
                np.pad(sets, pad, constant_values=outside),
            )
        return image, sets


class MixedPlans:
    """Index i from ``second`` with probability ``p_second`` (seeded per index), else ``first``."""

    def __init__(
        self,
        first: Callable[[int], Sample],
        second: Callable[[int], Sample],
        p_second: float,
        *,
        seed: int = 0,
    ) -> None:
        if not 0.0 <= p_second <= 1.0:
            raise InputError(f"the mixing probability must be in 0..1, got {p_second}")
        self.first, self.second, self.p_second, self.seed_value = first, second, p_second, seed

    def _source(self, index: int):
        rng = np.random.default_rng([self.seed_value, index, 7])
        return self.second if rng.random() < self.p_second else self.first

    def seed(self, index: int) -> int:
        return self._source(index).seed(index)

    def __call__(self, index: int) -> Sample:
        return self._source(index)(index)
