"""Metrics on hand-made arrays (values computed by hand) and the evaluation CLIs with stubs."""

from __future__ import annotations

import json

import numpy as np
import pytest
from shapely.geometry import box

from f2n_drake.core.classes import CLASS_ID, OPENING, SPACE_CLASSES
from f2n_drake.core.parsed import Instance, ParsedPlan
from f2n_drake.core.paths import resplan_sample_path
from f2n_drake.core.plan import FloorPlan
from f2n_drake.core.raster import PixelGrid
from f2n_drake.datasets.generator import generate_plan
from f2n_drake.datasets.render import DrawingStyle, render
from f2n_drake.evaluate import metrics, parse_speed, segmentation

# gt / pred, hand-scored below. Classes: 0 bg, 1 living, 2 bedroom, 6 wall, 7 door, 8 window.
GT = np.array([[0, 0, 1, 1], [1, 1, 7, 6]], np.uint8)
PRED = np.array([[0, 1, 1, 1], [1, 2, 7, 8]], np.uint8)


@pytest.fixture
def cm():
    return metrics.confusion_matrix(GT, PRED)


def test_confusion_matrix(cm):
    assert cm.shape == (10, 10) and cm.sum() == 8
    assert cm[0, 0] == 1 and cm[0, 1] == 1  # one background pixel called living
    assert cm[1, 1] == 3 and cm[1, 2] == 1
    assert cm[7, 7] == 1 and cm[6, 8] == 1
    with pytest.raises(ValueError):
        metrics.confusion_matrix(GT, PRED[:, :3])


def test_iou_accuracy(cm):
    iou = metrics.per_class_iou(cm)
    assert iou["background"] == pytest.approx(1 / 2)  # tp 1, fn 1
    assert iou["living"] == pytest.approx(3 / 5)  # tp 3, fp 1, fn 1
    assert iou["bedroom"] == 0.0 and iou["wall"] == 0.0 and iou["window"] == 0.0
    assert iou["door"] == 1.0
    assert iou["kitchen"] is None and iou["front_door"] is None  # absent from both
    # mean over the 6 classes present in gt or prediction
    assert metrics.mean_iou(cm) == pytest.approx((0.5 + 0.6 + 0 + 0 + 1 + 0) / 6)
    assert metrics.pixel_accuracy(cm) == pytest.approx(5 / 8)
    empty = np.zeros((10, 10), np.int64)
    assert metrics.mean_iou(empty) is None and metrics.pixel_accuracy(empty) is None


def test_categories(cm):
    cats = metrics.category_scores(cm)
    # living P 3/4 R 3/4 F1 3/4; bedroom P 0 (0 of 1) R 0 (no gt) F1 0
    assert cats["functional_spaces"] == pytest.approx(
        {"precision": 0.375, "recall": 0.375, "f1": 0.375}
    )
    # door 1/1/1; window P 0 R 0 F1 0
    assert cats["connectors"] == pytest.approx({"precision": 0.5, "recall": 0.5, "f1": 0.5})
    assert cats["wall"] == pytest.approx({"precision": 0.0, "recall": 0.0, "f1": 0.0})
    # background P 1/1, R 1/2, F1 2/3
    assert cats["background"] == pytest.approx({"precision": 1.0, "recall": 0.5, "f1": 2 / 3})
    only_bg = metrics.confusion_matrix(np.zeros(4, np.uint8), np.zeros(4, np.uint8))
    assert metrics.category_scores(only_bg)["connectors"] is None


def test_connector_confusion(cm):
    # gt connector: the door (predicted door); the wall pixel predicted window is a false positive
    np.testing.assert_array_equal(metrics.connector_confusion(cm), [[1, 0], [1, 6]])
    assert metrics.connector_precision_recall(cm) == (0.5, 1.0)


def _parsed(ids: np.ndarray, classes: dict[int, str]) -> ParsedPlan:
    instances = [
        Instance(i, c, np.zeros((0, 2)), int((ids == i).sum()), (0.0, 0.0))
        for i, c in classes.items()
    ]
    return ParsedPlan(ids.astype(np.int32), np.zeros(ids.shape, np.uint8), instances)


