"""Tests of ``python -m f2n_drake.data``: generate, render-resplan, benchmark, figure, errors."""

from __future__ import annotations

import json
import pickle
import re

import cv2
import numpy as np
import pytest
from shapely.geometry import box

import f2n_drake.datasets.cli as data_cli
from f2n_drake.core.errors import InputError, run_cli
from f2n_drake.core.paths import resplan_sample_path
from f2n_drake.core.plan import FloorPlan
from f2n_drake.core.raster import PixelGrid
from f2n_drake.datasets.cli import main
from f2n_drake.datasets.generator import generate_plan
from f2n_drake.datasets.render import render
from f2n_drake.datasets.resplan import load_resplan


def cli(*argv: str) -> int:
    return run_cli(main, [str(a) for a in argv])


def read(path) -> np.ndarray:
    image = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    assert image is not None, path
    return image


def test_generate_writes_triples_matching_the_renderer(tmp_path, capsys):
    out = tmp_path / "train"
    assert cli("generate", "--n", 3, "--out", out, "--size", 128, "--seed", 5) == 0
    assert "wrote 3 plans" in capsys.readouterr().out
    index = json.loads((out / "index.json").read_text())
    assert index["n"] == 3 and [e["seed"] for e in index["items"]] == [5, 6, 7]
    assert sum(index["class_pixel_counts"]) == 3 * 128 * 128
    for i, seed in enumerate((5, 6, 7)):
        expected = render(generate_plan(seed), 128)
        np.testing.assert_array_equal(read(out / f"{i:05d}_label.png"), expected.labels)
        np.testing.assert_array_equal(read(out / f"{i:05d}_image.png"), expected.image)
        plan = FloorPlan.load(out / f"{i:05d}_plan.json")
        assert plan.metadata["seed"] == seed
        assert PixelGrid.from_dict(plan.metadata["render"]) == expected.grid
    assert sorted(p.name for p in tmp_path.iterdir()) == ["train"]  # no scratch left


