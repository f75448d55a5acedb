"""How far the simulated building departs from its plan: :class:`WorldOptions`."""

from __future__ import annotations

import argparse
import numbers
from dataclasses import asdict, dataclass

from f2n_drake.core.errors import InputError, finite_float, non_negative_int

MAX_CLUTTER_FRACTION = 0.5
"""Most of a room's floor furniture may cover (beyond it rooms are storerooms)."""
MAX_DEVIATION_M = 0.3
"""Largest wall displacement [m] (the warp stays one-to-one well beyond it)."""
MAX_PEOPLE = 50
MAX_CLOSED_DOORS = 50


@dataclass(frozen=True)
class WorldOptions:
    """What the building has that its plan lacks (metric).

    Attributes:
        clutter_fraction: share of each room's floor covered by furniture, 0 to 0.5.
        people: people walking between rooms, 0 to 50.
        closed_doors: doors of the plan closed in the building (the route's doors first).
        deviation_m: largest displacement of a wall face along its normal [m], 0 to 0.3.

    Raises:
        InputError: a value out of its range or not finite.
    """

    clutter_fraction: float = 0.0
    people: int = 0
    closed_doors: int = 0
    deviation_m: float = 0.0

    def __post_init__(self) -> None:
        checks = (
            ("clutter_fraction", self.clutter_fraction, 0.0, MAX_CLUTTER_FRACTION),
            ("people", self.people, 0, MAX_PEOPLE),
            ("closed_doors", self.closed_doors, 0, MAX_CLOSED_DOORS),
            ("deviation_m", self.deviation_m, 0.0, MAX_DEVIATION_M),
        )
        for name, value, low, high in checks:
            if isinstance(low, int) and (
                isinstance(value, bool) or not isinstance(value, numbers.Integral)
            ):
                raise InputError(f"world option {name} must be an integer, got {value!r}")
            if not low <= value <= high:  # NaN fails too
                raise InputError(f"world option {name} must be in [{low}, {high}], got {value}")

    @property
    def is_plan(self) -> bool:
        """Whether the building is exactly its plan (every option zero)."""
        return self == WorldOptions()

    def as_dict(self) -> dict:
        """The options as plain JSON-ready values."""
        return asdict(self)


def _bounded_int(high: int):
    """argparse ``type``: an integer in 0..``high``."""

    def parse(text: str) -> int:
        value = non_negative_int(text)
        if value > high:
            raise argparse.ArgumentTypeError(f"must be at most {high}, got {value}")
        return value

    parse.__name__ = "integer"
    return parse


def add_world_options(p: argparse.ArgumentParser) -> None:
    """``--clutter``, ``--people``, ``--closed-doors``, ``--deviation``: the simulated building
    differs from the plan (:class:`~f2n_drake.world.options.WorldOptions`)."""
    p.add_argument(
        "--clutter",
        type=finite_float(0.0, MAX_CLUTTER_FRACTION),
        default=0.0,
        metavar="FRACTION",
        help="furniture the plan does not show on this share of each room's floor [0]",
    )
    p.add_argument(
        "--people",
        type=_bounded_int(MAX_PEOPLE),
        default=0,
        metavar="N",
        help="people walking between rooms [0]",
    )
    p.add_argument(
        "--closed-doors",
        type=_bounded_int(MAX_CLOSED_DOORS),
        default=0,
        metavar="N",
        help="doors closed in the building, the route's first [0]",
    )
    p.add_argument(
        "--deviation",
        type=finite_float(0.0, MAX_DEVIATION_M),
        default=0.0,
        metavar="METRES",
        help="walls of the building displaced by up to this much from the plan [0]",
    )


def world_options_of(args: argparse.Namespace) -> WorldOptions:
    """The WorldOptions of parsed ``add_world_options`` arguments."""
    return WorldOptions(args.clutter, args.people, args.closed_doors, args.deviation)


__all__ = [
    "MAX_CLUTTER_FRACTION",
    "MAX_DEVIATION_M",
    "WorldOptions",
    "add_world_options",
    "world_options_of",
]
