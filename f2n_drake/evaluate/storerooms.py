"""``python -m f2n_drake.evaluate storerooms``: can a drawing tell storerooms from bathrooms?

A storeroom renders as background (ResPlan's ``storage``), yet in a blank line drawing it is a
small room behind a door, exactly like a bathroom without a window. This measures, on ground
truth alone (no network, no drawing), how well a classifier that knows each small room's true
area, whether it has a window and which rooms its doors open from can tell the two apart. The
classifier is a lookup table fitted on training plans: each (window, rooms behind its doors, area
bin) cell takes its majority class, an unseen cell the majority overall (bathroom). It is then
scored on the evaluation plans. Its errors estimate what no segmenter can avoid with these cues;
the segmenter's own storeroom errors are in ``evaluate segmentation``'s instance confusion
(``background->bathroom``).
"""

from __future__ import annotations

import argparse
import json
from collections import Counter
from dataclasses import dataclass

from tqdm import tqdm

from f2n_drake.errors import InputError, non_negative_int
from f2n_drake.plan import FloorPlan
from f2n_drake.segmenter.dataset import TRAIN_SEED_BASE

SMALL_ROOM_CLASSES = ("bathroom", "storage")
_NEIGHBOUR_CLASSES = ("living", "bedroom", "bathroom", "kitchen", "balcony", "storage")
_TOUCH_M = 0.02  # a door or window within this distance of a room belongs to it [m]


@dataclass(frozen=True)
class SmallRoom:
    """What a drawing could show of a bathroom or storeroom: its class (the answer), area [m²],
    whether a window opens from it, and the classes of the rooms its doors lead to."""

    class_name: str
    area_m2: float
    window: bool
    behind_doors: tuple[str, ...]

    def cell(self, area_bin_m2: float) -> tuple[bool, tuple[str, ...], int]:
        return self.window, self.behind_doors, round(self.area_m2 / area_bin_m2)


def small_rooms(plan: FloorPlan) -> list[SmallRoom]:
    """The plan's bathrooms and storerooms with their ground-truth cues."""
    others = [(name, poly) for name in _NEIGHBOUR_CLASSES for poly in plan[name]]
    rooms = []
    for name in SMALL_ROOM_CLASSES:
        for room in plan[name]:
            behind = [
                other_name
                for door in plan["door"]
                if door.distance(room) < _TOUCH_M
                for other_name, other in others
                if other is not room and door.distance(other) < _TOUCH_M
            ]
            window = any(w.distance(room) < _TOUCH_M for w in plan["window"])
            rooms.append(SmallRoom(name, float(room.area), window, tuple(sorted(behind))))
    return rooms


def fit_lookup(rooms: list[SmallRoom], area_bin_m2: float) -> dict[tuple, str]:
    """Cell -> majority class of the ``rooms`` in it (ties: bathroom, the commoner class)."""
    votes: dict[tuple, Counter] = {}
    for room in rooms:
        votes.setdefault(room.cell(area_bin_m2), Counter())[room.class_name] += 1
    return {
        cell: max(SMALL_ROOM_CLASSES, key=lambda c: (count[c], c == "bathroom"))
        for cell, count in votes.items()
    }


def confusion(
    table: dict[tuple, str], rooms: list[SmallRoom], area_bin_m2: float
) -> Counter[tuple[str, str]]:
    """(true class, predicted class) counts of the lookup ``table`` on ``rooms``."""
    return Counter(
        (room.class_name, table.get(room.cell(area_bin_m2), "bathroom")) for room in rooms
    )


def _collect(seeds: range, desc: str, progress: bool) -> list[SmallRoom]:
    from f2n_drake.generator import generate_plan

    rooms: list[SmallRoom] = []
    for seed in tqdm(seeds, desc=desc, unit="plan", disable=not progress):
        rooms += small_rooms(generate_plan(seed))
    return rooms


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m f2n_drake.evaluate storerooms", description=__doc__.splitlines()[0]
    )
    parser.add_argument("--train", type=non_negative_int, default=2500, help="training plans")
    parser.add_argument("--synthetic", type=int, default=500, help="evaluation plans")
    parser.add_argument("--seed", type=non_negative_int, default=0, help="first evaluation seed")
    parser.add_argument("--area-bin", type=float, default=0.5, help="area bin of the table [m²]")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    args = parser.parse_args(argv)
    if args.synthetic < 1 or args.seed + args.synthetic > 1_000_000:
        raise InputError("evaluation seeds must lie in 0..999999 (training uses >= 1000000)")
    if not args.area_bin > 0:
        raise InputError(f"--area-bin must be positive, got {args.area_bin}")
    progress = not args.json
    train = _collect(range(TRAIN_SEED_BASE, TRAIN_SEED_BASE + args.train), "fit", progress)
    test = _collect(range(args.seed, args.seed + args.synthetic), "score", progress)
    counts = confusion(fit_lookup(train, args.area_bin), test, args.area_bin)
    truth = Counter(room.class_name for room in test)
    wrong = {f"{t}->{p}": n for (t, p), n in sorted(counts.items()) if t != p}
    report = {
        "n_train_plans": args.train,
        "n_images": args.synthetic,
        "seed": args.seed,
        "area_bin_m2": args.area_bin,
        "rooms": dict(sorted(truth.items())),
        "lookup_errors": wrong,
        "lookup_wrong": sum(wrong.values()),
        "always_bathroom_wrong": truth["storage"],
    }
    if args.json:
        print(json.dumps(report))
        return 0
    print(
        f"{args.synthetic} evaluation plans (seeds {args.seed}..{args.seed + args.synthetic - 1}): "
        f"{truth['bathroom']} bathrooms, {truth['storage']} storerooms"
    )
    print(
        f"  lookup table (window, rooms behind the doors, area in {args.area_bin:g} m² bins; "
        f"fitted on {args.train} training plans): {report['lookup_wrong']} wrong {wrong}"
    )
    print(f"  calling every small room a bathroom: {truth['storage']} wrong")
    return 0
