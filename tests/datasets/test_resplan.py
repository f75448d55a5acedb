"""Tests of the ResPlan reader on the two real sample plans and on broken inputs."""

from __future__ import annotations

import json
import pickle

import numpy as np
import pytest
import shapely
from shapely.geometry import MultiPolygon, Polygon, box

from f2n_drake.core.errors import InputError
from f2n_drake.core.paths import resplan_sample_path
from f2n_drake.core.plan import FloorPlan
from f2n_drake.datasets.resplan import load_resplan, resplan_to_floorplan


@pytest.fixture(scope="module")
def records():
    with resplan_sample_path().open("rb") as f:
        return {r["id"]: r for r in pickle.load(f)}


@pytest.fixture(scope="module")
def plans():
    return {p.metadata["id"]: p for p in load_resplan(resplan_sample_path())}


def sides(poly: Polygon) -> tuple[float, float]:
    """(long, short) sides of the minimum rotated rectangle [m]."""
    rect = np.asarray(poly.minimum_rotated_rectangle.exterior.coords)
    lengths = np.linalg.norm(np.diff(rect, axis=0), axis=1)
    return float(lengths.max()), float(lengths.min())


EXPECTED_COUNTS = {
    13: dict(
        living=1,
        bedroom=2,
        bathroom=2,
        kitchen=1,
        balcony=2,
        wall=5,
        door=7,
        window=4,
        front_door=1,
        storage=1,
    ),
    0: dict(
        living=3,
        bedroom=3,
        bathroom=4,
        kitchen=1,
        balcony=1,
        wall=8,
        door=8,
        window=6,
        front_door=1,
    ),
}


@pytest.mark.parametrize("plan_id", [13, 0])
def test_class_counts(plans, plan_id):
    plan = plans[plan_id]
    assert plan.source == "resplan"
    assert plan.counts() == EXPECTED_COUNTS[plan_id]


@pytest.mark.parametrize("plan_id", [13, 0])
def test_scale_area_and_wall_thickness(plans, records, plan_id):
    plan, rec = plans[plan_id], records[plan_id]
    s = plan.metadata["metres_per_unit"]
    assert 0.04 < s < 0.08 and plan.metadata["scale_source"] == "area/inner"
    assert plan.metadata["area"] == pytest.approx(rec["area"])
    assert plan.wall_thickness_m == pytest.approx(rec["wall_depth"] * s)
    assert 0.15 < plan.wall_thickness_m < 0.30
    # `area` is the area of `inner`: the footprint inside the exterior wall's inner face (rooms,
    # storage, interior walls and doors). Check it independently of `inner`, which we drop:
    # the outer footprint (rooms + walls + openings, holes filled) shrunk by one wall thickness.
    footprint = plan.union(
        "living",
        "bedroom",
        "bathroom",
        "kitchen",
        "storage",
        "wall",
        "door",
        "window",
        "front_door",
    )
    parts = getattr(footprint, "geoms", [footprint])
    outer = shapely.union_all([Polygon(p.exterior) for p in parts])
    inside = outer.buffer(-plan.wall_thickness_m, join_style="mitre")
    assert inside.area == pytest.approx(rec["area"], rel=0.03)
    rooms = plan.union("living", "bedroom", "bathroom", "kitchen", "storage").area
    assert rooms < rec["area"] < rooms + plan.union("wall").area


@pytest.mark.parametrize("plan_id", [13, 0])
def test_openings_fill_wall_gaps(plans, plan_id):
    plan = plans[plan_id]
    for name in ("door", "front_door", "window"):
        for poly in plan[name]:
            _, short = sides(poly)
            assert short == pytest.approx(plan.wall_thickness_m, rel=0.05), name
            assert poly.intersection(plan.union("wall")).area < 1e-3 * poly.area
    door_widths = [sides(p)[0] for p in plan["door"]]
    assert all(0.85 <= w <= 1.2 for w in door_widths), door_widths
    assert 0.9 <= sides(plan["front_door"][0])[0] <= 1.5


def test_geometry_in_metres_y_up(plans, records):
    plan, rec = plans[13], records[13]
    s = plan.metadata["metres_per_unit"]
    np.testing.assert_allclose(
        plan.bounds,
        np.asarray(
            shapely.total_bounds([rec[k] for k in ("living", "wall", "balcony", "front_door")])
        )
        * s,
        atol=1e-9,
    )
    assert plan["kitchen"][0].area == pytest.approx(rec["kitchen"].area * s * s)
    # Open kitchen: it shares an edge with the living room.
    shared = plan["kitchen"][0].intersection(plan["living"][0])
    assert shared.length > 1.0