def test_instance_accuracy():
    ids = np.array([[1, 1, 1, 2, 2, 3], [1, 1, 0, 2, 2, 3]])
    gt = np.array([[1, 1, 2, 4, 4, 1], [1, 1, 0, 4, 1, 4]], np.uint8)
    # instance 1: gt 4x living, 1x bedroom -> living (right); 2: 3x kitchen -> called bedroom
    # (wrong); 3: an opening, not counted
    parsed = _parsed(ids, {1: "living", 2: "bedroom", 3: OPENING})
    assert metrics.instance_accuracy_counts(parsed, gt) == (1, 2)
    truth = metrics.instance_truth(parsed, gt)
    assert truth == {1: "living", 2: "kitchen"}
    assert metrics.instance_accuracy_counts(parsed, gt, truth) == (1, 2)
    assert metrics.instance_accuracy_counts(_parsed(ids * 0, {}), gt) == (0, 0)


def test_left_out_truth_counts_rooms_and_connectors_voted_background():
    components = np.array([[1, 1, 2, 2, 3, 3, 4, 5, 5, 6, 6]])
    enclosed = np.array([False, True, True, True, False, True, True])  # 4 touches the border
    ids = np.array([[1, 1, 0, 0, 0, 0, 0, 2, 0, 0, 0]])
    bg, bath, bed, door = (CLASS_ID[c] for c in ("background", "bathroom", "bedroom", "door"))
    gt = np.array([[bed, bed, bath, bath, bg, bg, bed, door, door, door, door]], np.uint8)
    parsed = _parsed(ids, {1: "bedroom", 2: "door"})
    # 1 an instance; 2 a bathroom voted background; 3 background (a storeroom) voted background;
    # 4 no candidate; 5 half covered by instance 2: left out; 6 a door voted background
    left_out = metrics.left_out_truth(parsed, components, enclosed, gt)
    assert sorted(left_out) == ["bathroom", "door", "door"]
    assert metrics.left_out_truth(parsed, components, np.zeros(7, bool), gt) == []


def test_match_truth_iou_and_overlap():
    ids = np.zeros((20, 20), np.int32)
    ids[0:8, 0:10] = 1  # 80 px living, overlaps the truth by 60 px
    ids[10:20, 0:10] = 2  # kitchen
    truth_mask = np.zeros((20, 20), bool)
    truth_mask[2:12, 0:10] = True  # 100 px living: 60 with instance 1, 20 with instance 2
    parsed = _parsed(ids, {1: "living", 2: "kitchen"})
    truth = [metrics.TruthRegion("living", 0, truth_mask)]
    (m,) = metrics.match_truth(parsed, truth)
    assert m.instance_id == 1 and m.iou == pytest.approx(60 / 120) and m.found
    assert m.overlap == pytest.approx(60 / 80) and m.best_class == "living"
    (m,) = metrics.match_truth(parsed, truth, threshold=0.51)
    assert not m.found
    bedroom = [metrics.TruthRegion("bedroom", 0, truth_mask)]
    (m,) = metrics.match_truth(parsed, bedroom)
    assert not m.found and m.instance_id is None and m.best_class == "living"
    assert metrics.recall(metrics.match_truth(parsed, truth + bedroom)) == 0.5
    assert metrics.recall([]) is None


def test_rasterise_truth_square():
    plan = FloorPlan(
        {"kitchen": [box(1.0, 1.0, 2.0, 3.0)], "living": [box(2.0, 1.0, 4.0, 3.0)]}, 0.2
    )
    grid = PixelGrid(0.1, (0.0, 4.0), (40, 50))  # 0.1 m/px, top-left corner at (0, 4) m
    labels = np.zeros((40, 50), np.uint8)
    labels[10:30, 10:20] = CLASS_ID["kitchen"]  # rows of y 3..1 m, cols of x 1..2 m
    labels[10:30, 20:40] = CLASS_ID["living"]
    regions = metrics.rasterise_truth(plan, grid, labels, SPACE_CLASSES)
    assert [(r.class_name, r.area_px) for r in regions] == [("living", 400), ("kitchen", 200)]
    np.testing.assert_array_equal(regions[1].mask, labels == CLASS_ID["kitchen"])


def test_rasterise_truth_matches_renderer_with_rotation():
    plan = generate_plan(3)
    rendered = render(plan, 256, style=DrawingStyle(rotation_deg=2.5))
    regions = metrics.rasterise_truth(
        plan, rendered.grid, rendered.labels, SPACE_CLASSES, rotation_deg=2.5
    )
    union = np.zeros(rendered.labels.shape, bool)
    for r in regions:
        union |= r.mask
    space = np.isin(rendered.labels, [CLASS_ID[n] for n in SPACE_CLASSES])
    assert (union == space).mean() > 0.999  # same rasterisation as the label image
    assert len(regions) == sum(len(plan[n]) for n in SPACE_CLASSES)


