"""Runs of a mask along its rows: listed (:func:`row_runs`), painted back (:func:`row_spans`),
and each pixel's run length along rows and columns (:func:`run_lengths`,
:func:`stroke_widths_px`). Each works on the runs, not pixel by pixel."""

from __future__ import annotations

import numpy as np


def row_runs(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The runs of ``mask`` along its rows, in row-major order: (row, first column, last
    column) arrays."""
    h, w = mask.shape
    padded = np.zeros((h, w + 2), np.int8)
    padded[:, 1:-1] = mask
    steps = np.diff(padded, axis=1)  # (h, w + 1): 1 where a run starts, -1 after it ends
    starts, ends = np.flatnonzero(steps == 1), np.flatnonzero(steps == -1)
    return starts // (w + 1), starts % (w + 1), ends % (w + 1) - 1


def row_spans(
    shape: tuple[int, int], row: np.ndarray, first: np.ndarray, last: np.ndarray
) -> np.ndarray:
    """(H, W) bool: True on the columns ``first``..``last`` (inclusive) of each ``row`` (the
    inverse of :func:`row_runs`; empty spans, last < first, mark nothing)."""
    mask = np.zeros(shape, bool)
    length = np.maximum(last - first + 1, 0)
    offsets = np.repeat(row * shape[1] + first - np.cumsum(length) + length, length)
    mask.ravel()[offsets + np.arange(offsets.size)] = True
    return mask


def stroke_widths_px(ink: np.ndarray) -> np.ndarray:
    """(H, W) int32: per ink pixel, the shorter of the lengths of its row run and its column run
    of ink [px] (a horizontal wall t px thick gives t); 0 off the ink."""
    ink = np.asarray(ink, bool)
    return np.minimum(run_lengths(ink), run_lengths(ink.T).T)


def run_lengths(ink: np.ndarray) -> np.ndarray:
    """(H, W) int32: per ink pixel, the length of the run of ink along its row; 0 off it."""
    ink = np.asarray(ink, bool)
    steps = np.diff(np.pad(ink.view(np.int8), ((0, 0), (1, 1))), axis=1).ravel()
    starts, ends = np.flatnonzero(steps == 1), np.flatnonzero(steps == -1)
    lengths = (ends - starts).astype(np.int32)
    runs = np.zeros(ink.shape, np.int32)
    runs[ink] = np.repeat(lengths, lengths)  # the runs and their pixels, both in row order
    return runs
