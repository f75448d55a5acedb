"""Set-valued cross entropy: the loss of a pixel whose label is a set of acceptable classes.

Where a dataset merges classes (R3D's living/kitchen/dining room, its doors-and-windows), a pixel's
target is the union of its classes: its loss is ``-log`` of the summed probability of the
acceptable classes, ``-(logsumexp(logits[acceptable]) - logsumexp(logits))``. A pixel with one
acceptable class gets the plain cross entropy; a pixel with none (an empty set) is ignored.
"""

from __future__ import annotations

import torch

EMPHASIS_BIT = 1 << 15
"""Bit of a class set marking a pixel whose loss counts ``emphasis`` times (no class bit: the
class ids stay below 15)."""


def acceptable_classes(class_sets: torch.Tensor, num_classes: int) -> torch.Tensor:
    """(B, C, H, W) bool: is class c acceptable at the pixel, from (B, H, W) int bit masks."""
    bits = torch.arange(num_classes, device=class_sets.device).view(1, -1, 1, 1)
    return (class_sets.unsqueeze(1) >> bits) & 1 == 1


def set_cross_entropy(
    logits: torch.Tensor,
    class_sets: torch.Tensor,
    weight: torch.Tensor | None = None,
    emphasis: float = 1.0,
) -> torch.Tensor:
    """Mean set-valued cross entropy.

    Args:
        logits: (B, C, H, W) class scores.
        class_sets: (B, H, W) int64 bit masks, bit c set when class c is acceptable.
        weight: (C,) class weights; a pixel weighs the mean weight of its acceptable classes and
            the mean is weighted, as ``torch.nn.functional.cross_entropy`` does for one class.
        emphasis: factor on the weight of pixels whose set carries :data:`EMPHASIS_BIT`.

    Returns:
        The scalar loss (0 when no pixel has an acceptable class).
    """
    acceptable = acceptable_classes(class_sets, logits.shape[1])
    log_total = torch.logsumexp(logits, dim=1)
    log_acceptable = torch.logsumexp(logits.masked_fill(~acceptable, float("-inf")), dim=1)
    labelled = acceptable.any(dim=1)
    loss = (log_total - log_acceptable).masked_fill(~labelled, 0.0)
    counts = acceptable.sum(dim=1).clamp(min=1)
    if weight is None:
        pixel_weight = labelled.to(logits.dtype)
    else:
        w = weight.to(logits.dtype).view(1, -1, 1, 1)
        pixel_weight = (acceptable * w).sum(dim=1) / counts
    if emphasis != 1.0:
        emphasised = (class_sets & EMPHASIS_BIT) != 0
        pixel_weight = torch.where(emphasised, pixel_weight * emphasis, pixel_weight)
    return (loss * pixel_weight).sum() / pixel_weight.sum().clamp(min=1e-12)


def distillation_loss(
    logits: torch.Tensor, teacher: torch.Tensor, weight: torch.Tensor | None = None
) -> torch.Tensor:
    """Mean Kullback-Leibler divergence of the student's class distribution from the
    teacher's, per pixel (Hinton et al., "Distilling the Knowledge in a Neural Network", 2015,
    at temperature 1).

    Args:
        logits: (B, C, H, W) student class scores.
        teacher: (B, C, H, W) teacher class scores of the same crops.
        weight: (C,) class weights; a pixel weighs that of the teacher's best class, so thin
            doors and windows count as in :func:`set_cross_entropy`.

    Returns:
        The scalar loss (0 where student and teacher agree).
    """
    log_teacher = torch.log_softmax(teacher, dim=1)
    divergence = (log_teacher.exp() * (log_teacher - torch.log_softmax(logits, dim=1))).sum(1)
    if weight is None:
        return divergence.mean()
    pixel_weight = weight.to(logits.dtype)[teacher.argmax(dim=1)]
    return (divergence * pixel_weight).sum() / pixel_weight.sum().clamp(min=1e-12)
