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

A flat's room counts are a further cue: the generator gives a one-bedroom flat one bathroom, and
at most one storeroom to any flat. The second classifier labels a flat's small rooms together,
the labelling that best fits both the table's cells and how often training flats with as many
bedrooms had that many bathrooms and storerooms. ``--resplan`` shows how real flats' counts fall
in that training distribution.

:func:`vote_storerooms` is the same question asked of the segmenter: its mean background
probability over a small room is a cue too (``evaluate segmentation --storerooms P`` measures a
threshold; the parse does not use it, as it drops real bathrooms from the graph).
"""

from __future__ import annotations

import argparse
import dataclasses
import itertools
import json
import math
from collections import Counter
from dataclasses import dataclass

import numpy as np
from tqdm import tqdm

from f2n_drake.core.classes import CLASS_ID
from f2n_drake.core.errors import InputError, non_negative_int
from f2n_drake.core.parsed import ParsedPlan
from f2n_drake.core.plan import FloorPlan
from f2n_drake.evaluate.drawings import resplan_plans
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


def vote_storerooms(parsed: ParsedPlan, min_background: float) -> ParsedPlan:
    """``parsed`` with every bathroom whose background evidence (mean probability, else vote
    share) exceeds ``min_background`` voted background: left out, as the parse leaves out any
    region voted background (a storeroom is background in the ground truth). An experiment of
    the evaluation, not a prior of the parse."""
    background = CLASS_ID["background"]
    dropped = [
        i.id
        for i in parsed.instances
        if i.class_name == "bathroom" and i.evidence(background) > min_background
    ]
    if not dropped:
        return parsed
    instance_ids = np.where(np.isin(parsed.instance_ids, dropped), 0, parsed.instance_ids)
    return dataclasses.replace(
        parsed,
        instance_ids=instance_ids.astype(np.int32),
        instances=[i for i in parsed.instances if i.id not in dropped],
    )


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


@dataclass(frozen=True)
class Flat:
    """What a drawing could show of a flat's rooms: its bedroom count and its small rooms."""

    n_bedrooms: int
    small_rooms: tuple[SmallRoom, ...]

    @classmethod
    def of(cls, plan: FloorPlan) -> Flat:
        return cls(len(plan["bedroom"]), tuple(small_rooms(plan)))

    def counts(self, labels: tuple[str, ...] | None = None) -> tuple[int, int, int]:
        """(bedrooms, bathrooms, storerooms), of the true classes or of ``labels``."""
        labels = labels or tuple(room.class_name for room in self.small_rooms)
        return self.n_bedrooms, labels.count("bathroom"), labels.count("storage")


@dataclass(frozen=True)
class CountsModel:
    """How often training flats had each (bedrooms, bathrooms, storerooms) count, and how often
    each class's small rooms fell in each lookup cell."""

    flats: Counter[tuple[int, int, int]]
    cells: dict[str, Counter[tuple]]
    area_bin_m2: float
    smoothing: float = 0.1

    @classmethod
    def fit(cls, flats: list[Flat], area_bin_m2: float) -> CountsModel:
        cells: dict[str, Counter[tuple]] = {c: Counter() for c in SMALL_ROOM_CLASSES}
        for flat in flats:
            for room in flat.small_rooms:
                cells[room.class_name][room.cell(area_bin_m2)] += 1
        return cls(Counter(flat.counts() for flat in flats), cells, area_bin_m2)

    def log_likelihood(self, room: SmallRoom, class_name: str) -> float:
        n_cells = len(set().union(*self.cells.values()))
        seen = self.cells[class_name]
        hits = seen[room.cell(self.area_bin_m2)] + self.smoothing
        return math.log(hits / (seen.total() + self.smoothing * n_cells))

    def label(self, flat: Flat) -> tuple[str, ...]:
        """The small rooms' most likely classes, given the flat's counts (an unseen count is
        unlikely, not impossible)."""

        def score(labels: tuple[str, ...]) -> float:
            prior = self.flats[flat.counts(labels)] + 0.01 * self.smoothing
            return math.log(prior) + sum(
                self.log_likelihood(room, c)
                for room, c in zip(flat.small_rooms, labels, strict=True)
            )

        choices = itertools.product(SMALL_ROOM_CLASSES, repeat=len(flat.small_rooms))
        return max(choices, key=score)


