"""Robots: the shipped descriptions, YAML loading, profiles and traversable subgraphs."""

from __future__ import annotations

import networkx as nx
import pytest
import shapely
from shapely.geometry import box

from f2n_drake.core.errors import InputError
from f2n_drake.core.plan import FloorPlan, polygons_of
from f2n_drake.datasets.ground_truth import parse_ground_truth
from f2n_drake.mapping.graph import OUTSIDE, build_connectivity_graph
from f2n_drake.mapping.robots import (
    GROUND,
    ROBOT_FILES,
    UAV,
    Body,
    RobotProfile,
    load_profile,
    load_robot,
    shipped_robot,
    traversable_subgraph,
)
from f2n_drake.models import model_path
from f2n_drake.planning.endpoints import default_goal, default_start, unreachable_spaces


def small_graph() -> nx.Graph:
    """living -door(0.9)- bedroom, living -opening(3.0)- kitchen, bedroom -window- outside,
    living -front door- outside, bedroom -narrow door(0.5)- bathroom, balcony (open air) -door-
    bedroom."""
    g = nx.Graph()
    for n in ("living_0", "bedroom_0", "kitchen_0", "bathroom_0", "balcony_0"):
        g.add_node(n, kind="space", class_name=n[:-2])
    g.add_node(OUTSIDE, kind="outside", class_name=OUTSIDE)
    connectors = {
        "door_0": ("door", 0.9, ("living_0", "bedroom_0")),
        "door_1": ("door", 0.5, ("bedroom_0", "bathroom_0")),
        "door_2": ("door", 0.9, ("bedroom_0", "balcony_0")),
        "opening_0": ("opening", 3.0, ("living_0", "kitchen_0")),
        "window_0": ("window", 1.2, ("bedroom_0", OUTSIDE)),
        "front_door_0": ("front_door", 1.0, ("living_0", OUTSIDE)),
    }
    for key, (cls, width, sides) in connectors.items():
        g.add_node(key, kind="connector", class_name=cls, width_m=width, sides=sides)
        for side in sides:
            g.add_edge(key, side, contact_px=10, open_air=False)
    g.add_edge("balcony_0", OUTSIDE, contact_px=50, open_air=True)
    return g


def test_ground_robot_never_uses_windows_or_the_outside():
    sub = traversable_subgraph(small_graph(), GROUND)
    assert "window_0" not in sub and OUTSIDE not in sub
    assert {"door_0", "door_1", "door_2", "opening_0", "front_door_0", "balcony_0"} <= set(sub)
    assert nx.has_path(sub, "front_door_0", "kitchen_0")
    assert nx.has_path(sub, "front_door_0", "bathroom_0")
    assert sub.graph["robot"] == "ground"


def test_uav_flies_through_windows_and_off_balconies():
    graph = small_graph()
    sub = traversable_subgraph(graph, UAV)
    assert sub.has_edge("window_0", OUTSIDE) and sub.has_edge("balcony_0", OUTSIDE)
    assert "door_1" not in sub  # 0.5 m < 2 * (0.2 m + 0.1 m margin)
    assert graph.number_of_nodes() == 12  # the input graph is untouched


def test_narrow_door_blocks_a_wide_robot():
    wide = RobotProfile("wide", frozenset({"door", "front_door", "opening"}), radius_m=0.3)
    assert wide.required_width_m == pytest.approx(0.7)
    sub = traversable_subgraph(small_graph(), wide)
    assert "door_1" not in sub and "door_0" in sub
    assert not nx.has_path(sub, "living_0", "bathroom_0")


def test_unreachable_spaces_are_those_cut_off_from_the_start():
    graph = small_graph()
    assert unreachable_spaces(graph, GROUND, "front_door_0") == []
    wide = RobotProfile("wide", frozenset({"door", "front_door", "opening"}), radius_m=0.3)
    assert unreachable_spaces(graph, wide, "living_0") == ["bathroom_0"]
    graph.remove_node("door_0")  # a door the segmenter missed: the bedroom side is cut off
    assert unreachable_spaces(graph, GROUND, "kitchen_0") == [
        "balcony_0",
        "bathroom_0",
        "bedroom_0",
    ]
    assert unreachable_spaces(graph, UAV, "kitchen_0") == ["bathroom_0"]  # in by the window


