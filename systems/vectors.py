"""Named views of the vectors the navigation systems exchange (``namedview``), so a port's value
is read by name (``CollisionStatus(port.Eval(context)).collided``), never by index.

Each view wraps a numpy vector without copying; ``View(vector)[:]`` is the vector again.
"""

from __future__ import annotations

from pydrake.common.containers import namedview

Pose = namedview("Pose", ["x", "y", "theta"])
"""A planar pose X_WR [m, m, rad] of the robot R in the world W."""

Command = namedview("Command", ["v", "omega"])
"""A unicycle command [m/s, rad/s]."""

Progress = namedview("Progress", ["waypoint_index", "done"])
"""Route progress: index of the waypoint targeted, done (0/1)."""

Segment = namedview("Segment", ["x0", "y0", "x1", "y1"])
"""The segment followed: from the previous waypoint to the end of the target's leg [m]."""

CollisionStatus = namedview("CollisionStatus", ["collided", "min_clearance_m", "count"])
"""Collided at the last sample (0/1), smallest signed distance so far [m], samples in collision."""

PersonCollisions = namedview("PersonCollisions", ["in_contact", "min_clearance_m", "contacts"])
"""Robot touching a person at the last sample (0/1), smallest signed distance to a person so far
[m], contacts so far (each run of samples in contact counts once)."""

PoseCorrection = namedview("PoseCorrection", ["count", "x", "y", "theta"])
"""Corrections made so far, and the last corrected pose [m, m, rad]."""

FitQuality = namedview("FitQuality", ["inlier_ratio", "rms_m"])
"""How well the last scan fitted the walls: share of matched points, their RMS distance [m]."""

NavigationStatus = namedview("NavigationStatus", ["replans", "no_route", "closed_doors", "hold"])
"""Navigator status: replans so far, no route left (0/1), doors found closed, holding (0/1)."""

__all__ = [
    "CollisionStatus",
    "Command",
    "FitQuality",
    "NavigationStatus",
    "PersonCollisions",
    "Pose",
    "PoseCorrection",
    "Progress",
    "Segment",
]
