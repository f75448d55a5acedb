"""Where to step aside when something the robot cannot get round keeps standing in its way.

A person waits for a robot ahead of them (a robot in a doorway keeps a person inside the room
beyond), and a robot waits for a person in its way: neither moves. Nav2's answer is a recovery
behaviour (back up, wait, try again). Straight back is often no help here: a person waiting
for the robot waits because the robot stands on their way, and that way runs on from them
through the robot (the robot came the way people walk: both go through the same door). So
:func:`retreat_point` picks a spot a short drive away, reachable in a straight line clear of
the plan's walls and of the obstacles seen, off the line from what holds the robot through the
robot, and far from what holds it.
"""

from __future__ import annotations

import math

import numpy as np

from f2n_drake.planning.costmap import WallDistance


def segment_clear(
    start_xy: np.ndarray,
    end_xy: np.ndarray,
    walls: WallDistance,
    obstacles_xy: np.ndarray,
    clearance_m: float,
    step_m: float = 0.05,
) -> bool:
    """Whether every point of the segment [m] keeps ``clearance_m`` [m] from the plan's walls
    and from the obstacle points ((N, 2) [m])."""
    length = float(np.hypot(*(np.asarray(end_xy) - start_xy)))
    t = np.linspace(0.0, 1.0, max(2, math.ceil(length / step_m) + 1))[1:]
    points = np.asarray(start_xy) + t[:, None] * (np.asarray(end_xy) - start_xy)
    if np.any(walls(points) < clearance_m):
        return False
    if not len(obstacles_xy):
        return True
    d2 = ((points[:, None, :] - obstacles_xy[None, :, :]) ** 2).sum(-1)
    return bool(d2.min() >= clearance_m * clearance_m)


def retreat_point(
    pose: np.ndarray,
    blockers_xy: np.ndarray,
    walls: WallDistance,
    obstacles_xy: np.ndarray,
    *,
    clearance_m: float,
    distances_m: tuple[float, ...] = (1.0, 0.8, 0.6, 0.4),
    directions: int = 16,
    away_weight: float = 0.5,
) -> np.ndarray | None:
    """A spot [m] to step aside to from ``pose`` [x, y, theta], or None if none is clear.

    Candidates lie ``distances_m`` away in ``directions`` directions; a candidate must be
    reachable in a straight line keeping ``clearance_m`` from the plan's walls and from
    ``obstacles_xy`` ((N, 2) [m], the costmap's obstacles). Among those, the one farthest from
    the line through the middle of ``blockers_xy`` ((M, 2) [m], what holds the robot) and the
    robot (the line the robot faces along when nothing holds it), plus ``away_weight`` times
    its distance from the nearest blocker, wins.
    """
    xy = np.asarray(pose[:2], float)
    blockers = np.asarray(blockers_xy, float).reshape(-1, 2)
    along = xy - blockers.mean(axis=0) if len(blockers) else np.zeros(2)
    if np.hypot(*along) < 1e-6:
        along = np.array([math.cos(pose[2]), math.sin(pose[2])])
    along = along / np.hypot(*along)
    normal = np.array([-along[1], along[0]])
    obstacles = np.asarray(obstacles_xy, float).reshape(-1, 2)
    if len(obstacles):  # those near enough to matter, less those already within reach
        reach = max(distances_m) + clearance_m  # (the robot is moving away from them)
        obstacles = obstacles[np.all(np.abs(obstacles - xy) <= reach, axis=1)]
        obstacles = obstacles[np.hypot(*(obstacles - xy).T) > clearance_m + 0.05]
    best, best_score = None, -math.inf
    angles = 2 * math.pi * np.arange(directions) / directions
    for distance in distances_m:
        for angle in angles:
            candidate = xy + distance * np.array([math.cos(angle), math.sin(angle)])
            if not segment_clear(xy, candidate, walls, obstacles, clearance_m):
                continue
            away = float(np.hypot(*(blockers - candidate).T).min()) if len(blockers) else 0.0
            score = abs(float((candidate - xy) @ normal)) + away_weight * away
            if score > best_score:
                best, best_score = candidate, score
        if best is not None:
            return best
    return None


__all__ = ["retreat_point", "segment_clear"]
