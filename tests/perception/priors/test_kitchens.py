"""The one-kitchen prior on drawings whose answers are known: extra kitchens undone, a missing
one found."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from helpers import ProbabilityStub, probabilities_of

from f2n_drake.core.classes import CLASS_ID, OPENING
from f2n_drake.perception.instances import extract_instances
from f2n_drake.perception.priors.kitchens import assign_kitchens, kitchen_evidence
from f2n_drake.pipeline import parse_drawing

LIVING, BEDROOM, KITCHEN = CLASS_ID["living"], CLASS_ID["bedroom"], CLASS_ID["kitchen"]
BATHROOM = CLASS_ID["bathroom"]
WALL = CLASS_ID["wall"]
OPEN_KITCHEN = (slice(27, 174), slice(115, 174))  # the kitchen end of the open-plan room
ROOM = (slice(27, 114), slice(207, 294))  # the enclosed room on the right
OPEN_PLAN_PX = 147 * 147  # the open-plan room: rows and cols 27..173


def flat(room_probs: dict[int, float], open_kitchen_p: float):
    """An open-plan room (living left 60 %, kitchen right 40 %, no wall between) and, right of
    it, an enclosed room the network calls kitchen with ``room_probs``; the open kitchen has
    kitchen probability ``open_kitchen_p`` (the rest living)."""
    img = np.full((200, 320), 255, np.uint8)
    lab = np.zeros(img.shape, np.uint8)
    lab[20:181, 20:181] = WALL
    lab[27:174, 27:115] = LIVING
    lab[OPEN_KITCHEN] = KITCHEN
    lab[20:121, 200:301] = WALL
    lab[ROOM] = KITCHEN
    for corner, far in (((20, 20), (180, 180)), ((26, 26), (174, 174))):
        cv2.rectangle(img, corner, far, 0, 1)
    for corner, far in (((200, 20), (300, 120)), ((206, 26), (294, 114))):
        cv2.rectangle(img, corner, far, 0, 1)
    probs = probabilities_of(
        lab,
        (ROOM, room_probs),
        (OPEN_KITCHEN, {KITCHEN: open_kitchen_p, LIVING: 1 - open_kitchen_p}),
    )
    return img, lab, probs


def class_at(parsed, window) -> str:
    """Class of the instance at the window's centre."""
    rows, cols = window
    centre = (rows.start + rows.stop) // 2, (cols.start + cols.stop) // 2
    return parsed.by_id()[int(parsed.instance_ids[centre])].class_name


def test_a_second_open_kitchen_rejoins_its_living_room():
    img, lab, probs = flat({KITCHEN: 0.9, BEDROOM: 0.1}, open_kitchen_p=0.6)
    voted = extract_instances(img, lab, probabilities=probs)
    assert sorted(i.class_name for i in voted.of_class("kitchen", "living", OPENING)) == [
        "kitchen",
        "kitchen",
        "living",
        OPENING,
    ]
    parsed = assign_kitchens(voted)
    assert class_at(parsed, ROOM) == "kitchen"  # the surer kitchen stays
    assert not parsed.of_class(OPENING)
    (living,) = parsed.of_class("living")
    assert living.area_px == OPEN_PLAN_PX == (parsed.instance_ids == living.id).sum()
    assert living.votes == {LIVING: 88 * 147, KITCHEN: 59 * 147}
    assert living.scores[KITCHEN] == pytest.approx(0.6 * 59 / 147, abs=1e-3)
    np.testing.assert_allclose(living.centroid_px, (100.0, 100.0))
    np.testing.assert_allclose(living.contour_px.min(axis=0), [27, 27])
    np.testing.assert_allclose(living.contour_px.max(axis=0), [173, 173])
    assert len(voted.of_class(OPENING)) == 1  # the input is not edited
    ids = {i.id for i in parsed.instances}
    assert set(np.unique(parsed.instance_ids).tolist()) - {0} == ids


def test_a_less_sure_enclosed_kitchen_takes_its_runner_up():
    img, lab, probs = flat({KITCHEN: 0.5, BEDROOM: 0.45, LIVING: 0.05}, open_kitchen_p=0.7)
    voted = extract_instances(img, lab, probabilities=probs)
    assert kitchen_evidence(voted.by_id()[int(voted.instance_ids[30, 210])]) == pytest.approx(0.5)
    parsed = assign_kitchens(voted)
    assert class_at(parsed, ROOM) == "bedroom"
    assert class_at(parsed, OPEN_KITCHEN) == "kitchen" and len(parsed.of_class(OPENING)) == 1


def test_counts():
    img, lab, probs = flat({KITCHEN: 0.9, BEDROOM: 0.1}, open_kitchen_p=0.6)
    voted = extract_instances(img, lab, probabilities=probs)
    assert assign_kitchens(voted, None) is voted
    assert assign_kitchens(voted, 2) is voted
    assert not assign_kitchens(voted, 0).of_class("kitchen")
    with pytest.raises(ValueError):
        assign_kitchens(voted, -1)


def test_without_probabilities_the_vote_share_decides():
    img, lab, _ = flat({}, 0.0)
    lab[27:60, 207:294] = BEDROOM  # the enclosed room is 38 % bedroom: less kitchen-like
    parsed = assign_kitchens(extract_instances(img, lab))
    assert class_at(parsed, ROOM) == "bedroom" and class_at(parsed, OPEN_KITCHEN) == "kitchen"


def test_parse_drawing_applies_the_prior():
    img, lab, probs = flat({KITCHEN: 0.9, BEDROOM: 0.1}, open_kitchen_p=0.6)
    stub = ProbabilityStub(lab, probs)
    # the flat's two outlines stand apart, as two plans on a sheet would: parse both
    whole = {"segmenter": stub, "leave_out_sheet": False}
    assert len(parse_drawing(img, **whole).of_class("kitchen")) == 1
    assert len(parse_drawing(img, **whole, kitchens=None).of_class("kitchen")) == 2


def no_kitchen(room_class: int, room_probs: dict[int, float]):
    """``flat`` with the open-plan room all living and the enclosed room voted ``room_class``."""
    img, lab, _ = flat({}, 0.0)
    lab[27:174, 27:174] = LIVING
    lab[ROOM] = room_class
    probs = probabilities_of(lab, (ROOM, room_probs))
    return img, lab, probs


def test_a_flat_without_a_kitchen_gets_its_most_kitchen_like_room():
    img, lab, probs = no_kitchen(BEDROOM, {BEDROOM: 0.7, KITCHEN: 0.3})
    voted = extract_instances(img, lab, probabilities=probs)
    assert not voted.of_class("kitchen")
    parsed = assign_kitchens(voted)
    assert class_at(parsed, ROOM) == "kitchen" and class_at(parsed, OPEN_KITCHEN) == "living"
    assert class_at(voted, ROOM) == "bedroom"  # not edited
    assert assign_kitchens(voted, 0) is voted  # a count of 0 asks for no kitchen
    assert assign_kitchens(voted, min_evidence=0.31) is voted  # not kitchen-like enough


def test_the_only_bathroom_and_the_living_room_never_become_the_kitchen():
    img, lab, probs = no_kitchen(BATHROOM, {BATHROOM: 0.6, KITCHEN: 0.4})
    probs[KITCHEN, 27:174, 27:100] = 0.5  # the living room is kitchen-like enough too (0.25)
    probs[LIVING, 27:174, 27:100] = 0.5
    voted = extract_instances(img, lab, probabilities=probs)
    assert assign_kitchens(voted) is voted
