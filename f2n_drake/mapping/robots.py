"""Robot profiles: which connectors a robot may pass, how wide they must be, what they cost.

Two built-ins: ``GROUND`` (a TurtleBot3 Burger: doors, front doors and openings, never the
outside) and ``UAV`` (a small drone that may also fly through windows, off balconies and around
the outside). Others load from YAML: the ``RobotProfile`` fields, optionally ``base: ground|uav``
to start from a built-in.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import networkx as nx
import yaml

from f2n_drake.core.errors import InputError
from f2n_drake.mapping.graph import OUTSIDE


@dataclass(frozen=True)
class RobotProfile:
    """What a robot can traverse.

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
        max_speed_mps: cruise speed for simulation [m/s].
    """

    name: str
    traversable: frozenset[str]
    radius_m: float
    min_clear_width_m: float = 0.0
    cost_multipliers: dict[str, float] = field(default_factory=dict)
    narrow_penalty: float = 0.0
    clearance_margin_m: float = 0.05
    max_speed_mps: float = 0.22

    def __post_init__(self) -> None:
        for attr in ("radius_m", "min_clear_width_m", "narrow_penalty", "clearance_margin_m"):
            value = getattr(self, attr)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0):
                raise InputError(f"robot profile {self.name!r}: {attr} must be >= 0, got {value}")
        if not (isinstance(self.max_speed_mps, (int, float)) and self.max_speed_mps > 0):
            raise InputError(f"robot profile {self.name!r}: max_speed_mps must be > 0")
        for cls, factor in self.cost_multipliers.items():
            if not (isinstance(factor, (int, float)) and factor > 0):
                raise InputError(f"robot profile {self.name!r}: cost of {cls} must be > 0")

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


GROUND = RobotProfile(
    name="ground",
    traversable=frozenset({"door", "front_door", "opening"}),
    radius_m=0.105,  # TurtleBot3 Burger footprint
    clearance_margin_m=0.1,
    min_clear_width_m=0.3,
    narrow_penalty=0.5,
    max_speed_mps=0.22,
)
UAV = RobotProfile(
    name="uav",
    traversable=frozenset({"door", "front_door", "opening", "window", "balcony", OUTSIDE}),
    radius_m=0.2,
    clearance_margin_m=0.1,
    min_clear_width_m=0.5,
    cost_multipliers={"window": 2.0, OUTSIDE: 1.5},
    narrow_penalty=1.0,
    max_speed_mps=1.0,
)
PROFILES: dict[str, RobotProfile] = {GROUND.name: GROUND, UAV.name: UAV}

_FIELDS = {f.name for f in dataclasses.fields(RobotProfile)}


def load_profile(name_or_path: str | Path | RobotProfile) -> RobotProfile:
    """A built-in profile by name ("ground", "uav") or one read from a YAML file.

    Raises:
        InputError: unknown name, unreadable file, or a file that is not a valid profile.
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
    try:
        data = yaml.safe_load(path.read_text())
    except OSError as exc:
        raise InputError(f"cannot read robot profile {path}: {exc.strerror or exc}") from exc
    except UnicodeDecodeError:
        raise InputError(f"robot profile {path} is not a text file") from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(exc, "problem", None) or "not valid YAML"
        raise InputError(
            f"cannot read robot profile {path}: not valid YAML{where}: {problem}"
        ) from None
    if not isinstance(data, dict):
        raise InputError(f"robot profile {path} must be a YAML mapping")
    return profile_from_dict(data, default_name=path.stem)


def profile_from_dict(data: dict[str, Any], *, default_name: str = "custom") -> RobotProfile:
    """A profile from plain data (the YAML form); ``base`` names a built-in to start from."""
    data = dict(data)
    base_name = data.pop("base", None)
    unknown = set(data) - _FIELDS
    if unknown:
        raise InputError(f"robot profile has unknown fields: {sorted(unknown)}")
    if base_name is not None:
        if str(base_name).lower() not in PROFILES:
            raise InputError(f"robot profile base {base_name!r} is not one of {list(PROFILES)}")
        values: dict[str, Any] = dataclasses.asdict(PROFILES[str(base_name).lower()])
    else:
        values = {"name": default_name}
        if "traversable" not in data or "radius_m" not in data:
            raise InputError("robot profile needs 'traversable' and 'radius_m' (or a 'base')")
    values.update(data)
    try:
        trav = values["traversable"]
        if isinstance(trav, str) or not all(isinstance(t, str) for t in trav):
            raise TypeError("traversable must be a list of class names")
        values["traversable"] = frozenset(trav)
        values["cost_multipliers"] = {
            str(k): float(v) for k, v in dict(values.get("cost_multipliers") or {}).items()
        }
        for key in (
            "radius_m",
            "min_clear_width_m",
            "narrow_penalty",
            "clearance_margin_m",
            "max_speed_mps",
        ):
            if key in values:
                values[key] = float(values[key])
        values["name"] = str(values["name"])
    except (TypeError, ValueError) as exc:
        raise InputError(f"invalid robot profile: {exc}") from exc
    return RobotProfile(**values)


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