def test_the_default_goal_is_the_farthest_room_the_robot_fits_in():
    graph = small_graph()
    along = {
        "living_0": 0.0,
        "kitchen_0": 3.0,
        "bedroom_0": 5.0,
        "bathroom_0": 6.0,
        "balcony_0": 8.0,
    }
    for key, x in along.items():
        graph.nodes[key].update(centroid_m=(x, 0.0), area_m2=12.0)
    for _, data in graph.nodes(data=True):
        if data["kind"] == "connector":  # between its rooms (the outside at x = 10)
            xs = [along.get(side, 10.0) for side in data["sides"]]
            data["centroid_m"] = (sum(xs) / len(xs), 0.0)
    assert default_goal(graph, GROUND, "living_0") == "balcony_0"
    graph.nodes["balcony_0"]["area_m2"] = 0.05  # a sliver the parse cut off a room
    assert default_goal(graph, GROUND, "living_0") == "bathroom_0"
    for key in along:
        graph.nodes[key]["area_m2"] = 0.05  # no room fits: the farthest all the same
    assert default_goal(graph, GROUND, "living_0") == "balcony_0"


def test_the_default_start_is_a_front_door_that_leads_into_a_room():
    graph = small_graph()
    for key, area in {"living_0": 20, "kitchen_0": 8, "bedroom_0": 12, "bathroom_0": 4}.items():
        graph.nodes[key]["area_m2"] = float(area)
    graph.nodes["balcony_0"]["area_m2"] = 6.0
    assert default_start(graph, GROUND) == "front_door_0"
    # a second front door read on a window of the bathroom: the first still enters more rooms
    graph.add_node("front_door_1", kind="connector", class_name="front_door", width_m=1.0)
    graph.add_edge("front_door_1", OUTSIDE)
    assert default_start(graph, GROUND) == "front_door_0"
    # the only front door read on a window that leads nowhere: the largest room of the
    # largest group the robot can move in
    graph.remove_node("front_door_0")
    assert default_start(graph, GROUND) == "living_0"
    graph.remove_node("door_0")  # living + kitchen (28 m2) apart from bedroom + bathroom + balcony
    assert default_start(graph, GROUND) == "living_0"
    graph.nodes["bedroom_0"]["area_m2"] = 30.0
    assert default_start(graph, GROUND) == "bedroom_0"


def test_narrow_door_in_a_ground_truth_plan():
    hole = box(0, 0, 8, 4)
    door = box(3.9, 1.5, 4.1, 2.0)  # 0.5 m wide
    walls = shapely.union_all(
        [hole.buffer(0.2, join_style="mitre").difference(hole), box(3.9, 0, 4.1, 4)]
    ).difference(door)
    plan = FloorPlan(
        {
            "living": [box(0, 0, 3.9, 4)],
            "bedroom": [box(4.1, 0, 8, 4)],
            "wall": polygons_of(walls),
            "door": [door],
        },
        0.2,
    )
    graph = build_connectivity_graph(parse_ground_truth(plan))
    assert "door_0" in traversable_subgraph(graph, GROUND)
    wide = RobotProfile("wide", GROUND.traversable, radius_m=0.3)
    assert "door_0" not in traversable_subgraph(graph, wide)


def test_cost_factors():
    assert UAV.connector_factor("window", None) == 2.0
    assert GROUND.connector_factor("door", None) == 1.0
    req = GROUND.required_width_m
    assert GROUND.connector_factor("door", req) == pytest.approx(1.0 + GROUND.narrow_penalty)
    assert GROUND.connector_factor("door", 2 * req) == pytest.approx(1.0)
    assert GROUND.can_pass("door", None) and not GROUND.can_pass("window", 2.0)
    assert not GROUND.can_pass("door", req - 0.01)


def test_load_builtin_profiles_by_name():
    assert load_profile("ground") is GROUND
    assert load_profile(" UAV ") is UAV
    assert load_profile(GROUND) is GROUND


