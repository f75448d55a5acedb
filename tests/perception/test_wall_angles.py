"""The directions of walls drawn at an angle, and the drawing turned square to them and back."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from f2n_drake.perception.wall_angles import oblique_wall_angles, turned, turned_back


def angled_wall(degrees: float, shape=(200, 300)) -> np.ndarray:
    """A wall 6 px thick, 150 px long, rising ``degrees`` counter-clockwise from the rows."""
    wall = np.zeros(shape, np.uint8)
    start = np.array([50.0, 150.0])
    end = start + 150 * np.array([np.cos(np.radians(degrees)), -np.sin(np.radians(degrees))])
    cv2.line(wall, tuple(start.astype(int)), tuple(end.round().astype(int)), 1, 6)
    return wall > 0


def test_a_wall_at_an_angle_gives_its_direction_and_walls_on_the_axes_none():
    assert oblique_wall_angles(angled_wall(30), 6) == pytest.approx([30.0], abs=1.5)
    assert oblique_wall_angles(angled_wall(120), 6) == pytest.approx([30.0], abs=1.5)  # square
    assert oblique_wall_angles(angled_wall(0), 6) == []
    assert oblique_wall_angles(angled_wall(90), 6) == []
    assert oblique_wall_angles(np.zeros((50, 50), bool), 6) == []


def test_turned_square_the_wall_runs_along_the_rows_and_turns_back_onto_it():
    wall = angled_wall(30)
    square = turned(wall, 30)
    rows, cols = np.nonzero(square)
    assert rows.max() - rows.min() <= 10 and cols.max() - cols.min() >= 140  # along a row
    assert square.dtype == bool and square.sum() == pytest.approx(wall.sum(), rel=0.1)
    back = turned_back(square, 30, wall.shape)
    assert (back & wall).sum() >= 0.9 * (back | wall).sum()
    labels = np.where(wall, 6, 1).astype(np.uint8)  # other types keep theirs
    assert set(np.unique(turned(labels, 30))) == {0, 1, 6}
