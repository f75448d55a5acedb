"""People walking in the building: one upright cylinder each, moved along its walk at 10 Hz."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.geometry import (
    CollisionFilterDeclaration,
    Cylinder,
    FramePoseVector,
    GeometryFrame,
    GeometryInstance,
    GeometrySet,
    MakePhongIllustrationProperties,
    ProximityProperties,
    SceneGraph,
)
from pydrake.math import RigidTransform
from pydrake.systems.framework import (
    BasicVector,
    Context,
    DiagramBuilder,
    DiscreteValues,
    LeafSystem,
)

from f2n_drake.systems.collision_monitor import PEOPLE_SOURCE
from f2n_drake.world.building import Person
from f2n_drake.world.walkers import position_on_walk, walk_table

PERSON_HEIGHT_M = 1.7
PERSON_RGBA = np.array([0.2, 0.45, 0.85, 1.0])


class People(LeafSystem):
    """People walking their paths to and fro (:class:`~f2n_drake.world.building.Person`), who
    wait for the robot rather than walk into it.

    Each person's place on the round trip of its walk [m] is discrete state, advanced by
    ``speed_mps * period_s`` every ``period_s`` (10 Hz) unless the robot stands ahead: when the
    robot's disc (centre ``true_pose``, radius ``robot_radius_m``) comes within ``margin_m`` of
    the person's disc anywhere on the next ``lookahead_m`` of the walk, the person waits. So a
    robot that stops is never walked into; a robot that drives into a person is its own fault.
    A person kept waiting ``patience_s`` turns back the way they came (a robot and a person that
    each wait for the other in a corridor do not wait for ever).

    .. pydrake_system::

        name: People
        input_ports:
        - true_pose
        output_ports:
        - geometry_pose
        - positions

    ``true_pose`` is the robot's [x, y, theta] (m, rad); ``geometry_pose`` the FramePoseVector of
    the people's frames (valid once :meth:`RegisterGeometry` or :meth:`AddToBuilder` ran);
    ``positions`` their [x0, y0, x1, y1, ...] [m].
    """

    def __init__(
        self,
        people: Sequence[Person],
        *,
        robot_radius_m: float = 0.105,
        period_s: float = 0.1,
        lookahead_m: float = 0.6,
        margin_m: float = 0.1,
        patience_s: float = 3.0,
    ) -> None:
        super().__init__()
        if not people or not period_s > 0 or min(lookahead_m, margin_m, patience_s) < 0:
            raise ValueError("People: need people, period_s > 0, lookahead, margin, patience >= 0")
        self.people = tuple(people)
        self.period_s = float(period_s)
        self._robot_radius_m, self._margin_m = float(robot_radius_m), float(margin_m)
        self._lookahead_m = float(lookahead_m)
        self._patience_ticks = int(round(patience_s / self.period_s))
        self._tables = [walk_table(p.path_m) for p in self.people]
        self._round_trip_m = np.array([2 * table[1][-1] for table in self._tables])
        self._ahead = np.linspace(0.0, 1.0, 7)  # share of the look-ahead checked
        self._frame_ids: list = []
        self._source_id = None
        self._pose_port = self.DeclareVectorInputPort("true_pose", 3)
        offsets = np.array([p.offset_m for p in self.people], dtype=float)
        self._offset_index = self.DeclareDiscreteState(BasicVector(offsets))
        self._waited_index = self.DeclareDiscreteState(np.zeros(len(self.people)))
        self.DeclarePeriodicDiscreteUpdateEvent(self.period_s, 0.0, self._update)
        self.DeclareAbstractOutputPort(
            "geometry_pose",
            lambda: AbstractValue.Make(FramePoseVector()),
            self._calc_geometry_pose,
            prerequisites_of_calc={self.xd_ticket()},
        )
        self.DeclareVectorOutputPort(
            "positions",
            2 * len(self.people),
            self._calc_positions,
            prerequisites_of_calc={self.xd_ticket()},
        )

    def positions_at(self, offsets_m: np.ndarray) -> np.ndarray:
        """(N, 2) positions [m] of the people at round-trip places ``offsets_m`` (N,) [m]."""
        return np.vstack(
            [
                position_on_walk(p.path_m, [u], table)
                for p, u, table in zip(self.people, offsets_m, self._tables, strict=True)
            ]
        )

    def waits(self, i: int, offset_m: float, robot_xy: np.ndarray) -> bool:
        """Whether person ``i`` at ``offset_m`` [m] waits for a robot at ``robot_xy`` [m]: the
        robot stands on the next ``lookahead_m`` of the walk and the next step goes toward it
        (nobody waits for a robot behind them)."""
        person = self.people[i]
        step = person.speed_mps * self.period_s
        span = max(step, self._lookahead_m) - step
        ahead = position_on_walk(
            person.path_m, offset_m + step + span * self._ahead, self._tables[i]
        )
        here = position_on_walk(person.path_m, [offset_m], self._tables[i])[0]
        if np.hypot(*(ahead[0] - robot_xy)) >= np.hypot(*(here - robot_xy)):
            return False  # walking away from the robot
        reach = person.radius_m + self._robot_radius_m + self._margin_m
        return bool(np.min(np.hypot(*(ahead - robot_xy).T)) < reach)

    def _offsets(self, context: Context) -> np.ndarray:
        return context.get_discrete_state(self._offset_index).CopyToVector()

    def _update(self, context: Context, discrete_state: DiscreteValues) -> None:
        robot_xy = np.asarray(self._pose_port.Eval(context)[:2], dtype=float)
        offsets = self._offsets(context)
        waited = context.get_discrete_state(self._waited_index).CopyToVector()
        for i, person in enumerate(self.people):
            if not self.waits(i, offsets[i], robot_xy):
                offsets[i] += person.speed_mps * self.period_s
                waited[i] = 0.0
            elif waited[i] >= self._patience_ticks:  # same place, walking the other way
                offsets[i] = self._round_trip_m[i] - offsets[i] % self._round_trip_m[i]
                waited[i] = 0.0
            else:
                waited[i] += 1.0
        discrete_state.set_value(self._offset_index, offsets)
        discrete_state.set_value(self._waited_index, waited)

    def _calc_positions(self, context: Context, output: BasicVector) -> None:
        output.SetFromVector(self.positions_at(self._offsets(context)).reshape(-1))

    def _calc_geometry_pose(self, context: Context, output: AbstractValue) -> None:
        if not self._frame_ids:
            raise RuntimeError("People: call RegisterGeometry/AddToBuilder first")
        poses = output.get_mutable_value()
        for frame_id, xy in zip(
            self._frame_ids, self.positions_at(self._offsets(context)), strict=True
        ):
            poses.set_value(frame_id, RigidTransform([xy[0], xy[1], 0.0]))

    def RegisterGeometry(self, scene_graph: SceneGraph) -> None:
        """Register the source ``"people"``, a frame and an upright cylinder (proximity and
        illustration) per person, and filter out collisions of people with each other and with
        the anchored geometry (walls, furniture) registered so far: only the robot touches them.
        """
        self._source_id = scene_graph.RegisterSource(PEOPLE_SOURCE)
        geometry_ids = []
        for i, person in enumerate(self.people):
            frame_id = scene_graph.RegisterFrame(self._source_id, GeometryFrame(f"person_{i}"))
            body = GeometryInstance(
                RigidTransform([0.0, 0.0, PERSON_HEIGHT_M / 2]),
                Cylinder(person.radius_m, PERSON_HEIGHT_M),
                f"person_{i}",
            )
            body.set_proximity_properties(ProximityProperties())
            body.set_illustration_properties(MakePhongIllustrationProperties(PERSON_RGBA))
            geometry_ids.append(scene_graph.RegisterGeometry(self._source_id, frame_id, body))
            self._frame_ids.append(frame_id)
        people = GeometrySet(geometry_ids)
        world = GeometrySet(scene_graph.model_inspector().world_frame_id())
        scene_graph.collision_filter_manager().Apply(
            CollisionFilterDeclaration().ExcludeWithin(people).ExcludeBetween(people, world)
        )

    @property
    def source_id(self):
        """SceneGraph SourceId of the people (None before RegisterGeometry)."""
        return self._source_id

    @staticmethod
    def AddToBuilder(
        builder: DiagramBuilder,
        scene_graph: SceneGraph,
        people: Sequence[Person],
        *,
        name: str = "people",
        **options,
    ) -> People:
        """Add a People system named ``name`` (``options``: those of :class:`People`), register
        its geometry and connect its poses to SceneGraph; connect ``true_pose`` yourself."""
        system = builder.AddNamedSystem(name, People(people, **options))
        system.RegisterGeometry(scene_graph)
        builder.Connect(
            system.GetOutputPort("geometry_pose"),
            scene_graph.get_source_pose_port(system.source_id),
        )
        return system


__all__ = ["People"]