def test_metadata_is_json_and_round_trips(plans, tmp_path):
    plan = plans[0]
    assert set(plan.metadata) >= {"id", "unitType", "area", "net_area", "metres_per_unit"}
    json.dumps(plan.metadata)
    assert type(plan.metadata["net_area"]) is float
    plan.save(tmp_path / "p.json")
    back = FloorPlan.load(tmp_path / "p.json")
    assert back.counts() == plan.counts() and back.metadata == plan.metadata
    assert "inner" not in plan.polygons and "land" not in plan.polygons


def minimal_record(**extra):
    rec = {
        "living": MultiPolygon([box(0, 0, 40, 40)]),
        "wall": MultiPolygon([box(-4, -4, 44, 0)]),
        "door": MultiPolygon([box(10, 40, 25, 44)]),
        "window": Polygon(),
        "front_door": box(-4, 10, 0, 25),
        "inner": box(0, 0, 40, 40),
        "area": 4.0,  # 40 units = 2 m: 0.05 m/unit
        "wall_depth": 4.0,
    }
    rec.update(extra)
    return rec


def test_minimal_record_alias_and_explicit_scale():
    plan = resplan_to_floorplan(minimal_record(balacony=box(0, 44, 40, 60)))
    assert plan.metadata["metres_per_unit"] == pytest.approx(0.05)
    assert plan.wall_thickness_m == pytest.approx(0.2)
    assert len(plan["balcony"]) == 1 and plan["window"] == []
    assert plan["living"][0].bounds == pytest.approx((0, 0, 2, 2))
    explicit = resplan_to_floorplan(minimal_record(), metres_per_unit=0.1)
    assert explicit.metadata["scale_source"] == "explicit"
    assert explicit["living"][0].area == pytest.approx(16.0)


def test_missing_wall_depth_is_estimated_from_openings():
    rec = minimal_record()
    del rec["wall_depth"]
    assert resplan_to_floorplan(rec).wall_thickness_m == pytest.approx(0.2)


@pytest.mark.parametrize(
    ("record", "match"),
    [
        ({"living": box(0, 0, 1, 1)}, r"missing keys \['wall', 'door', 'window', 'front_door'\]"),
        (minimal_record(area=None), "metres_per_unit"),
        (minimal_record(inner=Polygon()), "metres_per_unit"),
        (
            minimal_record(living=Polygon(), wall=Polygon(), door=Polygon(), front_door=Polygon()),
            "empty geometry",
        ),
        (minimal_record(door="not a geometry"), "'door' is a str"),
    ],
)
def test_bad_records(record, match):
    with pytest.raises(InputError, match=match):
        resplan_to_floorplan(record)


def test_bad_files(tmp_path):
    with pytest.raises(InputError, match="cannot read"):
        load_resplan(tmp_path / "missing.pkl")
    data = resplan_sample_path().read_bytes()
    (tmp_path / "truncated.pkl").write_bytes(data[: len(data) // 2])
    with pytest.raises(InputError, match="not a readable pickle"):
        load_resplan(tmp_path / "truncated.pkl")
    (tmp_path / "garbage.pkl").write_bytes(b"hello world")
    with pytest.raises(InputError, match="not a readable pickle"):
        load_resplan(tmp_path / "garbage.pkl")
    (tmp_path / "ints.pkl").write_bytes(pickle.dumps([1, 2]))
    with pytest.raises(InputError, match="list of ResPlan dicts"):
        load_resplan(tmp_path / "ints.pkl")
    (tmp_path / "empty.pkl").write_bytes(pickle.dumps([]))
    with pytest.raises(InputError, match="no plans"):
        load_resplan(tmp_path / "empty.pkl")
    (tmp_path / "nokeys.pkl").write_bytes(pickle.dumps({"id": 3}))
    with pytest.raises(InputError, match=r"plan #0: .*missing keys"):
        load_resplan(tmp_path / "nokeys.pkl")
    with pytest.raises(InputError, match="positive"):
        load_resplan(resplan_sample_path(), metres_per_unit=-1.0)


def test_messages_are_one_line(tmp_path):
    (tmp_path / "garbage.pkl").write_bytes(b"\x80\x04garbage")
    with pytest.raises(InputError) as info:
        load_resplan(tmp_path / "garbage.pkl")
    assert "\n" not in str(info.value) and str(tmp_path) in str(info.value)
