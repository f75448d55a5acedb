"""Exports: graph JSON and GraphML, rooms GeoJSON, Nav2 maps."""

from __future__ import annotations

import json

import networkx as nx
import numpy as np
import pytest
import shapely
import yaml
from shapely.geometry import box, shape

from f2n_drake.core.classes import CLASS_ID
from f2n_drake.core.errors import InputError
from f2n_drake.core.plan import FloorPlan, polygons_of
from f2n_drake.core.raster import PixelGrid
from f2n_drake.datasets.ground_truth import parse_ground_truth
from f2n_drake.mapping.graph import build_connectivity_graph
from f2n_drake.outputs.exports import (
    read_pgm,
    write_graph_json,
    write_graphml,
    write_nav2_map,
    write_rooms_geojson,
)


@pytest.fixture(scope="module")
def parsed():
    hole = box(0, 0, 6, 4)
    door, window = box(2.9, 1.5, 3.1, 2.4), box(-0.2, 1.5, 0, 2.5)
    walls = shapely.union_all(
        [hole.buffer(0.2, join_style="mitre").difference(hole), box(2.9, 0, 3.1, 4)]
    ).difference(shapely.union_all([door, window]))
    plan = FloorPlan(
        {
            "living": [box(0, 0, 2.9, 4)],
            "bedroom": [box(3.1, 0, 6, 4)],
            "wall": polygons_of(walls),
            "door": [door],
            "window": [window],
        },
        0.2,
    )
    return parse_ground_truth(plan, size_px=256)


def test_graph_json_is_plain_node_link_in_metres(parsed, tmp_path):
    graph = build_connectivity_graph(parsed)
    path = tmp_path / "graph.json"
    write_graph_json(graph, path)
    data = json.loads(path.read_text())
    assert {n["id"] for n in data["nodes"]} == set(graph.nodes)
    assert len(data["edges"]) == graph.number_of_edges()
    living = next(n for n in data["nodes"] if n["id"] == "living_0")
    ring = living["polygon_m"]["exterior"]
    assert shapely.Polygon(ring).area == pytest.approx(2.9 * 4, rel=1e-6)
    assert data["graph"]["metres_per_px"] == pytest.approx(parsed.grid.metres_per_px)
    assert data["graph"]["grid"]["shape"] == [256, 256]
    back = nx.node_link_graph(data, edges="edges")
    assert set(map(frozenset, back.edges)) == set(map(frozenset, graph.edges))
    assert back.nodes["door_0"]["sides"] == list(graph.nodes["door_0"]["sides"])


def test_graphml_keeps_scalars(parsed, tmp_path):
    graph = build_connectivity_graph(parsed)
    path = tmp_path / "graph.graphml"
    write_graphml(graph, path)
    back = nx.read_graphml(path)
    assert set(back.nodes) == set(graph.nodes)
    door = back.nodes["door_0"]
    assert door["kind"] == "connector" and door["width_m"] == pytest.approx(0.9, abs=0.1)
    assert set(door["sides"].split(",")) == {"living_0", "bedroom_0"}
    assert door["centroid_x_m"] == pytest.approx(3.0, abs=0.05)
    assert "polygon_m" not in door
    assert back.graph["kernel_px"] == graph.graph["kernel_px"]


def test_rooms_geojson(parsed, tmp_path):
    path = tmp_path / "rooms.geojson"
    write_rooms_geojson(parsed, path)
    data = json.loads(path.read_text())
    assert data["type"] == "FeatureCollection"
    assert len(data["features"]) == len(parsed.instances)
    living = next(f for f in data["features"] if f["properties"]["class"] == "living")
    assert shape(living["geometry"]).symmetric_difference(box(0, 0, 2.9, 4)).area < 1e-9
    assert living["properties"]["area_m2"] == pytest.approx(2.9 * 4, rel=0.03)
    assert living["properties"]["confidence"] is None  # ground truth has no probabilities


def test_rooms_geojson_and_graph_carry_confidence(parsed, tmp_path):
    import dataclasses

    living_id = CLASS_ID["living"]
    scored = dataclasses.replace(
        parsed,
        instances=[
            dataclasses.replace(i, scores={living_id: 0.75, CLASS_ID["door"]: 0.25})
            for i in parsed.instances
        ],
    )
    path = tmp_path / "rooms.geojson"
    write_rooms_geojson(scored, path)
    confidence = {
        f["properties"]["class"]: f["properties"]["confidence"]
        for f in json.loads(path.read_text())["features"]
    }
    assert confidence["living"] == 0.75 and confidence["door"] == 0.25
    assert confidence["bedroom"] is None  # no score for its own class
    graph = build_connectivity_graph(scored)
    assert graph.nodes["living_0"]["confidence"] == 0.75
    assert graph.nodes["outside"].get("confidence") is None


def test_rooms_geojson_needs_a_scale(parsed, tmp_path):
    import dataclasses

    with pytest.raises(InputError, match="no scale"):
        write_rooms_geojson(dataclasses.replace(parsed, grid=None), tmp_path / "r.geojson")


def test_nav2_map_files(tmp_path):
    free = np.zeros((4, 6), bool)
    free[1:3, 1:5] = True
    free[0, 0] = True
    unknown = np.zeros_like(free)
    unknown[3, 5] = True
    grid = PixelGrid(0.05, (1.0, 2.0), (4, 6))
    pgm, yml = tmp_path / "map.pgm", tmp_path / "map.yaml"
    write_nav2_map(free, grid, pgm, yml, unknown=unknown)
    spec = yaml.safe_load(yml.read_text())
    assert spec["image"] == "map.pgm" and spec["mode"] == "trinary"
    assert spec["resolution"] == pytest.approx(0.05)
    assert spec["origin"] == pytest.approx([1.0, 2.0 - 4 * 0.05, 0.0])  # lower-left corner
    assert spec["negate"] == 0 and spec["occupied_thresh"] == 0.65
    image = read_pgm(pgm)
    assert image.shape == (4, 6) and image[0, 0] == 254  # row 0 is the top of the image
    np.testing.assert_array_equal(image == 254, free)
    assert image[3, 5] == 205 and np.count_nonzero(image == 0) == free.size - free.sum() - 1
    assert pgm.read_bytes().startswith(b"P5\n6 4\n255\n")
    # map_server semantics: occupancy = (255 - v) / 255, trinary thresholds
    occ = (255 - image.astype(float)) / 255
    loaded_free = occ < spec["free_thresh"]
    loaded_occupied = occ > spec["occupied_thresh"]
    np.testing.assert_array_equal(loaded_free, free & ~unknown)
    assert not loaded_free[3, 5] and not loaded_occupied[3, 5]


def test_nav2_map_shape_mismatch(tmp_path):
    grid = PixelGrid(0.05, (0.0, 0.0), (4, 6))
    with pytest.raises(InputError, match="shape"):
        write_nav2_map(np.ones((5, 6), bool), grid, tmp_path / "m.pgm", tmp_path / "m.yaml")