# -- evaluation CLIs with stub segmenters ----------------------------------------------------
def _json(capsys) -> dict:
    return json.loads(capsys.readouterr().out)


def test_segmentation_cli_with_perfect_oracle(capsys):
    code = segmentation.main(
        ["--synthetic", "3", "--seed", "0", "--json", "--size", "256"],
        predict=segmentation.oracle_predictor(0.0),
    )
    assert code == 0
    report = _json(capsys)
    for key in (
        "mean_iou",
        "pixel_accuracy",
        "per_class_iou",
        "instance_accuracy",
        "space_recall",
        "categories",
        "connector_confusion",
        "connector_precision",
        "connector_recall",
        "n_images",
        "n_instances",
    ):
        assert key in report
    assert report["n_images"] == 3 and report["n_instances"] > 10
    assert report["views"] is None and report["storage_network"] is None  # no segmenter ran
    assert report["mean_iou"] == 1.0 and report["instance_accuracy"] == 1.0
    assert report["instance_errors"] == {} and report["left_out"] == {}
    assert (
        report["split_effect"]["split"]["space_recall"]
        >= report["split_effect"]["no_split"]["space_recall"]
    )
    assert 0.9 <= report["space_recall"] <= 1.0
    for mode in ("prior", "no_prior"):  # perfect labels: the prior has nothing to change
        assert report["front_door_effect"][mode] == {
            "instance_accuracy": 1.0,
            "front_door_recall": 1.0,
            "front_door_precision": 1.0,
        }
    assert report["confidence_flag"]["unsure"] == {"instances": 0, "accuracy": None}
    assert report["kitchens_undone"] == report["kitchens_added"] == 0
    assert report["kitchen_effect"]["prior"] == report["kitchen_effect"]["no_prior"]


def report_with_rooms_voted(capsys, source: str, target: str) -> dict:
    """The evaluation JSON of plans 0 and 1 under an oracle that calls every ``source`` room
    ``target``, with probability 0.6 (0.4 left for ``source``)."""

    def oracle(rendered):
        labels = rendered.labels.copy()
        wrong = labels == CLASS_ID[source]
        labels[wrong] = CLASS_ID[target]
        probs = np.eye(10, dtype=np.float32)[labels].transpose(2, 0, 1)
        probs[CLASS_ID[target], wrong] = 0.6
        probs[CLASS_ID[source], wrong] = 0.4
        return labels, probs

    segmentation.main(
        ["--synthetic", "2", "--seed", "0", "--json", "--size", "256"], predict=oracle
    )
    report = _json(capsys)
    effect = report["kitchen_effect"]
    assert effect["prior"]["instance_accuracy"] == 1.0 > effect["no_prior"]["instance_accuracy"]
    return report


def test_segmentation_kitchen_effect_with_bedrooms_voted_kitchen(capsys):
    # every bedroom is a kitchen less sure than the true kitchen: the prior gives them back
    report = report_with_rooms_voted(capsys, "bedroom", "kitchen")
    bedrooms = sum(len(generate_plan(s)["bedroom"]) for s in (0, 1))
    assert bedrooms > 0 and report["kitchens_undone"] == bedrooms
    assert report["kitchens_added"] == 0


def test_segmentation_kitchen_effect_with_the_kitchen_voted_bedroom(capsys):
    # the kitchen is a bedroom with kitchen probability 0.4: the prior finds it where it is a
    # room of its own (an open kitchen voted bedroom stays part of the living room: the vote has
    # no kitchen there to find)
    report = report_with_rooms_voted(capsys, "kitchen", "bedroom")
    enclosed = [not generate_plan(s).metadata["open_kitchen"] for s in (0, 1)]
    assert sum(enclosed) == 1  # one of each
    assert report["kitchens_added"] == 1 and report["kitchens_undone"] == 0