def test_shipped_robots_keep_their_numbers():
    assert (GROUND.radius_m, GROUND.clearance_margin_m, GROUND.min_clear_width_m) == (
        0.105,
        0.1,
        0.3,
    )
    assert GROUND.narrow_penalty == 0.5 and GROUND.cost_multipliers == {}
    assert GROUND.traversable == {"door", "front_door", "opening"}
    assert (UAV.radius_m, UAV.clearance_margin_m, UAV.min_clear_width_m) == (0.2, 0.1, 0.5)
    assert UAV.narrow_penalty == 1.0 and UAV.cost_multipliers == {"window": 2.0, OUTSIDE: 1.5}
    assert UAV.traversable == {"door", "front_door", "opening", "window", "balcony", OUTSIDE}


@pytest.mark.parametrize("name", sorted(ROBOT_FILES))
def test_every_field_of_a_shipped_description_is_known(name):
    from pydrake.common.yaml import yaml_load

    data = yaml_load(filename=str(model_path(ROBOT_FILES[name])))
    robot = shipped_robot(name)
    assert robot.name == name == load_profile(name).name
    assert robot.base == ""
    for section, values in data.items():
        if isinstance(values, dict):
            for key, value in values.items():
                assert getattr(getattr(robot, section), key) == value


def test_the_simulated_robot_is_the_planned_one():
    robot = shipped_robot("ground")
    assert robot.body.radius_m == GROUND.radius_m
    assert robot.limits is not None and robot.lidar is not None
    assert shipped_robot("uav").limits is None  # planned only, never simulated


def test_load_profile_from_yaml(tmp_path):
    path = tmp_path / "cart.yaml"
    path.write_text(
        "body: {radius_m: 0.25}\n"
        "navigation: {traversable: [door, opening], cost_multipliers: {opening: 1.5}}\n"
    )
    cart = load_profile(path)
    assert cart.name == "cart" and cart.traversable == frozenset({"door", "opening"})
    assert cart.radius_m == 0.25 and cart.cost_multipliers == {"opening": 1.5}
    assert cart.clearance_margin_m == 0.05  # the default
    named = tmp_path / "big_drone.yaml"
    named.write_text("name: big\nbody: {radius_m: 0.4}\nnavigation: {traversable: [window]}\n")
    big = load_profile(str(named))
    assert big.name == "big" and big.traversable == {"window"} and big.radius_m == 0.4
    assert load_robot(named).limits is None


def test_a_description_may_start_from_a_shipped_robot(tmp_path):
    path = tmp_path / "wide.yaml"
    path.write_text(
        "base: ground\nname: wide_base\nbody: {radius_m: 0.25}\n"
        "navigation: {cost_multipliers: {opening: 1.2}}\n"
    )
    wide = load_robot(path)
    assert wide.name == "wide_base" and wide.body == Body(0.25, 0.192)
    assert wide.limits == shipped_robot("ground").limits
    profile = load_profile(path)
    assert profile.traversable == GROUND.traversable and profile.cost_multipliers == {
        "opening": 1.2
    }
    assert shipped_robot("ground").body.radius_m == 0.105  # the shipped robot is untouched


@pytest.mark.parametrize(
    "text, message",
    [
        ("body: {radius_m: [1\n", "cannot read"),
        ("- door\n", "cannot read"),
        ("base: tank\n", "unknown robot 'tank'"),
        ("body: {radius_m: 0.1}\nwheels: 4\n", "wheels"),
        ("body: {radius_m: 0.1}\nnavigation: {clearance_margin_m: -0.1}\n", "clearance_margin_m"),
        ("navigation: {traversable: [door]}\n", "radius_m"),
        ("body: {radius_m: 0.1}\nnavigation: {traversable: door}\n", "must list some of"),
    ],
)
def test_bad_profile_files_raise_input_error(tmp_path, text, message):
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(InputError, match=message):
        load_profile(path)


def test_unknown_profile_name_raises_input_error():
    with pytest.raises(InputError, match="unknown robot profile"):
        load_profile("hovercraft")
