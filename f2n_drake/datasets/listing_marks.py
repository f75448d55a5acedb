"""What a real-estate listing draws on a plan: room names and areas, furniture standing in the
rooms, furniture drawn against their walls (the ``labelled``, ``furnished`` and ``fitted`` looks of
:func:`f2n_drake.datasets.looks.restyle`)."""

from __future__ import annotations

import math
from collections.abc import Iterator

import cv2
import numpy as np

from f2n_drake.core.classes import CLASS_ID, SPACE_CLASSES
from f2n_drake.core.raster import PixelGrid

FURNITURE_M = {
    "bedroom": ((1.4, 1.8), (1.9, 2.1)),  # a bed
    "living": ((0.8, 1.0), (1.8, 2.4)),  # a sofa
    "kitchen": ((0.7, 0.9), (1.0, 1.4)),  # a table
}
"""Outline sizes (short side range, long side range) [m] of the piece ``furnished`` puts in a
room of each class."""

FITTED_M = {
    "bedroom": ((1.9, 2.1), (1.4, 1.8)),  # a bed, its head against the wall
    "living": ((0.8, 1.0), (1.8, 2.4)),  # a sofa
    "kitchen": ((0.6, 0.65), (1.8, 3.0)),  # a counter
    "bathroom": ((0.7, 0.8), (1.5, 1.7)),  # a bathtub
}
"""(depth off the wall, length along it) ranges [m] of the piece ``fitted`` draws against a wall
of a room of each class."""

ROOM_NAMES = {
    "living": "LIVING",
    "bedroom": "BEDROOM",
    "bathroom": "BATH",
    "kitchen": "KITCHEN",
    "balcony": "BALCONY",
}
"""The words ``labelled`` writes in rooms of each space class."""


def inscribed_rooms(
    labels: np.ndarray, names: tuple[str, ...] = SPACE_CLASSES
) -> Iterator[tuple[str, np.ndarray, np.ndarray, tuple[int, int]]]:
    """Each room of a label image (4-connected pixels of one of ``names``): its class, (H, W)
    uint8 mask, distance to its edge [px] and its most inscribed point (row, col)."""
    for name in names:
        n, rooms = cv2.connectedComponents((labels == CLASS_ID[name]).astype(np.uint8), 4)
        for k in range(1, n):
            room = (rooms == k).astype(np.uint8)
            depth = cv2.distanceTransform(room, cv2.DIST_L2, 3)
            row, col = np.unravel_index(int(np.argmax(depth)), depth.shape)
            yield name, room, depth, (int(row), int(col))


def write_room_names(
    image: np.ndarray, labels: np.ndarray, grid: PixelGrid, rng: np.random.Generator
) -> np.ndarray:
    """``image`` with each room's name and area ("BEDROOM", "12.4 m2") written at its most
    inscribed point, in letters 0.2-0.35 m high (one height per drawing, as a real-estate
    listing letters its rooms), made smaller where the room is too narrow and left out below
    5 px: free-standing text inside the rooms, never touching their outlines."""
    out = image.copy()
    font, thickness = cv2.FONT_HERSHEY_SIMPLEX, 1
    height_px = grid.length_px(rng.uniform(0.2, 0.35))
    (_, unit_h), _ = cv2.getTextSize("M", font, 1.0, thickness)
    ink = int(rng.integers(0, 60))
    for name, room, depth, (row, col) in inscribed_rooms(labels):
        area_m2 = room.sum() * grid.metres_per_px**2
        words = (ROOM_NAMES[name], f"{area_m2:.1f} m2")
        scale = height_px / unit_h
        (w, h), _ = cv2.getTextSize(max(words, key=len), font, scale, thickness)
        fit = min(1.0, 1.4 * depth[row, col] / max(w, 1), 0.8 * depth[row, col] / max(h, 1))
        scale, h = scale * fit, h * fit
        if h < 5:
            continue
        for line, word in enumerate(words):
            (w, _), _ = cv2.getTextSize(word, font, scale, thickness)
            y = int(round(row + (line - 0.5) * 1.6 * h + h / 2))
            cv2.putText(out, word, (int(col - w / 2), y), font, scale, ink, thickness, cv2.LINE_AA)
    return out


