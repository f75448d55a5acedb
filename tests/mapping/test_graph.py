"""Connectivity graph: dilation adjacency, semantic filtering, the outside node, kernel scaling."""

from __future__ import annotations

import math
import pickle

import networkx as nx
import numpy as np
import pytest
import shapely
from shapely.affinity import scale as scale_geom
from shapely.geometry import Polygon, box

from f2n_drake.core.classes import CLASS_ID, EXTRA_PLAN_KEYS, PLAN_CLASSES
from f2n_drake.core.parsed import Instance, ParsedPlan
from f2n_drake.core.paths import resplan_sample_path
from f2n_drake.core.plan import FloorPlan, polygons_of
from f2n_drake.core.raster import PixelGrid
from f2n_drake.datasets.ground_truth import parse_ground_truth
from f2n_drake.mapping.graph import (
    OUTSIDE,
    OUTSIDE_ID,
    build_connectivity_graph,
    exterior_mask,
    joined,
    kernel_size_px,
    line_gap_px,
    plan_exterior,
)
from f2n_drake.mapping.robots import GROUND, UAV, traversable_subgraph

WALL = 0.2


def box_plan(outer, rooms, connectors=None, inner_walls=(), extra=None) -> FloorPlan:
    """A plan from boxes: exterior wall ring around ``outer``, ``inner_walls`` boxes, connector
    boxes cut out of the walls. ``rooms``/``connectors``: class -> list of (x0, y0, x1, y1)."""
    connectors = connectors or {}
    hole = box(*outer)
    walls = shapely.union_all(
        [hole.buffer(WALL, join_style="mitre").difference(hole), *[box(*b) for b in inner_walls]]
    )
    cuts = [box(*b) for boxes in connectors.values() for b in boxes]
    if cuts:
        walls = walls.difference(shapely.union_all(cuts))
    polygons = {name: [box(*b) for b in boxes] for name, boxes in {**rooms, **connectors}.items()}
    polygons["wall"] = polygons_of(walls)
    polygons.update(extra or {})
    return FloorPlan(polygons, WALL, "test")


def two_rooms(**connectors) -> FloorPlan:
    """living (0..3.9) | wall at x=3.9..4.1 | bedroom (4.1..8), 4 m deep."""
    return box_plan(
        (0, 0, 8, 4),
        {"living": [(0, 0, 3.9, 4)], "bedroom": [(4.1, 0, 8, 4)]},
        connectors,
        inner_walls=[(3.9, 0, 4.1, 4)],
    )


def edge_set(graph: nx.Graph) -> set[frozenset[str]]:
    return {frozenset(e) for e in graph.edges}


def test_room_door_room_chain_window_and_front_door():
    plan = two_rooms(
        door=[(3.9, 1.5, 4.1, 2.4)], window=[(-0.2, 1.5, 0, 2.5)], front_door=[(5, -0.2, 6, 0)]
    )
    graph = build_connectivity_graph(parse_ground_truth(plan))
    assert edge_set(graph) == {
        frozenset({"door_0", "living_0"}),
        frozenset({"door_0", "bedroom_0"}),
        frozenset({"window_0", "living_0"}),
        frozenset({"window_0", OUTSIDE}),
        frozenset({"front_door_0", "bedroom_0"}),
        frozenset({"front_door_0", OUTSIDE}),
    }
    assert set(graph.nodes["door_0"]["sides"]) == {"living_0", "bedroom_0"}
    assert not graph.has_edge("living_0", "bedroom_0")
    assert graph.nodes["door_0"]["width_m"] == pytest.approx(0.9, abs=0.08)
    assert graph.nodes["front_door_0"]["width_m"] == pytest.approx(1.0, abs=0.08)
    assert all(d["contact_px"] > 0 for _, _, d in graph.edges(data=True))


def test_schema_node_and_graph_attributes():
    plan = two_rooms(door=[(3.9, 1.5, 4.1, 2.4)])
    parsed = parse_ground_truth(plan)
    graph = build_connectivity_graph(parsed)
    assert set(graph.graph) >= {"metres_per_px", "grid", "scale_source", "kernel_px"}
    assert graph.graph["metres_per_px"] == parsed.grid.metres_per_px
    assert graph.graph["scale_source"] == "input"
    living = graph.nodes["living_0"]
    assert living["kind"] == "space" and living["class_name"] == "living"
    assert isinstance(living["instance_id"], int) and isinstance(living["polygon_m"], Polygon)
    assert living["area_m2"] == pytest.approx(3.9 * 4, rel=0.03)
    assert living["centroid_m"] == pytest.approx((1.95, 2.0), abs=0.05)
    col, row = living["centroid_px"]
    assert parsed.instance_ids[round(row), round(col)] == living["instance_id"]
    door = graph.nodes["door_0"]
    assert door["kind"] == "connector" and isinstance(door["sides"], tuple)
    outside = graph.nodes[OUTSIDE]
    assert outside["kind"] == "outside" and outside["instance_id"] == -1
    assert outside["centroid_m"] is None and outside["polygon_m"] is None
    assert not any(d["class_name"] == "wall" for _, d in graph.nodes(data=True))


