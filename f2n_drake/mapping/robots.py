"""Robots: one description per robot (``models/*.yaml``), and the planner's view of it.

A :class:`RobotDescription` is the typed form of a robot's YAML file (loaded with Drake's
``yaml_load_typed``): its body, which connectors it may pass and at what cost, and, for a robot
that is simulated, its velocity limits and LiDAR. The planner reads it as a :class:`RobotProfile`;
the Drake plant, LiDAR and controller (``f2n_drake.systems``) read the description itself.

Two robots ship: ``GROUND`` (``models/turtlebot3_burger.yaml``, a TurtleBot3 Burger: doors, front
doors and openings, never the outside) and ``UAV`` (``models/uav.yaml``, a small drone that may
also fly through windows, off balconies and around the outside). ``--robot PATH`` reads another
file of the same form. (No ``from __future__ import annotations`` here: ``yaml_load_typed`` reads
the dataclass field types.)
"""

import copy
import math
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path

import networkx as nx

from f2n_drake.core.classes import CONNECTOR_CLASSES, OPENING
from f2n_drake.core.errors import F2NError, InputError
from f2n_drake.mapping.graph import OUTSIDE
from f2n_drake.models import model_path


@dataclass
class Body:
    """radius_m: footprint radius [m]; height_m: height of the simulated body [m] (only a
    simulated robot needs it)."""

    radius_m: float = 0.0
    height_m: float | None = None


@dataclass
class Navigation:
    """What the robot may traverse and what it costs (the :class:`RobotProfile` fields)."""

    traversable: list[str] = field(default_factory=list)
    clearance_margin_m: float = 0.05
    min_clear_width_m: float = 0.0
    narrow_penalty: float = 0.0
    cost_multipliers: dict[str, float] = field(default_factory=dict)


@dataclass
class VelocityLimits:
    """Velocity limits of a simulated robot [m/s, rad/s]."""

    max_linear_velocity_mps: float = 0.0
    max_angular_velocity_radps: float = 0.0


@dataclass
class LidarSpec:
    """A planar LiDAR: range [m], beams per turn, scans per second [Hz]."""

    min_range_m: float = 0.0
    max_range_m: float = 0.0
    num_beams: int = 0
    rate_hz: float = 0.0


@dataclass
class RobotDescription:
    """One robot, as its YAML file describes it (SI units). ``limits`` and ``lidar`` are needed
    only to simulate it; ``base`` names a shipped robot whose values the file starts from."""

    name: str = ""
    base: str = ""
    body: Body = field(default_factory=Body)
    navigation: Navigation = field(default_factory=Navigation)
    limits: VelocityLimits | None = None
    lidar: LidarSpec | None = None


TRAVERSABLE = (*CONNECTOR_CLASSES, OPENING, "balcony", OUTSIDE)
"""What a robot may be allowed to traverse (``navigation.traversable``, see ``RobotProfile``)."""

ROBOT_FILES = {"ground": "turtlebot3_burger.yaml", "uav": "uav.yaml"}
"""The shipped robots: name -> description file in ``models/``."""


def load_robot(path: str | Path) -> RobotDescription:
    """The description in a robot YAML file: the values it gives, on top of those of its
    ``base`` robot when it names one (``ROBOT_FILES``), else of the dataclass defaults. A file
    with neither ``name`` nor ``base`` is named after itself.

    Raises:
        InputError: unreadable file, unknown fields or base, wrong types, no ``body.radius_m``, or a
            ``navigation.traversable`` naming something else than ``TRAVERSABLE``.
    """
    import yaml
    from pydrake.common.yaml import yaml_load_typed

    path = Path(path)
    try:
        yaml.safe_load(path.read_text())
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read robot description {path}: {exc}") from exc
    except yaml.YAMLError as exc:  # said in one line, where Drake's reader says it in seven
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(exc, "problem", None) or "unreadable"
        raise InputError(
            f"cannot read robot description {path}: not valid YAML{where}: {problem}"
        ) from None
    try:
        robot = yaml_load_typed(schema=RobotDescription, filename=str(path))
        if robot.base:
            base = copy.deepcopy(shipped_robot(robot.base))
            robot = yaml_load_typed(filename=str(path), defaults=base)
    except F2NError:
        raise
    except Exception as exc:  # yaml_load_typed raises RuntimeError, TypeError, yaml errors
        raise InputError(f"cannot read robot description {path}: {exc}") from exc
    if not (isinstance(robot.body.radius_m, float) and robot.body.radius_m > 0):
        raise InputError(f"robot description {path} needs body.radius_m > 0")
    unknown = sorted(set(robot.navigation.traversable) - set(TRAVERSABLE))
    if unknown:
        raise InputError(
            f"robot description {path}: navigation.traversable must list some of "
            f"{', '.join(TRAVERSABLE)}, not {unknown}"
        )
    robot.name = robot.name or path.stem
    return robot


@cache
def shipped_robot(name: str) -> RobotDescription:
    """A shipped robot's description by name (``ROBOT_FILES``); raises InputError if unknown."""
    if name not in ROBOT_FILES:
        raise InputError(f"unknown robot {name!r} (use {', '.join(ROBOT_FILES)} or a YAML file)")
    return load_robot(model_path(ROBOT_FILES[name]))


