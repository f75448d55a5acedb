"""A run of openings taken as one connector is cut at the solid piers between them, not at the
thin lines drawn across a window."""

from __future__ import annotations

import numpy as np

from f2n_drake.core.classes import CLASS_ID
from f2n_drake.core.parsed import ParsedPlan, instance_from_mask
from f2n_drake.perception.opening_piers import part_at_piers

WINDOW = CLASS_ID["window"]


def facade(pier_px: int, pier_grey: int) -> tuple[np.ndarray, np.ndarray, ParsedPlan]:
    """A 60x120 drawing: a wall 10 px thick along row 20, its middle (columns 20-99) one window
    connector: glass lines along it, and across it at columns 58.. a pier ``pier_px`` wide of
    grey ``pier_grey``; the room below. (grey, ink, plan)"""
    grey = np.full((60, 120), 255, np.uint8)
    grey[20:30, :] = 0  # the wall
    grey[20:30, 20:100] = 255  # its opening
    grey[20, 20:100] = grey[24, 20:100] = grey[29, 20:100] = 0  # faces and glass
    grey[20:30, 58 : 58 + pier_px] = pier_grey
    ink = grey < 200
    labels = np.zeros(grey.shape, np.uint8)
    labels[ink] = CLASS_ID["wall"]
    labels[20:30, 20:100] = WINDOW
    labels[30:, :] = CLASS_ID["living"]
    ids = np.zeros(grey.shape, np.int32)
    ids[20:30, 20:100] = 1
    ids[30:, :] = 2
    instances = [
        instance_from_mask(1, "window", ids == 1, labels),
        instance_from_mask(2, "living", ids == 2, labels),
    ]
    return grey, ink, ParsedPlan(ids, labels, instances)


def windows(plan: ParsedPlan) -> list[tuple[int, int]]:
    """(first, last) column of each window, left to right."""
    spans = [np.nonzero(plan.mask(inst.id))[1] for inst in plan.of_class("window")]
    return sorted((int(c.min()), int(c.max())) for c in spans)


def test_a_solid_pier_parts_two_windows():
    grey, ink, plan = facade(pier_px=4, pier_grey=0)
    parted = part_at_piers(plan, grey, ink)
    assert windows(parted) == [(20, 57), (62, 99)]
    assert not parted.instance_ids[20:30, 58:62].any()  # the pier is wall
    assert len(parted.of_class("living")) == 1


def test_a_thin_or_light_line_across_a_window_leaves_it_one():
    for pier_px, pier_grey in ((1, 0), (4, 150)):  # a mullion; a light sash drawn across
        grey, ink, plan = facade(pier_px, pier_grey)
        assert part_at_piers(plan, grey, ink) is plan
