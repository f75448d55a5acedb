"""Read R3D (Rent3D) plans in the DeepFloorplan layout, with set-valued labels.

DeepFloorplan (Zeng et al., ICCV 2019) labels the Rent3D listing drawings (Liu et al., CVPR
2015) per plan ``NAME``: ``NAME.jpg`` (the drawing), ``NAME_rooms.png`` (room type as an RGB
colour), ``NAME_wall.png`` and ``NAME_close.png`` (walls, and doors and windows together, white
on black), all of one size. Openings are painted over walls, walls over rooms.

R3D merges classes f2n_drake tells apart, and has rooms f2n_drake has no class for. Each R3D
class is therefore a *set* of acceptable f2n_drake classes, never a guessed split:

============  ==========================================================================
R3D class     acceptable f2n_drake classes
============  ==========================================================================
background    background (outside the flat; also the unused colour and unknown colours)
closet        background: a closet is a storeroom, which f2n_drake's plans draw as background
bathroom      bathroom
living        living or kitchen (R3D's living room / kitchen / dining room)
bedroom       bedroom
hall          living: halls and corridors are circulation, which f2n_drake calls living
balcony       balcony
other         background or any room but balcony (den, laundry, study)
opening       door, window or front door (R3D tells none of them apart)
wall          wall
============  ==========================================================================

:func:`class_sets` writes them as a (H, W) uint16 bit mask per pixel (bit ``c`` set when class
id ``c`` is acceptable). The fixed development split (:data:`DEV_SPLIT_FILE`, 30 of the 179
training plans) is never trained on.
"""

from __future__ import annotations

import zlib
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from f2n_drake.core.classes import CLASS_ID
from f2n_drake.core.errors import InputError

R3D_CLASSES: tuple[str, ...] = (
    "background",
    "closet",
    "bathroom",
    "living",
    "bedroom",
    "hall",
    "balcony",
    "other",
    "opening",
    "wall",
)
"""R3D's merged classes, in the label order of :attr:`R3DPlan.labels`."""
R3D_ID: dict[str, int] = {name: i for i, name in enumerate(R3D_CLASSES)}

ROOM_COLOURS: dict[tuple[int, int, int], str] = {
    (224, 255, 192): "living",
    (255, 224, 128): "bedroom",
    (192, 255, 255): "bathroom",
    (255, 160, 96): "hall",
    (255, 224, 224): "balcony",
    (192, 192, 224): "closet",
    (224, 224, 128): "other",
}
"""RGB colour of ``NAME_rooms.png`` -> R3D class; every other colour is background."""

_ROOMS_BUT_BALCONY = ("living", "bedroom", "bathroom", "kitchen")
ACCEPTABLE: dict[str, tuple[str, ...]] = {
    "background": ("background",),
    "closet": ("background",),
    "bathroom": ("bathroom",),
    "living": ("living", "kitchen"),
    "bedroom": ("bedroom",),
    "hall": ("living",),
    "balcony": ("balcony",),
    "other": ("background", *_ROOMS_BUT_BALCONY),
    "opening": ("door", "window", "front_door"),
    "wall": ("wall",),
}
"""R3D class -> the f2n_drake classes a pixel of it may take (see the module docstring)."""

ACCEPTABLE_MASK = np.array(
    [sum(1 << CLASS_ID[c] for c in ACCEPTABLE[name]) for name in R3D_CLASSES], np.uint16
)
"""R3D class id -> bit mask of its acceptable f2n_drake class ids."""

ROOM_CLASSES: tuple[str, ...] = ("living", "bedroom", "bathroom", "hall", "balcony", "other")
"""R3D classes whose connected regions count as rooms (a closet is no room of ours)."""

DEV_SPLIT_FILE = Path(__file__).with_name("r3d_dev_split.txt")
SPLITS: tuple[str, ...] = ("dev", "train", "all")


@dataclass(frozen=True)
class R3DPlan:
    """One R3D drawing and its labels.

    Attributes:
        name: the plan's file stem.
        image: (H, W) uint8 grey drawing, dark lines on white paper.
        labels: (H, W) uint8 R3D class id per pixel (:data:`R3D_CLASSES`).
    """

    name: str
    image: np.ndarray
    labels: np.ndarray

    @property
    def class_sets(self) -> np.ndarray:
        """(H, W) uint16 bit mask of the acceptable f2n_drake class ids per pixel."""
        return class_sets(self.labels)


