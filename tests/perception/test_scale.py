"""The scale estimated from door widths: doors measured as openings, and the CLI that scores it."""

from __future__ import annotations

import json

import numpy as np
import pytest
from helpers import Oracle, simple_plan

from f2n_drake.core.classes import CLASS_ID
from f2n_drake.core.errors import run_cli
from f2n_drake.core.parsed import Instance, ParsedPlan
from f2n_drake.datasets.render import DrawingStyle, render
from f2n_drake.evaluate import scale as scale_cli
from f2n_drake.perception import scale as scale_module
from f2n_drake.perception.printed_sizes import PrintedScale
from f2n_drake.perception.scale import (
    door_openings_px,
    door_widths_px,
    jamb_line_px,
    plausible_doors,
    resolve_scale,
    walls_thickness_px,
)
from f2n_drake.pipeline import parse_drawing


@pytest.mark.usefixtures("drawings_at_own_size")
@pytest.mark.parametrize("line_width_px", [1, 3])
@pytest.mark.parametrize("filled_walls", [False, True])
def test_doors_are_measured_as_openings_whatever_the_pen(line_width_px, filled_walls):
    plan = simple_plan()  # a 0.9 m door and a 1.0 m front door
    style = DrawingStyle(line_width_px=line_width_px, filled_walls=filled_walls)
    rendered = render(plan, 400, style=style)
    parsed = parse_drawing(rendered.image, segmenter=Oracle(rendered.labels))
    m_per_px = rendered.grid.metres_per_px
    openings = sorted(w * m_per_px for w in door_openings_px(parsed))
    assert openings == pytest.approx([0.9, 1.0], abs=0.015)
    clear = sorted(w * m_per_px for w in door_widths_px(parsed))
    assert clear[0] < openings[0] - 0.8 * line_width_px * m_per_px  # the jamb lines' share
    # the median opening (0.95 m) taken as 0.9 m
    estimated = resolve_scale(parsed).grid.metres_per_px
    assert estimated == pytest.approx(m_per_px * 0.9 / 0.95, rel=0.02)


def test_jamb_lines_are_the_outlines_else_the_sides_of_door_boxes():
    ids = np.zeros((20, 40), np.int32)
    ids[:, :15], ids[:, 16:24], ids[:, 25:] = 1, 2, 3  # room | 1 px | door | 1 px | room
    rooms_and_door = [
        Instance(1, "living", np.zeros((0, 2)), 300, (7.0, 10.0)),
        Instance(2, "door", np.zeros((0, 2)), 160, (20.0, 10.0)),
        Instance(3, "bedroom", np.zeros((0, 2)), 300, (32.0, 10.0)),
    ]
    labels = np.zeros(ids.shape, np.uint8)
    outlined = ParsedPlan(ids, labels, rooms_and_door, door_outline_px=3.0)
    assert jamb_line_px(outlined) == 1.0  # measured between the door and its rooms
    ids[:, 15], ids[:, 24] = 2, 2  # a door box whose sides are the door's: no outline between
    boxed = ParsedPlan(ids, labels, rooms_and_door, door_outline_px=3.0)
    assert jamb_line_px(boxed) == 3.0
    assert jamb_line_px(ParsedPlan(ids, labels, rooms_and_door)) == 0.0  # ground truth


def test_the_scale_cli_scores_the_estimate_against_the_truth(capsys):
    def oracle(rendered):
        return Oracle(rendered.labels)

    args = ["--synthetic", "3", "--seed", "11", "--size", "384", "--json"]
    assert scale_cli.main(args, segmenter_for=oracle) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["n_images"] == report["n_estimated"] == 3
    rows = report["per_drawing"]
    for row in rows:
        # with true labels, the doors are measured to a few pixels, and the estimate errs by
        # about as much as the plan's own doors differ from the assumed 0.9 m
        assert row["measured_door_m"] == pytest.approx(row["door_m"], rel=0.08)
        assert row["estimate"] / row["true_m_per_px"] == pytest.approx(
            0.9 / row["door_m"], rel=0.08
        )
    errors = [abs(r["estimate"] / r["true_m_per_px"] - 1) for r in rows]
    assert report["mean_abs_error"] == pytest.approx(np.mean(errors))
    assert report["clear_width_only"]["n_estimated"] == 3
    assert scale_cli.main(args[:-1], segmenter_for=oracle) == 0
    assert "opening (shipped)" in capsys.readouterr().out
    assert run_cli(scale_cli.main, ["--synthetic", "1", "--door-width", "0"]) == 2
    assert "--door-width must be a positive" in capsys.readouterr().err


