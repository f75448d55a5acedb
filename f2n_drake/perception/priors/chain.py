"""The apartment priors that follow the majority vote, in the order the parse applies them.

Each prior takes a ``ParsedPlan`` and returns it, or a copy with some instances re-classed:

1. ``front_doors``: one front door per apartment (``f2n_drake.perception.priors.front_doors``);
2. ``connector_sizes``: no door or window wider than one can be
(``f2n_drake.perception.priors.connector_sizes``);
3. ``balconies``: a balcony is open to the air (``f2n_drake.perception.priors.balconies``);
4. ``kitchens``: at most one kitchen, and one if there is none
(``f2n_drake.perception.priors.kitchens``);
5. ``sealed_rooms``: no group of rooms without a door
(``f2n_drake.perception.priors.sealed_rooms``).

``parse_drawing`` keeps the last stage; the evaluation keeps every stage, to count what each prior
changed, and runs the chain again with one prior switched off to measure it. One chain for both,
so a new prior is measured as it is used.
"""

from __future__ import annotations

from f2n_drake.core.parsed import ParsedPlan
from f2n_drake.perception.priors.balconies import close_balconies
from f2n_drake.perception.priors.connector_sizes import wall_off_oversized
from f2n_drake.perception.priors.front_doors import assign_front_doors
from f2n_drake.perception.priors.kitchens import assign_kitchens
from f2n_drake.perception.priors.sealed_rooms import open_sealed_rooms

PRIORS = ("front_doors", "connector_sizes", "balconies", "kitchens", "sealed_rooms")


def prior_stages(
    voted: ParsedPlan,
    *,
    front_doors: int | None = 1,
    connector_sizes: bool = True,
    balconies: bool = True,
    kitchens: int | None = 1,
    sealed_rooms: bool = True,
) -> dict[str, ParsedPlan]:
    """``voted`` after each prior in turn, keyed by the prior's name in ``PRIORS`` order.

    A prior switched off (None or False, as each argument of ``parse_drawing``) leaves its stage
    equal to the one before; the last stage is the parse.
    """
    stages = {}
    parsed = stages["front_doors"] = assign_front_doors(voted, front_doors)
    parsed = stages["connector_sizes"] = wall_off_oversized(parsed, connector_sizes)
    parsed = stages["balconies"] = close_balconies(parsed, balconies)
    parsed = stages["kitchens"] = assign_kitchens(parsed, kitchens)
    stages["sealed_rooms"] = open_sealed_rooms(parsed) if sealed_rooms else parsed
    return stages


def apply_priors(voted: ParsedPlan, **switches) -> ParsedPlan:
    """``voted`` after every prior (``prior_stages``' keyword arguments switch them)."""
    return prior_stages(voted, **switches)["sealed_rooms"]
