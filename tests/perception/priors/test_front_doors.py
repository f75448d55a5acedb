"""The front-door prior on drawings whose answers are known, and the per-instance soft scores."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest
from helpers import (
    LEFT_BOX,
    RIGHT_BOX,
    ProbabilityStub,
    classes_at,
    facade,
    probabilities_of,
    two_rooms,
)

from f2n_drake.core.classes import CLASS_ID
from f2n_drake.core.errors import InputError, count_or_any
from f2n_drake.core.parsed import Instance
from f2n_drake.core.raster import PixelGrid
from f2n_drake.perception.instances import extract_instances
from f2n_drake.perception.priors.front_doors import (
    DOOR_WIDTH_M,
    EXTRA_WIDTH_M,
    MIN_DOOR_LIKENESS,
    MIN_REACH_WEIGHT,
    UNLIKELY_ENTRANCE_WEIGHT,
    assign_front_doors,
    door_likeness,
    front_door_evidence,
    opening_widths_m,
    possible_entrances,
    reach_weight,
    reached_rooms,
)
from f2n_drake.pipeline import parse_drawing

FRONT, WINDOW, DOOR = CLASS_ID["front_door"], CLASS_ID["window"], CLASS_ID["door"]


def test_scores_are_mean_probabilities_of_each_instance():
    img, lab = facade(FRONT, WINDOW)
    probs = probabilities_of(lab, (LEFT_BOX, {FRONT: 0.7, WINDOW: 0.3}))
    probs[(slice(None), slice(61, 70), slice(21, 26))] = 0.0
    probs[(FRONT, slice(61, 70), slice(21, 26))] = 0.4  # 9 of 19 rows less sure
    probs[(WINDOW, slice(61, 70), slice(21, 26))] = 0.6
    parsed = extract_instances(img, lab, probabilities=probs)
    left = parsed.by_id()[int(parsed.instance_ids[61, 21])]
    assert left.class_name == "front_door" and left.area_px == 19 * 5
    assert left.scores[FRONT] == pytest.approx((9 * 0.4 + 10 * 0.7) / 19, abs=1e-4)
    assert left.scores[WINDOW] == pytest.approx((9 * 0.6 + 10 * 0.3) / 19, abs=1e-4)
    assert front_door_evidence(left) == left.scores[FRONT]
    assert all(i.scores for i in parsed.instances)
    assert not extract_instances(img, lab).instances[0].scores
    with pytest.raises(InputError, match="probabilities"):
        extract_instances(img, lab, probabilities=probs[:, :50])


def test_two_front_doors_keep_the_surer_one():
    img, lab = facade(FRONT, FRONT)
    probs = probabilities_of(
        lab, (LEFT_BOX, {FRONT: 0.55, WINDOW: 0.4, DOOR: 0.05}), (RIGHT_BOX, {FRONT: 0.9})
    )
    voted = extract_instances(img, lab, probabilities=probs)
    assert classes_at(voted, LEFT_BOX, RIGHT_BOX) == ["front_door", "front_door"]
    parsed = assign_front_doors(voted)
    assert classes_at(parsed, LEFT_BOX, RIGHT_BOX) == ["window", "front_door"]
    assert classes_at(voted, LEFT_BOX, RIGHT_BOX) == ["front_door", "front_door"]  # not edited
    assert classes_at(assign_front_doors(voted, 2), LEFT_BOX, RIGHT_BOX) == ["front_door"] * 2
    assert assign_front_doors(voted, None) is voted


def test_no_front_door_promotes_the_likeliest_connector():
    img, lab = facade(WINDOW, WINDOW)
    probs = probabilities_of(
        lab, (LEFT_BOX, {WINDOW: 0.9, FRONT: 0.1}), (RIGHT_BOX, {WINDOW: 0.6, FRONT: 0.4})
    )
    parsed = assign_front_doors(extract_instances(img, lab, probabilities=probs))
    assert classes_at(parsed, LEFT_BOX, RIGHT_BOX) == ["window", "front_door"]
    assert [i.class_name for i in parsed.instances].count("door") == 1  # the inner door stays
    assert classes_at(assign_front_doors(parsed, 0), RIGHT_BOX) == ["window"]


def test_vote_share_is_the_evidence_without_probabilities():
    img, lab = facade(FRONT, FRONT)
    lab[61:75, 21:26] = WINDOW  # the left box is 14/19 window, 5/19 front door: votes window
    lab[131:135, 175:180] = WINDOW  # the right box is 15/19 front door
    lab[95:100, 98:103] = FRONT  # the inner door gets a few front-door votes too
    voted = extract_instances(img, lab)
    assert classes_at(voted, LEFT_BOX, RIGHT_BOX) == ["window", "front_door"]
    parsed = assign_front_doors(voted)
    assert parsed is voted  # already exactly one, and it has the largest share
    # now nothing votes front door: the left box has the largest share (5/19), though the inner
    # door has more front-door pixels (25 of 145)
    lab[RIGHT_BOX] = WINDOW
    promoted = assign_front_doors(extract_instances(img, lab))
    assert classes_at(promoted, LEFT_BOX, RIGHT_BOX) == ["front_door", "window"]
    assert len(promoted.of_class("door")) == 1
    with pytest.raises(ValueError, match="count"):
        assign_front_doors(voted, -1)


def test_parse_drawing_applies_the_prior_with_probabilities():
    img, lab = facade(FRONT, FRONT)
    probs = probabilities_of(lab, (LEFT_BOX, {FRONT: 0.8}), (RIGHT_BOX, {FRONT: 0.5, WINDOW: 0.5}))
    stub = ProbabilityStub(lab, probs)
    parsed = parse_drawing(img, segmenter=stub)
    assert classes_at(parsed, LEFT_BOX, RIGHT_BOX) == ["front_door", "window"]
    assert all(i.scores for i in parsed.instances)
    plain = parse_drawing(img, segmenter=stub, front_doors=None)
    assert classes_at(plain, LEFT_BOX, RIGHT_BOX) == ["front_door", "front_door"]


def test_count_or_any_argument():
    assert count_or_any("any") is None and count_or_any("ANY") is None
    assert count_or_any("3") == 3
    with pytest.raises(Exception, match="not an integer"):
        count_or_any("one")


def test_instance_evidence_and_best_class():
    def instance(votes, scores):
        return Instance(1, "window", np.zeros((0, 2)), 10, (0.0, 0.0), votes, scores)

    by_votes = instance({WINDOW: 6, FRONT: 3, 0: 1}, {})
    assert by_votes.evidence(FRONT) == pytest.approx(0.3) and by_votes.evidence(DOOR) == 0.0
    assert by_votes.best_class({FRONT, DOOR}, default="wall") == "front_door"
    assert by_votes.best_class({DOOR}, default="wall") == "wall"
    by_scores = instance({WINDOW: 10}, {WINDOW: 0.5, DOOR: 0.3, FRONT: 0.2})
    assert by_scores.evidence(DOOR) == pytest.approx(0.3)  # probabilities outrank votes
    assert by_scores.best_class({DOOR, FRONT}, default="wall") == "door"
    assert instance({}, {}).evidence(FRONT) == 0.0


def connectors(parsed) -> list[Instance]:
    return parsed.of_class("door", "window", "front_door")


def test_an_entrance_is_wide_enough_and_never_opens_into_a_bedroom():
    # the right box opens into the bedroom: however sure the network is, the left box, into the
    # living room, is the front door
    img, lab = facade(WINDOW, FRONT)
    probs = probabilities_of(
        lab, (LEFT_BOX, {FRONT: 0.4, WINDOW: 0.6}), (RIGHT_BOX, {FRONT: 0.9, WINDOW: 0.1})
    )
    metric = PixelGrid.from_scale(0.05, img.shape)  # the boxes are 19 px = 0.95 m wide
    voted = extract_instances(img, lab, grid=metric, probabilities=probs)
    left = int(voted.instance_ids[LEFT_BOX[0].start, LEFT_BOX[1].start])
    # the right box and the inner door open into the bedroom
    assert possible_entrances(voted, connectors(voted)) == {left}
    assert classes_at(assign_front_doors(voted), LEFT_BOX, RIGHT_BOX) == ["front_door", "window"]
    # at 3 cm/px the boxes are 0.57 m wide: no possible entrance, the network's choice stands
    narrow = extract_instances(
        img, lab, grid=PixelGrid.from_scale(0.03, img.shape), probabilities=probs
    )
    assert possible_entrances(narrow, connectors(narrow)) == set()
    assert classes_at(assign_front_doors(narrow), LEFT_BOX, RIGHT_BOX) == ["window", "front_door"]
    # without a scale the boxes are measured against the doors: 19 px < 0.9 x the 31 px door
    unscaled = extract_instances(img, lab, probabilities=probs)
    assert possible_entrances(unscaled, connectors(unscaled)) == set()


def test_an_entrance_is_as_wide_as_its_opening_not_the_paper_inside_it():
    # at 4.15 cm/px the left box's paper (19 px) is 0.79 m wide, under MIN_WIDTH_M; its opening,
    # from jamb line centre to jamb line centre (one 1 px outline more), is 0.83 m: wide enough
    img, lab = facade(WINDOW, FRONT)
    probs = probabilities_of(
        lab, (LEFT_BOX, {FRONT: 0.4, WINDOW: 0.6}), (RIGHT_BOX, {FRONT: 0.9, WINDOW: 0.1})
    )
    voted = extract_instances(
        img, lab, grid=PixelGrid.from_scale(0.0415, img.shape), probabilities=probs
    )
    left = int(voted.instance_ids[LEFT_BOX[0].start, LEFT_BOX[1].start])
    assert possible_entrances(voted, connectors(voted)) == {left}


def test_door_likeness_is_one_up_to_a_door_and_falls_with_the_extra_width():
    assert door_likeness(0.5) == door_likeness(DOOR_WIDTH_M) == 1.0
    excess_1 = MIN_DOOR_LIKENESS + (1 - MIN_DOOR_LIKENESS) * math.exp(-1)
    assert door_likeness(DOOR_WIDTH_M + EXTRA_WIDTH_M) == pytest.approx(excess_1)
    assert door_likeness(1.1) > door_likeness(1.3) > door_likeness(1.6) > MIN_DOOR_LIKENESS
    assert door_likeness(10.0) == pytest.approx(MIN_DOOR_LIKENESS)
    assert door_likeness(None) == 1.0


def test_of_two_boxes_in_the_living_rooms_facade_the_door_sized_one_is_the_entrance():
    # a door-sized box (29 px of paper, rows 41..69) and one twice as wide (60 px, rows
    # 100..159) in the living room's outer wall; the network is surer of the wide one
    img, lab = two_rooms()
    for row in (40, 70, 99, 160):
        cv2.line(img, (20, row), (26, row), 0, 1)
    narrow, wide = (slice(41, 70), slice(21, 26)), (slice(100, 160), slice(21, 26))
    lab[narrow], lab[wide] = WINDOW, FRONT
    probs = probabilities_of(
        lab, (narrow, {FRONT: 0.6, WINDOW: 0.4}), (wide, {FRONT: 0.8, WINDOW: 0.2})
    )
    # at 3 cm/px the openings are 0.9 and 1.83 m; without a scale they are measured in doors
    # (the inner door's opening is 30 px), which gives the same widths
    for grid in (PixelGrid.from_scale(0.03, img.shape), None):
        voted = extract_instances(img, lab, grid=grid, probabilities=probs)
        widths = opening_widths_m(voted, connectors(voted))
        ids = [int(voted.instance_ids[r.start, c.start]) for r, c in (narrow, wide)]
        assert [widths[i] for i in ids] == pytest.approx([0.9, 1.83])
        assert possible_entrances(voted, connectors(voted)) >= set(ids)
        assert classes_at(assign_front_doors(voted), narrow, wide) == ["front_door", "window"]
    # width never outweighs the network more than five times over: a far surer wide box stays
    probs = probabilities_of(
        lab, (narrow, {FRONT: 0.1, WINDOW: 0.9}), (wide, {FRONT: 0.9, WINDOW: 0.1})
    )
    voted = extract_instances(
        img, lab, grid=PixelGrid.from_scale(0.03, img.shape), probabilities=probs
    )
    assert classes_at(assign_front_doors(voted), narrow, wide) == ["window", "front_door"]


def test_an_unlikely_entrance_counts_a_tenth_not_nothing():
    # the right box opens into the bedroom, so it could not be the entrance; its evidence counts
    # UNLIKELY_ENTRANCE_WEIGHT of the left box's: it still wins when the network is more than ten
    # times surer of it (blur breaks some front doors into pieces too narrow for an entrance)
    img, lab = facade(WINDOW, FRONT)
    metric = PixelGrid.from_scale(0.05, img.shape)
    for left_p, expected in ((0.4, ["front_door", "window"]), (0.05, ["window", "front_door"])):
        probs = probabilities_of(
            lab,
            (LEFT_BOX, {FRONT: left_p, WINDOW: 1 - left_p}),
            (RIGHT_BOX, {FRONT: 0.9, WINDOW: 0.1}),
        )
        voted = extract_instances(img, lab, grid=metric, probabilities=probs)
        assert 0.05 < UNLIKELY_ENTRANCE_WEIGHT * 0.9 < 0.4
        assert classes_at(assign_front_doors(voted), LEFT_BOX, RIGHT_BOX) == expected


def test_a_front_door_left_out_stays_an_opening_never_a_room():
    img, lab = facade(FRONT, FRONT)
    probs = probabilities_of(
        lab,
        (LEFT_BOX, {FRONT: 0.4, CLASS_ID["living"]: 0.35, DOOR: 0.25}),  # a gap's room paper
        (RIGHT_BOX, {FRONT: 0.9}),
    )
    parsed = assign_front_doors(extract_instances(img, lab, probabilities=probs))
    assert classes_at(parsed, LEFT_BOX, RIGHT_BOX) == ["door", "front_door"]


def test_an_entrance_opens_into_a_room():
    # a door-sized box drawn on the paper outside the flat (a legend's symbol) joins no room:
    # however sure the network is of it, the living room's box is the entrance
    img, lab = facade(WINDOW, WINDOW)
    outside = (slice(186, 196), slice(60, 80))
    cv2.rectangle(img, (59, 185), (80, 196), 0, 1)
    lab[outside] = FRONT
    probs = probabilities_of(
        lab, (LEFT_BOX, {FRONT: 0.3, WINDOW: 0.7}), (outside, {FRONT: 0.9, WINDOW: 0.1})
    )
    voted = extract_instances(
        img, lab, grid=PixelGrid.from_scale(0.05, img.shape), probabilities=probs
    )
    left = int(voted.instance_ids[LEFT_BOX[0].start, LEFT_BOX[1].start])
    symbol = int(voted.instance_ids[outside[0].start, outside[1].start])
    assert voted.by_id()[symbol].class_name == "front_door"
    assert left in possible_entrances(voted, connectors(voted))
    assert symbol not in possible_entrances(voted, connectors(voted))
    assert classes_at(assign_front_doors(voted), LEFT_BOX, outside) == ["front_door", "window"]


def test_an_entrance_leads_into_the_rooms_not_into_a_room_of_its_own():
    # the bedroom's lower part walled off as a living room C that no door joins: its facade box
    # (RIGHT_BOX) reaches one room, the living room's (LEFT_BOX) two through the inner door. The
    # network is surer of the box into C (an office off a corridor the crop made the outside)
    img, lab = facade(WINDOW, FRONT)
    cv2.line(img, (103, 124), (174, 124), 0, 1)
    cv2.line(img, (103, 127), (174, 127), 0, 1)
    lab[124:128, 104:174] = CLASS_ID["wall"]
    lab[128:174, 104:174] = CLASS_ID["living"]
    probs = probabilities_of(
        lab, (LEFT_BOX, {FRONT: 0.4, WINDOW: 0.6}), (RIGHT_BOX, {FRONT: 0.5, WINDOW: 0.5})
    )
    voted = extract_instances(
        img, lab, grid=PixelGrid.from_scale(0.05, img.shape), probabilities=probs
    )
    left, right = (int(voted.instance_ids[r.start, c.start]) for r, c in (LEFT_BOX, RIGHT_BOX))
    assert voted.by_id()[int(voted.instance_ids[100, 140])].class_name == "bedroom"
    assert possible_entrances(voted, connectors(voted)) >= {left, right}
    assert {
        i: n for i, n in reached_rooms(voted, connectors(voted)).items() if i in (left, right)
    } == {
        left: 2,
        right: 1,
    }
    assert classes_at(assign_front_doors(voted), LEFT_BOX, RIGHT_BOX) == ["front_door", "window"]
    # a network far surer of the box into C still names it (the inner doors may have been missed)
    probs = probabilities_of(
        lab, (LEFT_BOX, {FRONT: 0.2, WINDOW: 0.8}), (RIGHT_BOX, {FRONT: 0.9, WINDOW: 0.1})
    )
    voted = extract_instances(
        img, lab, grid=PixelGrid.from_scale(0.05, img.shape), probabilities=probs
    )
    assert classes_at(assign_front_doors(voted), LEFT_BOX, RIGHT_BOX) == ["window", "front_door"]


def test_reach_weight_falls_with_the_share_of_rooms_reached():
    assert reach_weight(5, 5) == 1.0
    assert reach_weight(0, 4) == MIN_REACH_WEIGHT
    assert reach_weight(1, 2) == pytest.approx(MIN_REACH_WEIGHT + (1 - MIN_REACH_WEIGHT) / 2)
    assert reach_weight(0, 0) == 1.0  # no candidate reaches a room: reach says nothing
