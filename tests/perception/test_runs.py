"""Runs along a drawing's rows: the helper, and the gap and tread scans built on it."""

from __future__ import annotations

import numpy as np

from f2n_drake.perception.runs import row_runs, row_spans, run_lengths
from f2n_drake.perception.stairs import _longest_runs
from f2n_drake.perception.wall_gaps import _row_gaps


def test_row_runs_lists_each_runs_row_first_and_last_column():
    mask = np.array([[1, 1, 0, 1], [0, 0, 0, 0], [0, 1, 1, 1]], bool)
    rows, first, last = row_runs(mask)
    assert rows.tolist() == [0, 0, 2] and first.tolist() == [0, 3, 1] and last.tolist() == [1, 3, 3]


def test_row_spans_paint_back_the_runs_row_runs_lists():
    mask = np.random.default_rng(0).random((7, 9)) < 0.5
    assert (row_spans(mask.shape, *row_runs(mask)) == mask).all()
    empty = row_spans((2, 3), np.array([1]), np.array([2]), np.array([1]))  # last < first
    assert not empty.any()


def test_each_ink_pixel_gets_the_length_of_its_row_run():
    ink = np.array([[1, 1, 0, 1], [0, 0, 0, 0], [1, 1, 1, 1]], bool)
    assert run_lengths(ink).tolist() == [[2, 2, 0, 1], [0, 0, 0, 0], [4, 4, 4, 4]]
    assert run_lengths(ink.T).T.tolist() == [[1, 1, 0, 1], [0, 0, 0, 0], [1, 1, 1, 1]]


def test_the_longest_run_of_a_row_wins_the_leftmost_of_equals():
    ink = np.array([[1, 0, 1, 1, 0, 1, 1], [0, 0, 0, 0, 0, 0, 0], [1, 1, 1, 0, 1, 0, 0]], bool)
    starts, ends = _longest_runs(ink)
    assert starts.tolist() == [2, 0, 0] and ends.tolist() == [4, 0, 3]


def test_a_gap_is_paper_between_a_free_end_and_a_wall_run_close_enough():
    walls = np.array([[1, 1, 0, 0, 1, 1, 0, 0, 0, 0, 1]], bool)
    ends = walls.copy()
    gaps = _row_gaps(walls, ends, ends, max_gap=3)
    assert gaps.tolist() == [[False, False, True, True] + [False] * 7]  # 4 px apart: too wide
    assert not _row_gaps(walls, np.zeros_like(walls), ends, max_gap=3).any()  # no free end
