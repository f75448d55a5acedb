"""Tests of the synthetic floor-plan generator and validate_plan."""

from __future__ import annotations

import dataclasses
import json
import warnings

import numpy as np
import pytest
import shapely
from shapely.affinity import translate

from f2n_drake.core.plan import FloorPlan
from f2n_drake.datasets.generator import (
    OPENING_SIZES,
    TYPICAL_SIZES,
    generate_building,
    generate_plan,
    generate_residential,
    validate_plan,
)

SEEDS = range(50)


@pytest.fixture(scope="module")
def plans() -> list[FloorPlan]:
    return [generate_plan(s) for s in range(100)]


def _json(plan: FloorPlan) -> str:
    return json.dumps(plan.to_json_dict(), sort_keys=True)


def _sides(poly) -> tuple[float, float]:
    x0, y0, x1, y1 = poly.bounds
    return tuple(sorted((x1 - x0, y1 - y0)))


def test_same_seed_same_plan_and_different_seeds_differ():
    assert _json(generate_plan(7)) == _json(generate_plan(7))
    assert _json(generate_plan(7)) != _json(generate_plan(8))
    assert _json(generate_plan(3, building=True)) == _json(generate_plan(3, building=True))


def test_metadata_and_source():
    plan = generate_plan(5)
    assert plan.source == "synthetic"
    assert plan.metadata["seed"] == 5 and plan.metadata["kind"] == "residential"
    assert isinstance(plan.metadata["open_kitchen"], bool)
    assert plan.metadata["outline"] in ("rect", "L", "T", "U")


def test_generated_plans_validate(plans):
    for seed in SEEDS:
        assert validate_plan(plans[seed]) == [], f"seed {seed}"


def test_json_round_trip(tmp_path, plans):
    plans[0].save(tmp_path / "p.json")
    assert _json(FloorPlan.load(tmp_path / "p.json")) == _json(plans[0])


def test_ranges(plans):
    outlines = set()
    for plan in plans:
        c = plan.counts()
        assert 1 <= c["bedroom"] <= 4 and 1 <= c["bathroom"] <= 3
        assert c["kitchen"] == 1 and c["living"] == 1 and c["front_door"] == 1
        assert 0 <= c["balcony"] <= 3
        t_int, t_ext = plan.wall_thickness_m, plan.metadata["exterior_wall_thickness_m"]
        assert 0.15 <= t_int <= t_ext <= 0.30
        x0, y0, x1, y1 = shapely.total_bounds(plan["wall"])
        assert 8.0 - 1e-9 <= x1 - x0 - t_ext <= 20.0 + 1e-9
        assert 8.0 - 1e-9 <= y1 - y0 - t_ext <= 20.0 + 1e-9
        for name in ("door", "front_door"):
            for door in plan[name]:
                depth, width = _sides(door)
                assert 0.7 - 1e-9 <= width <= 1.2 + 1e-9
                assert min(abs(depth - t_int), abs(depth - t_ext)) < 1e-9
                assert door.area == pytest.approx(depth * width)  # a rectangle
        for window in plan["window"]:
            assert 0.6 - 1e-9 <= _sides(window)[1] <= 2.5 + 1e-9
        outlines.add(plan.metadata["outline"])
    assert outlines == {"rect", "L", "T", "U"}


def _window_widths_cm(plan: FloorPlan) -> dict[str, list[int]]:
    """Each window's width [cm] under the type of the room it lights."""
    widths: dict[str, list[int]] = {}
    for window in plan["window"]:
        room = next(
            name
            for name in ("living", "bedroom", "kitchen", "bathroom")
            for space in plan[name]
            if space.distance(window) < 1e-6
        )
        widths.setdefault(room, []).append(round(_sides(window)[1] * 100))
    return widths


def test_typical_sizes_keep_each_room_type_in_its_own_window_range(plans):
    for plan in plans[:30]:
        assert plan.metadata["opening_sizes"] == "typical"
        for room, widths in _window_widths_cm(plan).items():
            lo, hi = TYPICAL_SIZES.window[room]
            assert all(lo <= w <= hi for w in widths), (plan.metadata["seed"], room, widths)