def _plan_with_door_pieces() -> ParsedPlan:
    """Two rooms over and under a 6 px wall (labelled wall, no instance), with a whole 30 px
    door through it, a 6 px piece of door in it, and a 30 px "door" standing in a room (a stair
    tread the network calls door)."""
    ids = np.zeros((80, 120), np.int32)
    labels = np.zeros((80, 120), np.uint8)
    ids[5:37, 5:115], ids[43:75, 5:115] = 1, 2
    labels[37:43, 5:115] = CLASS_ID["wall"]
    ids[37:43, 40:70] = 3  # a whole gap between two wall ends
    ids[37:43, 90:96] = 4  # a piece of a door
    ids[15:21, 20:50] = 5  # in the room's paper, no wall at its ends
    names = {1: "living", 2: "bedroom", 3: "door", 4: "door", 5: "door"}
    instances = [
        Instance(k, name, np.zeros((0, 2)), int((ids == k).sum()), (0.0, 0.0))
        for k, name in names.items()
    ]
    return ParsedPlan(ids, labels, instances)


def test_only_whole_doors_through_a_wall_set_the_scale():
    parsed = _plan_with_door_pieces()
    assert walls_thickness_px(parsed) == 6
    doors = parsed.of_class("door")
    assert [d.id for d in plausible_doors(parsed, doors)] == [3]
    assert door_widths_px(parsed) == [30.0]
    assert sorted(door_widths_px(parsed, plausible=False)) == [6.0, 30.0, 30.0]
    assert resolve_scale(parsed).grid.metres_per_px == pytest.approx(0.9 / 30)
    # with none plausible, every door is measured
    assert [d.id for d in plausible_doors(parsed, [doors[1]])] == [4]


def test_a_door_opening_on_storage_does_not_set_the_scale():
    # a 30 px door between two rooms, and a 20 px door from the upper room into a closet: paper
    # of no instance, voted background, walled in (no way to the image border)
    ids = np.zeros((80, 170), np.int32)
    labels = np.zeros((80, 170), np.uint8)
    ids[5:37, 5:115], ids[43:75, 5:115] = 1, 2
    wall = CLASS_ID["wall"]
    labels[37:43, 5:161] = wall  # between the rooms, and under the closet
    labels[0:5, 115:161] = labels[0:43, 155:161] = labels[5:37, 115:121] = wall
    ids[37:43, 40:70] = 3  # the rooms' door
    ids[10:30, 115:121] = 4  # the closet's door
    labels[ids == 4] = 0
    names = {1: "living", 2: "bedroom", 3: "door", 4: "door"}
    instances = [
        Instance(k, name, np.zeros((0, 2)), int((ids == k).sum()), (0.0, 0.0))
        for k, name in names.items()
    ]
    parsed = ParsedPlan(ids, labels, instances)
    doors = parsed.of_class("door")
    assert [d.id for d in plausible_doors(parsed, doors)] == [3]
    assert resolve_scale(parsed).grid.metres_per_px == pytest.approx(0.9 / 30)
    # with no other door, the closet's door is measured
    assert [d.id for d in plausible_doors(parsed, [doors[1]])] == [4]


@pytest.mark.parametrize(
    ("rooms", "doors_px", "source"),
    [
        (1, [30, 30, 30], "printed"),  # doors 0.9 m at the printed scale
        (1, [120, 120, 120], "door"),  # 3.6 m: one misread size ("1017 SQM" for 101.7)
        (1, [120], "printed"),  # one door is no check (a studio's cupboard door)
        (2, [120, 120, 120], "printed"),  # two rooms' sizes check each other
        (0, [10, 10, 10], "door"),  # a total area, doors 0.3 m
    ],
)
def test_one_printed_size_is_left_out_where_the_doors_disagree(
    monkeypatch, rooms, doors_px, source
):
    printed = PrintedScale(metres_per_px=0.03, n_rooms=rooms, spread=0.0)
    monkeypatch.setattr(scale_module, "printed_scale", lambda parsed: printed)
    monkeypatch.setattr(scale_module, "door_openings_px", lambda parsed: doors_px)
    parsed = ParsedPlan(np.zeros((10, 10), np.int32), np.zeros((10, 10), np.uint8), [])
    resolved = resolve_scale(parsed)
    assert source in resolved.scale_source
    assert ("printed size left out" in resolved.scale_source) == (source == "door" and rooms < 2)
    expected = 0.03 if source == "printed" else 0.9 / np.median(doors_px)
    assert resolved.grid.metres_per_px == pytest.approx(expected)
