"""The balcony prior (a balcony is open to the air) on drawings whose answers are known."""

from __future__ import annotations

import json

import cv2
import numpy as np
import pytest
from helpers import ProbabilityStub, classes_at, probabilities_of, two_rooms

from f2n_drake.core.classes import CLASS_ID
from f2n_drake.evaluate import segmentation
from f2n_drake.mapping.graph import exterior_mask
from f2n_drake.perception.instances import extract_instances
from f2n_drake.perception.priors.balconies import close_balconies, reaches_exterior
from f2n_drake.pipeline import parse_drawing

BALCONY, BATHROOM, BEDROOM = CLASS_ID["balcony"], CLASS_ID["bathroom"], CLASS_ID["bedroom"]
RIGHT_ROOM = (slice(27, 174), slice(104, 174))  # the bedroom of ``two_rooms``
OUTSIDE_BALCONY = (slice(181, 215), slice(41, 90))  # below the outer wall, behind a railing


def with_balcony(railing_px: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """``two_rooms`` on a 240 px sheet with a balcony below its outer wall: a railing drawn
    ``railing_px`` thick, labelled balcony on its inner side and background on its outer."""
    img, lab = two_rooms()
    img = np.pad(img, ((0, 40), (0, 40)), constant_values=255)
    lab = np.pad(lab, ((0, 40), (0, 40)))
    cv2.rectangle(img, (40, 180), (90, 215), 0, 1)
    lab[OUTSIDE_BALCONY] = BALCONY
    if railing_px > 1:  # a thick pen: the railing grows into the balcony
        img[216 - railing_px : 216, 40:91] = 0
        img[181:216, 40 : 40 + railing_px] = 0
        img[181:216, 91 - railing_px : 91] = 0
    return img, lab


def test_a_room_walls_close_on_every_side_is_no_balcony():
    img, lab = with_balcony()
    lab[RIGHT_ROOM] = BALCONY  # the network saw a balcony in the bedroom
    probs = probabilities_of(lab, (RIGHT_ROOM, {BALCONY: 0.6, BATHROOM: 0.3, BEDROOM: 0.1}))
    voted = extract_instances(img, lab, probabilities=probs)
    assert classes_at(voted, RIGHT_ROOM, OUTSIDE_BALCONY) == ["balcony", "balcony"]
    parsed = close_balconies(voted)
    assert classes_at(parsed, RIGHT_ROOM, OUTSIDE_BALCONY) == ["bathroom", "balcony"]
    assert classes_at(voted, RIGHT_ROOM, OUTSIDE_BALCONY) == ["balcony", "balcony"]  # not edited
    assert close_balconies(voted, enabled=False) is voted


def test_a_balcony_behind_a_thick_railing_reaches_the_outside():
    img, lab = with_balcony(railing_px=6)
    voted = extract_instances(img, lab)
    balcony = int(voted.instance_ids[195, 65])
    exterior = exterior_mask(voted.instance_ids, 5, voted.labels)
    assert reaches_exterior(voted, balcony, exterior, reach_px=15)
    assert not reaches_exterior(voted, balcony, exterior, reach_px=3)  # the pen is 6 px
    lab[209:216, 40:91] = CLASS_ID["wall"]  # ... unless the network calls the railing wall
    lab[181:216, 40:47] = lab[181:216, 84:91] = CLASS_ID["wall"]
    walled = extract_instances(img, lab)
    balcony = int(walled.instance_ids[195, 65])
    exterior = exterior_mask(walled.instance_ids, 5, walled.labels)
    assert not reaches_exterior(walled, balcony, exterior, reach_px=15)


def test_a_closed_balcony_with_no_room_evidence_stays():
    img, lab = with_balcony()
    lab[RIGHT_ROOM] = BALCONY
    voted = extract_instances(img, lab, probabilities=probabilities_of(lab))
    assert classes_at(close_balconies(voted), RIGHT_ROOM) == ["balcony"]


@pytest.mark.usefixtures("drawings_at_own_size")
def test_parse_drawing_applies_the_balcony_prior():
    img, lab = with_balcony()
    lab[RIGHT_ROOM] = BALCONY
    probs = probabilities_of(lab, (RIGHT_ROOM, {BALCONY: 0.5, BEDROOM: 0.4, BATHROOM: 0.1}))
    stub = ProbabilityStub(lab, probs)
    assert classes_at(parse_drawing(img, segmenter=stub), RIGHT_ROOM) == ["bedroom"]
    kept = parse_drawing(img, segmenter=stub, balconies=False)
    assert classes_at(kept, RIGHT_ROOM) == ["balcony"]


def test_segmentation_cli_counts_the_balconies_it_closes(capsys):
    """Ground truth with every bathroom painted balcony (the network still 40 % sure of the
    bathroom): the prior gives each its class back, and the JSON says so."""
    bathroom_to_balcony = np.arange(len(CLASS_ID), dtype=np.uint8)
    bathroom_to_balcony[BATHROOM] = BALCONY

    def predict(rendered):
        labels = bathroom_to_balcony[rendered.labels]
        probs = np.eye(len(CLASS_ID), dtype=np.float32)[labels].transpose(2, 0, 1).copy()
        was_bathroom = rendered.labels == BATHROOM
        probs[BALCONY][was_bathroom], probs[BATHROOM][was_bathroom] = 0.6, 0.4
        return labels, probs

    segmentation.main(["--synthetic", "3", "--seed", "5", "--json"], predict=predict)
    report = json.loads(capsys.readouterr().out)
    closed = report["balconies_closed"]
    assert closed["instances"] >= 3  # every plan has a bathroom
    assert closed["right_after"] == closed["instances"] and closed["right_before"] == 0
    assert "bathroom->balcony" not in report["instance_errors"]
