"""The prior chain shared by the parse and the evaluation
(``f2n_drake.perception.priors.chain``)."""

from __future__ import annotations

from helpers import (
    FRONT,
    LEFT_BOX,
    RIGHT_BOX,
    WINDOW,
    classes_at,
    facade,
    probabilities_of,
)

from f2n_drake.perception.instances import extract_instances
from f2n_drake.perception.priors.chain import PRIORS, apply_priors, prior_stages

ALL_OFF = {
    "front_doors": None,
    "connector_sizes": False,
    "balconies": False,
    "kitchens": None,
    "sealed_rooms": False,
}


def two_front_doors():
    img, lab = facade(FRONT, FRONT)
    probs = probabilities_of(
        lab, (LEFT_BOX, {FRONT: 0.55, WINDOW: 0.45}), (RIGHT_BOX, {FRONT: 0.9})
    )
    return extract_instances(img, lab, probabilities=probs)


def test_stages_follow_the_priors_in_order_and_end_in_the_parse():
    voted = two_front_doors()
    stages = prior_stages(voted)
    assert tuple(stages) == PRIORS
    assert classes_at(stages["front_doors"], LEFT_BOX, RIGHT_BOX) == ["window", "front_door"]
    assert classes_at(apply_priors(voted), LEFT_BOX, RIGHT_BOX) == ["window", "front_door"]
    assert classes_at(voted, LEFT_BOX, RIGHT_BOX) == ["front_door", "front_door"]  # not edited


def test_a_prior_switched_off_passes_its_input_on():
    voted = two_front_doors()
    stages = prior_stages(voted, **ALL_OFF)
    assert all(stage is voted for stage in stages.values())
    assert apply_priors(voted, **ALL_OFF) is voted
    no_front_door_prior = prior_stages(voted, front_doors=None)
    assert no_front_door_prior["front_doors"] is voted
    assert (
        classes_at(no_front_door_prior["sealed_rooms"], LEFT_BOX, RIGHT_BOX) == ["front_door"] * 2
    )