def test_two_touching_doors_are_not_joined():
    plan = two_rooms(door=[(3.9, 1.0, 4.1, 1.9), (3.9, 1.9, 4.1, 2.8)])
    graph = build_connectivity_graph(parse_ground_truth(plan))
    assert not graph.has_edge("door_0", "door_1")
    for door in ("door_0", "door_1"):
        assert set(graph[door]) == {"living_0", "bedroom_0"}


def test_open_kitchen_gets_an_opening_connector():
    plan = box_plan((0, 0, 6, 4), {"living": [(0, 0, 3, 4)], "kitchen": [(3, 0, 6, 4)]})
    graph = build_connectivity_graph(parse_ground_truth(plan))
    assert set(graph["opening_0"]) == {"living_0", "kitchen_0"}
    assert graph.nodes["opening_0"]["kind"] == "connector"
    assert graph.nodes["opening_0"]["width_m"] == pytest.approx(4.0, abs=0.1)
    assert not graph.has_edge("living_0", "kitchen_0")


def test_partly_walled_boundary_opening_is_the_wall_less_part():
    plan = box_plan(
        (0, 0, 6, 4),
        {"living": [(0, 0, 3, 4)], "kitchen": [(3, 0, 6, 4)]},
        inner_walls=[(2.9, 2.5, 3.1, 4)],
    )
    graph = build_connectivity_graph(parse_ground_truth(plan))
    assert graph.nodes["opening_0"]["width_m"] == pytest.approx(2.5, abs=0.12)


def test_short_shared_boundary_is_no_opening():
    plan = box_plan(
        (0, 0, 6, 4),
        {"living": [(0, 0, 3, 4)], "kitchen": [(3, 0, 6, 4)]},
        inner_walls=[(2.9, 0.3, 3.1, 4)],  # only 0.3 m left open
    )
    graph = build_connectivity_graph(parse_ground_truth(plan))
    assert not [n for n in graph if n.startswith("opening")]


def test_balcony_is_open_to_the_air():
    plan = box_plan(
        (0, 0, 6, 4),
        {"living": [(0, 0, 6, 4)], "balcony": [(2, -1.5, 5, -0.2)]},
        {"door": [(3, -0.2, 4, 0)]},
    )
    graph = build_connectivity_graph(parse_ground_truth(plan))
    assert set(graph["door_0"]) == {"living_0", "balcony_0"}
    assert graph.edges["balcony_0", OUTSIDE]["open_air"] is True
    assert graph.edges["door_0", "living_0"]["open_air"] is False


def test_kernel_scales_with_resolution_and_can_be_overridden():
    plan = two_rooms(door=[(3.9, 1.5, 4.1, 2.4)], window=[(-0.2, 1.5, 0, 2.5)])
    small, large = parse_ground_truth(plan, size_px=256), parse_ground_truth(plan, size_px=1024)
    k_small, k_large = kernel_size_px(small.grid), kernel_size_px(large.grid)
    assert k_small % 2 == 1 and k_large % 2 == 1 and k_small >= 3
    assert 3.0 <= k_large / k_small <= 5.0
    g_small, g_large = build_connectivity_graph(small), build_connectivity_graph(large)
    assert g_large.graph["kernel_px"] == k_large
    assert edge_set(g_small) == edge_set(g_large)
    assert build_connectivity_graph(small, kernel_px=9).graph["kernel_px"] == 9
    coarse = PixelGrid.fit(plan.bounds, 64)
    assert kernel_size_px(coarse) == 3


def _drawn_plan(line: int, filled_walls: bool = False) -> ParsedPlan:
    """Perception-style plan: unlabelled ``line`` px lines between instances, all joined to the
    outline, exterior beyond it. | window band | living | door band | bedroom |. With
    ``filled_walls`` the walls are ink (no instance) labelled wall."""
    top, height = 4 + line, 40
    bands, col = {}, 4 + line
    for name, width in (("left", 3), ("living", 30), ("middle", 3), ("bedroom", 30)):
        bands[name] = (col, col + width)
        col += width + line
    ids = np.zeros((top + height + line + 4, col + 4), np.int32)
    labels = np.zeros_like(ids, np.uint8)
    instances: list[Instance] = []

    def paint(name: str, rows: tuple[int, int], cols: tuple[int, int]) -> None:
        inst_id = len(instances) + 1
        ids[rows[0] : rows[1], cols[0] : cols[1]] = inst_id
        (r0, r1), (c0, c1) = rows, cols
        contour = np.array([[c0, r0], [c1 - 1, r0], [c1 - 1, r1 - 1], [c0, r1 - 1]], float)
        centroid = ((c0 + c1 - 1) / 2, (r0 + r1 - 1) / 2)
        instances.append(Instance(inst_id, name, contour, (r1 - r0) * (c1 - c0), centroid))

    paint("living", (top, top + height), bands["living"])
    paint("bedroom", (top, top + height), bands["bedroom"])
    for band, name, (a, b) in (("left", "window", (10, 20)), ("middle", "door", (15, 25))):
        if filled_walls:
            c0, c1 = bands[band]
            labels[top - line : top + height + line, c0 - line : c1 + line] = CLASS_ID["wall"]
        else:
            paint("wall", (top, top + a - line), bands[band])  # the wall's inside, between lines
            paint("wall", (top + b + line, top + height), bands[band])
        paint(name, (top + a, top + b), bands[band])
    return ParsedPlan(ids, labels, instances)


