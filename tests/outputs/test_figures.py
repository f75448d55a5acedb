"""The segmentation figure marks what the segmenter is unsure of."""

from __future__ import annotations

import dataclasses

from helpers import FRONT, LEFT_BOX, WINDOW, facade, probabilities_of

from f2n_drake.core.classes import OPENING
from f2n_drake.outputs.figures import plot_segmentation
from f2n_drake.perception.instances import extract_instances


def test_segmentation_figure_outlines_unsure_instances():
    img, lab = facade(FRONT, WINDOW)
    probs = probabilities_of(lab, (LEFT_BOX, {FRONT: 0.55, WINDOW: 0.45}))
    parsed = extract_instances(img, lab, probabilities=probs)
    fig = plot_segmentation(img, parsed)
    instances_ax = fig.axes[2]
    dashed = [line for line in instances_ax.lines if line.get_linestyle() == "--"]
    assert len(dashed) == 1  # only the 55 % front door
    assert [t.get_text() for t in instances_ax.texts] == ["55%"]
    assert "1 below 80 %" in instances_ax.get_title()


def test_segmentation_figure_names_the_openings_outline_when_there_is_one():
    img, lab = facade(FRONT, WINDOW)
    parsed = extract_instances(img, lab)

    def legend(plan) -> list[str]:
        return [t.get_text() for t in plot_segmentation(img, plan).axes[2].get_legend().texts]

    assert "opening (outline)" not in legend(parsed)
    first, *rest = parsed.instances
    passage = dataclasses.replace(
        parsed, instances=[dataclasses.replace(first, class_name=OPENING), *rest]
    )
    assert "opening (outline)" in legend(passage)
    assert "living" in legend(passage)  # the classes stay
