"""People's walks: paths between rooms through the building's free space, walked to and fro.

Each person walks between a random free spot of one room and one of another room (seeded), along
the shortest 8-connected path (:func:`f2n_drake.planning.astar.astar`) on a raster where every
obstacle (walls as built, closed doors, furniture) is grown by the person's radius and
``PERSON_CLEARANCE_M``, shortened by line of sight on that raster
(:func:`f2n_drake.planning.smoothing.shortcut`). A person never starts within
``START_CLEARANCE_M`` of a point to keep clear (the robot's start).
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage
from shapely.geometry import Polygon
from shapely.geometry.base import BaseGeometry

from f2n_drake.planning.astar import astar
from f2n_drake.planning.smoothing import shortcut
from f2n_drake.world.building import Person
from f2n_drake.world.free_space import FloorRaster

PERSON_RADIUS_M = 0.25
PERSON_CLEARANCE_M = 0.05
WALKING_SPEED_MPS = (1.0, 1.4)
START_CLEARANCE_M = 1.0
MIN_SPOT_CLEARANCE_M = 0.1
"""A walk's end is a cell at least this far [m] inside the person's free space."""


def walk_table(path_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(path (N, 2) [m], distance along it at each vertex (N,) [m]) for :func:`position_on_walk`."""
    path = np.asarray(path_m, float).reshape(-1, 2)
    return path, np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(path, axis=0).T))])


def position_on_walk(
    path_m: np.ndarray, offset_m: np.ndarray, table: tuple[np.ndarray, np.ndarray] | None = None
) -> np.ndarray:
    """(K, 2) positions [m] at ``offset_m`` (K,) along the round trip of ``path_m`` (out along
    the path, then back: period twice its length); ``table``: :func:`walk_table` of the path, if
    already made."""
    path, cumulative = walk_table(path_m) if table is None else table
    length = cumulative[-1]
    if length <= 0:
        return np.repeat(path[:1], np.size(offset_m), axis=0)
    s = np.mod(np.asarray(offset_m, float).reshape(-1), 2 * length)
    s = np.where(s > length, 2 * length - s, s)
    return np.column_stack(
        [np.interp(s, cumulative, path[:, 0]), np.interp(s, cumulative, path[:, 1])]
    )


def walk_length_m(path_m: np.ndarray) -> float:
    """Length [m] of a walk's path (half its round trip)."""
    return float(np.hypot(*np.diff(np.asarray(path_m, float), axis=0).T).sum())


def plan_walks(
    raster: FloorRaster,
    obstacles: BaseGeometry,
    rooms: list[Polygon],
    count: int,
    rng: np.random.Generator,
    keep_clear_xy: list[np.ndarray],
    inside: np.ndarray | None = None,
    radius_m: float = PERSON_RADIUS_M,
) -> list[Person]:
    """Up to ``count`` people walking between pairs of ``rooms`` (fewer when no two rooms are
    joined for a person) within the cells of ``inside`` (default: all); module docstring for
    the rest."""
    if count <= 0 or len(rooms) < 2:
        return []
    free = ~raster.blocked_by(obstacles, radius_m + PERSON_CLEARANCE_M)
    if inside is not None:
        free &= inside
    depth = ndimage.distance_transform_edt(free) * raster.cell_m
    spots = []
    for room in rooms:
        cells = np.argwhere(raster.cover(room) & (depth >= MIN_SPOT_CLEARANCE_M))
        spots.append(cells)
    usable = [i for i, cells in enumerate(spots) if len(cells)]
    people: list[Person] = []
    for _ in range(20 * count):
        if len(people) == count or len(usable) < 2:
            break
        a, b = rng.choice(usable, size=2, replace=False)
        start = tuple(spots[a][rng.integers(len(spots[a]))])
        goal = tuple(spots[b][rng.integers(len(spots[b]))])
        found = astar(free, start, goal)
        if not found.found or len(found.cells) < 2:
            continue
        path = raster.points_of(shortcut(found.cells, free))
        length = walk_length_m(path)
        for _ in range(20):
            offset = rng.uniform(0.0, 2 * length)
            at = position_on_walk(path, np.array([offset]))[0]
            if all(np.hypot(*(at - np.asarray(xy))) > START_CLEARANCE_M for xy in keep_clear_xy):
                break
        else:
            continue
        speed = rng.uniform(*WALKING_SPEED_MPS)
        people.append(Person(path, float(speed), float(radius_m), float(offset)))
    return people


__all__ = [
    "PERSON_RADIUS_M",
    "WALKING_SPEED_MPS",
    "plan_walks",
    "position_on_walk",
    "walk_length_m",
    "walk_table",
]