def test_segmentation_counts_the_rooms_it_leaves_out(capsys):
    # an oracle that votes every bathroom background: the bathrooms are no instances of the
    # parse, but wrong regions all the same
    def oracle(rendered):
        labels = rendered.labels.copy()
        labels[labels == CLASS_ID["bathroom"]] = CLASS_ID["background"]
        return labels, None

    segmentation.main(
        ["--synthetic", "2", "--seed", "0", "--json", "--size", "256"], predict=oracle
    )
    report = _json(capsys)
    bathrooms = sum(len(generate_plan(s)["bathroom"]) for s in (0, 1))
    assert bathrooms > 0 and report["left_out"] == {"bathroom": bathrooms}
    assert report["instance_errors"] == {"bathroom->background": bathrooms}
    right = report["n_instances"] - bathrooms
    assert report["instance_accuracy"] == right / report["n_instances"]
    assert report["space_recall"] < 1.0


def test_segmentation_storeroom_experiment_pays_for_the_bathrooms_it_drops(capsys):
    # every bathroom 0.4 background-like: --storerooms 0.3 votes them all background
    def oracle(rendered):
        labels = rendered.labels
        probs = np.eye(10, dtype=np.float32)[labels].transpose(2, 0, 1)
        bathroom = labels == CLASS_ID["bathroom"]
        probs[CLASS_ID["bathroom"], bathroom] = 0.6
        probs[CLASS_ID["background"], bathroom] = 0.4
        return labels.copy(), probs

    argv = ["--synthetic", "2", "--seed", "0", "--json", "--size", "256"]
    segmentation.main([*argv, "--storerooms", "0.5"], predict=oracle)
    assert _json(capsys)["instance_accuracy"] == 1.0  # 0.4 < 0.5: nothing dropped
    segmentation.main([*argv, "--storerooms", "0.3"], predict=oracle)
    report = _json(capsys)
    bathrooms = sum(len(generate_plan(s)["bathroom"]) for s in (0, 1))
    assert report["storerooms"] == 0.3 and report["left_out"] == {"bathroom": bathrooms}
    assert report["instance_errors"] == {"bathroom->background": bathrooms}


def test_segmentation_front_door_effect_with_two_voted_front_doors(capsys):
    # an oracle that also calls every window a front door, though less surely (probability 0.6):
    # the prior must keep only the true front door and give the windows back their class
    def windows_as_front_doors(rendered):
        labels = rendered.labels.copy()
        front = labels == CLASS_ID["front_door"]
        labels[labels == CLASS_ID["window"]] = CLASS_ID["front_door"]
        probs = np.eye(10, dtype=np.float32)[labels].transpose(2, 0, 1)
        probs[CLASS_ID["front_door"], ~front & (labels == CLASS_ID["front_door"])] = 0.6
        probs[CLASS_ID["window"], ~front & (labels == CLASS_ID["front_door"])] = 0.4
        return labels, probs

    segmentation.main(
        ["--synthetic", "2", "--seed", "0", "--json", "--size", "256"],
        predict=windows_as_front_doors,
    )
    report = _json(capsys)
    effect = report["front_door_effect"]
    assert effect["prior"]["front_door_precision"] == 1.0
    assert effect["prior"]["front_door_recall"] == 1.0
    assert effect["no_prior"]["front_door_precision"] < 0.5
    assert effect["prior"]["instance_accuracy"] > effect["no_prior"]["instance_accuracy"]
    flag = report["confidence_flag"]  # the windows are right but only 40 % sure
    assert flag["unsure"]["instances"] > 0 and flag["unsure"]["accuracy"] == 1.0
    assert flag["sure"]["accuracy"] == 1.0


def test_segmentation_cli_noisy_oracle_and_no_split(capsys):
    segmentation.main(
        [
            "--synthetic",
            "2",
            "--seed",
            "5",
            "--json",
            "--size",
            "256",
            "--oracle",
            "0.05",
            "--no-split",
            "--styles",
            "random",
        ]
    )
    report = _json(capsys)
    assert 0.0 < report["mean_iou"] < 1.0
    assert report["after_vote"]["pixel_accuracy"] > report["pixel_accuracy"]
    assert report["split"] is False
    assert report["space_recall"] == report["split_effect"]["no_split"]["space_recall"]
    (tp, fn), (fp, tn) = report["connector_confusion"]
    assert report["connector_recall"] == pytest.approx(tp / (tp + fn))
    voted = report["after_vote"]  # the parse's labels: its connector scores beat the raw ones
    assert voted["connector_precision"] > report["connector_precision"]
    assert voted["categories"]["connectors"]["f1"] > report["categories"]["connectors"]["f1"]
    assert report["sealed_room_prior"] is True
    assert report["sealed_room_doors"] == 0  # no probabilities: the prior has no evidence


