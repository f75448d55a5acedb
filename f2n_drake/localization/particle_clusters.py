"""Reading a particle cloud: its clusters (the rival hypotheses), the pose estimate and whether
the filter has converged.

A cluster is found by weighted mean shift: start at the heaviest cell of a coarse (x, y, theta)
histogram, then move to the weighted mean of the particles within ``radius_m`` and
``heading_rad`` of it until it settles. The estimate is the mean of the dominant (heaviest)
cluster; the filter has converged when a share ``share`` of the weight lies within
``radius_m`` and ``heading_rad`` of it (:class:`ConvergenceTest`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from f2n_drake.localization.particle_filter import ParticleCloud


@dataclass(frozen=True)
class Cluster:
    """A hypothesis: weighted mean ``pose`` [x, y, theta], its share of the ``weight`` and the
    weighted RMS distance ``spread_m`` [m] of its particles from the mean."""

    pose: np.ndarray
    weight: float
    spread_m: float


@dataclass(frozen=True)
class ConvergenceTest:
    """The cloud has converged when ``share`` of the weight lies within ``radius_m`` [m] and
    ``heading_rad`` [rad] of the estimate."""

    radius_m: float = 0.2
    heading_rad: float = 0.1
    share: float = 0.95


def wrap(angle: np.ndarray) -> np.ndarray:
    """Angles wrapped to [-pi, pi)."""
    return (np.asarray(angle) + np.pi) % (2.0 * np.pi) - np.pi


def _near(poses: np.ndarray, centre: np.ndarray, radius_m: float, heading_rad: float):
    close = np.hypot(poses[:, 0] - centre[0], poses[:, 1] - centre[1]) <= radius_m
    return close & (np.abs(wrap(poses[:, 2] - centre[2])) <= heading_rad)


def _weighted_mean(poses: np.ndarray, weights: np.ndarray) -> np.ndarray:
    w = weights / weights.sum()
    theta = np.arctan2(w @ np.sin(poses[:, 2]), w @ np.cos(poses[:, 2]))
    return np.array([w @ poses[:, 0], w @ poses[:, 1], theta])


def _mode(poses: np.ndarray, weights: np.ndarray, radius_m: float, heading_rad: float):
    """Centre of the heaviest cell of an (x, y, theta) histogram of ``radius_m`` x
    ``radius_m`` x ``heading_rad`` cells."""
    cells = np.column_stack(
        [
            np.floor(poses[:, 0] / radius_m),
            np.floor(poses[:, 1] / radius_m),
            np.floor((poses[:, 2] + np.pi) / heading_rad),
        ]
    ).astype(np.int64)
    keys, inverse = np.unique(cells, axis=0, return_inverse=True)
    heaviest = int(np.argmax(np.bincount(inverse.reshape(-1), weights=weights)))
    members = inverse.reshape(-1) == heaviest
    return _weighted_mean(poses[members], weights[members])


def dominant_cluster(
    poses: np.ndarray,
    weights: np.ndarray,
    *,
    radius_m: float = 0.5,
    heading_rad: float = 0.5,
    iterations: int = 10,
) -> tuple[Cluster, np.ndarray]:
    """The heaviest cluster of the particles ``poses`` (N, 3) with ``weights`` (N,, summing
    to at most 1) and the mask (N,) of its particles."""
    centre = _mode(poses, weights, radius_m, heading_rad)
    members = _near(poses, centre, radius_m, heading_rad)
    for _ in range(iterations):
        if not weights[members].sum() > 0:
            break
        new = _weighted_mean(poses[members], weights[members])
        moved = np.hypot(*(new[:2] - centre[:2])) > 1e-4 or abs(wrap(new[2] - centre[2])) > 1e-4
        centre, members = new, _near(poses, new, radius_m, heading_rad)
        if not moved:
            break
    w = weights[members]
    spread = np.hypot(poses[members, 0] - centre[0], poses[members, 1] - centre[1])
    rms = float(np.sqrt(w @ spread**2 / w.sum())) if w.sum() > 0 else 0.0
    return Cluster(centre, float(w.sum()), rms), members


def clusters(
    cloud: ParticleCloud,
    *,
    radius_m: float = 0.5,
    heading_rad: float = 0.5,
    min_weight: float = 0.02,
    max_clusters: int = 10,
) -> list[Cluster]:
    """The cloud's hypotheses, heaviest first: clusters of at least ``min_weight`` of the
    weight, each taken out before the next is sought."""
    weights = cloud.weights / cloud.weights.sum()
    left = np.ones(len(cloud), bool)
    found: list[Cluster] = []
    while len(found) < max_clusters and weights[left].sum() >= min_weight:
        cluster, members = dominant_cluster(
            cloud.poses[left], weights[left], radius_m=radius_m, heading_rad=heading_rad
        )
        if cluster.weight < min_weight:
            break
        found.append(cluster)
        left[np.flatnonzero(left)[members]] = False
    return found


@dataclass(frozen=True)
class PoseEstimate:
    """The dominant cluster's ``pose`` [x, y, theta], the ``share`` of the weight within the
    convergence bounds of it, and whether that makes the filter ``converged``."""

    pose: np.ndarray
    share: float
    converged: bool


def share_within(cloud: ParticleCloud, pose: np.ndarray, test: ConvergenceTest) -> float:
    """Share of the cloud's weight within ``test.radius_m`` and ``test.heading_rad`` of
    ``pose``."""
    near = _near(cloud.poses, pose, test.radius_m, test.heading_rad)
    return float(cloud.weights[near].sum() / cloud.weights.sum())


def estimate_pose(cloud: ParticleCloud, test: ConvergenceTest | None = None) -> PoseEstimate:
    """The pose estimate of ``cloud`` and its convergence (:class:`ConvergenceTest`)."""
    test = ConvergenceTest() if test is None else test
    cluster, _ = dominant_cluster(cloud.poses, cloud.weights / cloud.weights.sum())
    share = share_within(cloud, cluster.pose, test)
    return PoseEstimate(cluster.pose, share, share >= test.share)


__all__ = [
    "Cluster",
    "ConvergenceTest",
    "PoseEstimate",
    "clusters",
    "dominant_cluster",
    "estimate_pose",
    "share_within",
    "wrap",
]
