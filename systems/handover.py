"""Switches that hand the robot from careful exploration to route following once it is localized.

While ``localized`` reads not converged, :class:`CommandSwitch` passes the explorer's command and
:class:`PoseGate` shows the route systems an unknown pose (NaN: no waypoint is ever reached by
it), so the route is neither followed nor advanced on an estimate that means nothing yet (and
shows the viewer the localizer's best guess). From the handover on, the route controller's
command and the odometry's estimate pass through.
"""

from __future__ import annotations

import numpy as np
from pydrake.systems.framework import BasicVector, Context, LeafSystem


def _converged(port, context: Context) -> bool:
    return bool(port.Eval(context)[0] > 0.5)


class CommandSwitch(LeafSystem):
    """The explorer's command until localized, the route controller's after.

    .. pydrake_system::

        name: CommandSwitch
        input_ports:
        - explorer_command
        - route_command
        - localized
        output_ports:
        - command

    Commands are ``[v (m/s), omega (rad/s)]``; ``localized`` is ``[converged (0/1), ...]``.
    """

    def __init__(self, localized_size: int = 2) -> None:
        super().__init__()
        self._explorer_port = self.DeclareVectorInputPort("explorer_command", 2)
        self._route_port = self.DeclareVectorInputPort("route_command", 2)
        self._localized_port = self.DeclareVectorInputPort("localized", localized_size)
        self.DeclareVectorOutputPort(
            "command", 2, self._calc, prerequisites_of_calc={self.all_input_ports_ticket()}
        )

    def _calc(self, context: Context, output: BasicVector) -> None:
        localized = _converged(self._localized_port, context)
        output.SetFromVector((self._route_port if localized else self._explorer_port).Eval(context))


class PoseGate(LeafSystem):
    """The estimated pose once localized; before, ``unsure_pose`` or, unconnected,
    ``[nan, nan, nan]`` (unknown).

    .. pydrake_system::

        name: PoseGate
        input_ports:
        - estimated_pose
        - localized
        - unsure_pose
        output_ports:
        - route_pose

    ``estimated_pose``, ``unsure_pose`` and ``route_pose`` are ``[x, y, theta]`` (m, rad);
    ``localized`` is ``[converged (0/1), ...]``. (With the localizer's best guess as
    ``unsure_pose`` it is what a viewer shows.)
    """

    def __init__(self, localized_size: int = 2) -> None:
        super().__init__()
        self._pose_port = self.DeclareVectorInputPort("estimated_pose", 3)
        self._localized_port = self.DeclareVectorInputPort("localized", localized_size)
        self._unsure_port = self.DeclareVectorInputPort("unsure_pose", 3)
        self.DeclareVectorOutputPort(
            "route_pose", 3, self._calc, prerequisites_of_calc={self.all_input_ports_ticket()}
        )

    def _calc(self, context: Context, output: BasicVector) -> None:
        if _converged(self._localized_port, context):
            output.SetFromVector(self._pose_port.Eval(context))
        elif self._unsure_port.HasValue(context):
            output.SetFromVector(self._unsure_port.Eval(context))
        else:
            output.SetFromVector(np.full(3, np.nan))


__all__ = ["CommandSwitch", "PoseGate"]
