"""Drawings, plans and segmenter stubs shared by tests in several folders.

Importable as ``helpers`` from every test (``pythonpath = ["tests"]`` in ``pyproject.toml``).
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import shapely
import torch
from shapely.geometry import box
from torch import nn

from f2n_drake.core.classes import CLASS_ID, NUM_CLASSES
from f2n_drake.core.plan import FloorPlan, polygons_of

LIVING, BEDROOM, KITCHEN = CLASS_ID["living"], CLASS_ID["bedroom"], CLASS_ID["kitchen"]
WALL, DOOR = CLASS_ID["wall"], CLASS_ID["door"]
FRONT, WINDOW = CLASS_ID["front_door"], CLASS_ID["window"]

TINY_RUN = [
    "--toy",
    "--steps",
    "2",
    "--batch",
    "2",
    "--crop",
    "64",
    "--input-size",
    "64",
    "--val-plans",
    "1",
    "--workers",
    "0",
    "--threads",
    "1",
    "--width",
    "0.25",
]
"""``python -m f2n_drake.train`` options of a two-step toy run on the CPU (a few seconds)."""

LEFT_BOX = (slice(61, 80), slice(21, 26))  # inside the left outer wall of ``facade``, rows 61..79
RIGHT_BOX = (slice(131, 150), slice(175, 180))  # inside the right outer wall of ``facade``
MIDDLE_BOX = (slice(91, 120), slice(98, 103))  # the door box of ``two_rooms``

WALL_THICKNESS_M = 0.2  # walls of ``simple_plan``


def two_rooms(size: int = 200) -> tuple[np.ndarray, np.ndarray]:
    """Living (left) and bedroom (right) in a walled box; a door in the middle wall."""
    img = np.full((size, size), 255, np.uint8)
    lab = np.zeros((size, size), np.uint8)
    lab[20:181, 20:181] = WALL
    lab[27:174, 27:97] = LIVING
    lab[27:174, 104:174] = BEDROOM
    lab[90:121, 97:104] = DOOR
    cv2.rectangle(img, (20, 20), (180, 180), 0, 1)
    cv2.rectangle(img, (26, 26), (174, 174), 0, 1)
    cv2.line(img, (97, 26), (97, 174), 0, 1)
    cv2.line(img, (103, 26), (103, 174), 0, 1)
    cv2.line(img, (97, 90), (103, 90), 0, 1)
    cv2.line(img, (97, 120), (103, 120), 0, 1)
    return img, lab


def classes(parsed) -> list[str]:
    """The class names of ``parsed``'s instances, sorted."""
    return sorted(inst.class_name for inst in parsed.instances)


def facade(left: int, right: int) -> tuple[np.ndarray, np.ndarray]:
    """``two_rooms`` plus two boxes drawn in the outer wall, labelled ``left`` and ``right``."""
    img, lab = two_rooms()
    for row in (60, 80):
        cv2.line(img, (20, row), (26, row), 0, 1)
    for row in (130, 150):
        cv2.line(img, (174, row), (180, row), 0, 1)
    lab[LEFT_BOX], lab[RIGHT_BOX] = left, right
    return img, lab


def probabilities_of(labels: np.ndarray, *boxes: tuple) -> np.ndarray:
    """(C, H, W) probabilities: one-hot of ``labels``, with ``boxes`` (slices, {class: p})."""
    probs = np.eye(NUM_CLASSES, dtype=np.float32)[labels].transpose(2, 0, 1).copy()
    for window, values in boxes:
        probs[(slice(None), *window)] = 0.0
        for cls, p in values.items():
            probs[(cls, *window)] = p
    return probs


def classes_at(parsed, *windows) -> list[str]:
    """The class names of the instances at the top-left pixel of each window."""
    ids = [int(parsed.instance_ids[r.start, c.start]) for r, c in windows]
    by_id = parsed.by_id()
    return [by_id[i].class_name for i in ids]


def simple_plan() -> FloorPlan:
    """living | bedroom joined by a door, a window and a front door in the exterior wall."""
    hole = box(0, 0, 8, 4)
    door, window, front = box(3.9, 1.5, 4.1, 2.4), box(-0.2, 1.5, 0, 2.5), box(5, -0.2, 6, 0)
    walls = shapely.union_all(
        [hole.buffer(WALL_THICKNESS_M, join_style="mitre").difference(hole), box(3.9, 0, 4.1, 4)]
    )
    walls = walls.difference(shapely.union_all([door, window, front]))
    polygons = {
        "living": [box(0, 0, 3.9, 4)],
        "bedroom": [box(4.1, 0, 8, 4)],
        "wall": polygons_of(walls),
        "door": [door],
        "window": [window],
        "front_door": [front],
    }
    return FloorPlan(polygons, WALL_THICKNESS_M, "test")


class Oracle:
    """A stub segmenter returning fixed labels."""

    def __init__(self, labels: np.ndarray) -> None:
        self.labels = labels
        self.calls = 0

    def predict(self, image: np.ndarray) -> np.ndarray:
        self.calls += 1
        return self.labels


class ProbabilityStub:
    """A segmenter stub that gives labels and probabilities."""

    def __init__(self, labels: np.ndarray, probabilities: np.ndarray) -> None:
        self.labels, self.probabilities = labels, probabilities

    def predict(self, image: np.ndarray) -> np.ndarray:
        raise AssertionError("parse_drawing must ask for probabilities")

    def predict_with_probabilities(self, image: np.ndarray):
        return self.labels, self.probabilities


class InkModel(nn.Module):
    """Class 1 wherever the input has ink (> 0.5), class 0 elsewhere: exposes the geometry."""

    config = {"num_classes": 2}

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return torch.cat([torch.full_like(x, 0.5), x], dim=1)


# RGB room colours of R3D (f2n_drake.datasets.r3d.ROOM_COLOURS)
R3D_LIVING, R3D_BEDROOM, R3D_CLOSET = (224, 255, 192), (255, 224, 128), (192, 192, 224)


def write_r3d_plan(root: Path, name: str) -> None:
    """A 120 x 160 px flat: a living room and a bedroom side by side behind 6 px walls, a closet
    in the bedroom's corner (no wall of its own), a window drawn as a box in the top wall."""
    h, w = 120, 160
    rooms = np.zeros((h, w, 3), np.uint8)
    rooms[10:110, 10:78] = R3D_LIVING
    rooms[10:110, 84:150] = R3D_BEDROOM
    rooms[80:110, 120:150] = R3D_CLOSET
    wall = np.zeros((h, w), np.uint8)
    wall[4:116, 4:156] = 255
    wall[(rooms > 0).any(axis=2)] = 0
    close = np.zeros((h, w), np.uint8)
    close[4:10, 30:50] = 255
    wall[close > 0] = 0
    drawing = np.full((h, w), 255, np.uint8)
    drawing[(wall > 0) | (close > 0)] = 0
    drawing[5:9, 31:49] = 255
    cv2.imwrite(str(root / f"{name}.jpg"), drawing)
    cv2.imwrite(str(root / f"{name}_rooms.png"), rooms[:, :, ::-1])
    cv2.imwrite(str(root / f"{name}_wall.png"), wall)
    cv2.imwrite(str(root / f"{name}_close.png"), close)


def bits(*names: str) -> int:
    return sum(1 << CLASS_ID[n] for n in names)