def test_generate_with_styles_is_deterministic(tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    assert cli("generate", "--n", 4, "--out", a, "--size", 96, "--styles") == 0
    assert cli("generate", "--n", 4, "--out", b, "--size", 96, "--styles") == 0
    images = [read(a / f"{i:05d}_image.png") for i in range(4)]
    for i in range(4):
        np.testing.assert_array_equal(images[i], read(b / f"{i:05d}_image.png"))
    styles = [FloorPlan.load(a / f"{i:05d}_plan.json").metadata["style"] for i in range(4)]
    assert len({json.dumps(s, sort_keys=True) for s in styles}) > 1


def big_plan(seed: int, *, building: bool = False) -> FloorPlan:
    """A fake 'building' 20 x 10 m, or 300 x 30 m for seed 1 (too big for 0.03 m/px)."""
    width = 300.0 if seed == 1 else 20.0
    return FloorPlan({"living": [box(0, 0, width, 10)], "wall": [box(0, 10, width, 10.2)]}, 0.2)


def test_building_mode_fixed_scale_with_size_cap(tmp_path, monkeypatch):
    monkeypatch.setattr(data_cli, "_generator", lambda: big_plan)
    assert cli("generate", "--n", 2, "--out", tmp_path / "b", "--building") == 0
    index = json.loads((tmp_path / "b" / "index.json").read_text())
    small, huge = index["items"]
    assert small["metres_per_px"] == pytest.approx(0.03)
    assert small["shape"][1] == pytest.approx(20 / 0.03 + 32, abs=2)
    assert huge["metres_per_px"] > 0.03 and max(huge["shape"]) <= 4096


def test_failure_midway_leaves_nothing(tmp_path, monkeypatch, capsys):
    def flaky(seed, *, building=False):
        if seed == 2:
            raise InputError("generator refused seed 2")
        return generate_plan(seed)

    monkeypatch.setattr(data_cli, "_generator", lambda: flaky)
    assert cli("generate", "--n", 4, "--out", tmp_path / "out", "--size", 64) == 2
    assert capsys.readouterr().err.strip() == "error: generator refused seed 2"
    assert list(tmp_path.iterdir()) == []


def test_render_resplan(tmp_path):
    out = tmp_path / "real"
    assert cli("render-resplan", resplan_sample_path(), "--out", out, "--size", 256) == 0
    index = json.loads((out / "index.json").read_text())
    assert [e["resplan_id"] for e in index["items"]] == [13, 0]
    plans = load_resplan(resplan_sample_path())
    for i, plan in enumerate(plans):
        np.testing.assert_array_equal(read(out / f"{i:05d}_label.png"), render(plan, 256).labels)
        saved = FloorPlan.load(out / f"{i:05d}_plan.json")
        assert saved.counts() == plan.counts()
        assert saved.metadata["metres_per_unit"] == plan.metadata["metres_per_unit"]


def bad_pickles(tmp_path):
    sample = resplan_sample_path().read_bytes()
    files = {
        "truncated.pkl": (sample[: len(sample) // 3], "not a readable pickle"),
        "garbage.pkl": (b"not a pickle at all", "not a readable pickle"),
        "dict.pkl": (pickle.dumps({"id": 1, "area": 3.0}), "missing keys"),
        "ints.pkl": (pickle.dumps([1, 2, 3]), "list of ResPlan dicts"),
        "empty_geom.pkl": (
            pickle.dumps(
                [
                    {k: box(0, 0, 0, 0) for k in ("wall", "door", "window", "front_door", "inner")}
                    | {"area": 10.0}
                ]
            ),
            "metres_per_unit|empty geometry",
        ),
    }
    for name, (content, _) in files.items():
        (tmp_path / name).write_bytes(content)
    return {tmp_path / name: match for name, (_, match) in files.items()}


def test_render_resplan_bad_files(tmp_path, capsys):
    cases = bad_pickles(tmp_path)
    cases[tmp_path / "missing.pkl"] = "cannot read"
    for path, match in cases.items():
        out = tmp_path / f"out_{path.stem}"
        assert cli("render-resplan", path, "--out", out) == 2
        err = capsys.readouterr().err
        assert err.startswith("error: ") and err.count("\n") == 1, err
        assert re.search(match, err), (path.name, err)
        assert not out.exists()


def test_empty_geometry_with_explicit_scale(tmp_path, capsys):
    record = {k: box(0, 0, 0, 0) for k in ("wall", "door", "window", "front_door", "living")}
    (tmp_path / "empty.pkl").write_bytes(pickle.dumps([record]))
    assert (
        cli(
            "render-resplan",
            tmp_path / "empty.pkl",
            "--out",
            tmp_path / "o",
            "--metres-per-unit",
            0.05,
        )
        == 2
    )
    assert "empty geometry" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_bad_arguments(tmp_path, capsys):
    (tmp_path / "afile").write_text("x")
    assert cli("render-resplan", resplan_sample_path(), "--out", tmp_path / "afile") == 2
    assert "not a directory" in capsys.readouterr().err
    assert (tmp_path / "afile").read_text() == "x"
    assert cli("generate", "--n", 2, "--out", tmp_path / "afile") == 2
    assert "not a directory" in capsys.readouterr().err
    assert cli("generate", "--n", 0, "--out", tmp_path / "g") == 2
    assert "--n must be a positive" in capsys.readouterr().err
    assert cli("generate", "--n", 1, "--size", 16, "--out", tmp_path / "g") == 2
    assert "at least 64" in capsys.readouterr().err
    assert cli("figure", "--out", tmp_path) == 2
    assert "is a directory" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile"]


def test_benchmark_json(capsys):
    assert cli("benchmark", "--n", 3, "--size", 128, "--json") == 0
    result = json.loads(capsys.readouterr().out)
    assert result["n"] == 3 and result["plans_per_s"] > 0
    assert result["render_ms"] > 0 and result["generate_ms"] > 0


def test_figure(tmp_path, capsys):
    out = tmp_path / "figs" / "cmp.png"
    assert cli("figure", "--out", out, "--size", 128) == 0
    image = read(out)
    assert image.shape[0] > 400 and image.shape[1] > 400
    assert sorted(p.name for p in out.parent.iterdir()) == ["cmp.png"]
