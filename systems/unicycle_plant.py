"""A differential-drive robot as a unicycle, with its cylinder body in SceneGraph."""

from __future__ import annotations

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.geometry import (
    Cylinder,
    FramePoseVector,
    GeometryFrame,
    GeometryInstance,
    MakePhongIllustrationProperties,
    ProximityProperties,
    SceneGraph,
)
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.systems.framework import (
    BasicVector,
    Context,
    ContinuousState,
    DiagramBuilder,
    LeafSystem,
)

from f2n_drake.mapping.robots import shipped_robot

ROBOT_RGBA = np.array([0.15, 0.15, 0.15, 1.0])


class UnicyclePlant(LeafSystem):
    r"""Planar unicycle x' = v cos(theta), y' = v sin(theta), theta' = omega.

    The command is clipped to the TurtleBot3 Burger limits (|v| <= 0.22 m/s,
    |omega| <= 2.84 rad/s). State and outputs are the true pose X_WR = [x, y, theta]
    (m, m, rad) of the robot R in the world W; theta is not wrapped.

    .. pydrake_system::

        name: UnicyclePlant
        input_ports:
        - command
        output_ports:
        - state
        - geometry_pose

    ``command`` is [v (m/s), omega (rad/s)]; ``geometry_pose`` is the FramePoseVector of the
    robot body frame, valid once :meth:`AddToBuilder` (or :meth:`RegisterGeometry`) ran.
    """

    def __init__(
        self,
        x0: np.ndarray = (0.0, 0.0, 0.0),
        *,
        v_max: float | None = None,
        omega_max: float | None = None,
    ) -> None:
        super().__init__()
        robot = shipped_robot("ground")  # models/turtlebot3_burger.yaml
        limits = robot.limits
        self.v_max = limits.max_linear_velocity_mps if v_max is None else float(v_max)
        self.omega_max = (
            limits.max_angular_velocity_radps if omega_max is None else float(omega_max)
        )
        self.radius_m, self.height_m = robot.body.radius_m, robot.body.height_m
        self._frame_id = None
        self._source_id = None
        self._command_port = self.DeclareVectorInputPort("command", 2)
        self.DeclareContinuousState(BasicVector(np.asarray(x0, float)))
        self._state_port = self.DeclareVectorOutputPort(
            "state", 3, self._calc_state, prerequisites_of_calc={self.xc_ticket()}
        )
        self._pose_port = self.DeclareAbstractOutputPort(
            "geometry_pose",
            lambda: AbstractValue.Make(FramePoseVector()),
            self._calc_geometry_pose,
            prerequisites_of_calc={self.xc_ticket()},
        )

    def clip(self, command: np.ndarray) -> np.ndarray:
        """[v, omega] clipped to the velocity limits."""
        v, omega = command
        return np.array(
            [np.clip(v, -self.v_max, self.v_max), np.clip(omega, -self.omega_max, self.omega_max)]
        )

    def DoCalcTimeDerivatives(self, context: Context, derivatives: ContinuousState) -> None:
        theta = context.get_continuous_state_vector().GetAtIndex(2)
        v, omega = self.clip(self._command_port.Eval(context))
        derivatives.get_mutable_vector().SetFromVector(
            [v * np.cos(theta), v * np.sin(theta), omega]
        )

    def _calc_state(self, context: Context, output: BasicVector) -> None:
        output.SetFromVector(context.get_continuous_state_vector().CopyToVector())

    def _calc_geometry_pose(self, context: Context, output: AbstractValue) -> None:
        if self._frame_id is None:
            raise RuntimeError("UnicyclePlant: call RegisterGeometry/AddToBuilder first")
        x, y, theta = context.get_continuous_state_vector().CopyToVector()
        X_WR = RigidTransform(RotationMatrix.MakeZRotation(theta), [x, y, 0.0])
        output.get_mutable_value().set_value(self._frame_id, X_WR)

    def RegisterGeometry(self, scene_graph: SceneGraph) -> None:
        """Register a source, the body frame and its cylinder (proximity + illustration)."""
        source_id = scene_graph.RegisterSource("robot")
        self._frame_id = scene_graph.RegisterFrame(source_id, GeometryFrame("robot_body"))
        X_RG = RigidTransform([0.0, 0.0, self.height_m / 2])
        body = GeometryInstance(X_RG, Cylinder(self.radius_m, self.height_m), "robot_cylinder")
        body.set_proximity_properties(ProximityProperties())
        body.set_illustration_properties(MakePhongIllustrationProperties(ROBOT_RGBA))
        scene_graph.RegisterGeometry(source_id, self._frame_id, body)
        self._source_id = source_id

    @property
    def source_id(self):
        """SceneGraph SourceId of the robot (None before RegisterGeometry)."""
        return self._source_id

    @staticmethod
    def AddToBuilder(
        builder: DiagramBuilder,
        scene_graph: SceneGraph,
        x0: np.ndarray = (0.0, 0.0, 0.0),
        name: str = "plant",
    ) -> UnicyclePlant:
        """Add a plant named ``name``, register its geometry and connect its pose port."""
        plant = builder.AddNamedSystem(name, UnicyclePlant(x0))
        plant.RegisterGeometry(scene_graph)
        builder.Connect(
            plant.GetOutputPort("geometry_pose"),
            scene_graph.get_source_pose_port(plant.source_id),
        )
        return plant
