"""The connector-size prior on drawings whose answers are known."""

from __future__ import annotations

import json

import cv2
import numpy as np
import pytest
from helpers import MIDDLE_BOX, ProbabilityStub, classes_at, probabilities_of, two_rooms

from f2n_drake.core.classes import CLASS_ID
from f2n_drake.core.raster import PixelGrid
from f2n_drake.evaluate import segmentation
from f2n_drake.perception.instances import extract_instances
from f2n_drake.perception.priors.connector_sizes import oversized, wall_off_oversized
from f2n_drake.perception.priors.sealed_rooms import open_sealed_rooms
from f2n_drake.pipeline import parse_drawing

DOOR, WINDOW, FRONT = CLASS_ID["door"], CLASS_ID["window"], CLASS_ID["front_door"]
LONG_DOOR = (slice(30, 100), slice(21, 26))  # 70 px of paper in the left outer wall
LONG_WINDOW = (slice(30, 140), slice(175, 180))  # 110 px in the right outer wall
SHORT_WINDOW = (slice(150, 170), slice(175, 180))  # 20 px in the right outer wall


def boxed_walls(front_door_box=None):
    """``two_rooms`` (inner door: 29 px of paper) with a long door box in the left outer wall
    and a long and a short window box in the right one."""
    img, lab = two_rooms()
    for (rows, cols), cls in ((LONG_DOOR, DOOR), (LONG_WINDOW, WINDOW), (SHORT_WINDOW, WINDOW)):
        for row in (rows.start - 1, rows.stop):
            cv2.line(img, (cols.start - 1, row), (cols.stop, row), 0, 1)
        lab[rows, cols] = cls
    if front_door_box is not None:
        lab[front_door_box] = FRONT
    return img, lab


def test_doors_and_windows_wider_than_one_can_be_are_wall():
    img, lab = boxed_walls()
    # at 5 cm/px the openings are 3.55, 5.55, 1.05 and 1.5 m
    voted = extract_instances(img, lab, grid=PixelGrid.from_scale(0.05, img.shape))
    boxes = (LONG_DOOR, LONG_WINDOW, SHORT_WINDOW, MIDDLE_BOX)
    assert classes_at(voted, *boxes) == ["door", "window", "window", "door"]
    walled = wall_off_oversized(voted)
    assert classes_at(walled, *boxes) == ["wall", "wall", "window", "door"]
    assert classes_at(voted, *boxes) == ["door", "window", "window", "door"]  # not edited
    assert wall_off_oversized(voted, enabled=False) is voted
    assert wall_off_oversized(walled) is walled


def test_front_doors_are_left_to_the_front_door_prior():
    img, lab = boxed_walls(front_door_box=LONG_DOOR)
    voted = extract_instances(img, lab, grid=PixelGrid.from_scale(0.05, img.shape))
    assert classes_at(wall_off_oversized(voted), LONG_DOOR) == ["front_door"]


def test_without_a_scale_nothing_is_walled():
    # the doors would be the yardstick: measured by the inner door (0.9 m) the long window is
    # 3.33 m, but the long door would set the median too; no scale, no judgement
    img, lab = boxed_walls()
    voted = extract_instances(img, lab)
    assert oversized(voted, voted.instances, "window") == set()
    assert wall_off_oversized(voted) is voted


def test_the_sealed_room_prior_opens_no_wall_wider_than_a_door():
    # ``two_rooms`` with the middle wall's box 119 px long instead of 29, voted wall with door
    # probability 0.3: at 3 cm/px its opening is 3.6 m, a piece of wall, and the rooms stay
    # sealed; without a scale it is the door they need
    img, lab = two_rooms()
    img[89:122, 98:103] = 255
    cv2.line(img, (97, 40), (103, 40), 0, 1)
    cv2.line(img, (97, 160), (103, 160), 0, 1)
    long_box = (slice(41, 160), slice(98, 103))
    lab[89:122, 97:104] = CLASS_ID["wall"]
    probs = probabilities_of(lab, (long_box, {CLASS_ID["wall"]: 0.7, DOOR: 0.3}))
    metric = PixelGrid.from_scale(0.03, img.shape)
    wide = extract_instances(img, lab, grid=metric, probabilities=probs)
    assert int(wide.instance_ids[41, 98]) in oversized(wide, wide.of_class("wall"), "door")
    assert open_sealed_rooms(wide, kernel_px=7) is wide
    unscaled = extract_instances(img, lab, probabilities=probs)
    assert classes_at(open_sealed_rooms(unscaled, kernel_px=7), long_box) == ["door"]


@pytest.mark.usefixtures("drawings_at_own_size")
def test_parse_drawing_applies_the_prior_when_it_has_a_scale():
    img, lab = boxed_walls()
    stub = ProbabilityStub(lab, probabilities_of(lab))
    boxes = (LONG_DOOR, LONG_WINDOW)
    parsed = parse_drawing(img, segmenter=stub, metres_per_px=0.05)
    assert classes_at(parsed, *boxes) == ["wall", "wall"]
    kept = parse_drawing(img, segmenter=stub, metres_per_px=0.05, connector_sizes=False)
    assert classes_at(kept, *boxes) == ["door", "window"]
    assert classes_at(parse_drawing(img, segmenter=stub), *boxes) == ["door", "window"]


def test_segmentation_cli_counts_what_the_prior_walls(capsys):
    """Ground truth with every window labelled door: the living rooms' windows wider than 2 m
    are walled, none of them rightly, and the JSON says so."""
    window_to_door = np.arange(len(CLASS_ID), dtype=np.uint8)
    window_to_door[WINDOW] = DOOR

    def predict(rendered):
        labels = window_to_door[rendered.labels]
        return labels, np.eye(len(CLASS_ID), dtype=np.float32)[labels].transpose(2, 0, 1).copy()

    segmentation.main(["--synthetic", "3", "--seed", "5", "--json"], predict=predict)
    walled = json.loads(capsys.readouterr().out)["oversized_connectors_walled"]
    assert walled["instances"] >= 1
    assert walled["right_after"] == walled["right_before"] == 0
