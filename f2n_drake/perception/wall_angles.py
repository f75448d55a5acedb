"""Walls drawn at an angle: the directions of a drawing's straight walls off its rows and
columns, and the drawing turned until such walls run along its rows (and back).

The steps that find a wall's gaps scan rows and columns; a bay window's cheeks or a facade set at
45 degrees is scanned by turning the drawing square to it first
(:mod:`~f2n_drake.perception.window_inserts`).
"""

from __future__ import annotations

import cv2
import numpy as np

_OFF_AXIS_DEG = 8  # walls this far off the rows and columns are looked at turned [deg]
_ANGLE_BIN_DEG = 2  # directions this close vote together [deg]
_OBLIQUE_WALLS = 6  # a direction needs this many shortest straight runs of outline (4 walls long)
_OBLIQUE_SHARE = 0.03  # and this share of all the walls' straight outline
_MAX_ANGLES = 4  # directions looked at, at most


def oblique_wall_angles(thick: np.ndarray, wall_px: int) -> list[float]:
    """Directions of the straight thick walls that run along neither rows nor columns [deg,
    0..90 counter-clockwise from the rows: a wall and the walls square to it share one], at most
    ``_MAX_ANGLES``, the most drawn first.

    Straight runs of the walls' outlines (a probabilistic Hough transform, at least four walls
    long) vote for their direction by their length; a direction at least ``_OFF_AXIS_DEG`` off
    the rows and columns whose votes (summed over ``_ANGLE_BIN_DEG`` degrees to each side) reach
    ``_OBLIQUE_WALLS`` such runs and ``_OBLIQUE_SHARE`` of all is one; it is the mean direction of
    the runs within ``_ANGLE_BIN_DEG`` of it.
    """
    min_len = max(4 * wall_px, 12)
    edges = cv2.Canny(thick.astype(np.uint8) * 255, 50, 150)
    segments = cv2.HoughLinesP(edges, 1, np.pi / 180, min_len, minLineLength=min_len, maxLineGap=2)
    if segments is None:
        return []
    x0, y0, x1, y1 = segments.reshape(-1, 4).T.astype(float)
    length = np.hypot(x1 - x0, y1 - y0)
    angle = np.degrees(np.arctan2(y0 - y1, x1 - x0)) % 90  # rows grow down the page
    votes = np.bincount(np.round(angle).astype(int) % 90, weights=length, minlength=90)
    votes = sum(np.roll(votes, k) for k in range(-_ANGLE_BIN_DEG, _ANGLE_BIN_DEG + 1))
    degrees = np.arange(90)
    off_axis = np.minimum(degrees, 90 - degrees) >= _OFF_AXIS_DEG
    least = max(_OBLIQUE_WALLS * min_len, _OBLIQUE_SHARE * length.sum())
    angles: list[float] = []
    for a in np.argsort(-votes):
        if len(angles) == _MAX_ANGLES or votes[a] < least:
            break
        if not off_axis[a] or any(_apart(a, b) <= 2 * _ANGLE_BIN_DEG + 1 for b in angles):
            continue
        offset = (angle - a + 45) % 90 - 45
        near = np.abs(offset) <= _ANGLE_BIN_DEG
        if near.any():
            angles.append(float(a + np.average(offset[near], weights=length[near])) % 90)
        else:  # its votes came from runs half a degree farther off
            angles.append(float(a))
    return angles


def _apart(a: float, b: float) -> float:
    """Degrees between two directions taken modulo 90."""
    return min(abs(a - b) % 90, 90 - abs(a - b) % 90)


def turned(image: np.ndarray, angle: float) -> np.ndarray:
    """``image`` turned ``angle`` degrees clockwise on a canvas holding all of it, so that a
    wall at ``angle`` runs along its rows (nearest pixel)."""
    matrix, size = turn_matrix(image.shape[:2], angle)
    binary = image.dtype == np.bool_
    source = image.astype(np.uint8) if binary else image
    out = cv2.warpAffine(source, matrix, size, flags=cv2.INTER_NEAREST, borderValue=0)
    return out > 0 if binary else out


def turned_back(image: np.ndarray, angle: float, shape: tuple[int, int]) -> np.ndarray:
    """A ``turned`` image of a (H, W) ``shape`` drawing, back on the drawing's grid."""
    matrix, _ = turn_matrix(shape, angle)
    h, w = shape
    out = cv2.warpAffine(
        image.astype(np.uint8), matrix, (w, h), flags=cv2.INTER_NEAREST | cv2.WARP_INVERSE_MAP
    )
    return out > 0


def turn_matrix(shape: tuple[int, ...], angle: float) -> tuple[np.ndarray, tuple[int, int]]:
    """The affine map turning a (H, W) ``shape`` image ``angle`` degrees clockwise about its
    centre, and the (width, height) of the canvas holding all of it."""
    h, w = shape[:2]
    matrix = cv2.getRotationMatrix2D((w / 2, h / 2), -angle, 1.0)
    cos, sin = abs(matrix[0, 0]), abs(matrix[0, 1])
    size = (int(np.ceil(h * sin + w * cos)), int(np.ceil(h * cos + w * sin)))
    matrix[0, 2] += size[0] / 2 - w / 2
    matrix[1, 2] += size[1] / 2 - h / 2
    return matrix, size
