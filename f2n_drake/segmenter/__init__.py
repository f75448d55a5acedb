"""DeepLabV3+ segmenter: network, weights, inference on images of any size."""

VIEW_COUNTS: tuple[int, ...] = (1, 2, 4, 8)
"""Test-time view counts ``Segmenter`` accepts (see ``f2n_drake.segmenter.inference``)."""
DEFAULT_VIEWS = 2
"""The drawing and its mirror image: measured in docs/segmenter.md (*Two views of each drawing*)."""
