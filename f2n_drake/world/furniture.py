"""Furniture placed in a building's rooms: seeded boxes and cylinders covering a share of the
floor, mostly against the walls, never where the robot must pass.

What :func:`place_furniture` guarantees, for each room polygon:

- every piece lies inside the room, at least ``WALL_GAP_M`` from the walls and ``PIECE_GAP_M``
  from the other pieces, and outside ``keep_out`` (doorways and the route's start and goal, as
  :func:`f2n_drake.world.generation.make_building` builds it);
- the pieces cover at most ``fraction`` of the room's area, and at least ``fraction`` less
  ``MIN_PIECE_AREA_M2`` unless ``TRIES_PER_ROOM`` draws found no more room (small rooms with
  doors on every wall fall short: the true cover is reported, not assumed);
- with a :class:`RouteGuard`, no piece cuts the route's start from its goal for the robot's disc
  where they were joined before it (the route's path itself is not kept clear: furniture may
  stand on it, as it would in a real flat).

About 60 % of the pieces are boxes against a wall (cupboards, beds, desks), 20 % free-standing
boxes (tables) and 20 % cylinders (round tables, bins, plants).
"""

from __future__ import annotations

import math

import numpy as np
import shapely
from shapely.geometry import Point, Polygon
from shapely.geometry.base import BaseGeometry

from f2n_drake.mapping.walls import dominant_angle
from f2n_drake.world.building import Cylinder
from f2n_drake.world.free_space import FloorRaster, same_component

WALL_GAP_M = 0.02
PIECE_GAP_M = 0.03
MIN_PIECE_AREA_M2 = 0.1
TRIES_PER_ROOM = 300
AGAINST_WALL, FREE_STANDING = 0.6, 0.8  # cumulative shares of the kinds; the rest are cylinders


class RouteGuard:
    """Keeps the route's start and goal joined for a disc of ``radius_m`` [m] while obstacles
    are added, in each of several variants of the building (e.g. doors open, doors closed).

    Only the cells of ``inside`` (default: all) count as a way (a way round the outside of the
    building is no way). A variant where start and goal are apart from the outset is not watched.
    """

    def __init__(
        self,
        raster: FloorRaster,
        variants: list[BaseGeometry],
        start_xy: np.ndarray,
        goal_xy: np.ndarray,
        radius_m: float,
        inside: np.ndarray | None = None,
    ) -> None:
        self._raster, self._radius_m = raster, float(radius_m)
        self._ends = raster.cell_of(start_xy), raster.cell_of(goal_xy)
        outside = np.zeros(raster.shape, bool) if inside is None else ~inside
        self._blocked = [raster.blocked_by(v, radius_m) | outside for v in variants]
        self._watched = [same_component(~b, *self._ends) for b in self._blocked]

    def allows(self, piece: BaseGeometry) -> bool:
        """Whether adding ``piece`` keeps start and goal joined in every watched variant."""
        extra = self._raster.blocked_by(piece, self._radius_m)
        return all(
            not watched or same_component(~(blocked | extra), *self._ends)
            for blocked, watched in zip(self._blocked, self._watched, strict=True)
        )

    def add(self, piece: BaseGeometry) -> None:
        """Add ``piece`` to every variant."""
        extra = self._raster.blocked_by(piece, self._radius_m)
        for blocked in self._blocked:
            blocked |= extra


def rectangle(centre: np.ndarray, along: np.ndarray, length_m: float, depth_m: float) -> Polygon:
    """The rectangle centred at ``centre`` [m], ``length_m`` along the unit vector ``along`` and
    ``depth_m`` across it."""
    across = np.array([-along[1], along[0]])
    a, b = along * length_m / 2, across * depth_m / 2
    return Polygon([centre - a - b, centre + a - b, centre + a + b, centre - a + b])