def class_sets(r3d_labels: np.ndarray) -> np.ndarray:
    """(H, W) uint16 acceptable-class bit masks of (H, W) R3D class ids."""
    return ACCEPTABLE_MASK[r3d_labels]


def _read(path: Path, flags: int) -> np.ndarray:
    image = cv2.imread(str(path), flags)
    if image is None:
        raise InputError(f"cannot read {path}")
    return image


def load_r3d_plan(root: str | Path, name: str) -> R3DPlan:
    """Read plan ``name`` of the folder ``root``.

    Raises:
        InputError: a file is missing or unreadable, or the four images differ in size.
    """
    root = Path(root)
    image = _read(root / f"{name}.jpg", cv2.IMREAD_GRAYSCALE)
    rooms = _read(root / f"{name}_rooms.png", cv2.IMREAD_COLOR)[:, :, ::-1]
    wall = _read(root / f"{name}_wall.png", cv2.IMREAD_GRAYSCALE)
    close = _read(root / f"{name}_close.png", cv2.IMREAD_GRAYSCALE)
    if not image.shape == rooms.shape[:2] == wall.shape == close.shape:
        raise InputError(f"R3D plan {name}: its images differ in size")
    labels = np.zeros(image.shape, np.uint8)
    for colour, r3d_class in ROOM_COLOURS.items():
        labels[np.all(rooms == colour, axis=2)] = R3D_ID[r3d_class]
    labels[wall > 3] = R3D_ID["wall"]
    labels[close > 3] = R3D_ID["opening"]
    return R3DPlan(name, image, labels)


def enlarged(plan: R3DPlan, factor: float) -> R3DPlan:
    """``plan`` as a scan at ``factor`` times its resolution: the drawing resized bicubically,
    the labels by nearest neighbour."""
    if factor == 1.0:
        return plan
    h, w = plan.image.shape
    size = (max(1, round(w * factor)), max(1, round(h * factor)))
    image = cv2.resize(plan.image, size, interpolation=cv2.INTER_CUBIC)
    labels = cv2.resize(plan.labels, size, interpolation=cv2.INTER_NEAREST)
    return R3DPlan(plan.name, image, labels)


def askew(plan: R3DPlan, degrees: float) -> R3DPlan:
    """``plan`` as a scan of the page laid ``degrees`` askew (counter-clockwise as shown) and the
    skew step run on it as ``run`` runs it (:mod:`f2n_drake.perception.skew`): the drawing turned
    bicubically on its own canvas, white paper at the corners, then turned upright by the skew
    measured on it; the labels turned alike by nearest neighbour."""
    from f2n_drake.perception.skew import skew_deg, upright
    from f2n_drake.perception.wall_angles import turn_matrix

    if degrees == 0.0:
        return plan
    h, w = plan.image.shape
    matrix = cv2.getRotationMatrix2D((w / 2, h / 2), degrees, 1.0)
    image = cv2.warpAffine(plan.image, matrix, (w, h), flags=cv2.INTER_CUBIC, borderValue=255)
    labels = cv2.warpAffine(plan.labels, matrix, (w, h), flags=cv2.INTER_NEAREST, borderValue=0)
    skew = skew_deg(image)
    if skew == 0.0:
        return R3DPlan(plan.name, image, labels)
    matrix, size = turn_matrix(image.shape, skew)
    labels = cv2.warpAffine(labels, matrix, size, flags=cv2.INTER_NEAREST, borderValue=0)
    return R3DPlan(plan.name, upright(image, skew), labels)


def scanned_turned(plan: R3DPlan, turns: int) -> R3DPlan:
    """``plan`` as a page scanned ``turns`` quarter turns counter-clockwise off upright (on its
    side, or upside down), and the orientation step run on it as ``run`` runs it
    (:mod:`f2n_drake.perception.orientation`): turned back where its words say so, its labels
    alike (quarter turns resample nothing)."""
    from f2n_drake.perception.orientation import quarter_turns, turned

    if turns % 4 == 0:
        return plan
    image, labels = turned(plan.image, turns), turned(plan.labels, turns)
    back = quarter_turns(image)
    return R3DPlan(plan.name, turned(image, back), turned(labels, back))


