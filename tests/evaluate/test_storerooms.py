"""The storeroom/bathroom separability measurement: cues from a hand-made plan, the lookup table
on hand-made rooms with known answers, the CLI's JSON and its argument errors."""

import json

import numpy as np
from shapely.geometry import box

from f2n_drake.core.classes import CLASS_ID
from f2n_drake.core.parsed import Instance, ParsedPlan
from f2n_drake.core.paths import resplan_sample_path
from f2n_drake.core.plan import FloorPlan
from f2n_drake.evaluate.__main__ import main as evaluate_main
from f2n_drake.evaluate.storerooms import (
    CountsModel,
    Flat,
    SmallRoom,
    confusion,
    fit_lookup,
    small_rooms,
    vote_storerooms,
)


def _plan() -> FloorPlan:
    """Kitchen (0..4 m) with a pantry east of it (4.1..6 m, 2 m deep) behind a door, and a
    bathroom north of the pantry with a window in the outer wall and a door from the kitchen."""
    return FloorPlan(
        {
            "kitchen": [box(0, 0, 4, 4)],
            "storage": [box(4.1, 0, 6, 2)],
            "bathroom": [box(4.1, 2.1, 6, 4)],
            "door": [box(4, 0.5, 4.1, 1.3), box(4, 2.6, 4.1, 3.4)],
            "window": [box(6, 2.8, 6.1, 3.4)],
            "wall": [box(4, 0, 4.1, 4), box(4.1, 2, 6, 2.1)],
        },
        0.1,
        "test",
    )


def test_small_rooms_reads_area_window_and_the_rooms_behind_the_doors():
    rooms = {room.class_name: room for room in small_rooms(_plan())}
    pantry = rooms["storage"]
    assert (pantry.window, pantry.behind_doors) == (False, ("kitchen",))
    assert abs(pantry.area_m2 - 1.9 * 2.0) < 1e-9
    assert rooms["bathroom"].window and rooms["bathroom"].behind_doors == ("kitchen",)
    assert abs(rooms["bathroom"].area_m2 - 1.9 * 1.9) < 1e-9


def test_lookup_takes_each_cells_majority_and_bathroom_on_ties_and_unseen_cells():
    small_pantry = SmallRoom("storage", 2.0, False, ("kitchen",))
    small_bath = SmallRoom("bathroom", 2.1, False, ("kitchen",))  # same 0.5 m² cell
    windowed_bath = SmallRoom("bathroom", 4.0, True, ("living",))
    table = fit_lookup([small_pantry, small_pantry, small_bath, windowed_bath], 0.5)
    assert table[small_pantry.cell(0.5)] == "storage"
    assert table[windowed_bath.cell(0.5)] == "bathroom"
    assert fit_lookup([small_pantry, small_bath], 0.5)[small_pantry.cell(0.5)] == "bathroom"
    unseen = SmallRoom("storage", 9.0, False, ("bedroom",))
    counts = confusion(table, [small_pantry, small_bath, windowed_bath, unseen], 0.5)
    assert counts == {
        ("storage", "storage"): 1,
        ("bathroom", "storage"): 1,
        ("bathroom", "bathroom"): 1,
        ("storage", "bathroom"): 1,
    }


def test_flat_counts_tell_rooms_the_table_cannot():
    bath, pantry = (
        SmallRoom("bathroom", 4.0, False, ("living",)),
        SmallRoom("storage", 4.0, False, ("living",)),
    )  # one lookup cell
    one_bed = [Flat(1, (bath, pantry))] * 10  # one-bedroom flats: a bathroom and a storeroom
    two_bed = [Flat(2, (bath, bath))] * 10  # two-bedroom flats: two bathrooms
    model = CountsModel.fit(one_bed + two_bed, 0.5)
    assert model.flats == {(1, 1, 1): 10, (2, 2, 0): 10}
    assert fit_lookup([bath, bath, bath, pantry], 0.5)[bath.cell(0.5)] == "bathroom"
    assert sorted(model.label(Flat(1, (bath, bath)))) == ["bathroom", "storage"]
    assert model.label(Flat(2, (pantry, pantry))) == ("bathroom", "bathroom")
    # counts never seen are unlikely, not impossible: the cells decide
    assert model.label(Flat(5, (bath,))) == ("bathroom",)
    assert Flat(1, (bath, pantry)).counts(("storage", "storage")) == (1, 0, 2)


def test_storerooms_cli_json(capsys):
    argv = ["storerooms", "--train", "20", "--synthetic", "20", "--seed", "7", "--json"]
    argv += ["--resplan", str(resplan_sample_path())]
    assert evaluate_main(argv) == 0
    out = json.loads(capsys.readouterr().out)
    n_small = sum(out["rooms"].values())
    assert out["rooms"]["bathroom"] >= 20  # every generated flat has a bathroom
    assert 0 <= out["lookup_wrong"] <= n_small
    assert 0 <= out["with_counts_wrong"] <= n_small
    assert out["always_bathroom_wrong"] == out["rooms"].get("storage", 0)
    assert set(out["lookup_errors"]) <= {"bathroom->storage", "storage->bathroom"}
    # ResPlan plan 0 has three bedrooms and four bathrooms; no generated flat has more than three
    real = {flat["name"]: flat for flat in out["real_flats"]}
    assert real["resplan 0"]["counts"] == [3, 4, 0]
    assert real["resplan 0"]["training_flats_alike"] == 0


def test_storerooms_cli_rejects_bad_arguments(capsys):
    assert evaluate_main(["storerooms", "--area-bin", "0"]) == 2
    assert "--area-bin" in capsys.readouterr().err
    assert evaluate_main(["storerooms", "--seed", "999990", "--synthetic", "20"]) == 2


def _bathrooms_with_background(*background: float) -> ParsedPlan:
    """One-row parse: a living room (id 1) and bathrooms (ids 2..) with the given mean
    background probabilities."""
    ids = np.repeat(np.arange(1, len(background) + 2, dtype=np.int32), 2)[None, :]
    instances = [Instance(1, "living", np.zeros((0, 2)), 2, (0.5, 0.0), scores={0: 0.9})]
    for k, p in enumerate(background, start=2):
        scores = {CLASS_ID["background"]: p, CLASS_ID["bathroom"]: 1 - p}
        instances.append(
            Instance(k, "bathroom", np.zeros((0, 2)), 2, (2.0 * k, 0.0), scores=scores)
        )
    return ParsedPlan(ids, np.zeros(ids.shape, np.uint8), instances)


def test_vote_storerooms_leaves_out_background_like_bathrooms_only():
    parsed = _bathrooms_with_background(0.05, 0.3, 0.2)
    voted = vote_storerooms(parsed, 0.2)
    assert [i.id for i in voted.instances] == [1, 2, 4]  # 0.3 > 0.2; a living room stays
    assert not (voted.instance_ids == 3).any() and (voted.instance_ids == 4).sum() == 2
    assert vote_storerooms(parsed, 0.5) is parsed


def test_segmentation_cli_refuses_a_storeroom_threshold_outside_0_1(capsys):
    assert evaluate_main(["segmentation", "--synthetic", "1", "--storerooms", "1.5"]) == 2
    assert "--storerooms" in capsys.readouterr().err