def _collect(seeds: range, desc: str, progress: bool) -> list[Flat]:
    from f2n_drake.datasets.generator import generate_plan

    return [
        Flat.of(generate_plan(seed))
        for seed in tqdm(seeds, desc=desc, unit="plan", disable=not progress)
    ]


def _errors(counts: Counter[tuple[str, str]]) -> dict[str, int]:
    return {f"{t}->{p}": n for (t, p), n in sorted(counts.items()) if t != p}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m f2n_drake.evaluate storerooms", description=__doc__.splitlines()[0]
    )
    parser.add_argument("--train", type=non_negative_int, default=2500, help="training plans")
    parser.add_argument("--synthetic", type=int, default=500, help="evaluation plans")
    parser.add_argument("--seed", type=non_negative_int, default=0, help="first evaluation seed")
    parser.add_argument("--area-bin", type=float, default=0.5, help="area bin of the table [m²]")
    parser.add_argument(
        "--resplan", metavar="FILE.pkl", help="also show these real flats' room counts"
    )
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    args = parser.parse_args(argv)
    if args.synthetic < 1 or args.seed + args.synthetic > 1_000_000:
        raise InputError("evaluation seeds must lie in 0..999999 (training uses >= 1000000)")
    if not args.area_bin > 0:
        raise InputError(f"--area-bin must be positive, got {args.area_bin}")
    real = resplan_plans(args.resplan) if args.resplan else []
    progress = not args.json
    train = _collect(range(TRAIN_SEED_BASE, TRAIN_SEED_BASE + args.train), "fit", progress)
    test = _collect(range(args.seed, args.seed + args.synthetic), "score", progress)
    test_rooms = [room for flat in test for room in flat.small_rooms]
    table = fit_lookup([room for flat in train for room in flat.small_rooms], args.area_bin)
    wrong = _errors(confusion(table, test_rooms, args.area_bin))
    model = CountsModel.fit(train, args.area_bin)
    with_counts = _errors(
        Counter(
            (room.class_name, label)
            for flat in test
            for room, label in zip(flat.small_rooms, model.label(flat), strict=True)
        )
    )
    truth = Counter(room.class_name for room in test_rooms)
    report = {
        "n_train_plans": args.train,
        "n_images": args.synthetic,
        "seed": args.seed,
        "area_bin_m2": args.area_bin,
        "rooms": dict(sorted(truth.items())),
        "lookup_errors": wrong,
        "lookup_wrong": sum(wrong.values()),
        "with_counts_errors": with_counts,
        "with_counts_wrong": sum(with_counts.values()),
        "always_bathroom_wrong": truth["storage"],
        "real_flats": [
            {
                "name": name,
                "counts": flat.counts(),
                "training_flats_alike": model.flats[flat.counts()],
            }
            for name, flat in ((name, Flat.of(plan)) for name, plan in real)
        ],
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
    print(
        f"  the same with the flat's bedroom, bathroom and storeroom counts: "
        f"{report['with_counts_wrong']} wrong {with_counts}"
    )
    print(f"  calling every small room a bathroom: {truth['storage']} wrong")
    for flat in report["real_flats"]:
        bedrooms, bathrooms, storerooms = flat["counts"]
        print(
            f"  {flat['name']}: {bedrooms} bedrooms, {bathrooms} bathrooms, {storerooms} "
            f"storerooms; training flats alike: {flat['training_flats_alike']} of {args.train}"
        )
    return 0
