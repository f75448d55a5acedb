"""The run CLI end to end on the bundled plan, and its one-line errors (exit code 2)."""

from __future__ import annotations

import json

import pytest

from f2n_drake.core.errors import run_cli
from f2n_drake.core.parsed import UNSURE_BELOW
from f2n_drake.core.paths import REPO_ROOT
from f2n_drake.outputs.summary import LISTED
from f2n_drake.outputs.writer import PARSE_FILES
from f2n_drake.run import RunSummary, format_summary, main, run

EXAMPLE_JSON = REPO_ROOT / "examples" / "plan.json"
EXAMPLE_PNG = REPO_ROOT / "examples" / "plan.png"


def run_json(argv, capsys) -> dict:
    assert run_cli(main, [*argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_plan_json_no_sim_writes_exports(tmp_path, capsys):
    out = tmp_path / "out"
    summary = run_json([str(EXAMPLE_JSON), "--no-sim", "--out", str(out)], capsys)
    assert summary["perception"].startswith("ground truth")
    assert summary["route"][0] == "front_door_0"
    assert summary["route"][-1] == summary["goal"]
    assert summary["path_length_m"] > 1.0
    assert summary["simulation"] == []
    names = {p.name for p in out.iterdir()}
    assert {*PARSE_FILES, "route.json"} <= names
    assert "rooms.geojson" not in names  # no --origin: rooms_m.json in plan metres only
    route = json.loads((out / "route.json").read_text())
    assert route["sequence"] == summary["route"]


def test_run_tells_its_progress_each_step_as_it_starts(tmp_path):
    told = []
    run(EXAMPLE_JSON, out=tmp_path / "out", progress=told.append, correction="off")
    assert told == [
        "loading the input",
        "building the graph",
        "planning the route",
        "driving the route in Drake, correction off",
        "writing the outputs",
    ]


def test_explicit_rooms_and_uav(tmp_path, capsys):
    summary = run_json(
        [
            str(EXAMPLE_JSON),
            "--no-sim",
            "--out",
            str(tmp_path / "o"),
            "--start",
            "kitchen",
            "--goal",
            "bedroom_0",
            "--robot",
            "uav",
        ],
        capsys,
    )
    assert summary["robot"] == "uav"
    assert summary["route"][0].startswith("kitchen")
    assert summary["route"][-1] == "bedroom_0"


@pytest.mark.slow
def test_simulated_run_reaches_goal(tmp_path, capsys):
    summary = run_json([str(EXAMPLE_JSON), "--out", str(tmp_path / "o"), "--seed", "1"], capsys)
    (sim,) = summary["simulation"]
    assert sim["correction"] == "continuous"
    assert sim["reached"] and not sim["collided"]
    assert sim["mean_error_m"] < 0.05


def test_simulated_building_differs_from_the_plan(tmp_path, capsys):
    argv = [str(EXAMPLE_JSON), "--out", str(tmp_path / "o"), "--seed", "1", "--json"]
    world = ["--clutter", "0.1", "--people", "1", "--closed-doors", "1", "--deviation", "0.05"]
    assert run_cli(main, [*argv, *world]) in (0, 4)  # 4: the robot met what it did not know
    summary = json.loads(capsys.readouterr().out)
    (note,) = [n for n in summary["notes"] if "differs from the plan" in n]
    assert "closed doors: door_" in note and "1 people walking" in note
    (sim,) = summary["simulation"]
    assert sim["person_collisions"] >= 0 and sim["sim_time_s"] > 0


@pytest.mark.slow
def test_unknown_start_localizes_then_reaches_goal(tmp_path, capsys):
    argv = [str(EXAMPLE_JSON), "--out", str(tmp_path / "o"), "--seed", "1", "--unknown-start"]
    summary = run_json(argv, capsys)
    (sim,) = summary["simulation"]
    assert sim["reached"] and not sim["collided"]
    assert sim["converged"] and not sim["wrong_convergence"]
    assert sim["converged_error_m"] < 0.1
    assert any(
        note.startswith("unknown start (continuous): localized") for note in summary["notes"]
    )


@pytest.mark.slow
@pytest.mark.parametrize(("views", "perception"), [([], "2 views"), (["--views", "1"], "1 view")])
def test_drawing_input_uses_the_segmenter(views, perception, tmp_path, capsys):
    summary = run_json([str(EXAMPLE_PNG), "--no-sim", "--out", str(tmp_path / "o"), *views], capsys)
    assert summary["perception"] == f"segmenter, {perception}"
    assert summary["scale_source"].startswith("door-width estimate")
    # The drawing is 2.06 cm/px and its doors are narrower than the 0.9 m assumed: the
    # estimate lands 12 % high (18 % before doors were measured as openings).
    assert 0.0206 < summary["scale_m_per_px"] < 0.0206 * 1.15
    assert summary["rooms"].get("bedroom", 0) >= 1
    assert summary["connectors"]["front_door"] == 1  # the one-front-door prior
    assert summary["rooms"].get("kitchen", 0) <= 1  # the one-kitchen prior
    assert summary["unreachable"] == []
    assert all(0.0 <= c < UNSURE_BELOW for c in summary["unsure"].values())
    assert set(summary["unsure"]) <= {*summary["route"], *_graph_nodes(tmp_path / "o")}


def _graph_nodes(out) -> set[str]:
    return {n["id"] for n in json.loads((out / "graph.json").read_text())["nodes"]}


def test_summary_lists_unsure_instances():
    summary = RunSummary(
        input="p.png",
        perception="segmenter",
        scale_m_per_px=0.02,
        scale_source="argument",
        rooms={"living": 1},
        connectors={"door": 1},
        robot="ground",
        start="living_0",
        goal="living_0",
        route=["living_0"],
        path_length_m=0.0,
        planning_precompute_ms=1.0,
        planning_query_ms=0.1,
        unsure={"door_0": 0.55},
    )
    assert "unsure      door_0 55 %" in format_summary(summary)
    summary.unsure = {f"room_{i}": 0.7 - i / 100 for i in range(LISTED + 3)}  # an office floor
    line = next(s for s in format_summary(summary).splitlines() if s.startswith("unsure"))
    assert line.startswith(f"unsure      room_{LISTED + 2} 56 %, room_{LISTED + 1} 57 %")
    assert "room_2 68 %" not in line and "and 3 more (summary.json lists them)" in line
    summary.unsure = {}
    assert "unsure" not in format_summary(summary)


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["missing.png"], "no such file"),
        ([str(EXAMPLE_JSON), "--robot", "tank"], "tank"),
        ([str(EXAMPLE_JSON), "--goal", "sauna"], "sauna"),
        ([str(EXAMPLE_JSON), "--start", "100,100"], "start"),
        ([str(EXAMPLE_JSON), "--scale", "-1"], "scale"),
        ([str(EXAMPLE_JSON), "--start", "nan,0"], "finite"),
        ([str(EXAMPLE_JSON), "--goal", "inf,1"], "finite"),
        ([str(EXAMPLE_JSON), "--html", "/nonexistent-dir/replay.html"], "html"),
        ([str(EXAMPLE_JSON), "--clutter", "0.8"], "clutter"),
        ([str(EXAMPLE_JSON), "--closed-doors", "-1"], "closed-doors"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(argv, message, tmp_path, capsys):
    out = tmp_path / "never"
    assert run_cli(main, [*argv, "--no-sim", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("error: ") and "\n" not in err
    assert message in err
    assert not out.exists()


@pytest.mark.parametrize(
    ("name", "message"),
    [("plan.pdf", "not a PDF PDFium can read"), ("plan.svg", "export"), ("plan.txt", "expected")],
)
def test_files_that_are_no_plan_say_what_to_give_instead(name, message, tmp_path, capsys):
    path = tmp_path / name
    path.write_bytes(b"%PDF-1.4\n")
    assert run_cli(main, [str(path), "--no-sim", "--out", str(tmp_path / "never")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("error: ") and "\n" not in err and message in err
    assert not (tmp_path / "never").exists()


def test_uav_route_is_planned_but_not_driven_by_the_turtlebot(tmp_path, capsys):
    summary = run_json([str(EXAMPLE_JSON), "--robot", "uav", "--out", str(tmp_path / "o")], capsys)
    assert summary["simulation"] == []
    assert any("simulation skipped" in note for note in summary["notes"])


def test_given_endpoints_do_not_need_a_default(tmp_path, capsys):
    summary = run_json(
        [
            str(EXAMPLE_JSON),
            "--no-sim",
            "--out",
            str(tmp_path / "o"),
            "--start",
            "living_0",
            "--goal",
            "bathroom_0",
        ],
        capsys,
    )
    assert summary["route"][0] == "living_0" and summary["route"][-1] == "bathroom_0"


def test_not_an_image(tmp_path, capsys):
    fake = tmp_path / "plan.png"
    fake.write_text("this is not a picture")
    assert run_cli(main, [str(fake), "--no-sim", "--out", str(tmp_path / "o")]) == 2
    assert capsys.readouterr().err.startswith("error: ")


def test_output_path_is_a_file(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    assert run_cli(main, [str(EXAMPLE_JSON), "--no-sim", "--out", str(blocker)]) == 2
    assert "not a directory" in capsys.readouterr().err


def test_a_long_unreachable_list_is_cut_in_the_message_and_kept_in_the_summary():
    from f2n_drake.core.errors import PlanningError
    from f2n_drake.outputs.summary import RunSummary
    from f2n_drake.run import no_route_message

    names = [f"living_{i}" for i in range(LISTED + 5)][::-1]
    summary = RunSummary("plan.png", "segmenter", 0.02, "doors", {}, {}, robot="ground")
    summary.start, summary.unreachable = "front_door_0", names
    message = no_route_message(PlanningError("no room reachable"), summary)
    assert "living_2, living_3" in message and f"living_{LISTED}" not in message
    assert "and 5 more (summary.json lists them)" in message
    assert len(summary.unreachable) == LISTED + 5


@pytest.mark.slow
def test_a_pdf_page_is_parsed_like_an_image(tmp_path, capsys):
    import cv2
    from matplotlib.backends.backend_pdf import PdfPages
    from matplotlib.figure import Figure

    drawing = cv2.imread(str(EXAMPLE_PNG), cv2.IMREAD_GRAYSCALE)
    pdf = tmp_path / "plan.pdf"
    with PdfPages(pdf) as pages:
        for _ in range(2):  # the plan on two pages
            fig = Figure(figsize=(drawing.shape[1] / 100, drawing.shape[0] / 100), dpi=100)
            fig.figimage(drawing, cmap="gray", vmin=0, vmax=255)
            pages.savefig(fig, dpi=100)
    out = tmp_path / "o"
    argv = [str(pdf), "--page", "2", "--paper-scale", "1:100", "--no-sim", "--out", str(out)]
    summary = run_json(argv, capsys)
    assert summary["perception"].startswith("segmenter")
    assert summary["route"][-1] == summary["goal"]
    assert any("page 2 of 2" in note for note in summary["notes"])
    assert set(PARSE_FILES) <= {p.name for p in out.iterdir()}
    # the page is 6.4 inches wide, drawn 2000 px: at 1:100, 0.8128 cm of building per px
    assert summary["scale_m_per_px"] == pytest.approx(100 * 6.4 * 0.0254 / 2000)
    assert summary["scale_source"].startswith("paper scale 1:100")
    never = tmp_path / "never"
    for bad, message in [
        ([str(pdf), "--page", "3"], "has 2 pages; there is no page 3"),
        ([str(EXAMPLE_PNG), "--paper-scale", "1:100"], "--paper-scale needs a PDF"),
        ([str(pdf), "--paper-scale", "1:100", "--scale", "0.01"], "not both"),
    ]:
        assert run_cli(main, [*bad, "--no-sim", "--out", str(never)]) == 2
        assert message in capsys.readouterr().err
    assert not never.exists()


@pytest.mark.slow
def test_a_photographed_page_is_squared_and_its_outputs_lie_on_it(tmp_path, capsys):
    import cv2

    from f2n_drake.evaluate.photos import photographed

    photo, _ = photographed(cv2.imread(str(EXAMPLE_PNG)))
    cv2.imwrite(str(tmp_path / "photo.jpg"), photo)
    out = tmp_path / "o"
    summary = run_json([str(tmp_path / "photo.jpg"), "--no-sim", "--out", str(out)], capsys)
    assert any("photographed at an angle, squared" in note for note in summary["notes"])
    page = cv2.imread(str(out / "page.png"), cv2.IMREAD_UNCHANGED)
    labels = cv2.imread(str(out / "labels.png"), cv2.IMREAD_UNCHANGED)
    assert page.shape[:2] == labels.shape[:2] != photo.shape[:2]
    assert summary["route"] and summary["rooms"].get("bedroom", 0) >= 1


@pytest.mark.slow
def test_a_drawing_laid_askew_is_turned_upright_and_its_outputs_lie_on_it(tmp_path, capsys):
    import cv2

    drawing = cv2.imread(str(EXAMPLE_PNG), cv2.IMREAD_GRAYSCALE)
    h, w = drawing.shape
    matrix = cv2.getRotationMatrix2D((w / 2, h / 2), 2.5, 1.0)
    askew = cv2.warpAffine(drawing, matrix, (w, h), flags=cv2.INTER_CUBIC, borderValue=255)
    cv2.imwrite(str(tmp_path / "scan.png"), askew)
    out = tmp_path / "o"
    summary = run_json([str(tmp_path / "scan.png"), "--no-sim", "--out", str(out)], capsys)
    assert any("2.5 degrees off square, turned upright" in note for note in summary["notes"])
    page = cv2.imread(str(out / "page.png"), cv2.IMREAD_UNCHANGED)
    labels = cv2.imread(str(out / "labels.png"), cv2.IMREAD_UNCHANGED)
    assert page.shape[:2] == labels.shape[:2] != askew.shape[:2]
    assert summary["route"] and summary["rooms"].get("bedroom", 0) >= 1


@pytest.mark.slow
@pytest.mark.parametrize(
    ("saved_turns", "note"),
    [
        (-1, "run down the page, turned a quarter turn counter-clockwise"),
        (2, "read upside down, turned a half turn"),
    ],
)
def test_a_drawing_on_its_side_or_upside_down_is_turned_upright_by_its_words(
    tmp_path, capsys, saved_turns, note
):
    import cv2
    import numpy as np

    drawing = cv2.imread(str(EXAMPLE_PNG), cv2.IMREAD_GRAYSCALE)
    lines = ("GROUND FLOOR", "GROSS INTERNAL AREA", "72 SQ M", "NOT TO SCALE", "FOR SALE")
    title = np.full((45 * len(lines) + 15, drawing.shape[1]), 255, np.uint8)  # a title block
    for k, words in enumerate(lines):
        cv2.putText(title, words, (20, 40 + 45 * k), cv2.FONT_HERSHEY_SIMPLEX, 0.8, 0, 2)
    sheet = np.vstack([drawing, title])
    cv2.imwrite(str(tmp_path / "scan.png"), np.rot90(sheet, saved_turns))
    out = tmp_path / "o"
    summary = run_json([str(tmp_path / "scan.png"), "--no-sim", "--out", str(out)], capsys)
    assert any(note in n for n in summary["notes"])
    page = cv2.imread(str(out / "page.png"), cv2.IMREAD_GRAYSCALE)
    labels = cv2.imread(str(out / "labels.png"), cv2.IMREAD_UNCHANGED)
    assert np.array_equal(page, sheet) and labels.shape == sheet.shape
    assert summary["route"] and summary["rooms"].get("bedroom", 0) >= 1
