"""Run the segmenter on a drawing of any size and return labels on the drawing's own pixel grid.

A drawing is padded with white to a square, resized to the network input size and segmented in
one pass (letterboxed), as in training, whenever that keeps its rooms about as big as the training
drawings had them: always up to ``letterbox_max_px`` on the long side, and beyond that when the
drawing's rooms (:func:`~f2n_drake.perception.room_width.room_width_px`) stay at least
``ROOM_WIDTH_MIN * input_size`` wide, the case of a high-resolution scan of a flat. Otherwise (a
large building) the drawing is resized so its rooms are ``ROOM_WIDTH_TARGET * input_size`` wide
(long side at most ``tile_max_side_px``) and segmented in overlapping ``input_size`` tiles whose
logits are blended with a tent window. Either way the logits are resampled bilinearly back onto
the original grid before the argmax. Hatched walls are filled solid once the drawing is at the
network's scale (``preparation.solid_hatching``), where the hatching's lines are a few pixels
apart whatever the drawing's resolution. Torch stays inside this module: callers pass and
receive numpy arrays.

Test-time views: the network was trained on drawings flipped and turned by quarter turns, so the
mirror image of a drawing is as good an input as the drawing itself. ``views`` of the eight flips
and turns (the drawing, its mirror image, their half turns, then the quarter turns) go through the
network as one batch, each result is turned back, and their logits are averaged. A mistake that
depends on the drawing's orientation (which of two identical boxes in the facade is the front door)
is outvoted; two views double the network time.

Storage: the shipped segmenter reads closets as the room beside them (a closet is storage, which
renders as background). A second network of the same shape, fine-tuned with R3D's closet pixels
weighing four times in the loss (``models/storage.pt``), reads the same canvas; where the first
says living room or bedroom (``STORAGE_LOOKALIKES``) and the second says background, the second's
logits are taken. The second network alone loses small bathrooms and halls to background, so it
decides nothing else. It doubles the network time.
"""

from __future__ import annotations

import logging
import os

import cv2
import numpy as np
import torch
import torch.nn.functional as F
from tqdm import tqdm

from f2n_drake.core.classes import CLASS_ID
from f2n_drake.models import model_path
from f2n_drake.perception.ink import binarize, free_marks, stroke_width_px
from f2n_drake.perception.preparation import (
    content_box,
    on_white_paper,
    solid_hatching,
    to_grey,
    visible_strokes,
    with_dark_ink,
    without_marks,
)
from f2n_drake.perception.room_width import room_width_px
from f2n_drake.segmenter import DEFAULT_VIEWS, VIEW_COUNTS
from f2n_drake.segmenter.network import DeepLabV3Plus, fold_batch_norms
from f2n_drake.segmenter.weights import DEFAULT_NAME, load_segmenter

log = logging.getLogger(__name__)

ROOM_WIDTH_TARGET = 100 / 512
"""Room width the network reads best, as a fraction of its input side: the training drawings,
flats letterboxed to 512 px, have rooms 64-125 px wide (median inscribed diameter, about 110)."""
ROOM_WIDTH_MIN = 30 / 512
"""Narrowest typical room, as a fraction of the input side, for which one letterboxed pass is
kept; the rooms of 50-300 room buildings letterboxed to 512 px are 14-22 px wide, those of R3D's
flats 30-190 px (median 75)."""
PROBE_MAX_PX = 1024
"""Long side [px] at which a large drawing is binarised to measure its rooms."""
VIEWS: tuple[tuple[int, bool], ...] = (
    (0, False),
    (0, True),
    (2, False),
    (2, True),
    (1, False),
    (1, True),
    (3, False),
    (3, True),
)
"""Test-time views in the order ``views`` takes them: (quarter turns, mirrored)."""
STORAGE_LOOKALIKES: tuple[str, ...] = ("living", "bedroom")
"""Classes the segmenter gives closets (R3D: 42 % and 20 % of closet pixels), where the storage
network's background is taken."""
STORAGE_NAME = "storage.pt"
"""Shipped weights of the storage network (see the module docstring)."""


