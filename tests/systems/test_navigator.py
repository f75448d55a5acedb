"""The Navigator in the navigation Diagram: obstacles avoided, closed doors replanned around."""

from __future__ import annotations

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from shapely.geometry import LineString, box
from two_doors import GOAL, LOWER, START, UPPER, door_key, geometry, replanner, with_closed

from f2n_drake.systems.controller import pure_pursuit_command
from f2n_drake.systems.diagram import MakeNavigationDiagram
from f2n_drake.systems.navigator import Navigator
from f2n_drake.systems.simulation import simulate_navigation
from f2n_drake.systems.vectors import NavigationStatus
from f2n_drake.world.building import Building


def _route() -> np.ndarray:
    return replanner().replan(START, GOAL).waypoints_m


def _drove_through(result, door) -> bool:
    return LineString(result.true_path[:, :2]).intersects(door)


def test_diagram_with_a_replanner_has_a_navigator_and_its_status():
    diagram = MakeNavigationDiagram(geometry(), _route(), replanner=replanner())
    assert diagram.HasSubsystemNamed("navigator") and not diagram.HasSubsystemNamed("waypoints")
    navigator = diagram.GetSubsystemByName("navigator")
    for name, size in (("estimated_pose", 3), ("scan", 360), ("replan_request", 1)):
        assert navigator.GetInputPort(name).size() == size
    sizes = {"target": 2, "segment": 4, "progress": 2, "guidance": 3, "navigation_status": 4}
    for name, size in sizes.items():
        assert navigator.GetOutputPort(name).size() == size
    assert diagram.GetOutputPort("navigation_status").size() == 4


def test_nothing_in_the_way_drives_as_without_a_replanner():
    plain = simulate_navigation(geometry(), _route(), seed=1)
    guarded = simulate_navigation(geometry(), _route(), seed=1, replanner=replanner())
    assert guarded.success and guarded.replans == 0 and guarded.message == "route done"
    # Same commands; the navigator's state updates only change the integrator's step sizes.
    np.testing.assert_allclose(guarded.true_path, plain.true_path, atol=1e-6)
    assert plain.message == "route done" and plain.replans == 0


def test_box_on_the_route_is_avoided():
    building = Building(walls=tuple(geometry().walls), furniture=(box(4.0, 2.1, 4.4, 2.7),))
    blind = simulate_navigation(geometry(), _route(), seed=1, building=building)
    assert blind.collided and blind.message == "collision"
    result = simulate_navigation(
        geometry(), _route(), seed=1, building=building, replanner=replanner()
    )
    assert result.success and result.replans >= 1
    assert result.min_clearance_m > 0.02


def test_closed_door_is_replanned_through_the_other_door():
    result = simulate_navigation(
        geometry(), _route(), seed=1, building=with_closed(UPPER), replanner=replanner()
    )
    assert result.success and result.replans >= 1
    assert _drove_through(result, LOWER) and not _drove_through(result, UPPER)


def test_only_doors_closed_stops_and_says_so():
    result = simulate_navigation(
        geometry(), _route(), seed=1, building=with_closed(UPPER, LOWER), replanner=replanner()
    )
    assert not result.reached and not result.collided
    assert result.message.startswith("no route left to living_0: ")
    assert door_key(UPPER) in result.message
    assert result.time_s < 30.0  # it gave up, it did not wait for the time limit


def test_replan_request_replans_from_the_estimate():
    navigator = Navigator(_route(), replanner(), geometry().wall_segments(), spacing_m=0.025)
    context = navigator.CreateDefaultContext()
    off_route = np.array([1.0, 0.6, 0.0])  # in the bedroom, below the planned route
    navigator.GetInputPort("estimated_pose").FixValue(context, off_route)
    navigator.GetInputPort("scan").FixValue(context, np.full(360, np.inf))
    request = navigator.GetInputPort("replan_request").FixValue(context, [0.0])
    simulator = Simulator(navigator, context)
    simulator.AdvanceTo(0.5)
    status = NavigationStatus(navigator.GetOutputPort("navigation_status").Eval(context))
    assert status.replans == 0
    request.GetMutableData().set_value(np.array([1.0]))
    simulator.AdvanceTo(1.0)
    status = NavigationStatus(navigator.GetOutputPort("navigation_status").Eval(context))
    assert status.replans == 1
    assert np.hypot(*(navigator.waypoints(context)[0] - off_route[:2])) < 0.05


def test_pipeline_simulate_builds_the_replanner_from_a_plan_map_only():
    from f2n_drake import simulate
    from f2n_drake.core.errors import InputError

    with pytest.raises(InputError, match="PlanMap"):
        simulate(geometry(), _route(), replan=True)


def test_guided_controller_holds_forward_motion_but_turns():
    from f2n_drake.systems.controller import PurePursuitController

    controller = PurePursuitController(1, guided=True)
    context = controller.CreateDefaultContext()
    controller.GetInputPort("estimated_pose").FixValue(context, [0.0, 0.0, 0.0])
    controller.GetInputPort("segment").FixValue(context, [0.0, 0.0, 1.0, 1.0])
    controller.GetInputPort("progress").FixValue(context, [0.0, 0.0])
    guidance = controller.GetInputPort("guidance").FixValue(context, [0.0, 0.0, 0.0])
    v, omega = controller.GetOutputPort("command").Eval(context)
    assert v > 0.05 and omega > 0.1
    guidance.GetMutableData().set_value(np.array([0.0, 0.0, 1.0]))
    v, omega_held = controller.GetOutputPort("command").Eval(context)
    assert v == 0.0 and omega_held == omega


def test_obstacles_across_the_way_wait_and_the_end_says_why():
    wall_of_boxes = (box(4.2, 0.0, 4.5, 1.6), box(4.2, 1.6, 4.5, 3.0))  # no door is closed
    building = Building(walls=tuple(geometry().walls), furniture=wall_of_boxes)
    result = simulate_navigation(
        geometry(), _route(), seed=1, building=building, replanner=replanner(), time_limit_s=25.0
    )
    assert not result.reached and not result.collided
    assert result.message == "time limit: obstacles block every route to living_0"


def test_a_route_ending_short_of_the_goal_or_a_detour_does_not_end_the_run():
    route = _route()
    navigator = Navigator(route, replanner(), geometry().wall_segments())
    assert navigator.track(route).short_m == 0.0
    short = navigator.track(np.vstack([route[:-1], route[-1] - [0.3, 0.0]]))
    assert short.short_m == pytest.approx(0.3, abs=0.03) and not short.detour
    aside = navigator.track(np.array([[1.0, 2.4], [1.0, 1.8]]), detour=True)
    assert aside.detour and aside.short_m == 0.0
    assert aside.remaining_m(0) == pytest.approx(0.6, abs=0.01)


def test_pure_pursuit_stops_at_the_end_instead_of_turning_on_the_spot():
    pose, segment = np.array([1.0, 1.0, 0.0]), np.array([0.0, 1.0, 1.0, 1.01])
    np.testing.assert_array_equal(
        pure_pursuit_command(pose, segment, True, lookahead_m=0.25, v_max=0.22, omega_max=2.8),
        [0.0, 0.0],
    )
    v, omega = pure_pursuit_command(
        pose, segment, False, lookahead_m=0.25, v_max=0.22, omega_max=2.8
    )
    assert abs(omega) > 1.0  # not the route's end: it turns toward the point
