"""Ground-truth ParsedPlan from FloorPlan polygons."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import simple_plan
from shapely.geometry import box

from f2n_drake.core.classes import CLASS_ID, OPENING
from f2n_drake.core.plan import FloorPlan
from f2n_drake.core.raster import PixelGrid
from f2n_drake.datasets.ground_truth import parse_ground_truth

WALL = 0.2


def label_at(parsed, xy_m) -> int:
    col, row = np.round(parsed.grid.to_px(np.asarray(xy_m))).astype(int)
    return int(parsed.labels[row, col])


def test_every_polygon_is_an_instance_with_its_class():
    plan = simple_plan()
    parsed = parse_ground_truth(plan, size_px=256)
    assert parsed.scale_source == "input" and parsed.grid.shape == (256, 256)
    assert parsed.instance_ids.shape == parsed.labels.shape == (256, 256)
    names = [inst.class_name for inst in parsed.instances]
    assert names == ["living", "bedroom"] + ["wall"] * len(plan["wall"]) + [
        "window",
        "door",
        "front_door",
    ]
    assert len({inst.id for inst in parsed.instances}) == len(parsed.instances)
    for inst in parsed.instances:
        mask = parsed.instance_ids == inst.id
        assert mask.sum() == inst.area_px > 0
        assert np.all(parsed.labels[mask] == CLASS_ID[inst.class_name])
        assert inst.votes == {}
    assert label_at(parsed, (2, 2)) == CLASS_ID["living"]  # inside the wall ring's hole
    assert label_at(parsed, (-0.1, 3.5)) == CLASS_ID["wall"]
    assert label_at(parsed, (4.0, 2.0)) == CLASS_ID["door"]
    assert label_at(parsed, (-1.0, -1.0)) == 0
    assert (parsed.instance_ids == 0).sum() == (parsed.labels == 0).sum()


def test_contours_and_areas_match_the_polygons():
    plan = simple_plan()
    parsed = parse_ground_truth(plan, size_px=512)
    living = parsed.of_class("living")[0]
    assert living.polygon_m(parsed.grid).symmetric_difference(plan["living"][0]).area < 1e-9
    assert living.area_m2(parsed.grid) == pytest.approx(3.9 * 4, rel=0.02)
    assert living.centroid_m(parsed.grid) == pytest.approx((1.95, 2.0), abs=0.03)


def test_later_classes_paint_over_earlier_ones():
    plan = simple_plan()
    plan.polygons["front_door"] = [box(3.9, 1.5, 4.1, 2.4)]  # exactly on top of the door
    parsed = parse_ground_truth(plan, size_px=256)
    assert label_at(parsed, (4.0, 2.0)) == CLASS_ID["front_door"]
    assert not parsed.of_class("door")  # painted over entirely: left out


def test_open_kitchen_opening_is_a_thin_strip_from_both_spaces():
    hole = box(0, 0, 6, 4)
    plan = FloorPlan(
        {
            "living": [box(0, 0, 3, 4)],
            "kitchen": [box(3, 0, 6, 4)],
            "wall": [hole.buffer(WALL, join_style="mitre").difference(hole)],
        },
        WALL,
    )
    parsed = parse_ground_truth(plan, size_px=512)
    (opening,) = parsed.of_class(OPENING)
    mask = parsed.instance_ids == opening.id
    rows, cols = np.nonzero(mask)
    assert cols.max() - cols.min() + 1 <= 2  # 1-2 px across x = 3 m
    assert 4.0 * 0.9 <= opening.area_px * parsed.grid.metres_per_px / (cols.max() - cols.min() + 1)
    assert opening.area_px * parsed.grid.metres_per_px <= 2 * 4.0 * 1.05
    assert set(np.unique(parsed.labels[mask])) == {CLASS_ID["living"], CLASS_ID["kitchen"]}
    x_m = parsed.grid.to_m(np.stack([cols, rows], -1))[:, 0]
    assert np.all(np.abs(x_m - 3.0) < 2 * parsed.grid.metres_per_px)


def test_explicit_grid_is_used():
    plan = simple_plan()
    grid = PixelGrid(0.05, (-1.0, 5.0), (120, 200))
    parsed = parse_ground_truth(plan, grid)
    assert parsed.grid == grid and parsed.instance_ids.shape == (120, 200)
    assert label_at(parsed, (6.0, 2.0)) == CLASS_ID["bedroom"]


def test_generated_plans_parse_into_connected_graphs():
    """Every space of a synthetic apartment is reachable from its front door (ground robot)."""
    import networkx as nx

    from f2n_drake.datasets.generator import generate_plan
    from f2n_drake.mapping.graph import build_connectivity_graph
    from f2n_drake.mapping.robots import GROUND, traversable_subgraph

    for seed in (0, 2, 3):
        plan = generate_plan(seed)
        parsed = parse_ground_truth(plan)
        counts = {n: len(parsed.of_class(n)) for n in ("door", "window", "front_door")}
        assert counts == {n: len(plan[n]) for n in counts}
        sub = traversable_subgraph(build_connectivity_graph(parsed), GROUND)
        fronts = [n for n in sub if n.startswith("front_door")]
        reach = set().union(*(nx.node_connected_component(sub, f) for f in fronts))
        spaces = {n for n, d in sub.nodes(data=True) if d["kind"] == "space"}
        assert spaces and spaces <= reach, seed
        if plan.metadata.get("open_kitchen"):
            assert parsed.of_class(OPENING), seed


# -- scale -------------------------------------------------------------------------------


def test_resolve_scale_sources():
    import dataclasses

    from f2n_drake.core.errors import InputError
    from f2n_drake.perception.scale import resolve_scale

    plan = simple_plan()
    parsed = parse_ground_truth(plan, size_px=512)
    assert resolve_scale(parsed) is parsed  # the input's own grid
    given = resolve_scale(parsed, metres_per_px=0.02)
    assert given.scale_source == "argument" and given.grid.metres_per_px == 0.02
    assert given.grid.shape == (512, 512)
    blind = dataclasses.replace(parsed, grid=None, scale_source="unknown")
    # doors 0.9 m (inner) and 1.0 m (front): the median (0.95 m) is taken as 0.9 m
    estimated = resolve_scale(blind)
    assert estimated.scale_source == "door-width estimate, 0.9 m doors"
    assert estimated.grid.metres_per_px == pytest.approx(
        parsed.grid.metres_per_px * 0.9 / 0.95, rel=0.05
    )
    with pytest.raises(InputError, match="no door"):
        resolve_scale(dataclasses.replace(blind, instances=blind.of_class("living", "wall")))
    with pytest.raises(InputError, match="positive"):
        resolve_scale(blind, metres_per_px=-1.0)
