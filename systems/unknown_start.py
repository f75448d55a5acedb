"""The systems a robot that does not know its start pose adds to the navigation Diagram.

:func:`AddGlobalLocalization` adds the :class:`~f2n_drake.systems.global_localizer.GlobalLocalizer`
(Monte Carlo localization on the plan), the
:class:`~f2n_drake.systems.explorer.CarefulExplorer` (slow, safe motion from the scan while
unsure), the :class:`~f2n_drake.systems.handover.CommandSwitch` and
:class:`~f2n_drake.systems.handover.PoseGate` (explorer and no route until localized, the route
after), and with meshcat a :class:`~f2n_drake.systems.particle_view.ParticleView`. The caller
connects the route controller's command to the switch, the switch to the robot, the gate to the
route systems and the localizer's ``pose_correction`` to the odometry.
"""

from __future__ import annotations

from dataclasses import dataclass

from pydrake.geometry import Meshcat
from pydrake.systems.framework import DiagramBuilder, OutputPort

from f2n_drake.localization.likelihood_field import LikelihoodField
from f2n_drake.localization.particle_filter import FilterOptions
from f2n_drake.mapping.robots import LidarSpec
from f2n_drake.mapping.walls import PlanGeometry
from f2n_drake.systems.explorer import CarefulExplorer, CarefulMotion
from f2n_drake.systems.global_localizer import GlobalLocalizer
from f2n_drake.systems.handover import CommandSwitch, PoseGate
from f2n_drake.systems.particle_view import ParticleView


@dataclass(frozen=True)
class GlobalLocalization:
    """The systems :func:`AddGlobalLocalization` added."""

    localizer: GlobalLocalizer
    explorer: CarefulExplorer
    switch: CommandSwitch
    gate: PoseGate
    view: ParticleView | None
    shown: PoseGate | None


def AddGlobalLocalization(
    builder: DiagramBuilder,
    geometry: PlanGeometry,
    *,
    seed: int,
    scan: OutputPort,
    odometry_pose: OutputPort,
    lidar: LidarSpec,
    robot_radius_m: float,
    period_s: float,
    offset_s: float,
    meshcat: Meshcat | None = None,
    particles_path: str | None = None,
) -> GlobalLocalization:
    """Add and connect the unknown-start systems (named ``"global_localizer"``,
    ``"explorer"``, ``"command_switch"``, ``"pose_gate"``, and with meshcat ``"particle_view"``
    and ``"shown_pose"``: the localizer's guess until the handover, the odometry's estimate
    after, for the run's viewer).

    Args:
        geometry: the plan the robot knows (its walls and free space).
        scan, odometry_pose: the LiDAR's scan and the odometry's estimate.
        lidar: the LiDAR's beams and range.
        period_s, offset_s: update period and first update [s] of the localizer and explorer
            (after the scan and the odometry tick of the same instant).
        meshcat, particles_path: draw the particle cloud there.
    """
    field = LikelihoodField.from_geometry(geometry, robot_radius_m=robot_radius_m)
    options = FilterOptions(min_range_m=lidar.min_range_m, max_range_m=lidar.max_range_m)
    localizer = builder.AddNamedSystem(
        "global_localizer",
        GlobalLocalizer(
            field,
            geometry.wall_segments(),
            seed,
            options=options,
            num_beams=lidar.num_beams,
            period_s=period_s,
            offset_s=offset_s,
        ),
    )
    motion = CarefulMotion(min_range_m=lidar.min_range_m, max_range_m=lidar.max_range_m)
    explorer = builder.AddNamedSystem(
        "explorer",
        CarefulExplorer(motion, num_beams=lidar.num_beams, period_s=period_s, offset_s=offset_s),
    )
    switch = builder.AddNamedSystem("command_switch", CommandSwitch())
    gate = builder.AddNamedSystem("pose_gate", PoseGate())
    localized = localizer.GetOutputPort("localized")
    for system in (localizer, explorer):
        builder.Connect(scan, system.GetInputPort("scan"))
        builder.Connect(odometry_pose, system.GetInputPort("odometry_pose"))
    builder.Connect(odometry_pose, gate.GetInputPort("estimated_pose"))
    builder.Connect(localized, gate.GetInputPort("localized"))
    builder.Connect(localized, switch.GetInputPort("localized"))
    builder.Connect(explorer.GetOutputPort("command"), switch.GetInputPort("explorer_command"))
    view = shown = None
    if meshcat is not None and particles_path is not None:
        view = builder.AddNamedSystem(
            "particle_view", ParticleView(meshcat, particles_path, offset_s=offset_s)
        )
        builder.Connect(localizer.GetOutputPort("particles"), view.GetInputPort("particles"))
        builder.Connect(localized, view.GetInputPort("localized"))
        shown = builder.AddNamedSystem("shown_pose", PoseGate())
        builder.Connect(odometry_pose, shown.GetInputPort("estimated_pose"))
        builder.Connect(localized, shown.GetInputPort("localized"))
        builder.Connect(localizer.GetOutputPort("pose_estimate"), shown.GetInputPort("unsure_pose"))
    return GlobalLocalization(localizer, explorer, switch, gate, view, shown)


__all__ = ["AddGlobalLocalization", "GlobalLocalization"]