def draw_furniture(
    image: np.ndarray, labels: np.ndarray, grid: PixelGrid, rng: np.random.Generator
) -> np.ndarray:
    """``image`` with a piece of furniture standing free in each bedroom, living room and kitchen
    it fits in (``FURNITURE_M``, at least 0.2 m from the walls and from any other ink, such as a
    room name, turned at random by quarter turns): an outlined rectangle, a bed with its pillow
    line, a table with a round top."""
    out = image.copy()
    ink = int(rng.integers(0, 60))
    thickness = int(rng.integers(1, 3))
    margin_px = grid.length_px(0.2)
    for name, (short_m, long_m) in FURNITURE_M.items():
        n, rooms = cv2.connectedComponents((labels == CLASS_ID[name]).astype(np.uint8), 4)
        for k in range(1, n):
            depth = cv2.distanceTransform((rooms == k).astype(np.uint8), cv2.DIST_L2, 3)
            w, h = (grid.length_px(rng.uniform(*r)) for r in (short_m, long_m))
            w, h = (h, w) if rng.random() < 0.5 else (w, h)
            fits = np.argwhere(depth >= 0.5 * math.hypot(w, h) + margin_px)
            m = int(math.ceil(margin_px))
            for row, col in fits[rng.permutation(len(fits))[:50]]:
                x0, y0 = int(col - w / 2), int(row - h / 2)
                x1, y1 = int(col + w / 2), int(row + h / 2)
                if out[y0 - m : y1 + m + 1, x0 - m : x1 + m + 1].min() > 200:  # clear of ink
                    break
            else:
                continue
            cv2.rectangle(out, (x0, y0), (x1, y1), ink, thickness, cv2.LINE_AA)
            if name == "bedroom":  # the pillow end
                if h > w:
                    cv2.line(out, (x0, y0 + int(0.2 * h)), (x1, y0 + int(0.2 * h)), ink, thickness)
                else:
                    cv2.line(out, (x0 + int(0.2 * w), y0), (x0 + int(0.2 * w), y1), ink, thickness)
            elif name == "kitchen":
                radius = int(0.35 * min(w, h))
                cv2.circle(out, (int(col), int(row)), radius, ink, thickness, cv2.LINE_AA)
    return out


def fit_furniture(
    image: np.ndarray, labels: np.ndarray, grid: PixelGrid, rng: np.random.Generator
) -> np.ndarray:
    """``image`` with a piece of furniture (``FITTED_M``) outlined against a wall of each room
    it fits in: a rectangle whose one side is drawn over the wall's line, wholly in the room,
    clear of other ink, with no door within 0.5 m behind it (a piece never blocks a door; it
    may stand under a window)."""
    out = image.copy()
    ink = int(rng.integers(0, 60))
    behind_px = max(1, round(grid.length_px(0.5)))
    doors = np.isin(labels, [CLASS_ID["door"], CLASS_ID["front_door"]])
    for name, (depth_m, length_m) in FITTED_M.items():
        n, rooms = cv2.connectedComponents((labels == CLASS_ID[name]).astype(np.uint8), 4)
        for k in range(1, n):
            room = rooms == k
            rows, cols = np.nonzero(room)
            depth, length = (round(grid.length_px(rng.uniform(*r))) for r in (depth_m, length_m))
            for side in rng.permutation(4):
                box = _against(
                    side, (rows.min(), rows.max(), cols.min(), cols.max()), depth, length, rng
                )
                if box is None:
                    continue
                r0, r1, c0, c1 = box
                inside = room[r0 + 2 : r1 - 1, c0 + 2 : c1 - 1]
                clear = out[r0 + 2 : r1 - 1, c0 + 2 : c1 - 1]
                behind = (
                    doors[max(r0 - behind_px, 0) : r0 + 1, c0:c1],
                    doors[r1 : r1 + behind_px, c0:c1],
                    doors[r0:r1, max(c0 - behind_px, 0) : c0 + 1],
                    doors[r0:r1, c1 : c1 + behind_px],
                )[side]
                if not (inside.size and inside.all() and clear.min() > 200 and not behind.any()):
                    continue
                box = _onto_wall(out, (r0, r1, c0, c1), side)
                if box is not None:
                    r0, r1, c0, c1 = box
                    cv2.rectangle(out, (c0, r0), (c1, r1), ink, 1)
                    break
    return out


def _onto_wall(
    image: np.ndarray, box: tuple[int, int, int, int], side: int, reach: int = 6
) -> tuple[int, int, int, int] | None:
    """``box`` (r0, r1, c0, c1) with its ``side`` moved out onto the nearest line of ink along
    most of it, at most ``reach`` px away; None if there is none."""
    r0, r1, c0, c1 = box
    for step in range(reach):
        if side == 0 and r0 - step >= 0:
            run, moved = image[r0 - step, c0 + 1 : c1], (r0 - step, r1, c0, c1)
        elif side == 1 and r1 + step < image.shape[0]:
            run, moved = image[r1 + step, c0 + 1 : c1], (r0, r1 + step, c0, c1)
        elif side == 2 and c0 - step >= 0:
            run, moved = image[r0 + 1 : r1, c0 - step], (r0, r1, c0 - step, c1)
        elif side == 3 and c1 + step < image.shape[1]:
            run, moved = image[r0 + 1 : r1, c1 + step], (r0, r1, c0, c1 + step)
        else:
            return None
        if np.mean(run < 128) > 0.5:
            return moved
    return None


def _against(
    side: int, bounds: tuple[int, int, int, int], depth: int, length: int, rng: np.random.Generator
) -> tuple[int, int, int, int] | None:
    """(r0, r1, c0, c1) [px] of a ``depth`` x ``length`` box against ``side`` (0 top, 1
    bottom, 2 left, 3 right) of a room of ``bounds`` (first and last row and column), placed at
    random along it and over the wall's line; None if the room is too short."""
    top, bottom, left, right = (int(v) for v in bounds)
    along = right - left - length if side < 2 else bottom - top - length
    if along < 2:
        return None
    at = int(rng.integers(0, along))
    if side == 0:
        return top - 1, top - 1 + depth, left + at, left + at + length
    if side == 1:
        return bottom + 1 - depth, bottom + 1, left + at, left + at + length
    if side == 2:
        return top + at, top + at + length, left - 1, left - 1 + depth
    return top + at, top + at + length, right + 1 - depth, right + 1
