"""Bad input and faults: one error line and a documented exit code, never a traceback, runaway
memory or a half-written output."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time

import cv2
import numpy as np
import pytest
import shapely
from shapely.geometry import shape

from f2n_drake.core import limits
from f2n_drake.core.classes import CLASS_ID
from f2n_drake.core.errors import (
    EXIT_BAD_INPUT,
    EXIT_GOAL_NOT_REACHED,
    EXIT_NO_ROUTE,
    EXIT_TERMINATED,
    InputError,
    Terminated,
    run_cli,
)
from f2n_drake.core.output_dir import MARKER, StagedDir
from f2n_drake.core.paths import REPO_ROOT, resplan_sample_path
from f2n_drake.outputs.writer import PARSE_FILES
from f2n_drake.run import main

EXAMPLE_JSON = REPO_ROOT / "examples" / "plan.json"
EXAMPLE_PNG = REPO_ROOT / "examples" / "plan.png"
AS_ROOT = hasattr(os, "geteuid") and os.geteuid() == 0


def error_of(code: int, argv: list[str], capsys, cli=main) -> str:
    """Run ``cli`` under run_cli; assert the exit code and one ``error:`` line; return it."""
    assert run_cli(cli, argv) == code
    err = capsys.readouterr().err.strip()
    assert err.startswith("error: ") and "\n" not in err, err
    return err


def only(path) -> list[str]:
    return sorted(p.name for p in path.iterdir())


# 1. A plan's size is a building's.


@pytest.mark.parametrize(
    ("scale", "message"),
    [
        ("5", "Did you mean --scale 0.05"),  # cm/px typed for m/px
        ("3.5", "Did you mean --scale 0.035"),
        ("1e-6", "a building is 2 m to 2 km across"),
        ("1e6", "a building is 2 m to 2 km across"),
        ("1e308", "finite number in (0, 1e+06]"),
        ("nan", "finite number"),
    ],
)
def test_scale_that_makes_no_building_is_refused_before_the_work(scale, message, tmp_path, capsys):
    out = tmp_path / "o"
    argv = [str(EXAMPLE_PNG), "--scale", scale, "--no-sim", "--out", str(out)]
    err = error_of(EXIT_BAD_INPUT, argv, capsys)
    assert message in err
    assert only(tmp_path) == []


def test_vector_plan_at_a_scale_that_would_draw_it_huge_is_refused(tmp_path, capsys):
    argv = [str(EXAMPLE_JSON), "--scale", "1e-6", "--no-sim", "--out", str(tmp_path / "o")]
    assert "give a scale of" in error_of(EXIT_BAD_INPUT, argv, capsys)


def test_plan_extent_suggests_the_unit_probably_meant():
    limits.check_plan_extent((600, 800), 0.02, source="--scale 0.02")  # 16 m: fine
    with pytest.raises(InputError, match=r"4 km across.*Did you mean --scale 0.05"):
        limits.check_plan_extent((600, 800), 5.0, source="--scale 5")
    with pytest.raises(InputError, match=r"Did you mean --scale 0\.02 "):
        limits.check_plan_extent((600, 800), 20.0, source="--scale 20")  # mm/px
    with pytest.raises(InputError, match="metres per pixel"):
        limits.check_plan_extent((600, 800), 1e-9, source="--scale 1e-9")


# 2. Float options finite and in range; simulations under a wall-clock limit.


@pytest.mark.parametrize(
    "argv",
    [
        ["--sigma", "nan"],
        ["--rotate", "nan"],
        ["--rotate", "inf"],
        ["--sigma", "-1"],
        ["--margin", "1e300"],
        ["--spacing", "0"],
    ],
)
def test_navigation_float_options_are_finite_and_in_range(argv, capsys):
    from f2n_drake.evaluate.navigation import main as navigation

    err = error_of(EXIT_BAD_INPUT, ["--plans", "1", "--tasks", "1", *argv], capsys, navigation)
    assert "finite number" in err


@pytest.mark.parametrize(
    "option", ["--lr", "--lr-min", "--warmup", "--width", "--max-minutes", "--emphasis"]
)
def test_training_float_options_are_finite(option, tmp_path, capsys):
    from f2n_drake.segmenter.train import main as train

    argv = ["--toy", option, "nan", "--out", str(tmp_path / "w.pt")]
    assert "finite" in error_of(
        EXIT_BAD_INPUT, [*argv, "--runs", str(tmp_path / "r")], capsys, train
    )
    assert only(tmp_path) == []


def test_simulation_stops_at_its_wall_clock_limit():
    from f2n_drake.datasets.generator import generate_plan
    from f2n_drake.evaluate.navigation import sample_tasks
    from f2n_drake.systems.simulation import simulate_navigation

    plan = generate_plan(0)
    (route,) = sample_tasks(plan, 1, np.random.default_rng(0))
    start = time.perf_counter()
    result = simulate_navigation(plan, route, correction="off", wall_time_limit_s=1e-3)
    assert result.wall_time_limited and not result.reached
    assert time.perf_counter() - start < 60
    with pytest.raises(InputError, match="finite"):
        simulate_navigation(plan, route, odometry_sigma_m=float("nan"))


# 3. and 4. Every output place checked before the work; --out replaced as one unit.


def test_output_places_that_cannot_be_written_are_refused_before_the_work(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    argv = [str(EXAMPLE_PNG), "--no-sim", "--out", str(blocker / "out")]
    assert "cannot write --out" in error_of(EXIT_BAD_INPUT, argv, capsys)
    argv = [str(EXAMPLE_PNG), "--out", str(tmp_path / "o"), "--html", str(blocker / "r.html")]
    assert "--html" in error_of(EXIT_BAD_INPUT, argv, capsys)
    assert only(tmp_path) == ["file"]
    from f2n_drake.datasets.cli import main as data

    argv = ["generate", "--n", "1", "--out", str(blocker / "d")]
    assert "cannot write --out" in error_of(EXIT_BAD_INPUT, argv, capsys, data)


@pytest.mark.skipif(AS_ROOT, reason="root writes into read-only folders")
def test_read_only_folders_are_refused_before_the_work(tmp_path, capsys):
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o500)
    try:
        argv = [str(EXAMPLE_PNG), "--out", str(locked / "o")]
        assert "cannot write" in error_of(EXIT_BAD_INPUT, argv, capsys)
        argv = [str(EXAMPLE_PNG), "--out", str(tmp_path / "o"), "--html", str(locked / "r.html")]
        assert "--html" in error_of(EXIT_BAD_INPUT, argv, capsys)
    finally:
        locked.chmod(0o700)


def test_a_folder_of_other_files_is_never_replaced(tmp_path, capsys):
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "thesis.tex").write_text("years of work")
    argv = [str(EXAMPLE_JSON), "--no-sim", "--out", str(mine)]
    assert "did not write" in error_of(EXIT_BAD_INPUT, argv, capsys)
    assert only(mine) == ["thesis.tex"]


def test_out_is_replaced_as_a_whole_and_a_second_writer_is_refused(tmp_path, capsys):
    out = tmp_path / "o"
    argv = [str(EXAMPLE_JSON), "--no-sim", "--out", str(out)]
    assert run_cli(main, [*argv, "--origin", "52.2,0.12"]) == 0
    assert "rooms.geojson" in only(out)
    (tmp_path / ".o.stale.partial").mkdir()  # left by a killed run
    assert run_cli(main, argv) == 0
    assert "rooms.geojson" not in only(out)  # replaced, not merged with the earlier run
    assert only(tmp_path) == ["o"]  # stale scratch removed, lock released
    capsys.readouterr()
    with StagedDir(out):
        assert "another process is writing" in error_of(EXIT_BAD_INPUT, argv, capsys)


def test_terminated_run_leaves_neither_output_nor_scratch(tmp_path, monkeypatch, capsys):
    import f2n_drake.run as run_module

    def terminated(*args, **kwargs):
        raise Terminated()

    monkeypatch.setattr(run_module, "write_outputs", terminated)
    argv = [str(EXAMPLE_JSON), "--no-sim", "--out", str(tmp_path / "o")]
    assert error_of(EXIT_TERMINATED, argv, capsys) == "error: terminated"
    assert only(tmp_path) == []


def test_sigterm_cleans_the_scratch_folder(tmp_path):
    out = tmp_path / "o"
    proc = subprocess.Popen(
        [sys.executable, "-m", "f2n_drake.run", str(EXAMPLE_PNG), "--out", str(out)],
        stderr=subprocess.PIPE,
        text=True,
    )
    deadline = time.monotonic() + 60
    while not list(tmp_path.glob(".o.*.partial")) and time.monotonic() < deadline:
        time.sleep(0.05)
    time.sleep(0.5)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == EXIT_TERMINATED, err
    assert "Traceback" not in err
    assert only(tmp_path) == []


# 5. Training traps.


def test_training_refuses_a_folder_as_out_before_training(tmp_path, capsys):
    from f2n_drake.segmenter.train import main as train

    argv = ["--toy", "--out", str(tmp_path), "--runs", str(tmp_path / "runs")]
    assert "is a folder" in error_of(EXIT_BAD_INPUT, argv, capsys, train)
    assert only(tmp_path) == []


def test_training_that_diverges_stops_and_writes_nothing(tmp_path, monkeypatch, capsys):
    import torch

    from f2n_drake.segmenter import train as train_module

    nan_loss = lambda *a, **k: torch.tensor(float("nan"))
    monkeypatch.setattr(train_module, "set_cross_entropy", nan_loss)
    tiny = ["--toy", "--steps", "2", "--batch", "1", "--crop", "64", "--input-size", "64"]
    tiny += ["--val-plans", "1", "--workers", "0", "--threads", "1", "--width", "0.25"]
    out = tmp_path / "w.pt"
    argv = [*tiny, "--out", str(out), "--runs", str(tmp_path / "runs")]
    assert run_cli(train_module.main, argv) == EXIT_BAD_INPUT
    err = capsys.readouterr().err.strip().splitlines()[-1]  # after the progress bar
    assert "error: training diverged" in err and "nothing was written" in err
    assert not out.exists()
    assert not (tmp_path / "runs").exists() or only(tmp_path / "runs") == []


def test_training_with_missing_data_leaves_no_run_folder(tmp_path, capsys):
    from f2n_drake.segmenter.train import main as train

    argv = ["--data", str(tmp_path / "none"), "--out", str(tmp_path / "w.pt")]
    assert run_cli(train, [*argv, "--runs", str(tmp_path / "runs")]) == EXIT_BAD_INPUT
    assert not (tmp_path / "runs").exists() or only(tmp_path / "runs") == []


# 6. Memory: refused up front.


def test_data_generate_size_is_bounded(tmp_path, capsys):
    from f2n_drake.datasets.cli import main as data

    argv = ["generate", "--n", "1", "--size", "100000", "--out", str(tmp_path / "d")]
    assert "8192 px limit" in error_of(EXIT_BAD_INPUT, argv, capsys, data)


def test_drawing_that_needs_more_memory_than_is_free_is_refused(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(limits, "available_memory_bytes", lambda: limits.PARSE_BASE_BYTES)
    err = error_of(EXIT_BAD_INPUT, [str(EXAMPLE_PNG), "--out", str(tmp_path / "o")], capsys)
    assert "GiB of memory" in err and "Downscale" in err
    # the 12400 x 8000 px drawing: about 8 GB, as measured
    assert 6e9 < limits.parse_memory_bytes((8000, 12400)) < 11e9


# 7. The smaller ones.


def test_robot_profile_errors_are_one_line(tmp_path, capsys):
    bad = tmp_path / "bot.yaml"
    bad.write_text("name: bot\nnavigation:\n  traversable: [door\nbody:\n  radius_m: 0.1\n")
    argv = [str(EXAMPLE_JSON), "--no-sim", "--out", str(tmp_path / "o"), "--robot", str(bad)]
    assert "not valid YAML at line " in error_of(EXIT_BAD_INPUT, argv, capsys)
    argv[-1] = str(tmp_path / "missing.yaml")
    assert "robot profile file not found" in error_of(EXIT_BAD_INPUT, argv, capsys)


def test_truncated_png_prints_only_the_error(tmp_path, capfd):
    broken = tmp_path / "plan.png"
    broken.write_bytes(EXAMPLE_PNG.read_bytes()[:4000])
    assert run_cli(main, [str(broken), "--out", str(tmp_path / "o")]) == EXIT_BAD_INPUT
    err = capfd.readouterr().err.strip()
    assert err.startswith("error: ") and "\n" not in err and "libpng" not in err


def test_file_name_that_is_not_utf8_prints(tmp_path):
    name = os.fsdecode(b"plan\xff.json")
    shutil.copy(EXAMPLE_JSON, tmp_path / name)
    env = {**os.environ, "LC_ALL": "C.UTF-8", "PYTHONIOENCODING": "utf-8"}
    cmd = [sys.executable, "-m", "f2n_drake.run", name, "--no-sim", "--out", "o"]
    done = subprocess.run(cmd, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert "plan\\udcff.json" in done.stdout


@pytest.mark.skipif(not resplan_sample_path().exists(), reason="ResPlan sample not present")
def test_file_of_several_plans_says_which_was_taken(tmp_path, capsys):
    argv = [str(resplan_sample_path()), "--no-sim", "--out", str(tmp_path / "o"), "--json"]
    assert run_cli(main, argv) == 0
    notes = json.loads(capsys.readouterr().out)["notes"]
    assert any("plans; plan 0 was taken" in n for n in notes)


def test_html_replay_is_written_only_with_the_output_folder(tmp_path, monkeypatch, capsys):
    import f2n_drake.run as run_module
    import f2n_drake.systems.simulation as simulation

    path = np.zeros((1, 3))
    done = simulation.NavigationResult(True, False, 1.0, 0, 0, 0, path, path, 0.1, 10.0)

    def drive(world, route, correction, seed, meshcat, replay, **options):
        replay.scratch.write_text("<html></html>")
        return {"continuous": done}

    monkeypatch.setattr(run_module, "simulate_route", drive)
    argv = [str(EXAMPLE_JSON), "--out", str(tmp_path / "o"), "--html", str(tmp_path / "r.html")]
    assert run_cli(main, argv) == 0
    assert only(tmp_path) == ["o", "r.html"]
    shutil.rmtree(tmp_path / "o")
    (tmp_path / "r.html").unlink()

    def fail(*args, **kwargs):
        raise InputError("disk full")

    monkeypatch.setattr(run_module, "write_outputs", fail)
    assert error_of(EXIT_BAD_INPUT, argv, capsys) == "error: disk full"
    assert only(tmp_path) == []


def test_sheet_of_several_plans_is_counted():
    from f2n_drake.perception.ink import binarize
    from f2n_drake.perception.sheet import find_plan

    plan = cv2.imread(str(EXAMPLE_PNG), cv2.IMREAD_GRAYSCALE)[::2, ::2]
    h, w = plan.shape
    gap = w // 4  # plans set apart on the sheet, as sheets print them
    sheet = np.full((2 * h + 3 * gap, 3 * w + 4 * gap), 255, np.uint8)
    for r in range(2):
        for c in range(3):
            sheet[gap + r * (h + gap) :][:h, gap + c * (w + gap) :][:, :w] = plan
    assert find_plan(binarize(plan)).plans == 1
    assert find_plan(binarize(sheet)).plans == 6


@pytest.mark.usefixtures("drawings_at_own_size")
def test_run_notes_a_sheet_of_several_plans(tmp_path, monkeypatch):
    from f2n_drake.perception.ink import binarize
    from f2n_drake.segmenter.inference import Segmenter

    class WallsAndLiving:  # stands in for the network: ink is wall, paper is living room
        def predict(self, image):
            return np.where(binarize(image), CLASS_ID["wall"], CLASS_ID["living"]).astype(np.uint8)

    monkeypatch.setattr(Segmenter, "load", classmethod(lambda cls, *a, **k: WallsAndLiving()))
    room = np.full((60, 80), 255, np.uint8)
    cv2.rectangle(room, (5, 5), (74, 54), 0, 2)
    cv2.line(room, (40, 5), (40, 22), 0, 2)  # walls inside, a doorway between two rooms
    cv2.line(room, (40, 38), (40, 54), 0, 2)
    cv2.line(room, (40, 30), (74, 30), 0, 2)
    sheet = np.full((80, 260), 255, np.uint8)
    sheet[10:70, 10:90] = sheet[10:70, 170:250] = room  # floors drawn 4.5 m apart
    cv2.imwrite(str(tmp_path / "sheet.png"), sheet)
    out = tmp_path / "o"
    argv = [str(tmp_path / "sheet.png"), "--scale", "0.05", "--no-sim", "--out", str(out)]
    assert run_cli(main, argv) in (0, EXIT_NO_ROUTE)
    summary = json.loads((out / "summary.json").read_text())
    assert any("the sheet holds 2 plans" in n for n in summary["notes"])
    # the other plan's rooms are told apart from rooms cut off on the start's plan
    assert summary["on_other_plans"] and set(summary["on_other_plans"]) <= set(
        summary["unreachable"]
    )
    assert any("on another plan of the sheet" in n for n in summary["notes"])


def test_goal_not_reached_has_its_own_exit_code(tmp_path, monkeypatch, capsys):
    import f2n_drake.systems.simulation as simulation

    def nowhere(plan, route, **kwargs):
        path = np.zeros((1, 3))
        return simulation.NavigationResult(False, False, 1.0, 0, 0, 0, path, path, 0.1, 10.0)

    monkeypatch.setattr(simulation, "simulate_navigation", nowhere)
    out = tmp_path / "o"
    argv = [str(EXAMPLE_JSON), "--out", str(out)]
    assert "did not reach its goal" in error_of(EXIT_GOAL_NOT_REACHED, argv, capsys)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "goal not reached"
    assert {*PARSE_FILES, "route.json", "drive.png"} <= set(only(out))


# 8. Rooms: plan metres, or GeoJSON longitude/latitude with --origin; rings counter-clockwise.


def test_rooms_in_plan_metres_and_georeferenced(tmp_path, capsys):
    out = tmp_path / "o"
    argv = [str(EXAMPLE_JSON), "--no-sim", "--out", str(out), "--origin", "52.2,0.12"]
    assert run_cli(main, [*argv, "--heading", "90"]) == 0
    metric = json.loads((out / "rooms_m.json").read_text())
    geo = json.loads((out / "rooms.geojson").read_text())
    assert "not longitude/latitude" in metric["coordinates"]
    assert geo["georeference"] == {"latitude_deg": 52.2, "longitude_deg": 0.12, "heading_deg": 90}
    for a, b in zip(metric["features"], geo["features"], strict=True):
        plan, earth = shape(a["geometry"]), shape(b["geometry"])
        for polygon in (plan, earth):
            assert polygon.exterior.is_ccw and all(not r.is_ccw for r in polygon.interiors)
        lon, lat = earth.centroid.coords[0]
        x, y = plan.centroid.coords[0]
        # heading 90: the drawing's up is east, its right is south
        assert lat == pytest.approx(52.2 - np.degrees(x / 6378137.0), abs=1e-7)
        assert lon == pytest.approx(
            0.12 + np.degrees(y / (6378137.0 * np.cos(np.radians(52.2)))), abs=1e-7
        )
    assert error_of(EXIT_BAD_INPUT, [*argv, "--origin", "95,0"], capsys).endswith(
        "heading finite [deg]"
    )


# Issue 30: the parse is written when no route can be planned.


def test_no_route_writes_the_parse_and_names_the_unreachable_rooms(tmp_path, capsys):
    robot = tmp_path / "wheel.yaml"
    robot.write_text("base: ground\nname: wheel\nnavigation:\n  traversable: [opening]\n")
    out = tmp_path / "o"
    argv = [str(EXAMPLE_JSON), "--no-sim", "--out", str(out), "--robot", str(robot)]
    argv += ["--goal", "bedroom_0"]
    err = error_of(EXIT_NO_ROUTE, argv, capsys)
    assert "no route for the wheel robot" in err and "unreachable from" in err
    assert "bedroom_0" in err
    names = only(out)
    assert set(PARSE_FILES) <= set(names) and "route.json" not in names
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "no route" and summary["unreachable"]
    labels = cv2.imread(str(out / "labels.png"), cv2.IMREAD_UNCHANGED)
    assert labels.dtype == np.uint8 and labels.ndim == 2
    assert {1, 2, 6, 7} <= set(np.unique(labels).tolist()) <= set(range(10))


def test_scene_floors_of_rooms_that_split_in_two():
    import dataclasses

    from f2n_drake.core.plan import FloorPlan
    from f2n_drake.datasets.ground_truth import parse_ground_truth
    from f2n_drake.mapping.walls import PlanGeometry

    parsed = parse_ground_truth(FloorPlan.load(EXAMPLE_JSON), size_px=256)
    room = next(i for i in parsed.instances if i.class_name == "living")
    (c0, r0), (c1, r1) = room.contour_px.min(0), room.contour_px.max(0)
    cm, rm = (c0 + c1) / 2, (r0 + r1) / 2
    bow_tie = np.array([[c0, r0], [cm, rm], [c0, r1], [c1, r1], [cm, rm], [c1, r0]])
    instances = [
        dataclasses.replace(i, contour_px=bow_tie) if i is room else i for i in parsed.instances
    ]
    assert room.polygon_m(parsed.grid).geom_type == "Polygon"
    assert dataclasses.replace(room, contour_px=bow_tie).polygon_m(parsed.grid).geom_type == (
        "MultiPolygon"
    )
    geometry = PlanGeometry.from_parsed(dataclasses.replace(parsed, instances=instances))
    assert all(p.geom_type == "Polygon" for _, p in geometry.floors)
    assert shapely.union_all([p for _, p in geometry.floors]).area > 0


def test_marker_names_every_output_folder(tmp_path):
    out = tmp_path / "o"
    assert run_cli(main, [str(EXAMPLE_JSON), "--no-sim", "--out", str(out)]) == 0
    assert MARKER in only(out)
