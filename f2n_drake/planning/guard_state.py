"""What :class:`~f2n_drake.planning.route_guard.RouteGuard` keeps between scans and what it
answers each scan: plain frozen data, replaced, never modified, so a Drake state can hold it."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from f2n_drake.planning.route import Route


@dataclass(frozen=True)
class GuardState:
    """What the guard remembers between scans.

    ``counts``: the costmap; ``closed``: connectors found closed; ``door_streaks``: scans in a
    row each watched door looked closed; ``held_since_s``: when the current stop began (nan: not
    held); ``next_replan_s``: earliest obstacle replan; ``waiting``: the last replan was blocked
    by obstacles, ``blocked`` says how ("" when not); ``replans``: new routes taken;
    ``message``: why the robot gave up ("" while it has a route); ``since``: per costmap cell,
    since when [s] it is an obstacle (nan: not one); ``retreat``: while stepping aside, (x, y,
    started, arrived) [m, s] (arrived nan on the way); ``next_shortcut_s``: the next look for
    a clearly shorter route; ``why``: what holds the robot now ("" when nothing);
    ``stuck_since_s``: since when the robot is held, new routes or not (nan: not held).
    """

    counts: np.ndarray
    closed: frozenset[str] = frozenset()
    door_streaks: tuple[tuple[str, int], ...] = ()
    held_since_s: float = math.nan
    next_replan_s: float = 0.0
    waiting: bool = False
    replans: int = 0
    message: str = ""
    blocked: str = ""
    since: np.ndarray | None = None
    retreat: tuple[float, ...] = ()
    next_shortcut_s: float = 0.0
    why: str = ""
    stuck_since_s: float = math.nan

    def __deepcopy__(self, memo: dict) -> GuardState:
        return self  # immutable: replaced, never modified (Drake clones abstract state)


@dataclass(frozen=True)
class Decision:
    """The guard's answer to one scan: ``hold`` (no forward motion), a new ``route`` to take,
    ``stop`` (no route left: give up), the ``reasons`` of a replan attempt, and ``detour_xy``
    ((2, 2) [m], from here to a spot to step aside to; None when not)."""

    hold: bool = False
    route: Route | None = None
    stop: bool = False
    reasons: tuple[str, ...] = field(default_factory=tuple)
    detour_xy: np.ndarray | None = None


__all__ = ["Decision", "GuardState"]