def _against_wall(room: Polygon, rng: np.random.Generator, budget_m2: float) -> Polygon | None:
    """A box with its back along a random edge of the room (longer edges likelier)."""
    xy = np.asarray(room.exterior.coords)
    edges = np.diff(xy, axis=0)
    lengths = np.hypot(edges[:, 0], edges[:, 1])
    usable = lengths >= 0.6
    if not usable.any():
        return None
    k = rng.choice(np.flatnonzero(usable), p=lengths[usable] / lengths[usable].sum())
    along = edges[k] / lengths[k]
    normal = np.array([-along[1], along[0]])
    middle = xy[k] + edges[k] / 2
    if not room.contains(Point(*(middle + 0.05 * normal))):
        normal = -normal
    depth = rng.uniform(0.35, 0.8)
    length = min(rng.uniform(0.5, 1.8), lengths[k] - 0.1, budget_m2 / depth)
    if length < 0.3:
        return None
    s = rng.uniform(length / 2 + WALL_GAP_M, lengths[k] - length / 2 - WALL_GAP_M)
    centre = xy[k] + along * s + normal * (WALL_GAP_M + depth / 2)
    return rectangle(centre, along, length, depth)


def _random_point(room: Polygon, rng: np.random.Generator) -> np.ndarray:
    xmin, ymin, xmax, ymax = room.bounds
    return np.array([rng.uniform(xmin, xmax), rng.uniform(ymin, ymax)])


def _free_standing(room: Polygon, rng: np.random.Generator, budget_m2: float) -> Polygon | None:
    """A table: a box anywhere in the room, square to its walls."""
    angle = dominant_angle(room) + rng.choice([0.0, math.pi / 2])
    depth = rng.uniform(0.5, 1.0)
    length = min(rng.uniform(0.6, 1.6), budget_m2 / depth)
    if length < 0.3:
        return None
    along = np.array([math.cos(angle), math.sin(angle)])
    return rectangle(_random_point(room, rng), along, length, depth)


def _cylinder(room: Polygon, rng: np.random.Generator, budget_m2: float) -> Cylinder | None:
    radius = min(rng.uniform(0.15, 0.4), math.sqrt(budget_m2 / math.pi))
    if radius < 0.12:
        return None
    return Cylinder(tuple(_random_point(room, rng)), float(radius))


def place_furniture(
    rooms: list[Polygon],
    walls: BaseGeometry,
    keep_out: BaseGeometry,
    fraction: float,
    rng: np.random.Generator,
    guard: RouteGuard | None = None,
) -> tuple[list[Polygon], list[Cylinder]]:
    """Boxes and cylinders covering ``fraction`` of each room's floor (module docstring).

    Args:
        rooms: room floors [m]; walls: the walls as built; keep_out: where no piece may stand.
        fraction: share of each room's area to cover, 0 to 1.
        rng: the only source of randomness (same generator state, same furniture).
        guard: keeps the route's start and goal joined; pieces it refuses are redrawn.

    Returns (box footprints, cylinders).
    """
    boxes: list[Polygon] = []
    cylinders: list[Cylinder] = []
    if fraction <= 0:
        return boxes, cylinders
    shapely.prepare(walls)
    shapely.prepare(keep_out)
    for room in rooms:
        target = fraction * room.area
        inside = room.buffer(1e-6)
        shapely.prepare(inside)
        pieces: list[BaseGeometry] = []
        covered = 0.0
        for _ in range(TRIES_PER_ROOM):
            budget = target - covered
            if budget < MIN_PIECE_AREA_M2:
                break
            kind = rng.uniform()
            if kind < AGAINST_WALL:
                shape = _against_wall(room, rng, budget)
            elif kind < FREE_STANDING:
                shape = _free_standing(room, rng, budget)
            else:
                shape = _cylinder(room, rng, budget)
            if shape is None:
                continue
            footprint = shape.footprint() if isinstance(shape, Cylinder) else shape
            if (
                footprint.area > budget
                or not inside.contains(footprint)
                or footprint.intersects(keep_out)
                or footprint.distance(walls) < WALL_GAP_M - 1e-6
                or any(footprint.distance(p) < PIECE_GAP_M for p in pieces)
                or (guard is not None and not guard.allows(footprint))
            ):
                continue
            if guard is not None:
                guard.add(footprint)
            pieces.append(footprint)
            covered += footprint.area
            if isinstance(shape, Cylinder):
                cylinders.append(shape)
            else:
                boxes.append(shape)
    return boxes, cylinders


__all__ = ["MIN_PIECE_AREA_M2", "RouteGuard", "place_furniture", "rectangle"]
