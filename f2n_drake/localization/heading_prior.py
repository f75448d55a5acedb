"""Where the robot may be facing, from the directions of the walls in one scan.

Most plans are drawn along two perpendicular directions (a "Manhattan world"): the walls a scan
sees run, in the robot's frame, at ``scan_angle`` modulo 90 degrees, and the plan's at
``plan_angle``; the heading is then ``plan_angle - scan_angle`` plus a multiple of 90 degrees.
Four headings instead of a full turn make the first particle cloud of global localization
(:func:`f2n_drake.localization.particle_filter.uniform_cloud`) about 40 times denser where it
matters. A plan or a scan whose walls do not share such directions gives no prior.
"""

from __future__ import annotations

import numpy as np

from f2n_drake.localization.scans import extract_line_segments


def dominant_direction(segments: np.ndarray, min_agreement: float = 0.7) -> float | None:
    """Length-weighted direction [rad, in (-pi/4, pi/4]] of ``segments`` (N, 4) modulo 90
    degrees; None when fewer than ``min_agreement`` (mean resultant length of the quadrupled
    angles, 0 to 1) of them agree or there are none."""
    d = np.asarray(segments, dtype=float).reshape(-1, 4)
    dx, dy = d[:, 2] - d[:, 0], d[:, 3] - d[:, 1]
    length = np.hypot(dx, dy)
    if length.sum() <= 0:
        return None
    angle4 = 4.0 * np.arctan2(dy, dx)
    c, s = length @ np.cos(angle4), length @ np.sin(angle4)
    if np.hypot(c, s) / length.sum() < min_agreement:
        return None
    return float(0.25 * np.arctan2(s, c))


def heading_hypotheses(points_robot: np.ndarray, wall_segments: np.ndarray) -> np.ndarray:
    """The four headings [rad] that align the straight walls in a scan (robot-frame points
    (M, 2) [m], in beam order) with the plan's ``wall_segments`` (N, 4) [m]; empty when either
    has no dominant direction (:func:`dominant_direction`)."""
    scan_direction = dominant_direction(extract_line_segments(points_robot))
    plan_direction = dominant_direction(wall_segments)
    if scan_direction is None or plan_direction is None:
        return np.zeros(0)
    base = plan_direction - scan_direction
    return (base + 0.5 * np.pi * np.arange(4) + np.pi) % (2.0 * np.pi) - np.pi


__all__ = ["dominant_direction", "heading_hypotheses"]
