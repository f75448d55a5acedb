"""Watches the robot's clearance to the walls and furniture, and to the people, in SceneGraph."""

from __future__ import annotations

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.geometry import QueryObject, Role
from pydrake.systems.framework import Context, DiscreteValues, LeafSystem, ValueProducer

from f2n_drake.systems.vectors import CollisionStatus, PersonCollisions

PEOPLE_SOURCE = "people"
"""Name of the SceneGraph source whose geometry is people (:mod:`f2n_drake.systems.people`)."""


def clearance_m(query: QueryObject, max_distance_m: float) -> float:
    """Smallest signed distance [m] between any two proximity geometries that may collide
    (the robot and the walls; anchored pairs are filtered out), capped at ``max_distance_m``."""
    pairs = query.ComputeSignedDistancePairwiseClosestPoints(max_distance_m)
    distances = [pair.distance for pair in pairs]
    return float(min(distances, default=max_distance_m))


def split_clearances_m(
    query: QueryObject, max_distance_m: float, people: frozenset
) -> tuple[float, float]:
    """(smallest signed distance [m] of the pairs with no geometry in ``people``, smallest of the
    pairs with one), each capped at ``max_distance_m``. Pairs the collision filters exclude
    (anchored pairs, people with each other and with the walls) are never computed."""
    static, person = max_distance_m, max_distance_m
    for pair in query.ComputeSignedDistancePairwiseClosestPoints(max_distance_m):
        if pair.id_A in people or pair.id_B in people:
            person = min(person, pair.distance)
        else:
            static = min(static, pair.distance)
    return float(static), float(person)


class CollisionMonitor(LeafSystem):
    """Collisions with walls and furniture, and contacts with people, sampled at 1 / ``period_s``
    Hz.

    The robot is in collision when its cylinder's signed distance to a wall or a piece of
    furniture is <= 0 (signed distance, not penetration: a centre inside a wall gives a z-normal
    penetration), and in contact with a person when its distance to a person's cylinder (the
    geometry of the SceneGraph source named ``people_source``) is <= 0. Distances beyond
    ``max_distance_m`` are reported as ``max_distance_m``.

    .. pydrake_system::

        name: CollisionMonitor
        input_ports:
        - geometry_query
        output_ports:
        - collision
        - person_collision

    ``collision`` is a :data:`~f2n_drake.systems.vectors.CollisionStatus` of the walls and
    furniture: collided (0/1, at the last sample), min_clearance_m (smallest signed distance
    seen so far, m), count (samples in collision so far). ``person_collision`` is a
    :data:`~f2n_drake.systems.vectors.PersonCollisions`: in_contact (0/1), min_clearance_m [m],
    contacts (each run of samples in contact counts once).
    """

    def __init__(
        self,
        robot_radius: float = 0.105,
        period_s: float = 0.1,
        max_distance_m: float = 0.5,
        people_source: str = PEOPLE_SOURCE,
    ) -> None:
        super().__init__()
        self.robot_radius = float(robot_radius)  # documented size; the geometry carries it
        self.max_distance_m = float(max_distance_m)
        self._people_source = people_source
        self._query_port = self.DeclareAbstractInputPort(
            "geometry_query", AbstractValue.Make(QueryObject())
        )
        self._people_cache = self.DeclareCacheEntry(
            description="people geometry ids",
            value_producer=ValueProducer(
                allocate=lambda: AbstractValue.Make(frozenset()), calc=self._calc_people
            ),
            prerequisites_of_calc={self.nothing_ticket()},
        )
        self._collision_index = self.DeclareDiscreteState(
            CollisionStatus(np.array([0.0, self.max_distance_m, 0.0]))[:]
        )
        self._person_index = self.DeclareDiscreteState(
            PersonCollisions(np.array([0.0, self.max_distance_m, 0.0]))[:]
        )
        self.DeclarePeriodicDiscreteUpdateEvent(period_s, 0.0, self._update)
        self._collision_port = self.DeclareStateOutputPort("collision", self._collision_index)
        self._person_port = self.DeclareStateOutputPort("person_collision", self._person_index)

    def _calc_people(self, context: Context, value: AbstractValue) -> None:
        inspector = self._query_port.Eval(context).inspector()
        value.set_value(
            frozenset(
                geometry_id
                for geometry_id in inspector.GetAllGeometryIds(Role.kProximity)
                if inspector.GetOwningSourceName(geometry_id) == self._people_source
            )
        )

    def _update(self, context: Context, discrete_state: DiscreteValues) -> None:
        status = CollisionStatus(context.get_discrete_state(self._collision_index).CopyToVector())
        person = PersonCollisions(context.get_discrete_state(self._person_index).CopyToVector())
        static_m, person_m = split_clearances_m(
            self._query_port.Eval(context), self.max_distance_m, self._people_cache.Eval(context)
        )
        status.collided = float(static_m <= 0.0)
        status.min_clearance_m = min(status.min_clearance_m, static_m)
        status.count += status.collided
        touching = float(person_m <= 0.0)
        person.contacts += float(touching and not person.in_contact)
        person.in_contact = touching
        person.min_clearance_m = min(person.min_clearance_m, person_m)
        discrete_state.set_value(self._collision_index, status[:])
        discrete_state.set_value(self._person_index, person[:])