def textured_floors(plan: R3DPlan, seed: int = 0) -> R3DPlan:
    """``plan`` as a rendered listing paints its floors, in grey
    (:func:`~f2n_drake.datasets.looks.painted_floors`): its living rooms, bedrooms and halls
    laid with planks of one wood, edges every 5-14 px, its bathrooms with tiles, joints every
    8-16 px; the labels as they are. Random per plan from ``seed`` and the plan's name."""
    from f2n_drake.datasets.looks import painted_floors

    rng = np.random.default_rng([seed, zlib.crc32(plan.name.encode())])
    floors = [
        (plan.labels == R3D_ID[name], "tiles" if name == "bathroom" else "planks")
        for name in ("living", "bedroom", "hall", "bathroom")
    ]
    image = painted_floors(plan.image, floors, rng, plank_px=(5, 15), tile_px=(8, 17))
    return R3DPlan(plan.name, image, plan.labels)


def on_squared_paper(plan: R3DPlan, spacing_px: int, grey: int = 200) -> R3DPlan:
    """``plan`` drawn on squared paper: a grid of lines one pixel wide, ``spacing_px`` apart
    and ``grey`` dark, printed under the drawing (each pixel the darker of the two); the
    labels as they are."""
    if spacing_px < 2 or not 0 <= grey <= 255:
        raise InputError(
            f"squared paper needs a spacing of 2 px or more and a grey in 0-255, got "
            f"{spacing_px} px and {grey}"
        )
    from f2n_drake.datasets import looks

    return R3DPlan(plan.name, looks.on_squared_paper(plan.image, spacing_px, grey), plan.labels)


def coarse_scan(plan: R3DPlan, quality: int = 50) -> R3DPlan:
    """``plan`` as a coarse scan: the drawing shrunk to half its size (area averaging), saved as
    JPEG at ``quality`` and enlarged back bilinearly, so thin grey lines fade and blocks of JPEG
    noise sit round every stroke; the labels as they are."""
    if not 1 <= quality <= 100:
        raise InputError(f"a scan's JPEG quality must be in 1-100, got {quality}")
    h, w = plan.image.shape
    small = cv2.resize(plan.image, (max(1, w // 2), max(1, h // 2)), interpolation=cv2.INTER_AREA)
    _, jpeg = cv2.imencode(".jpg", small, [cv2.IMWRITE_JPEG_QUALITY, quality])
    coarse = cv2.imdecode(jpeg, cv2.IMREAD_GRAYSCALE)
    return R3DPlan(
        plan.name, cv2.resize(coarse, (w, h), interpolation=cv2.INTER_LINEAR), plan.labels
    )


def r3d_names(root: str | Path) -> list[str]:
    """Sorted names of the complete plans (a drawing and its three label images) in ``root``.

    Raises:
        InputError: the folder holds none.
    """
    root = Path(root)
    names = sorted(
        p.stem
        for p in root.glob("*.jpg")
        if all((root / f"{p.stem}_{part}.png").is_file() for part in ("rooms", "wall", "close"))
    )
    if not names:
        raise InputError(f"no R3D plans (NAME.jpg with NAME_rooms/_wall/_close.png) in {root}")
    return names


def dev_split_names() -> list[str]:
    """Names of the fixed development split (:data:`DEV_SPLIT_FILE`)."""
    lines = DEV_SPLIT_FILE.read_text().splitlines()
    return [line.strip() for line in lines if line.strip() and not line.startswith("#")]


def choose_dev_split(names: list[str], count: int = 30, seed: int = 30) -> list[str]:
    """The rule that made :data:`DEV_SPLIT_FILE`: ``count`` of the sorted ``names`` drawn
    without replacement by ``numpy.random.default_rng(seed)``, returned sorted."""
    rng = np.random.default_rng(seed)
    picked = rng.choice(len(names), size=count, replace=False)
    return sorted(sorted(names)[i] for i in picked)


def split_names(root: str | Path, split: str = "dev") -> list[str]:
    """Names of ``root``'s plans in ``split``: "dev" (those of the development split found in
    ``root``), "train" (the others) or "all".

    Raises:
        InputError: an unknown split, or none of its plans in ``root``.
    """
    if split not in SPLITS:
        raise InputError(f"unknown R3D split {split!r}; choose from {', '.join(SPLITS)}")
    names = r3d_names(root)
    dev = set(dev_split_names())
    chosen = {
        "dev": [n for n in names if n in dev],
        "train": [n for n in names if n not in dev],
        "all": names,
    }[split]
    if not chosen:
        raise InputError(f"no plan of the R3D {split} split in {root}")
    return chosen
