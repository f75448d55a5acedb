"""Watches the robot's clearance to the walls in SceneGraph."""

from __future__ import annotations

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.geometry import QueryObject
from pydrake.systems.framework import Context, DiscreteValues, LeafSystem

from f2n_drake.systems.vectors import CollisionStatus


def clearance_m(query: QueryObject, max_distance_m: float) -> float:
    """Smallest signed distance [m] between any two proximity geometries that may collide
    (the robot and the walls; anchored pairs are filtered out), capped at ``max_distance_m``."""
    pairs = query.ComputeSignedDistancePairwiseClosestPoints(max_distance_m)
    distances = [pair.distance for pair in pairs]
    return float(min(distances, default=max_distance_m))


class CollisionMonitor(LeafSystem):
    """Collision flag, closest approach and collision ticks, sampled at 1 / ``period_s`` Hz.

    The robot is in collision when its cylinder's signed distance to a wall is <= 0 (signed
    distance, not penetration: a centre inside a wall gives a z-normal penetration). Distances
    beyond ``max_distance_m`` are reported as ``max_distance_m``.

    .. pydrake_system::

        name: CollisionMonitor
        input_ports:
        - geometry_query
        output_ports:
        - collision

    ``collision`` is a :data:`~f2n_drake.systems.vectors.CollisionStatus`: collided (0/1, at the
    last sample), min_clearance_m (smallest signed distance seen so far, m), count (samples in
    collision so far).
    """

    def __init__(
        self, robot_radius: float = 0.105, period_s: float = 0.1, max_distance_m: float = 0.5
    ) -> None:
        super().__init__()
        self.robot_radius = float(robot_radius)  # documented size; the geometry carries it
        self.max_distance_m = float(max_distance_m)
        self._query_port = self.DeclareAbstractInputPort(
            "geometry_query", AbstractValue.Make(QueryObject())
        )
        self._collision_index = self.DeclareDiscreteState(
            CollisionStatus(np.array([0.0, self.max_distance_m, 0.0]))[:]
        )
        self.DeclarePeriodicDiscreteUpdateEvent(period_s, 0.0, self._update)
        self._collision_port = self.DeclareStateOutputPort("collision", self._collision_index)

    def _update(self, context: Context, discrete_state: DiscreteValues) -> None:
        status = CollisionStatus(context.get_discrete_state(self._collision_index).CopyToVector())
        distance = clearance_m(self._query_port.Eval(context), self.max_distance_m)
        status.collided = float(distance <= 0.0)
        status.min_clearance_m = min(status.min_clearance_m, distance)
        status.count += status.collided
        discrete_state.set_value(self._collision_index, status[:])
