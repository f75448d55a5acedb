"""Tests of the shared core: FloorPlan JSON, PixelGrid, atomic_output_dir, run_cli."""

from __future__ import annotations

import json

import numpy as np
import pytest
from shapely.geometry import Polygon, box

from f2n_drake.core.classes import PLAN_CLASSES
from f2n_drake.core.errors import InputError, run_cli
from f2n_drake.core.output_dir import MARKER, atomic_output_dir
from f2n_drake.core.plan import FloorPlan, polygons_of
from f2n_drake.core.raster import PixelGrid


def awkward_plan() -> FloorPlan:
    """Floats that do not survive a naive round trip, a hole, an extra key and metadata."""
    ring = [(0.1, 0.2), (3.0000000000000004, 0.2), (3.0000000000000004, 1 / 3), (0.1, 2 / 3)]
    wall = Polygon(box(-1, -1, 5, 5).exterior.coords, [box(0, 0, 4, 4).exterior.coords])
    return FloorPlan(
        {"living": [Polygon(ring)], "wall": [wall], "storage": [box(1e-17, 7, 8, 9.123456789)]},
        0.2 + 1e-15,
        "test",
        {"seed": 7, "nested": {"a": [1, 2.5]}},
    )


def test_json_round_trip_is_lossless(tmp_path):
    plan = awkward_plan()
    plan.save(tmp_path / "plan.json")
    back = FloorPlan.load(tmp_path / "plan.json")
    assert back.wall_thickness_m == plan.wall_thickness_m
    assert back.source == plan.source and back.metadata == plan.metadata
    assert list(back.polygons) == list(plan.polygons)
    for name, polys in plan.polygons.items():
        assert len(back[name]) == len(polys)
        for a, b in zip(polys, back[name], strict=True):
            assert a.equals_exact(b, 0.0)  # bit-exact coordinates, holes included
    assert len(back["wall"][0].interiors) == 1
    assert back.to_json_dict() == plan.to_json_dict()


def test_plan_has_every_class_and_rejects_bad_input():
    plan = FloorPlan({"door": [box(0, 0, 1, 0.2)]}, 0.2)
    assert set(PLAN_CLASSES) <= set(plan.polygons) and plan["bedroom"] == []
    assert plan.bounds == (0.0, 0.0, 1.0, 0.2)
    with pytest.raises(InputError, match="unknown"):
        FloorPlan({"garage": []}, 0.2)
    with pytest.raises(InputError, match="thickness"):
        FloorPlan({}, 0.0)
    with pytest.raises(InputError, match="no geometry"):
        _ = FloorPlan({}, 0.2).bounds


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ('{"type": "FeatureCollection", "properties": {"format": "f2n_drake.floorplan/1"', "JSON"),
        ("garbage \x00\x01", "not valid JSON"),
        ("[1, 2]", "not a floor-plan JSON object"),
        ('{"type": "FeatureCollection", "properties": {"format": "other"}}', "format"),
        ('{"properties": {"format": "f2n_drake.floorplan/1"}}', "malformed"),
    ],
)
def test_load_rejects_truncated_and_garbage(tmp_path, text, match):
    (tmp_path / "bad.json").write_text(text)
    with pytest.raises(InputError, match=match):
        FloorPlan.load(tmp_path / "bad.json")


def test_load_rejects_truncated_saved_plan_and_missing_file(tmp_path):
    awkward_plan().save(tmp_path / "p.json")
    text = (tmp_path / "p.json").read_text()
    (tmp_path / "p.json").write_text(text[: len(text) // 2])
    with pytest.raises(InputError, match="not valid JSON"):
        FloorPlan.load(tmp_path / "p.json")
    with pytest.raises(InputError, match="cannot read"):
        FloorPlan.load(tmp_path / "missing.json")
    data = json.loads(text)
    data["features"][0]["geometry"] = {"type": "Point", "coordinates": [0, 0]}
    with pytest.raises(InputError, match="Point"):
        FloorPlan.from_json_dict(data)


def test_polygons_of_splits_and_drops_empty():
    multi = box(0, 0, 1, 1).union(box(3, 3, 4, 4))
    assert len(polygons_of(multi)) == 2
    assert polygons_of(Polygon()) == [] and polygons_of(None) == []


def test_pixel_grid_to_px_and_to_m_are_inverse():
    grid = PixelGrid(0.05, (-1.0, 7.0), (200, 300))
    xy = np.random.default_rng(0).uniform(-5, 10, size=(50, 2))
    np.testing.assert_allclose(grid.to_m(grid.to_px(xy)), xy, atol=1e-12)
    px = np.array([[0.0, 0.0], [299.0, 199.0]])
    np.testing.assert_allclose(grid.to_px(grid.to_m(px)), px, atol=1e-9)
    # Pixel (0, 0) is centred half a pixel inside the top-left corner; y points up.
    np.testing.assert_allclose(grid.to_m(np.array([0.0, 0.0])), [-0.975, 6.975])
    assert grid.length_px(1.0) == pytest.approx(20.0) and grid.area_m2(400) == pytest.approx(1.0)
    assert PixelGrid.from_dict(json.loads(json.dumps(grid.to_dict()))) == grid
    with pytest.raises(ValueError):
        PixelGrid(0.0, (0, 0), (1, 1))


def test_pixel_grid_fit_centres_bounds_inside_margin():
    bounds = (2.0, -1.0, 12.0, 4.0)  # 10 m x 5 m
    grid = PixelGrid.fit(bounds, 256, margin_px=16)
    assert grid.shape == (256, 256)
    assert grid.metres_per_px == pytest.approx(10.0 / (256 - 32))
    corners = grid.to_px(np.array([[2.0, 4.0], [12.0, -1.0]]))
    # The long side spans exactly the inner width; the short side is centred.
    np.testing.assert_allclose(corners[:, 0], [15.5, 239.5])
    assert corners[0, 1] - 0 == pytest.approx(255 - corners[1, 1])
    from_scale = PixelGrid.from_scale(0.1, (100, 50))
    np.testing.assert_allclose(from_scale.to_m(np.array([-0.5, 99.5])), [0.0, 0.0], atol=1e-12)


def test_atomic_output_dir_replaces_the_folder_as_a_whole(tmp_path):
    out = tmp_path / "out"
    with atomic_output_dir(out) as tmp:
        (tmp / "a.txt").write_text("old")
        (tmp / "gone.txt").write_text("old")
    with atomic_output_dir(out) as tmp:
        (tmp / "a.txt").write_text("new")
        assert (out / "a.txt").read_text() == "old"  # nothing visible before success
    assert (out / "a.txt").read_text() == "new"
    assert not (out / "gone.txt").exists()  # replaced, not merged
    assert sorted(p.name for p in out.iterdir()) == [MARKER, "a.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # no scratch, no lock left


def test_atomic_output_dir_leaves_nothing_on_error(tmp_path):
    out = tmp_path / "out"
    with pytest.raises(RuntimeError), atomic_output_dir(out) as tmp:
        (tmp / "half.txt").write_text("half")
        raise RuntimeError("boom")
    assert not out.exists()
    assert list(tmp_path.iterdir()) == []  # no scratch directory left behind
    (tmp_path / "file").write_text("x")
    with pytest.raises(InputError, match="not a directory"), atomic_output_dir(tmp_path / "file"):
        pass


def test_run_cli_turns_input_errors_into_exit_2(capsys):
    def failing(argv):
        raise InputError("bad thing")

    assert run_cli(failing, []) == 2
    assert capsys.readouterr().err.strip() == "error: bad thing"
    assert run_cli(lambda argv: 0, []) == 0
