"""The building the robot drives in, as opposed to the plan it knows (metres).

A :class:`Building` is plain shapely/numpy data: the walls as built (the plan's walls, perhaps
displaced, with closed doors walled up), furniture (box footprints and round
:class:`Cylinder` pieces) and people walking along paths. ``Building.as_planned(geometry)`` is
the building that is exactly its plan; :func:`f2n_drake.world.generation.make_building` makes
one that is not.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from shapely.geometry import Point, Polygon

from f2n_drake.mapping.walls import PlanGeometry


@dataclass(frozen=True)
class Person:
    """A person walking ``path_m`` ((N, 2) [m]) back and forth at ``speed_mps`` [m/s], drawn as an
    upright cylinder of ``radius_m`` [m]. ``offset_m`` [m] is where on the round trip (out along
    the path, then back; ``2 * length`` long) the person is at t = 0."""

    path_m: np.ndarray
    speed_mps: float = 1.0
    radius_m: float = 0.25
    offset_m: float = 0.0


@dataclass(frozen=True)
class Cylinder:
    """A round piece of furniture (table, bin, plant pot): an upright cylinder [m]."""

    centre_m: tuple[float, float]
    radius_m: float

    def footprint(self, quad_segs: int = 8) -> Polygon:
        """Its footprint as a polygon (``4 * quad_segs`` sides)."""
        return Point(*self.centre_m).buffer(self.radius_m, quad_segs=quad_segs)


@dataclass(frozen=True)
class Building:
    """What the simulated sensors and the collision check see (metres).

    Attributes:
        walls: the walls as built, closed doors included (they are walls in the building).
        furniture: footprints of static obstacles the plan does not show (boxes).
        people: people walking in the building.
        closed_doors: graph node ids of the plan's doors that are closed in the building.
            Ground truth for the evaluation: the robot never reads it.
        cylinders: round furniture.
        door_walls: the walls that close ``closed_doors`` (also in ``walls``), for drawing.
    """

    walls: tuple[Polygon, ...]
    furniture: tuple[Polygon, ...] = ()
    people: tuple[Person, ...] = ()
    closed_doors: tuple[str, ...] = ()
    cylinders: tuple[Cylinder, ...] = ()
    door_walls: tuple[Polygon, ...] = ()

    @classmethod
    def as_planned(cls, geometry: PlanGeometry) -> Building:
        """The building that is exactly its plan: the plan's walls, nothing else."""
        return cls(walls=tuple(geometry.walls))

    def static_geometry(self, plan: PlanGeometry) -> PlanGeometry:
        """The building's static obstacles (walls, furniture and the cylinders' footprints) with
        the plan's floors and connectors for the figures."""
        obstacles = [*self.walls, *self.furniture, *(c.footprint() for c in self.cylinders)]
        return PlanGeometry(obstacles, plan.floors, plan.connectors)


__all__ = ["Building", "Cylinder", "Person"]
