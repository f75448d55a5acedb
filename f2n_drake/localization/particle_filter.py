"""Monte Carlo localization: where on the plan is a robot that does not know where it started?

A particle filter over poses ``[x, y, theta]`` [m, m, rad] (Dellaert, Fox, Burgard and Thrun,
"Monte Carlo Localization for Mobile Robots", ICRA 1999; Thrun, Burgard and Fox, *Probabilistic
Robotics*, 2005, chapter 8):

- :func:`uniform_cloud`: particles spread uniformly over the plan's free space, all headings, or
  mostly the few headings that align the scan's walls with the plan's
  (:mod:`f2n_drake.localization.heading_prior`);
- :func:`predict`: each particle moved by the odometry increment (robot frame), with noise;
- :func:`weigh`: weights multiplied by the likelihood of a subsample of the scan's returns
  (:class:`~f2n_drake.localization.likelihood_field.LikelihoodField`; returns with no echo are
  skipped; particles off the free space get none). Two beam models, annealed: a ``coarse`` one
  (wide Gaussian) for the first ``coarse_steps`` steps, so that a hypothesis the first cloud
  sampled only roughly (a few centimetres and degrees off) survives beside a rival sampled
  closer to its own optimum while both settle, then a ``fine`` one that tells apart rooms
  differing by a few centimetres;
- :func:`resample`: low-variance resampling when the effective sample size falls below a share
  of the particles, down to the working size after the large first cloud;
- :func:`step`: the three in a row, run only once the robot has moved enough since the last
  one (:func:`moved_enough`, as AMCL's ``update_min_d`` / ``update_min_a``: scans taken from the
  same place are not independent evidence, and weighing each would let a rival hypothesis win
  by repetition); :mod:`f2n_drake.localization.particle_clusters` reads the estimate and
  decides convergence.

Everything is vectorised numpy; randomness comes from a ``numpy.random.Generator`` passed in.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from f2n_drake.localization.likelihood_field import BeamModel, LikelihoodField
from f2n_drake.localization.scans import beam_angles


@dataclass(frozen=True)
class FilterOptions:
    """Tuning of the particle filter.

    Attributes:
        num_particles: particles kept after the first resampling.
        initial_per_m2: particles per m^2 of free space in the first cloud (all headings).
        initial_min, initial_max: bounds on the size of the first cloud.
        heading_prior_share, heading_prior_sigma_rad: with heading hypotheses, the share of the
            first cloud drawn around them and their spread [rad] (the rest: any heading).
        beams: returns used per scan (evenly spaced, shifted each scan).
        coarse, fine: the beam models of the first ``coarse_steps`` steps and of the others.
        min_range_m, max_range_m: the LiDAR's valid range [m].
        exponent: each scan's log-likelihood is multiplied by this (< 1 tempers the model for
            returns that are not independent, keeping rival hypotheses alive longer).
        xy_sigma_m: position noise added per prediction [m] (covers the odometry noise).
        xy_sigma_per_m: position noise per metre travelled [m/m].
        theta_sigma_rad, theta_sigma_per_rad: heading noise per prediction [rad] and per
            radian turned [rad/rad].
        resample_below: resample when the effective sample size falls below this share.
        update_min_m, update_min_rad: the motion since the last step [m, rad] that makes the
            next one (:func:`moved_enough`).
    """

    num_particles: int = 3000
    initial_per_m2: float = 2000.0
    initial_min: int = 20_000
    initial_max: int = 200_000
    heading_prior_share: float = 0.8
    heading_prior_sigma_rad: float = 0.02
    beams: int = 40
    coarse: BeamModel = BeamModel(sigma_hit_m=0.25)
    fine: BeamModel = BeamModel(sigma_hit_m=0.1)
    coarse_steps: int = 1
    min_range_m: float = 0.12
    max_range_m: float = 3.5
    exponent: float = 0.5
    xy_sigma_m: float = 0.03
    xy_sigma_per_m: float = 0.1
    theta_sigma_rad: float = 0.01
    theta_sigma_per_rad: float = 0.05
    resample_below: float = 0.5
    update_min_m: float = 0.05
    update_min_rad: float = 0.1


@dataclass(frozen=True)
class ParticleCloud:
    """Particles ``poses`` (N, 3) [m, m, rad] and their normalised ``weights`` (N,)."""

    poses: np.ndarray
    weights: np.ndarray

    def __len__(self) -> int:
        return len(self.weights)

    @property
    def effective_size(self) -> float:
        """Effective sample size 1 / sum(w^2)."""
        return float(1.0 / np.sum(self.weights**2))


def uniform_cloud(
    field: LikelihoodField,
    options: FilterOptions,
    rng: np.random.Generator,
    headings: np.ndarray | None = None,
) -> ParticleCloud:
    """Particles uniform over the free space (``initial_per_m2``, within the bounds) and
    headings, equally weighted; with ``headings`` [rad] (hypotheses, e.g. from
    :func:`~f2n_drake.localization.heading_prior.heading_hypotheses`) a share
    ``heading_prior_share`` of them is drawn around those instead."""
    n = options.initial_per_m2 * field.free_area_m2
    n = int(np.clip(n, options.initial_min, options.initial_max))
    xy = field.sample_free(n, rng)
    theta = rng.uniform(-np.pi, np.pi, n)
    if headings is not None and len(headings):
        prior = rng.random(n) < options.heading_prior_share
        picked = rng.choice(np.asarray(headings, dtype=float), int(prior.sum()))
        theta[prior] = picked + options.heading_prior_sigma_rad * rng.standard_normal(len(picked))
        theta = (theta + np.pi) % (2.0 * np.pi) - np.pi
    return ParticleCloud(np.column_stack([xy, theta]), np.full(n, 1.0 / n))


def relative_motion(previous: np.ndarray, current: np.ndarray) -> np.ndarray:
    """Odometry increment ``[forward, left, dtheta]`` [m, m, rad] from pose ``previous`` to
    ``current``, in the frame of ``previous``."""
    c, s = np.cos(previous[2]), np.sin(previous[2])
    dx, dy = current[0] - previous[0], current[1] - previous[1]
    dtheta = (current[2] - previous[2] + np.pi) % (2.0 * np.pi) - np.pi
    return np.array([c * dx + s * dy, -s * dx + c * dy, dtheta])


def moved_enough(motion: np.ndarray, options: FilterOptions) -> bool:
    """Whether the odometry increment ``motion`` [forward, left, dtheta] calls for a step."""
    return bool(
        np.hypot(motion[0], motion[1]) >= options.update_min_m
        or abs(motion[2]) >= options.update_min_rad
    )


def predict(
    cloud: ParticleCloud,
    motion: np.ndarray,
    options: FilterOptions,
    rng: np.random.Generator,
) -> ParticleCloud:
    """Every particle moved by ``motion`` ([forward, left, dtheta], its own frame) plus
    Gaussian noise growing with the distance and angle (``FilterOptions``)."""
    forward, left, dtheta = motion
    n = len(cloud)
    xy_sigma = options.xy_sigma_m + options.xy_sigma_per_m * float(np.hypot(forward, left))
    theta_sigma = options.theta_sigma_rad + options.theta_sigma_per_rad * abs(float(dtheta))
    noise = rng.standard_normal((n, 3))
    x, y, theta = cloud.poses.T
    c, s = np.cos(theta), np.sin(theta)
    moved = np.column_stack(
        [
            x + c * forward - s * left + xy_sigma * noise[:, 0],
            y + s * forward + c * left + xy_sigma * noise[:, 1],
            theta + dtheta + theta_sigma * noise[:, 2],
        ]
    )
    moved[:, 2] = (moved[:, 2] + np.pi) % (2.0 * np.pi) - np.pi
    return ParticleCloud(moved, cloud.weights)


def beam_subset(scan: np.ndarray, options: FilterOptions, shift: int = 0) -> np.ndarray:
    """Robot-frame end points (K, 2) [m] of about ``options.beams`` returns evenly spaced among
    the scan's valid ones (out of range, no echo: skipped), starting ``shift`` returns in."""
    scan = np.asarray(scan, dtype=float)
    valid = np.flatnonzero(
        np.isfinite(scan) & (scan >= options.min_range_m) & (scan <= options.max_range_m)
    )
    stride = max(1, len(valid) // max(1, options.beams))
    index = valid[shift % stride :: stride]
    angles = beam_angles(len(scan))[index]
    return np.column_stack([scan[index] * np.cos(angles), scan[index] * np.sin(angles)])


def scan_log_likelihood(
    poses: np.ndarray, points_robot: np.ndarray, field: LikelihoodField, model: BeamModel
) -> np.ndarray:
    """Sum over the returns ``points_robot`` (K, 2) of their log-likelihood seen from each pose
    (N, 3): (N,)."""
    if len(points_robot) == 0:
        return np.zeros(len(poses))
    return field.scan_log_likelihood(poses, points_robot, model)


def weigh(
    cloud: ParticleCloud,
    scan: np.ndarray,
    field: LikelihoodField,
    options: FilterOptions,
    model: BeamModel,
    shift: int = 0,
) -> tuple[ParticleCloud, float]:
    """The cloud reweighted by ``scan`` under ``model`` (and by the free space: a particle off
    it weighs 0),
    and the mean per-return log-likelihood of the weighted particles (how well the scan fits
    where the filter believes the robot is)."""
    points = beam_subset(scan, options, shift)
    log_l = scan_log_likelihood(cloud.poses, points, field, model)
    log_w = np.log(np.maximum(cloud.weights, 1e-300)) + options.exponent * log_l
    log_w[~field.is_free(cloud.poses[:, :2])] = -np.inf
    if not np.isfinite(log_w).any():  # every particle off the map: start again from the prior
        log_w = np.zeros(len(cloud))
    weights = np.exp(log_w - np.max(log_w))
    weights /= weights.sum()
    fit = float(weights @ log_l) / max(1, len(points))
    return ParticleCloud(cloud.poses, weights), fit


def resample(cloud: ParticleCloud, n: int, rng: np.random.Generator) -> ParticleCloud:
    """``n`` particles drawn by low-variance (systematic) resampling, equally weighted
    (*Probabilistic Robotics*, table 4.4)."""
    positions = (rng.random() + np.arange(n)) / n
    cumulative = np.cumsum(cloud.weights)
    cumulative[-1] = 1.0
    index = np.searchsorted(cumulative, positions, side="right")
    index = np.minimum(index, len(cloud) - 1)
    return ParticleCloud(cloud.poses[index].copy(), np.full(n, 1.0 / n))


def step(
    cloud: ParticleCloud,
    motion: np.ndarray,
    scan: np.ndarray,
    field: LikelihoodField,
    options: FilterOptions,
    rng: np.random.Generator,
    index: int = 0,
) -> tuple[ParticleCloud, float]:
    """Step ``index`` (0 for the first): predict with ``motion``, weigh with ``scan`` (the
    coarse model for the first ``coarse_steps`` steps, then the fine one; the subsample of
    returns shifts with ``index``), and resample (to ``num_particles``) when the effective
    sample size is low or the cloud is larger than the working size. Returns the cloud and the
    scan's fit (:func:`weigh`)."""
    cloud = predict(cloud, motion, options, rng)
    model = options.coarse if index < options.coarse_steps else options.fine
    cloud, fit = weigh(cloud, scan, field, options, model, index)
    n = options.num_particles
    if len(cloud) != n or cloud.effective_size < options.resample_below * n:
        cloud = resample(cloud, n, rng)
    return cloud, fit


__all__ = [
    "FilterOptions",
    "ParticleCloud",
    "beam_subset",
    "moved_enough",
    "predict",
    "relative_motion",
    "resample",
    "scan_log_likelihood",
    "step",
    "uniform_cloud",
    "weigh",
]