def to_tensor(grey: np.ndarray) -> torch.Tensor:
    """(H,W) uint8 grey -> (1,1,H,W) float tensor with ink = 1, paper = 0 (the network input)."""
    return torch.from_numpy(1.0 - grey.astype(np.float32) / 255.0)[None, None]


def _resize(grey: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    h, w = shape
    shrink = h < grey.shape[0] or w < grey.shape[1]
    return cv2.resize(grey, (w, h), interpolation=cv2.INTER_AREA if shrink else cv2.INTER_LINEAR)


def network_drawing(
    grey: np.ndarray, *, white_paper: bool = True, erase_marks: bool = True
) -> tuple[np.ndarray, tuple[int, int, int, int], int]:
    """The drawing as the network is shown it, before scaling: on white paper
    (:func:`on_white_paper`) in dark lines (:func:`with_dark_ink`), without room names and
    furniture (:func:`without_marks`), cut to its content box; with that box (row0, row1, col0,
    col1) and the drawing's stroke width [px]."""
    lines = binarize(grey)
    if white_paper:
        grey = on_white_paper(grey, lines)
        if (dark := with_dark_ink(grey)) is not grey:  # light lines the cut lost, now dark
            grey, lines = dark, binarize(dark)
    marks = free_marks(lines).ink
    if erase_marks:
        grey = without_marks(grey, lines, marks)
    r0, r1, c0, c1 = content_box(lines & ~marks)
    return grey[r0:r1, c0:c1], (r0, r1, c0, c1), stroke_width_px(lines[r0:r1, c0:c1])


def _for_cpu(model: DeepLabV3Plus) -> DeepLabV3Plus:
    """Batch norms folded into the convolutions and channels-last weights: about 15 % and 20 %
    faster convolutions on CPU, same logits (to 1e-5)."""
    return fold_batch_norms(model).to(memory_format=torch.channels_last)


def _view(x: torch.Tensor, turns: int, mirrored: bool) -> torch.Tensor:
    """(N, C, S, S) images turned by ``turns`` quarter turns, then mirrored left-right."""
    x = torch.rot90(x, turns, (2, 3)) if turns else x  # rot90 copies even by no turn
    return torch.flip(x, (3,)) if mirrored else x


def _unview(x: torch.Tensor, turns: int, mirrored: bool) -> torch.Tensor:
    """The inverse of :func:`_view`."""
    x = torch.flip(x, (3,)) if mirrored else x
    return torch.rot90(x, -turns, (2, 3)) if turns else x


def _best_class(logits: torch.Tensor) -> np.ndarray:
    """(C, H, W) scores -> (H, W) uint8 index of the largest (``max``: about 5x faster than
    ``argmax`` over the leading dimension on CPU)."""
    return logits.max(0).indices.to(torch.uint8).cpu().numpy()


def _tent(size: int, overlap: int) -> np.ndarray:
    """1-D blending weights: 1 in the middle, ramping down over ``overlap`` px at both ends."""
    ramp = np.ones(size, np.float32)
    if overlap > 0:
        edge = (np.arange(overlap, dtype=np.float32) + 0.5) / overlap
        ramp[:overlap] = np.maximum(edge, 0.05)
        ramp[size - overlap :] = np.maximum(edge[::-1], 0.05)
    return ramp


class Segmenter:
    """A trained DeepLabV3+ wrapped for numpy images of any size.

    Args:
        model: the network (eval mode is set here).
        input_size: side of the square network input for the letterbox path and of tiles [px].
        letterbox_max_px: drawings with a long side up to this are always segmented in one
            pass [px]; larger ones too unless their rooms come out narrower than
            ``ROOM_WIDTH_MIN * input_size`` (see the module docstring).
        tile_max_side_px: longest working side of a tiled drawing [px] (bounds the time).
        overlap_px: overlap between neighbouring tiles [px], < input_size / 2; default
            3/16 of ``input_size`` (96 px for 512 px tiles).
        device: torch device the model runs on.
        views: test-time views averaged, 1, 2, 4 or 8 (see the module docstring); 1 is the
            network alone.
        white_paper: show the network the drawing :func:`on_white_paper` (else as given).
        erase_marks: show it the drawing :func:`without_marks` (no room names, furniture).
        storage_model: a network of the same classes whose background is taken where ``model``
            says a ``STORAGE_LOOKALIKES`` class (see the module docstring); None: ``model`` alone.
    """

    def __init__(
        self,
        model: DeepLabV3Plus,
        *,
        input_size: int = 512,
        letterbox_max_px: int = 1024,
        tile_max_side_px: int = 4096,
        overlap_px: int | None = None,
        device: str | torch.device = "cpu",
        views: int = DEFAULT_VIEWS,
        white_paper: bool = True,
        erase_marks: bool = True,
        storage_model: DeepLabV3Plus | None = None,
    ) -> None:
        if input_size % 16 or input_size < 64:
            raise ValueError(f"input_size must be a multiple of 16 and >= 64, got {input_size}")
        overlap_px = input_size * 3 // 16 if overlap_px is None else overlap_px
        if not 0 <= overlap_px < input_size // 2:
            raise ValueError(f"overlap_px must be in [0, input_size/2), got {overlap_px}")
        if views not in VIEW_COUNTS:
            raise ValueError(f"views must be 1, 2, 4 or 8, got {views}")
        self.device = torch.device(device)
        self.model = model.to(self.device).eval()
        self.input_size = input_size
        self.letterbox_max_px = letterbox_max_px
        self.tile_max_side_px = max(tile_max_side_px, input_size)
        self.overlap_px = overlap_px
        self.num_classes = int(model.config["num_classes"])
        if storage_model is not None:
            if int(storage_model.config["num_classes"]) != self.num_classes:
                raise ValueError("the storage network must have the segmenter's classes")
            storage_model = storage_model.to(self.device).eval()
        self.storage_model = storage_model
        self.views = views
        self.white_paper = white_paper
        self.erase_marks = erase_marks

    @classmethod
    def load(
        cls,
        path: str | os.PathLike | None = None,
        *,
        storage: str | os.PathLike | bool | None = None,
        device: str = "cpu",
        verify: bool = True,
        **options,
    ) -> Segmenter:
        """Load shipped (``path=None``) or given weights; ``device="cuda"`` uses a GPU if present.

        ``storage`` picks the storage network (module docstring): None, the one beside the
        default weights (``storage.pt`` in ``models/`` or in ``$F2N_DRAKE_MODELS`` with its own
        ``segmenter.pt``), none with given weights; False, none; True, the default one; or a file.

        Raises:
            InputError: weights missing, failing their sha256 check, or unloadable.
        """
        if device.startswith("cuda") and not torch.cuda.is_available():
            log.warning("CUDA requested but not available; running the segmenter on CPU")
            device = "cpu"
        checkpoint = load_segmenter(path, verify=verify, device=device)
        options.setdefault("input_size", checkpoint.input_size)
        if storage is None:  # the default weights' own storage network, if they have one
            beside = model_path(STORAGE_NAME).parent == model_path(DEFAULT_NAME).parent
            storage = path is None and beside
        if storage is True:
            storage = model_path(STORAGE_NAME)
        if storage is not False:
            storage_checkpoint = load_segmenter(storage, verify=verify, device=device)
            options["storage_model"] = _for_cpu(storage_checkpoint.model)
        return cls(_for_cpu(checkpoint.model), device=device, **options)

    def predict(self, image: np.ndarray) -> np.ndarray:
        """Label every pixel: (H,W) or (H,W,3) uint8 drawing -> (H,W) uint8 class ids."""
        canvas, mapping = self._canvas_logits(to_grey(image))
        labels = np.empty(image.shape[:2], np.uint8)
        for rows, band in self._resample(canvas, mapping, image.shape[:2]):
            labels[rows] = _best_class(band)
        return labels

    def predict_with_probabilities(self, image: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Labels and (num_classes, H, W) float16 softmax probabilities on the original grid
        (2 bytes per class and pixel: 20 MB for a 1024 x 1024 drawing)."""
        canvas, mapping = self._canvas_logits(to_grey(image))
        labels = np.empty(image.shape[:2], np.uint8)
        probabilities = np.empty((self.num_classes, *image.shape[:2]), np.float16)
        for rows, band in self._resample(canvas, mapping, image.shape[:2]):
            labels[rows] = _best_class(band)
            probabilities[:, rows] = band.softmax(0).to(torch.float16).cpu().numpy()
        return labels, probabilities

    def predict_logits(self, image: np.ndarray) -> np.ndarray:
        """(H,W[,3]) uint8 drawing -> (num_classes, H, W) float32 logits on the original grid."""
        canvas, mapping = self._canvas_logits(to_grey(image))
        logits = np.empty((self.num_classes, *image.shape[:2]), np.float32)
        for rows, band in self._resample(canvas, mapping, image.shape[:2]):
            logits[:, rows] = band.float().cpu().numpy()
        return logits

    def _forward(self, batch: np.ndarray) -> torch.Tensor:
        """(N, S, S) uint8 squares -> (N, C, S, S) logits (:meth:`logits`)."""
        return self.logits(torch.from_numpy(1.0 - batch.astype(np.float32) / 255.0)[:, None])

    @torch.inference_mode()
    def logits(self, x: torch.Tensor) -> torch.Tensor:
        """(N, 1, S, S) ink (1) on paper (0) -> (N, C, S, S) logits, averaged over
        ``self.views`` views, the storage network's where it reads storage (module docstring):
        what the network says of a square it is shown, as training shows it squares."""
        x = x.to(self.device)
        logits = self._viewed(self.model, x)
        if self.storage_model is None:
            return logits
        storage = self._viewed(self.storage_model, x)
        lookalikes = torch.tensor([CLASS_ID[c] for c in STORAGE_LOOKALIKES], device=self.device)
        # ``max`` for the best class: several times faster than ``argmax`` over dimension 1
        taken = torch.isin(logits.max(1).indices, lookalikes) & (storage.max(1).indices == 0)
        return torch.where(taken[:, None], storage, logits)

    def _viewed(self, model: DeepLabV3Plus, x: torch.Tensor) -> torch.Tensor:
        """``model``'s logits of ``x``, averaged over ``self.views`` views."""
        views = VIEWS[: self.views]
        logits = model(torch.cat([_view(x, turns, mirrored) for turns, mirrored in views]))
        parts = zip(logits.split(len(x)), views, strict=True)
        total = sum(_unview(part, turns, mirrored) for part, (turns, mirrored) in parts)
        return total / len(views)

    def _canvas_logits(self, grey: np.ndarray) -> tuple[torch.Tensor, tuple[float, ...]]:
        """Logits (C,h,w) on a working canvas and the affine map original px -> canvas px.

        The map is (scale_x, scale_y, offset_x, offset_y): canvas = (original + offset) * scale
        in continuous coordinates where pixel i covers [i, i+1).
        """
        grey, (r0, r1, c0, c1), stroke = network_drawing(
            grey, white_paper=self.white_paper, erase_marks=self.erase_marks
        )
        h, w = grey.shape
        side = self.working_side_px(grey)
        if side is None:
            long_side = max(h, w)
            top, left = (long_side - h) // 2, (long_side - w) // 2
            square = np.full((long_side, long_side), 255, np.uint8)
            square[top : top + h, left : left + w] = grey
            scale = self.input_size / long_side
            net_in = _resize(visible_strokes(square, stroke, scale), (self.input_size,) * 2)
            net_in = solid_hatching(net_in)
            return self._forward(net_in[None])[0], (scale, scale, left - c0, top - r0)
        factor = side / max(h, w)
        hs, ws = max(1, round(h * factor)), max(1, round(w * factor))
        work = solid_hatching(_resize(grey, (hs, ws)) if factor != 1.0 else grey)
        return self._tiled_logits(work), (ws / w, hs / h, -c0, -r0)

    def working_side_px(self, grey: np.ndarray) -> int | None:
        """Long side [px] at which ``grey`` is tiled, or None for one letterboxed pass.

        None up to ``letterbox_max_px``, when nothing is enclosed, or when the drawing's rooms
        letterboxed to the input are at least ``ROOM_WIDTH_MIN * input_size`` wide; otherwise
        the side that makes them ``ROOM_WIDTH_TARGET * input_size`` wide, within
        [input_size, tile_max_side_px].
        """
        long_side = max(grey.shape)
        if long_side <= self.letterbox_max_px:
            return None
        probe = min(1.0, PROBE_MAX_PX / long_side)
        small = _resize(
            grey, (max(1, round(grey.shape[0] * probe)), max(1, round(grey.shape[1] * probe)))
        )
        width = room_width_px(binarize(small))
        if width is None:
            return None
        width /= probe  # [px of grey]
        if width * self.input_size / long_side >= ROOM_WIDTH_MIN * self.input_size:
            return None
        side = long_side * ROOM_WIDTH_TARGET * self.input_size / width
        return int(round(min(max(side, self.input_size), self.tile_max_side_px)))

    def _tiled_logits(self, work: np.ndarray) -> torch.Tensor:
        tile, overlap = self.input_size, self.overlap_px
        step = tile - overlap
        h, w = work.shape
        ny, nx = max(1, -(-(h - overlap) // step)), max(1, -(-(w - overlap) // step))
        hp, wp = (ny - 1) * step + tile, (nx - 1) * step + tile
        padded = np.full((hp, wp), 255, np.uint8)
        padded[:h, :w] = work
        window = torch.from_numpy(np.outer(_tent(tile, overlap), _tent(tile, overlap)))
        window = window.to(self.device)
        total = torch.zeros((self.num_classes, hp, wp), device=self.device)
        weight = torch.zeros((hp, wp), device=self.device)
        origins = [(y * step, x * step) for y in range(ny) for x in range(nx)]
        batches = range(0, len(origins), 4)
        # a large building takes seconds: show progress when there are many tiles
        for start in tqdm(batches, "segmenting tiles", disable=len(origins) <= 16, leave=False):
            chunk = origins[start : start + 4]
            logits = self._forward(np.stack([padded[y : y + tile, x : x + tile] for y, x in chunk]))
            for (y, x), tile_logits in zip(chunk, logits, strict=True):
                total[:, y : y + tile, x : x + tile] += tile_logits * window
                weight[y : y + tile, x : x + tile] += window
        return (total / weight)[:, :h, :w]

    def _resample(
        self,
        canvas: torch.Tensor,
        mapping: tuple[float, ...],
        shape: tuple[int, int],
        band_rows: int = 256,
    ):
        """Yield (row slice, (C, rows, W) logits) bilinearly sampled onto the original grid."""
        sx, sy, ox, oy = mapping
        _, hc, wc = canvas.shape
        height, width = shape
        if mapping == (1.0, 1.0, 0, 0) and (hc, wc) == (height, width):  # the canvas is the grid
            for r0 in range(0, height, band_rows):
                yield slice(r0, min(height, r0 + band_rows)), canvas[:, r0 : r0 + band_rows]
            return
        cols = torch.arange(width, dtype=torch.float32, device=canvas.device)
        x_norm = 2.0 * (cols + 0.5 + ox) * sx / wc - 1.0
        with torch.inference_mode():
            for r0 in range(0, height, band_rows):
                r1 = min(height, r0 + band_rows)
                rows = torch.arange(r0, r1, dtype=torch.float32, device=canvas.device)
                y_norm = 2.0 * (rows + 0.5 + oy) * sy / hc - 1.0
                grid = torch.stack(torch.broadcast_tensors(x_norm[None, :], y_norm[:, None]), -1)
                band = F.grid_sample(
                    canvas[None],
                    grid[None],
                    mode="bilinear",
                    padding_mode="border",
                    align_corners=False,
                )[0]
                yield slice(r0, r1), band