@pytest.mark.parametrize("line, filled", [(1, False), (3, False), (1, True)])
def test_drawn_lines_are_jumped_but_do_not_carry_the_exterior_indoors(line, filled):
    graph = build_connectivity_graph(_drawn_plan(line, filled))
    assert graph.graph["kernel_px"] >= 2 * line + 3 and graph.graph["metres_per_px"] is None
    assert set(graph["door_0"]) == {"living_0", "bedroom_0"}
    assert set(graph["window_0"]) == {"living_0", OUTSIDE}
    assert graph.nodes["door_0"]["width_m"] is None and graph.nodes["door_0"]["width_px"] == 10
    assert graph.nodes["living_0"]["centroid_m"] is None


def test_line_gap_is_measured_between_connectors_and_spaces():
    assert line_gap_px(_drawn_plan(1)) == 1
    assert line_gap_px(_drawn_plan(3)) == 3
    assert kernel_size_px(None, line_gap_px=3) == 9
    assert kernel_size_px(None) == 5


# -- the real ResPlan sample ----------------------------------------------------------------


def resplan_sample_plans() -> list[FloorPlan]:
    """The two sample plans in metres (scale sqrt(area / inner.area)), read without the reader."""
    with open(resplan_sample_path(), "rb") as fh:
        records = pickle.load(fh)
    plans = []
    for rec in records:
        f = math.sqrt(rec["area"] / rec["inner"].area)
        polygons = {
            k: [scale_geom(p, f, f, origin=(0, 0)) for p in polygons_of(rec[k])]
            for k in (*PLAN_CLASSES, *EXTRA_PLAN_KEYS)
            if hasattr(rec.get(k), "geom_type")
        }
        plans.append(FloorPlan(polygons, rec["wall_depth"] * f, "resplan"))
    return plans


@pytest.mark.parametrize("index", [0, 1])
def test_resplan_sample_every_space_reachable_from_front_door(index):
    plan = resplan_sample_plans()[index]
    graph = build_connectivity_graph(parse_ground_truth(plan))
    for profile in (GROUND, UAV):
        sub = traversable_subgraph(graph, profile)
        reach = nx.node_connected_component(sub, "front_door_0")
        spaces = [n for n, d in sub.nodes(data=True) if d["kind"] == "space"]
        assert spaces and set(spaces) <= reach, profile.name
    assert graph.has_edge("front_door_0", OUTSIDE)
    assert all(graph.has_edge(w, OUTSIDE) for w in graph if w.startswith("window"))
    for u, v, data in graph.edges(data=True):
        kinds = {graph.nodes[u]["kind"], graph.nodes[v]["kind"]}
        if kinds == {"space", "outside"}:
            assert data["open_air"] and "balcony" in {
                graph.nodes[u]["class_name"],
                graph.nodes[v]["class_name"],
            }
        else:
            assert kinds in ({"space", "connector"}, {"outside", "connector"})


def test_joined_keeps_contacts_of_a_kernel_side_and_a_fifth_of_the_strongest():
    assert joined({4: 40, 7: 9, OUTSIDE_ID: 30}, kernel_px=5) == [4, OUTSIDE_ID, 7]
    assert joined({4: 40, 7: 7}, kernel_px=5) == [4]  # 7 px < 0.2 x 40 px: a grazing corner
    assert joined({4: 12, 7: 4}, kernel_px=5) == [4]  # 4 px < the 5 px kernel side
    assert joined({}, kernel_px=5) == []


def test_a_plans_exterior_is_found_once_and_read_only():
    ids = np.zeros((20, 20), np.int32)
    ids[5:15, 5:15] = 1
    plan = ParsedPlan(ids, np.zeros_like(ids, np.uint8), [])
    exterior = plan_exterior(plan, 3)
    assert np.array_equal(exterior, exterior_mask(ids, 3, plan.labels))
    assert exterior[0, 0] and not exterior[10, 10]
    assert plan_exterior(plan, 3) is exterior and not exterior.flags.writeable