@dataclass(frozen=True)
class RobotProfile:
    """What a robot can traverse: the planner's view of a :class:`RobotDescription`.

    Attributes:
        name: profile name.
        traversable: connector classes it may pass ("door", "front_door", "opening", "window"),
            plus "outside" (may use the outside node) and "balcony" (may fly off a balcony: the
            open-air balcony-outside edge). Spaces are always traversable.
        radius_m: body radius [m].
        min_clear_width_m: narrowest connector it will pass, before the body check [m].
        cost_multipliers: class -> factor on the cost of passing that connector (default 1).
        narrow_penalty: extra cost factor for a connector exactly ``required_width_m`` wide,
            falling linearly to 0 at twice that width (see ``connector_factor``).
        clearance_margin_m: free space kept beside the body [m]: grid planning inflates walls by
            ``radius_m + clearance_margin_m``, and connectors need twice that clear width.
    """

    name: str
    traversable: frozenset[str]
    radius_m: float
    min_clear_width_m: float = 0.0
    cost_multipliers: dict[str, float] = field(default_factory=dict)
    narrow_penalty: float = 0.0
    clearance_margin_m: float = 0.05

    def __post_init__(self) -> None:
        for attr in ("radius_m", "min_clear_width_m", "narrow_penalty", "clearance_margin_m"):
            value = getattr(self, attr)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0):
                raise InputError(f"robot profile {self.name!r}: {attr} must be >= 0, got {value}")
        for cls, factor in self.cost_multipliers.items():
            if not (isinstance(factor, (int, float)) and factor > 0):
                raise InputError(f"robot profile {self.name!r}: cost of {cls} must be > 0")

    @classmethod
    def from_description(cls, robot: RobotDescription) -> "RobotProfile":
        """The profile of a robot description."""
        nav = robot.navigation
        return cls(
            name=robot.name,
            traversable=frozenset(nav.traversable),
            radius_m=robot.body.radius_m,
            min_clear_width_m=nav.min_clear_width_m,
            cost_multipliers=dict(nav.cost_multipliers),
            narrow_penalty=nav.narrow_penalty,
            clearance_margin_m=nav.clearance_margin_m,
        )

    @property
    def required_width_m(self) -> float:
        """Narrowest connector this robot passes [m]: max(min clear width, body + margins)."""
        return max(self.min_clear_width_m, 2 * self.radius_m + 2 * self.clearance_margin_m)

    def can_pass(self, class_name: str, width_m: float | None) -> bool:
        """Whether a connector of this class and clear width (None: unknown, assumed fine) is
        usable."""
        if class_name not in self.traversable:
            return False
        return width_m is None or width_m >= self.required_width_m

    def connector_factor(self, class_name: str, width_m: float | None) -> float:
        """Factor (>= the class multiplier) on the cost of passing a connector."""
        factor = self.cost_multipliers.get(class_name, 1.0)
        if width_m is None or self.narrow_penalty == 0:
            return factor
        required = self.required_width_m
        slack = min(max((width_m - required) / max(required, 1e-9), 0.0), 1.0)
        return factor * (1.0 + self.narrow_penalty * (1.0 - slack))


GROUND = RobotProfile.from_description(shipped_robot("ground"))
UAV = RobotProfile.from_description(shipped_robot("uav"))
PROFILES: dict[str, RobotProfile] = {GROUND.name: GROUND, UAV.name: UAV}


def load_profile(name_or_path: str | Path | RobotProfile) -> RobotProfile:
    """A shipped robot's profile by name ("ground", "uav") or one read from a robot YAML file
    (the form of ``models/turtlebot3_burger.yaml``).

    Raises:
        InputError: unknown name, unreadable file, or a file that is not a valid description.
    """
    if isinstance(name_or_path, RobotProfile):
        return name_or_path
    key = str(name_or_path).strip().lower()
    if key in PROFILES:
        return PROFILES[key]
    path = Path(name_or_path)
    if not path.is_file():
        if path.suffix.lower() in (".yaml", ".yml") or len(path.parts) > 1:
            raise InputError(f"robot profile file not found: {path}")
        raise InputError(
            f"unknown robot profile {str(name_or_path)!r} "
            f"(use {', '.join(PROFILES)} or a YAML file)"
        )
    return RobotProfile.from_description(load_robot(path))


def traversable_subgraph(graph: nx.Graph, profile: RobotProfile) -> nx.Graph:
    """A copy of the connectivity graph keeping what ``profile`` can use.

    Drops connectors of classes it cannot pass or narrower than ``profile.required_width_m``
    (unknown widths are kept), the ``outside`` node unless "outside" is traversable, and the
    open-air balcony-outside edges unless "balcony" is. Sets graph attribute ``robot``.
    """
    sub = graph.copy()
    drop = [
        n
        for n, d in sub.nodes(data=True)
        if d.get("kind") == "connector" and not profile.can_pass(d["class_name"], d.get("width_m"))
    ]
    if OUTSIDE not in profile.traversable:
        drop.append(OUTSIDE)
    sub.remove_nodes_from([n for n in drop if n in sub])
    if "balcony" not in profile.traversable:
        sub.remove_edges_from([(u, v) for u, v, d in sub.edges(data=True) if d.get("open_air")])
    sub.graph["robot"] = profile.name
    return sub