def test_varied_sizes_overlap_across_room_types_and_leave_layouts_valid():
    varied = [generate_plan(s, sizes=OPENING_SIZES["varied"]) for s in range(40)]
    bedroom_windows, doors = [], []
    for plan in varied:
        assert validate_plan(plan) == [] and plan.metadata["opening_sizes"] == "varied"
        bedroom_windows += _window_widths_cm(plan).get("bedroom", [])
        doors += [round(_sides(d)[1] * 100) for d in plan["door"]]
    typical_lo = TYPICAL_SIZES.window["bedroom"][0]
    assert min(bedroom_windows) < typical_lo  # bedroom windows as small as a bathroom's
    assert max(doors) > TYPICAL_SIZES.door[1]
    # the layout is the seed's: only the openings' widths change
    typical = generate_plan(3)
    assert [s.area for s in varied[3]["bedroom"]] == [s.area for s in typical["bedroom"]]


def test_doors_exactly_fill_wall_gaps(plans):
    plan = plans[1]
    walls = shapely.union_all(plan["wall"])
    for door in plan["door"] + plan["front_door"] + plan["window"]:
        assert shapely.area(shapely.intersection(door, walls)) < 1e-9
        # both short ends of the gap are wall faces
        assert (
            shapely.length(shapely.intersection(door.boundary, walls.boundary))
            >= 2 * _sides(door)[0] - 1e-6
        )


def test_open_kitchen_share_and_geometry(plans):
    open_plans = [p for p in plans if p.metadata["open_kitchen"]]
    assert 20 <= len(open_plans) <= 60
    for plan in open_plans:
        kitchen, living = plan["kitchen"][0], plan["living"][0]
        shared = shapely.intersection(kitchen.boundary, living.boundary).length
        assert shared >= 0.6
    closed = next(p for p in plans if not p.metadata["open_kitchen"])
    assert (
        closed["kitchen"][0].distance(closed["living"][0]) > 0.1
        or shapely.intersection(closed["kitchen"][0].boundary, closed["living"][0].boundary).length
        < 1e-9
    )


def test_validate_catches_overlap(plans):
    plan = plans[2]
    bedroom = plan["bedroom"][0]
    broken = dataclasses.replace(
        plan,
        polygons={**plan.polygons, "bedroom": [*plan["bedroom"], translate(bedroom, 0.5, 0.0)]},
    )
    assert any("overlaps" in p for p in validate_plan(broken))


def test_validate_catches_unreachable_room(plans):
    plan = plans[3]
    bedroom = plan["bedroom"][0]
    doors = [d for d in plan["door"] if d.distance(bedroom) > 1e-6]
    broken = dataclasses.replace(plan, polygons={**plan.polygons, "door": doors})
    problems = validate_plan(broken)
    assert "bedroom[0] is not reachable from the front door" in problems


def test_validate_catches_door_touching_one_space(plans):
    plan = plans[4]
    fake = plan["window"][0]
    broken = dataclasses.replace(
        plan,
        polygons={**plan.polygons, "window": plan["window"][1:], "door": [*plan["door"], fake]},
    )
    assert any("touches 1 spaces, expected 2" in p for p in validate_plan(broken))


def test_validate_catches_small_room_and_nonfinite(plans):
    plan = plans[5]
    tiny = shapely.box(100.0, 100.0, 101.0, 101.5)
    broken = dataclasses.replace(plan, polygons={**plan.polygons, "storage": [tiny]})
    problems = validate_plan(broken)
    assert any("too small" in p for p in problems)
    assert any("storage[0] is not reachable" in p for p in problems)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        nan = shapely.Polygon([(0, 0), (1, 0), (float("nan"), 1)])
    broken = dataclasses.replace(plan, polygons={**plan.polygons, "balcony": [nan]})
    assert validate_plan(broken) == ["non-finite coordinates"]


def test_residential_takes_a_generator():
    a = generate_residential(np.random.default_rng(11))
    b = generate_residential(np.random.default_rng(11))
    assert _json(a) == _json(b)


def test_building_mode():
    plan = generate_building(np.random.default_rng(0), n_rooms=60)
    c = plan.counts()
    assert c["bedroom"] + c["bathroom"] + c["kitchen"] + c["living"] - 1 == 60  # minus corridors
    assert (
        plan.metadata["kind"] == "building"
        and plan.metadata["n_front_doors"] == c["front_door"] >= 1
    )
    assert validate_plan(plan) == []
    x0, y0, x1, y1 = plan.bounds
    assert 20 <= max(x1 - x0, y1 - y0) <= 130
    with pytest.raises(ValueError):
        generate_building(np.random.default_rng(0), n_rooms=20)


def test_building_default_room_count():
    plan = generate_plan(1, building=True)
    assert 50 <= plan.metadata["n_rooms"] <= 300
    assert plan.metadata["seed"] == 1 and plan.source == "synthetic"
    assert validate_plan(plan) == []
