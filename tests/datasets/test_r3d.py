"""R3D reader: merged classes as sets of acceptable classes and the fixed development split
(tiny plans written in tmp_path)."""

from __future__ import annotations

import pytest
from helpers import bits, write_r3d_plan

from f2n_drake.core.errors import InputError
from f2n_drake.datasets import r3d


def test_reader_maps_colours_walls_and_openings_to_r3d_classes(tmp_path):
    write_r3d_plan(tmp_path, "7")
    plan = r3d.load_r3d_plan(tmp_path, "7")
    assert plan.image.shape == plan.labels.shape == (120, 160)
    assert plan.labels[50, 40] == r3d.R3D_ID["living"]
    assert plan.labels[50, 100] == r3d.R3D_ID["bedroom"]
    assert plan.labels[100, 140] == r3d.R3D_ID["closet"]
    assert plan.labels[50, 80] == r3d.R3D_ID["wall"]
    assert plan.labels[8, 40] == r3d.R3D_ID["opening"]  # openings are painted over walls
    assert plan.labels[2, 2] == r3d.R3D_ID["background"]
    sets = plan.class_sets
    assert sets[50, 40] == bits("living", "kitchen")
    assert sets[8, 40] == bits("door", "window", "front_door")
    assert sets[100, 140] == bits("background")


def test_every_r3d_class_accepts_some_class_and_hall_is_living():
    assert all(r3d.ACCEPTABLE_MASK > 0)
    assert r3d.ACCEPTABLE_MASK[r3d.R3D_ID["hall"]] == bits("living")
    other = r3d.ACCEPTABLE_MASK[r3d.R3D_ID["other"]]
    assert other & bits("bedroom") and not other & bits("balcony", "wall")


def test_names_need_all_label_images_and_an_empty_folder_is_refused(tmp_path):
    with pytest.raises(InputError, match="no R3D plans"):
        r3d.r3d_names(tmp_path)
    write_r3d_plan(tmp_path, "b")
    write_r3d_plan(tmp_path, "a")
    (tmp_path / "a_wall.png").unlink()
    assert r3d.r3d_names(tmp_path) == ["b"]


def test_development_split_is_30_listed_plans_kept_out_of_train(tmp_path):
    dev = r3d.dev_split_names()
    assert len(dev) == len(set(dev)) == 30
    for name in [dev[0], dev[1], "not_in_dev"]:
        write_r3d_plan(tmp_path, name)
    assert r3d.split_names(tmp_path, "dev") == sorted(dev[:2])
    assert r3d.split_names(tmp_path, "train") == ["not_in_dev"]
    assert len(r3d.split_names(tmp_path, "all")) == 3
    with pytest.raises(InputError, match="unknown R3D split"):
        r3d.split_names(tmp_path, "test")


def test_dev_split_rule_is_seeded_and_sorted():
    names = [f"{i:03d}" for i in range(179)]
    assert r3d.choose_dev_split(names) == r3d.choose_dev_split(list(reversed(names)))
    assert r3d.choose_dev_split(names) == sorted(r3d.choose_dev_split(names))
