"""The building the robot drives in, as opposed to the plan it knows (metres).

A :class:`Building` is plain shapely/numpy data: the walls as built (the plan's walls, perhaps
displaced, with closed doors walled up), furniture footprints and people walking along paths.
``Building.as_planned(geometry)`` is the building that is exactly its plan.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from shapely.geometry import Polygon

from f2n_drake.mapping.walls import PlanGeometry


@dataclass(frozen=True)
class Person:
    """A person walking ``path_m`` ((N, 2) [m]) back and forth at ``speed_mps`` [m/s], drawn as an
    upright cylinder of ``radius_m`` [m]."""

    path_m: np.ndarray
    speed_mps: float = 1.0
    radius_m: float = 0.25


@dataclass(frozen=True)
class Building:
    """What the simulated sensors and the collision check see (metres).

    Attributes:
        walls: the walls as built, closed doors included (they are walls in the building).
        furniture: footprints of static obstacles the plan does not show.
        people: people walking in the building.
        closed_doors: graph node ids of the plan's doors that are closed in the building.
    """

    walls: tuple[Polygon, ...]
    furniture: tuple[Polygon, ...] = ()
    people: tuple[Person, ...] = ()
    closed_doors: tuple[str, ...] = ()

    @classmethod
    def as_planned(cls, geometry: PlanGeometry) -> Building:
        """The building that is exactly its plan: the plan's walls, nothing else."""
        return cls(walls=tuple(geometry.walls))

    def static_geometry(self, plan: PlanGeometry) -> PlanGeometry:
        """The building's static obstacles (walls and furniture) with the plan's floors and
        connectors for the figures."""
        return PlanGeometry([*self.walls, *self.furniture], plan.floors, plan.connectors)


__all__ = ["Building", "Person"]