@pytest.mark.parametrize(
    "look, size",
    [
        ("negative", 256),
        ("room-fills", 256),
        ("wide-margins", 256),
        ("shaded", 256),
        ("labelled", 512),  # letters 5 px high and more
        ("furnished", 512),
        ("sheet", 512),
        ("evacuation", 512),  # in colour
        ("textured-floors", 512),  # planks and tiles
        ("light-lines", 512),  # grey hairlines, black names
    ],
)
def test_segmentation_cli_restyled_drawings_give_the_same_instances(capsys, look, size):
    args = ["--synthetic", "2", "--seed", "7", "--json", "--size", str(size), "--oracle", "0"]
    segmentation.main(args)
    drawn = _json(capsys)
    segmentation.main([*args, "--look", look])
    restyled = _json(capsys)
    assert drawn["look"] == "drawn" and restyled["look"] == look
    assert restyled["n_instances"] == drawn["n_instances"]  # no letter's inside, no bed a room
    assert restyled["instance_accuracy"] == drawn["instance_accuracy"] == 1.0
    assert restyled["after_vote"]["mean_iou"] == pytest.approx(drawn["after_vote"]["mean_iou"])


def test_segmentation_cli_resplan_lists_misses(capsys):
    # an oracle that forgets every door: each door must be listed as missed
    def no_doors(rendered):
        labels = rendered.labels.copy()
        labels[labels == CLASS_ID["door"]] = CLASS_ID["wall"]
        return labels, None

    segmentation.main(["--resplan", str(resplan_sample_path()), "--size", "256"], predict=no_doors)
    out = capsys.readouterr().out
    assert "missed door#0" in out and out.count("resplan") == 2
    assert "in wall)" in out and "None" not in out  # names the instance that took each door
    assert "wrong instances (truth->voted): door->wall " in out


@pytest.mark.parametrize("cli", [segmentation.main, parse_speed.main])
def test_view_counts_other_than_1_2_4_8_are_refused(cli, capsys):
    argv = ["--views", "3"] + (["--synthetic", "1"] if cli is segmentation.main else [])
    with pytest.raises(SystemExit) as exit_:  # argparse: one usage line, exit status 2
        cli(argv)
    assert exit_.value.code == 2
    assert "argument --views: invalid choice: 3" in capsys.readouterr().err


def test_parse_speed_cli_with_stub(capsys):
    class Stub:
        def predict(self, image):
            return np.full(image.shape, CLASS_ID["living"], np.uint8)

    assert parse_speed.main(["--repeats", "3", "--size", "128", "--json"], segmenter=Stub()) == 0
    report = _json(capsys)
    assert report["repeats"] == 3 and report["device"] == "injected" and report["views"] is None
    for key in ("network", "instances", "total"):
        assert 0 <= report[key]["median_ms"] <= report[key]["p90_ms"]
    assert report["total"]["median_ms"] >= report["instances"]["median_ms"]
    assert report["target_median_ms"] is None and report["meets_target"] is None  # 128 px: none
    assert parse_speed.TARGET_MEDIAN_MS[1000] == 1500.0  # the real drawings' goal


def test_segmentation_cli_can_parse_without_the_scale(capsys, monkeypatch):
    from f2n_drake.evaluate import segmentation_scores

    grids = []
    steps = segmentation_scores.parse_steps

    def spy(*args, grid=None, **kwargs):
        grids.append(grid)
        return steps(*args, grid=grid, **kwargs)

    monkeypatch.setattr(segmentation_scores, "parse_steps", spy)
    args = ["--synthetic", "1", "--seed", "0", "--size", "256"]
    oracle = segmentation.oracle_predictor(0.0)
    assert segmentation.main([*args, "--json"], predict=oracle) == 0
    assert _json(capsys)["known_scale"] is True and all(g is not None for g in grids)
    grids.clear()
    assert segmentation.main([*args, "--json", "--unknown-scale"], predict=oracle) == 0
    report = _json(capsys)
    assert report["known_scale"] is False and grids and all(g is None for g in grids)
    assert report["instance_accuracy"] == 1.0  # true labels need no scale
    segmentation.main([*args, "--unknown-scale"], predict=oracle)
    assert "scale unknown" in capsys.readouterr().out
