"""The sealed-room prior on drawings whose answers are known."""

from __future__ import annotations

import cv2
import networkx as nx
import numpy as np
import pytest
from helpers import (
    LEFT_BOX,
    MIDDLE_BOX,
    ProbabilityStub,
    classes_at,
    facade,
    probabilities_of,
    two_rooms,
)

from f2n_drake.core.classes import CLASS_ID
from f2n_drake.mapping.graph import build_connectivity_graph
from f2n_drake.perception.instances import extract_instances
from f2n_drake.perception.priors.front_doors import assign_front_doors
from f2n_drake.perception.priors.sealed_rooms import open_sealed_rooms
from f2n_drake.pipeline import parse_drawing

WALL, DOOR, FRONT = CLASS_ID["wall"], CLASS_ID["door"], CLASS_ID["front_door"]
LOWER_BOX = (slice(141, 146), slice(131, 150))  # a box in the wall cutting the right room


def unsure_doors(door_p: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``two_rooms`` whose door the network labels wall, giving it door probability ``door_p``."""
    img, lab = two_rooms()
    lab[MIDDLE_BOX] = WALL
    return img, lab, probabilities_of(lab, (MIDDLE_BOX, {WALL: 1 - door_p, DOOR: door_p}))


def test_the_most_door_like_wall_between_sealed_rooms_becomes_a_door():
    img, lab, probs = unsure_doors(0.3)
    parsed = extract_instances(img, lab, probabilities=probs)
    assert classes_at(parsed, MIDDLE_BOX) == ["wall"]
    opened = open_sealed_rooms(parsed)
    assert classes_at(opened, MIDDLE_BOX) == ["door"]
    # only that box changed: the rest of the middle wall and the outer wall touch both rooms too,
    # but the network gives them no door probability
    changed = [a.id for a, b in zip(parsed.instances, opened.instances, strict=True) if a != b]
    assert changed == [int(parsed.instance_ids[91, 98])]
    assert classes_at(parsed, MIDDLE_BOX) == ["wall"]  # the input is not edited


def test_too_little_door_evidence_or_none_changes_nothing():
    img, lab, probs = unsure_doors(0.05)
    parsed = extract_instances(img, lab, probabilities=probs)
    assert open_sealed_rooms(parsed) is parsed
    assert classes_at(open_sealed_rooms(parsed, min_evidence=0.04), MIDDLE_BOX) == ["door"]
    labels_only = extract_instances(img, lab)  # no scores: no evidence either way
    assert open_sealed_rooms(labels_only) is labels_only


def test_connected_rooms_are_left_alone():
    img, lab = two_rooms()
    probs = probabilities_of(lab, (MIDDLE_BOX, {DOOR: 0.6, WALL: 0.4}))
    parsed = extract_instances(img, lab, probabilities=probs)
    assert open_sealed_rooms(parsed) is parsed


def three_rooms() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``facade`` (front door in the living room's wall) with the right room cut in two by a
    wall holding a box; both inner doors are labelled wall, with door probability 0.3 and 0.4."""
    img, lab = facade(FRONT, WALL)
    lab[MIDDLE_BOX] = WALL
    for row in (140, 146):
        cv2.line(img, (103, row), (174, row), 0, 1)
    for col in (130, 150):
        cv2.line(img, (col, 140), (col, 146), 0, 1)
    lab[140:147, 104:174] = WALL
    probs = probabilities_of(
        lab, (MIDDLE_BOX, {WALL: 0.7, DOOR: 0.3}), (LOWER_BOX, {WALL: 0.6, DOOR: 0.4})
    )
    return img, lab, probs


def test_rooms_behind_rooms_are_opened_one_door_at_a_time():
    img, lab, probs = three_rooms()
    parsed = assign_front_doors(extract_instances(img, lab, probabilities=probs))
    assert classes_at(parsed, LEFT_BOX, MIDDLE_BOX, LOWER_BOX) == ["front_door", "wall", "wall"]
    assert len(parsed.of_class("bedroom")) == 2
    opened = open_sealed_rooms(parsed)
    assert classes_at(opened, MIDDLE_BOX, LOWER_BOX) == ["door", "door"]


@pytest.mark.usefixtures("drawings_at_own_size")
def test_parse_drawing_applies_the_prior():
    img, lab, probs = three_rooms()
    stub = ProbabilityStub(lab, probs)
    assert classes_at(parse_drawing(img, segmenter=stub), MIDDLE_BOX, LOWER_BOX) == [
        "door",
        "door",
    ]
    kept = parse_drawing(img, segmenter=stub, sealed_rooms=False)
    assert classes_at(kept, MIDDLE_BOX, LOWER_BOX) == ["wall", "wall"]


GRAZING_BOX = (slice(101, 139), slice(98, 103))  # living | upper bedroom, its end grazing the lower
BEHIND_BOX = (slice(151, 165), slice(98, 103))  # living | lower bedroom


def grazing_door() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Living (left); upper and lower bedroom (right, split by a wall at rows 130-136). A door
    joins living and upper bedroom, its lower end reaching 2 px past the split wall, so its
    dilation grazes the lower bedroom's corner; the box behind the lower bedroom is labelled wall
    with door probability 0.3."""
    img, lab = two_rooms()
    img[90:121, 98:103] = 255  # no door box in the middle of ``two_rooms``
    lab[lab == DOOR] = WALL
    for row in (100, 139, 150, 165):
        cv2.line(img, (97, row), (103, row), 0, 1)
    for row in (130, 136):
        cv2.line(img, (103, row), (174, row), 0, 1)
    lab[130:137, 104:174] = WALL
    lab[GRAZING_BOX] = DOOR
    probs = probabilities_of(lab, (BEHIND_BOX, {WALL: 0.7, DOOR: 0.3}))
    return img, lab, probs


def test_a_door_grazing_a_room_does_not_join_it():
    img, lab, probs = grazing_door()
    parsed = extract_instances(img, lab, probabilities=probs)
    ids = parsed.instance_ids
    living, upper, lower = int(ids[50, 50]), int(ids[50, 150]), int(ids[160, 150])
    door = int(ids[120, 100])
    assert len({living, upper, lower, door, 0}) == 5
    graph = build_connectivity_graph(parsed)
    key = {d["instance_id"]: k for k, d in graph.nodes(data=True)}
    assert set(graph[key[door]]) == {key[living], key[upper]}  # the graph's rule
    # the lower bedroom is sealed by that rule, so the prior opens the box behind it
    opened = open_sealed_rooms(parsed)
    assert classes_at(opened, BEHIND_BOX) == ["door"]
    graph = build_connectivity_graph(opened)
    assert nx.has_path(graph, key[living], key[lower])
