"""Scan-to-plan registration: point-to-line ICP on SE(2) against a floor plan's wall segments.

Each scan point is paired with its nearest wall segment (within a gate that shrinks over the
iterations); the signed distance to that wall's line is linearised in ``(x, y, theta)`` and a
Huber-weighted Gauss-Newton step is solved. Directions of the 3x3 information matrix with too
little support (a corridor gives none along its axis) are left at the initial estimate.
Point-to-line ICP after Censi, "An ICP variant using a point-to-line metric", ICRA 2008.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from f2n_drake.localization.scans import (
    as_segments,
    cast_rays,
    transform_points,
    visible_segments,
)

RECAST_RAD = np.deg2rad(0.5)
VISIBILITY_RAYS = 360
"""Rays cast from the initial pose to find the wall faces it sees (the LiDAR's 1 degree)."""


@dataclass(frozen=True)
class IcpResult:
    """Outcome of :func:`icp_point_to_line`.

    Attributes:
        pose: refined ``[x, y, theta]`` [m, m, rad] (the initial pose in unconstrained directions).
        inlier_ratio: fraction of scan points within the final gate of a wall at ``pose``.
        rms_m: root-mean-square point-to-wall distance of those inliers [m].
        iterations: Gauss-Newton steps taken.
        converged: the last step was below tolerance.
        constrained_dirs: ``(k, 3)`` unit vectors in ``(x [m], y [m], theta*length_scale [m])``
            that the scan constrains; ``k == 3`` for a well-conditioned fit.
        accepted: inlier ratio and rms within thresholds, ``k >= 1``.
    """

    pose: np.ndarray
    inlier_ratio: float
    rms_m: float
    iterations: int
    converged: bool
    constrained_dirs: np.ndarray
    accepted: bool


def nearest_wall(
    points: np.ndarray, segments: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For world points ``(M, 2)``: distance [m] to the nearest segment, that segment's unit
    normal ``(M, 2)`` and the signed distance [m] to its supporting line."""
    a, ab = segments[:, :2], segments[:, 2:] - segments[:, :2]
    length = np.maximum(np.hypot(ab[:, 0], ab[:, 1]), 1e-12)
    ap = points[:, None, :] - a[None, :, :]
    u = np.clip(np.einsum("mnk,nk->mn", ap, ab) / length**2, 0.0, 1.0)
    diff = ap - u[..., None] * ab[None, :, :]
    dist2 = np.einsum("mnk,mnk->mn", diff, diff)
    best = np.argmin(dist2, axis=1)
    normals = np.stack([-ab[:, 1], ab[:, 0]], axis=1) / length[:, None]
    n = normals[best]
    signed = np.einsum("mk,mk->m", points - a[best], n)
    return np.sqrt(dist2[np.arange(len(points)), best]), n, signed


def fit_quality(
    points_robot: np.ndarray, segments: np.ndarray, pose: np.ndarray, gate_m: float = 0.1
) -> tuple[float, float]:
    """``(inlier_ratio, rms_m)`` of robot-frame scan points placed at ``pose`` against walls."""
    pts = np.asarray(points_robot, dtype=float)
    seg = as_segments(segments)
    if len(pts) == 0 or len(seg) == 0:
        return 0.0, float("inf")
    dist = nearest_wall(transform_points(pts, pose), seg)[0]
    inliers = dist <= gate_m
    if not inliers.any():
        return 0.0, float("inf")
    return float(inliers.mean()), float(np.sqrt(np.mean(dist[inliers] ** 2)))


def beam_consistent(
    points_robot: np.ndarray, segments: np.ndarray, pose: np.ndarray, gate_m: float
) -> np.ndarray:
    """(M,) bool: the robot-frame scan points whose range is within ``gate_m`` [m] of the
    plan's range along the same beam from ``pose`` (the first wall of ``segments`` it meets).

    A return well short of the plan's wall is something standing in front of it (furniture, a
    person, a closed door); one well beyond it is a wall the plan has wrong, or a beam through a
    gap the plan lacks. Neither can be matched to the plan.
    """
    pts = np.asarray(points_robot, dtype=float).reshape(-1, 2)
    ranges = np.hypot(pts[:, 0], pts[:, 1])
    angles = np.arctan2(pts[:, 1], pts[:, 0]) + pose[2]
    expected = cast_rays(np.asarray(pose[:2], float), angles, segments, np.inf)
    return np.abs(ranges - expected) <= gate_m


def icp_point_to_line(
    points_robot: np.ndarray,
    segments: np.ndarray,
    initial_pose: np.ndarray,
    *,
    max_iterations: int = 15,
    initial_gate_m: float = 0.8,
    final_gate_m: float = 0.1,
    gate_decay: float = 0.6,
    huber_m: float = 0.03,
    max_range: float = 3.5,
    min_information: float = 5.0,
    length_scale_m: float = 1.0,
    tolerance: float = 1e-4,
    min_inlier_ratio: float = 0.5,
    max_rms_m: float = 0.05,
    min_points: int = 20,
    beam_gate_m: float | None = 0.3,
    min_inliers: int = 30,
) -> IcpResult:
    """Register robot-frame scan points ``(M, 2)`` to wall segments ``(N, 4)`` near a pose.

    Returns the plan cannot explain (furniture, people, a closed door, a wall the plan has
    wrong) are rejected, never averaged in:

    1. beam gate (with ``beam_gate_m``): at every iteration a point is paired only if its range
       is within ``beam_gate_m`` of the range the plan predicts along its beam from the current
       pose (:func:`beam_consistent`), so a cupboard in front of a wall is dropped even where
       its face runs parallel to the wall, or near another wall;
    2. distance gate: a point is paired only with a wall within the gate, which shrinks from
       ``initial_gate_m`` to ``final_gate_m`` after the first (coarse) iterations;
    3. the kept points are Huber-weighted, so a point just inside the gate pulls no harder
       than one at ``huber_m``;
    4. a fit is refused unless at least ``min_inliers`` points, and ``min_inlier_ratio`` of the
       beam-consistent ones, lie within ``final_gate_m`` of a wall at the final pose.

    Args:
        points_robot: valid scan returns in the robot frame [m].
        segments: plan walls in the world [m]; only the faces visible from the initial pose
            (within ``max_range`` + gate) are used, so a wall's hidden back face never attracts
            points.
        initial_pose: ``[x, y, theta]`` estimate [m, m, rad].
        initial_gate_m, final_gate_m, gate_decay: pairing gate [m], multiplied by
            ``gate_decay`` each iteration down to ``final_gate_m``; early exit only at the
            final gate.
        huber_m: Huber threshold on the point-to-line residual [m].
        min_information: smallest eigenvalue [points] of the unweighted information matrix
            ``J^T J`` (in x, y, theta*length_scale_m) for a direction to be corrected. Low (5
            points' worth), so that a direction seen past furniture by a short stretch of wall is
            corrected rather than left to drift (the beam gate keeps the furniture out of it).
        tolerance: step size [m, or rad * length_scale_m] below which the fit has converged.
        min_inlier_ratio, max_rms_m, min_points: acceptance thresholds of the final fit.
        beam_gate_m: the beam gate [m] (None: no beam gate, every point may pair).
        min_inliers: fewest inliers [points] of an accepted fit.
    """
    pts = np.asarray(points_robot, dtype=float).reshape(-1, 2)
    pose0 = np.asarray(initial_pose, dtype=float).copy()
    walls = visible_segments(pose0[:2], segments, max_range + initial_gate_m, VISIBILITY_RAYS)
    pose = pose0.copy()
    no_dirs = np.zeros((0, 3))
    if len(pts) < min_points or len(walls) == 0:
        return IcpResult(pose0, 0.0, float("inf"), 0, False, no_dirs, False)

    cache: dict = {}

    def consistent(at: np.ndarray) -> np.ndarray:
        """The beam gate at ``at``, recast only once the pose moved (2 cm, 0.5 deg)."""
        if beam_gate_m is None:
            return np.ones(len(pts), bool)
        moved = np.abs(at - cache.get("at", np.full(3, np.inf)))
        if moved[0] > 0.02 or moved[1] > 0.02 or moved[2] > RECAST_RAD:
            cache["at"], cache["mask"] = at.copy(), beam_consistent(pts, walls, at, beam_gate_m)
        return cache["mask"]

    gate, converged, iterations, dirs = initial_gate_m, False, 0, no_dirs
    for iterations in range(1, max_iterations + 1):  # noqa: B007 (read after the loop)
        world = transform_points(pts, pose)
        dist, normal, residual = nearest_wall(world, walls)
        inl = (dist <= gate) & consistent(pose)
        if inl.sum() < min_points:
            break
        lever = world[inl] - pose[:2]
        n, r = normal[inl], residual[inl]
        jac = np.column_stack([n, (n[:, 1] * lever[:, 0] - n[:, 0] * lever[:, 1]) / length_scale_m])
        weight = np.minimum(1.0, huber_m / np.maximum(np.abs(r), 1e-12))
        # Which directions the geometry constrains: unweighted information, in points.
        eigval, eigvec = np.linalg.eigh(jac.T @ jac)
        basis = eigvec[:, eigval >= min_information]  # (3, k)
        dirs = basis.T
        if basis.shape[1] == 0:
            break
        # Huber-weighted Gauss-Newton step restricted to those directions.
        reduced = basis.T @ (jac.T @ (weight[:, None] * jac)) @ basis
        step = -basis @ np.linalg.solve(reduced, basis.T @ (jac.T @ (weight * r)))
        pose = pose + np.array([step[0], step[1], step[2] / length_scale_m])
        at_final_gate = gate <= final_gate_m
        gate = max(final_gate_m, gate * gate_decay)
        if at_final_gate and np.max(np.abs(step)) < tolerance:
            converged = True
            break
    pose[2] = pose0[2] + (pose[2] - pose0[2] + np.pi) % (2.0 * np.pi) - np.pi
    inlier_ratio, rms = fit_quality(pts, walls, pose, final_gate_m)
    inliers = inlier_ratio * len(pts)
    kept = max(int(consistent(pose).sum()), 1)
    accepted = bool(
        len(dirs) > 0
        and inliers >= min_inliers
        and inliers / kept >= min_inlier_ratio
        and rms <= max_rms_m
        and np.isfinite(pose).all()
    )
    return IcpResult(pose, inlier_ratio, rms, iterations, converged, dirs, accepted)
