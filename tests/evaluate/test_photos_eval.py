"""``evaluate photos``: pictures a phone would take of a drawing, or a user would save of it,
parsed with and without the steps that undo them."""

from __future__ import annotations

import json

import cv2
import numpy as np
import pytest
from helpers import Oracle, two_rooms

from f2n_drake.evaluate import photos


def test_dimming_darkens_towards_the_bottom_right_corner():
    image = np.full((50, 80), 200, np.uint8)
    dim = photos.dimmed(image, 0.5)
    assert dim[0, 0] == 200 and dim[-1, -1] == 100 and dim[25, 40] == pytest.approx(150, abs=2)
    colour = photos.dimmed(np.full((50, 80, 3), 200, np.uint8), 0.5)
    assert colour.shape == (50, 80, 3) and colour[-1, -1, 2] == 100


def test_a_photo_maps_the_drawing_onto_its_page_on_the_table():
    image = np.full((100, 100), 255, np.uint8)
    image[40:60, 40:60] = 0
    photo, to_photo = photos.photographed(image)
    assert photo.shape == (round(1.3 * 116), round(1.3 * 116))  # 8 px margins, 30 % of table
    centre = cv2.perspectiveTransform(np.float32([[[50, 50]]]), to_photo)[0, 0]
    assert photo[round(centre[1]), round(centre[0])] < 60  # the black square
    assert photo[2, 2] < 100  # the table


def test_a_drawing_saved_as_jpeg_or_at_half_size_keeps_its_grid_mapping():
    image = np.full((60, 100, 3), 255, np.uint8)
    image[20:40, 40:60] = 0
    jpeg, to_jpeg = photos.picture(image, "JPEG 60")
    assert jpeg.shape == image.shape and np.array_equal(to_jpeg, np.eye(3))
    assert np.abs(jpeg.astype(int) - image).mean() < 5  # lossy, but the same drawing
    small, to_small = photos.picture(image, "half size")
    assert small.shape == (30, 50, 3)
    centre = cv2.perspectiveTransform(np.float32([[[50, 30]]]), to_small)[0, 0]
    np.testing.assert_allclose(centre, [25, 15])
    assert small[15, 25].max() < 60  # the black square


def test_maps_come_back_onto_the_drawing_grid():
    labels = np.zeros((40, 60), np.uint8)
    labels[10:20, 10:30] = 3
    rooms = (labels > 0).astype(np.float32) * 7
    shift = np.array([[1, 0, 5], [0, 1, 2], [0, 0, 1]], np.float64)  # drawing -> picture
    moved = [
        cv2.warpAffine(m, shift[:2], (60, 40), flags=cv2.INTER_NEAREST) for m in (labels, rooms)
    ]
    back_labels, back_rooms = photos.carried_back((*moved, np.eye(3)), shift, labels.shape)
    np.testing.assert_array_equal(back_labels, labels)
    np.testing.assert_array_equal(back_rooms, rooms)
    assert photos.carried_back(None, shift, labels.shape) is None


def test_rooms_kept_matches_rooms_whatever_their_ids():
    reference = np.zeros((20, 40), np.float32)
    reference[:, :20], reference[:, 20:] = 1, 2
    swapped = np.where(reference == 1, 5, 9).astype(np.float32)
    assert photos.rooms_kept(swapped, reference) == 1.0
    merged = np.full_like(reference, 4)  # one room over both: IoU 0.5 with each
    assert photos.rooms_kept(merged, reference) == 1.0
    merged[:, 35:] = 0  # short of the second room: it is no longer matched
    assert photos.rooms_kept(merged, reference) == 0.5
    assert photos.rooms_kept(None, reference) == 0.0


def test_agreement_counts_the_labelled_pixels_and_refusals_score_nothing():
    reference = np.array([[0, 1, 1, 2]], np.uint8)
    assert photos.agreement(reference.copy(), reference) == 1.0
    assert photos.agreement(np.array([[0, 1, 2, 2]], np.uint8), reference) == pytest.approx(2 / 3)
    assert photos.agreement(None, reference) == 0.0


def test_the_benchmark_prints_one_row_per_drawing_and_picture(tmp_path, monkeypatch, capsys):
    img, lab = two_rooms(300)
    cv2.imwrite(str(tmp_path / "rooms.png"), img)
    monkeypatch.setattr(
        "f2n_drake.segmenter.inference.Segmenter.load", classmethod(lambda cls: Oracle(lab))
    )
    argv = [str(tmp_path / "rooms.png"), "--pictures", "dimmed 40 %", "--json"]
    assert photos.main(argv) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["drawings"] == 1 and len(report["per_drawing"]) == 1
    row = report["per_drawing"][0]
    assert row["picture"] == "dimmed 40 %" and row["refused"] == []
    assert row["labels_undone"] == 1.0  # the stub labels alike; lit evenly, the lines are too
    assert row["rooms_undone"] == 1.0


def test_a_parse_whose_instance_ids_leave_a_gap_is_read(monkeypatch):
    import dataclasses

    from f2n_drake.pipeline import parse_drawing

    img, lab = two_rooms()
    parsed = parse_drawing(img, segmenter=Oracle(lab), reader=None)
    top = max(i.id for i in parsed.instances)
    room = parsed.of_class("bedroom")[0]
    ids = np.where(parsed.instance_ids == room.id, top + 5, parsed.instance_ids)  # a prior's gap
    moved = [dataclasses.replace(i, id=top + 5) if i is room else i for i in parsed.instances]
    gapped = dataclasses.replace(parsed, instance_ids=ids, instances=moved)
    monkeypatch.setattr("f2n_drake.pipeline.parse_drawing", lambda *a, **k: gapped)
    labels, rooms, _ = photos.read(img, Oracle(lab), undo=False)
    assert set(np.unique(rooms[ids == top + 5])) == {top + 5}  # the bedroom keeps its id
