"""LidarCorrector LeafSystem: ports, when it fires, and what it outputs."""

from __future__ import annotations

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder

from f2n_drake.localization.scans import apply_pose_delta, simulate_scan
from f2n_drake.systems.lidar_corrector import LidarCorrector

ROOM = np.array([[0, 0, 5, 0], [5, 0, 5, 4], [5, 4, 0, 4], [0, 4, 0, 0]], dtype=float)
TRUE_POSE = np.array([2.0, 1.5, 0.05])
ESTIMATE = TRUE_POSE + np.array([0.2, -0.15, 0.0])


def make(mode: str, estimate=ESTIMATE, waypoint=0.0, **kwargs):
    system = LidarCorrector(ROOM, mode, **kwargs)
    context = system.CreateDefaultContext()
    rng = np.random.default_rng(0)
    system.GetInputPort("scan").FixValue(
        context, simulate_scan(TRUE_POSE, ROOM, noise_std_m=0.005, rng=rng)
    )
    system.GetInputPort("estimated_pose").FixValue(context, estimate)
    system.GetInputPort("waypoint_index").FixValue(context, [waypoint])
    return system, context


def step(system, context) -> None:
    """Apply one periodic discrete update to ``context``."""
    context.SetDiscreteState(system.EvalUniquePeriodicDiscreteUpdate(context))


def correction(system, context) -> np.ndarray:
    return system.GetOutputPort("pose_correction").Eval(context)


def test_ports_and_sizes():
    system = LidarCorrector(ROOM, "continuous", num_beams=180)
    sizes = {
        system.get_input_port(i).get_name(): system.get_input_port(i).size()
        for i in range(system.num_input_ports())
    }
    assert sizes == {"scan": 180, "estimated_pose": 3, "waypoint_index": 1}
    outputs = {
        system.get_output_port(i).get_name(): system.get_output_port(i).size()
        for i in range(system.num_output_ports())
    }
    assert outputs == {"pose_correction": 4, "fit_quality": 2, "correction_delta": 3}
    context = system.CreateDefaultContext()
    np.testing.assert_array_equal(correction(system, context), np.zeros(4))
    assert system.GetUniquePeriodicDiscreteUpdateAttribute().period_sec() == pytest.approx(0.2)


def test_bad_mode_raises():
    with pytest.raises(ValueError, match="mode"):
        LidarCorrector(ROOM, "sometimes")


def test_continuous_mode_corrects_every_scan():
    system, context = make("continuous", estimate=TRUE_POSE + [0.2, -0.15, np.deg2rad(5)])
    step(system, context)
    out = correction(system, context)
    assert out[0] == 1
    np.testing.assert_allclose(out[1:3], TRUE_POSE[:2], atol=0.01)
    assert abs(out[3] - TRUE_POSE[2]) < np.deg2rad(0.5)
    inlier_ratio, rms = system.GetOutputPort("fit_quality").Eval(context)
    assert inlier_ratio > 0.9 and rms < 0.02
    delta = system.GetOutputPort("correction_delta").Eval(context)
    np.testing.assert_allclose(
        apply_pose_delta(delta, TRUE_POSE + [0.2, -0.15, np.deg2rad(5)]), out[1:], atol=1e-9
    )
    step(system, context)
    assert correction(system, context)[0] == 2


def test_continuous_mode_skips_a_bad_fit():
    system, context = make("continuous", estimate=np.array([-3.0, 9.0, 0.0]))
    step(system, context)
    assert correction(system, context)[0] == 0
    assert system.GetOutputPort("fit_quality").Eval(context)[0] < 0.5


def test_paper_mode_fires_only_when_waypoint_index_crosses_a_multiple_of_five():
    system, context = make("paper")
    port = system.GetInputPort("waypoint_index")
    counts = []
    for index in [0, 1, 3, 4, 5, 5, 6, 9, 12, 12, 15]:
        port.FixValue(context, [float(index)])
        step(system, context)
        counts.append(correction(system, context)[0])
    assert counts == [0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 3]
    out = correction(system, context)
    np.testing.assert_allclose(out[1:3], TRUE_POSE[:2], atol=0.02)
    assert out[3] == ESTIMATE[2]  # yaw is not corrected in paper mode


def test_simulator_run_is_reproducible_and_corrects():
    def run() -> np.ndarray:
        builder = DiagramBuilder()
        corrector = builder.AddNamedSystem("corrector", LidarCorrector(ROOM, "continuous"))
        builder.ExportInput(corrector.GetInputPort("scan"), "scan")
        builder.ExportInput(corrector.GetInputPort("estimated_pose"), "estimated_pose")
        builder.ExportOutput(corrector.GetOutputPort("pose_correction"), "pose_correction")
        diagram = builder.Build()
        simulator = Simulator(diagram)
        context = simulator.get_mutable_context()
        rng = np.random.default_rng(0)
        diagram.GetInputPort("scan").FixValue(
            context, simulate_scan(TRUE_POSE, ROOM, noise_std_m=0.01, rng=rng)
        )
        diagram.GetInputPort("estimated_pose").FixValue(context, ESTIMATE)
        simulator.AdvanceTo(0.3)
        return diagram.GetOutputPort("pose_correction").Eval(context).copy()

    first, second = run(), run()
    np.testing.assert_array_equal(first, second)
    assert first[0] >= 1
    np.testing.assert_allclose(first[1:3], TRUE_POSE[:2], atol=0.01)


def test_paper_mode_retries_a_failed_attempt_on_the_next_scans():
    system, context = make("paper")
    scan_port, index_port = system.GetInputPort("scan"), system.GetInputPort("waypoint_index")
    scan_port.FixValue(context, np.full(360, np.inf))  # nothing to match
    index_port.FixValue(context, [5.0])
    step(system, context)
    assert correction(system, context)[0] == 0
    index_port.FixValue(context, [6.0])  # no new multiple of 5, but the attempt is pending
    scan_port.FixValue(
        context, simulate_scan(TRUE_POSE, ROOM, noise_std_m=0.005, rng=np.random.default_rng(1))
    )
    step(system, context)
    assert correction(system, context)[0] == 1
    step(system, context)  # done: no further attempt until the next multiple
    assert correction(system, context)[0] == 1
