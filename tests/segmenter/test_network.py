"""DeepLabV3+ network shape contract, checkpoint verification, and inference geometry."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
import torch
from helpers import InkModel
from torch import nn

from f2n_drake.core.classes import CLASS_ID
from f2n_drake.core.errors import InputError
from f2n_drake.perception.ink import binarize, ink_is_dark
from f2n_drake.perception.preparation import (
    content_box,
    drawn_in_light_lines,
    on_white_paper,
    to_grey,
    visible_strokes,
    with_dark_ink,
)
from f2n_drake.segmenter.inference import Segmenter
from f2n_drake.segmenter.network import DeepLabV3Plus, count_parameters, fold_batch_norms
from f2n_drake.segmenter.weights import load_segmenter, save_segmenter, sha256_path

TINY = dict(width=0.25, aspp_channels=16, decoder_channels=16, low_level_channels=8)


@pytest.mark.parametrize("output_stride", [8, 16])
def test_logits_have_input_size_for_both_output_strides(output_stride):
    model = DeepLabV3Plus(output_stride=output_stride, **TINY).eval()
    with torch.inference_mode():
        assert model(torch.rand(1, 1, 64, 64)).shape == (1, 10, 64, 64)
        assert model(torch.rand(2, 1, 80, 48)).shape == (2, 10, 80, 48)


def test_output_stride_8_dilates_instead_of_striding():
    deep16, deep8 = DeepLabV3Plus(output_stride=16, **TINY), DeepLabV3Plus(output_stride=8, **TINY)
    x = torch.rand(1, 1, 64, 64)
    assert deep16.eval().encoder(x)[1].shape[-1] == 4
    assert deep8.eval().encoder(x)[1].shape[-1] == 8
    assert deep8.encoder(x)[0].shape[-1] == 16  # low-level features at 1/4


@pytest.mark.parametrize(
    "kwargs",
    [
        dict(output_stride=32),
        dict(num_classes=1),
        dict(width=0.0),
        dict(width=3.0),
        dict(aspp_channels=0),
        dict(in_channels=-1),
    ],
)
def test_bad_constructor_arguments_raise_value_error(kwargs):
    with pytest.raises(ValueError):
        DeepLabV3Plus(**kwargs)


def test_default_network_is_small():
    n = count_parameters(DeepLabV3Plus())
    assert 100_000 < n <= 6_000_000


def test_folded_batch_norms_give_the_same_logits_without_batch_norms():
    model = DeepLabV3Plus(**TINY)
    generator = torch.Generator().manual_seed(0)
    for m in model.modules():  # statistics far from the identity, so folding is visible
        if isinstance(m, nn.BatchNorm2d):
            m.running_mean.uniform_(-1, 1, generator=generator)
            m.running_var.uniform_(0.5, 2, generator=generator)
            m.weight.data.uniform_(0.5, 1.5, generator=generator)
            m.bias.data.uniform_(-0.5, 0.5, generator=generator)
    model.eval()
    folded = fold_batch_norms(model)
    x = torch.rand(2, 1, 64, 48, generator=generator)
    with torch.inference_mode():
        expected, got = model(x), folded(x)
    assert not any(isinstance(m, nn.BatchNorm2d) for m in folded.modules())
    assert any(isinstance(m, nn.BatchNorm2d) for m in model.modules())  # original untouched
    assert folded.config == model.config
    assert expected.abs().max() > 1e-2
    torch.testing.assert_close(got, expected, rtol=1e-4, atol=1e-5)


# --- checkpoints ---------------------------------------------------------------------------


def _saved(tmp_path):
    path = tmp_path / "seg.pt"
    digest = save_segmenter(DeepLabV3Plus(**TINY), path, input_size=128, metrics={"miou": 0.5})
    return path, digest


def test_checkpoint_round_trip_keeps_weights_and_metadata(tmp_path):
    model = DeepLabV3Plus(**TINY)
    path = tmp_path / "seg.pt"
    digest = save_segmenter(model, path, input_size=128, metrics={"miou": 0.5})
    assert sha256_path(path).read_text().split()[0] == digest
    checkpoint = load_segmenter(path)
    assert checkpoint.input_size == 128 and checkpoint.metrics == {"miou": 0.5}
    assert checkpoint.classes[9] == "front_door" and checkpoint.sha256 == digest
    ref = model.state_dict()["classifier.weight"].half().float()
    assert torch.equal(checkpoint.model.state_dict()["classifier.weight"], ref)


def test_tampered_weights_fail_the_sha256_check(tmp_path):
    path, _ = _saved(tmp_path)
    data = bytearray(path.read_bytes())
    data[len(data) // 2] ^= 0xFF
    path.write_bytes(bytes(data))
    with pytest.raises(InputError, match="sha256"):
        load_segmenter(path)


def test_missing_weights_or_record_raise_input_error(tmp_path):
    with pytest.raises(InputError, match="not found"):
        load_segmenter(tmp_path / "nope.pt")
    path, _ = _saved(tmp_path)
    sha256_path(path).unlink()
    with pytest.raises(InputError, match="sha256 record"):
        load_segmenter(path)
    assert load_segmenter(path, verify=False).input_size == 128


def test_corrupt_file_with_matching_record_raises_input_error(tmp_path):
    path, _ = _saved(tmp_path)
    path.write_bytes(b"not a checkpoint at all")
    import hashlib

    sha256_path(path).write_text(hashlib.sha256(b"not a checkpoint at all").hexdigest() + "  x\n")
    with pytest.raises(InputError, match="cannot be loaded"):
        load_segmenter(path)


# --- inference geometry --------------------------------------------------------------------


def _block_image(shape, box):
    image = np.full(shape, 255, np.uint8)
    r0, r1, c0, c1 = box
    image[r0:r1, c0:c1] = 0
    return image


@pytest.mark.parametrize("views", [1, 2, 8])
@pytest.mark.parametrize(
    "shape, box",
    [
        ((300, 700), (40, 200, 500, 690)),  # letterboxed, wide
        ((700, 300), (10, 120, 20, 200)),  # letterboxed, tall
        ((2500, 1800), (300, 2400, 1000, 1500)),  # large, nothing enclosed: letterboxed
    ],
)
def test_predictions_land_on_the_original_pixel_grid(shape, box, views):
    segmenter = Segmenter(
        InkModel(),
        input_size=128,
        letterbox_max_px=800,
        tile_max_side_px=600,
        overlap_px=32,
        views=views,
    )
    labels = segmenter.predict(_block_image(shape, box))
    assert labels.shape == shape and labels.dtype == np.uint8
    r0, r1, c0, c1 = box
    margin = 8 if max(shape) < 1000 else 12  # a few output pixels of the working scale
    assert labels[r0 + margin : r1 - margin, c0 + margin : c1 - margin].all()
    outside = np.ones(shape, bool)
    outside[max(0, r0 - margin) : r1 + margin, max(0, c0 - margin) : c1 + margin] = False
    assert not labels[outside].any()


def test_a_drawing_of_the_input_size_keeps_its_pixels():
    image = np.full((128, 128), 255, np.uint8)
    image[6:122, 9:120] = 0  # an outline spanning > 80 % of the sheet: not cropped
    image[9:119, 12:117] = 255
    image[40:43, 12:90] = 0
    segmenter = Segmenter(InkModel(), input_size=128, views=2)
    labels, probabilities = segmenter.predict_with_probabilities(image)
    np.testing.assert_array_equal(labels, (image < 128).astype(np.uint8))
    np.testing.assert_array_equal(probabilities.argmax(0), labels)


def test_the_network_does_not_see_text_standing_free_in_the_rooms():
    image = np.full((256, 256), 255, np.uint8)
    image[6:250, 9:248] = 0
    image[9:247, 12:245] = 255  # a room spanning the sheet: marks are at most 9 px across
    cv2.putText(image, "BED 2", (80, 120), cv2.FONT_HERSHEY_SIMPLEX, 0.3, 0, 1, cv2.LINE_AA)
    text = np.zeros(image.shape, bool)
    text[105:128, 75:135] = True
    assert (image[text] < 128).any()
    erased = Segmenter(InkModel(), input_size=256).predict(image)
    seen = Segmenter(InkModel(), input_size=256, erase_marks=False).predict(image)
    assert not erased[text].any() and seen[text].any()  # InkModel: class 1 where it sees ink
    np.testing.assert_array_equal(erased[~text], seen[~text])  # the room's outline stays


def test_strokes_of_a_large_drawing_stay_visible_once_shrunk():
    drawing = np.full((100, 100), 255, np.uint8)
    drawing[50, :] = 0  # a 1 px line
    thick = visible_strokes(drawing, 1, 0.2)  # shrunk 5x: grown to 3 px, 0.6 px once shrunk
    assert (thick[:, 50] < 128).sum() == 3 and (thick[49:52] == 0).all()
    np.testing.assert_array_equal(visible_strokes(drawing, 1, 0.5), drawing)  # <= 2x: as drawn
    np.testing.assert_array_equal(visible_strokes(drawing, 3, 0.2), drawing)  # thick enough
    ink = 1.0 - cv2.resize(thick, (20, 20), interpolation=cv2.INTER_AREA) / 255.0
    assert ink[:, 10].sum() == pytest.approx(0.6, abs=0.01)  # >= half a pixel of ink across
    faint = 1.0 - cv2.resize(drawing, (20, 20), interpolation=cv2.INTER_AREA) / 255.0
    assert faint[:, 10].sum() == pytest.approx(0.2, abs=0.01)  # as drawn: a fifth


def _room_grid(shape, period, line):
    """A drawing of square rooms ``period`` px apart outlined ``line`` px thick, and its ink."""
    ink = np.zeros(shape, bool)
    for k in range(0, max(shape), period):
        ink[k : k + line, :] = True
        ink[:, k : k + line] = True
    return np.where(ink, 0, 255).astype(np.uint8), ink


def test_large_drawings_are_tiled_only_when_their_rooms_are_small():
    segmenter = Segmenter(InkModel(), input_size=128, letterbox_max_px=800, overlap_px=32)
    flat, _ = _room_grid((2000, 1600), 700, 12)  # a flat scanned at high resolution
    assert segmenter.working_side_px(flat) is None  # rooms ~690 px: one letterboxed pass
    for k in range(300, 2000, 700):  # every wall cut by a door-wide gap: the rooms join up
        flat[:, k : k + 60] = 255
        flat[k : k + 60, :] = 255
    for row, col in ((100, 100), (100, 900), (900, 100), (900, 900)):  # closed letters
        flat[row : row + 20, col : col + 20] = 0
        flat[row + 5 : row + 15, col + 5 : col + 15] = 255
    assert segmenter.working_side_px(flat) is None  # measured with the gaps closed
    small, _ = _room_grid((600, 600), 40, 2)
    assert segmenter.working_side_px(small) is None  # up to letterbox_max_px: always one pass
    building, _ = _room_grid((2500, 1800), 48, 4)  # 44 px rooms: 2 px once letterboxed to 128
    side = segmenter.working_side_px(building)
    # tiled where rooms are ROOM_WIDTH_TARGET * 128 = 25 px wide: 2500 * 25 / 44
    assert side == pytest.approx(2500 * 25 / 44, rel=0.1)
    capped = Segmenter(InkModel(), input_size=128, letterbox_max_px=800, tile_max_side_px=1000)
    assert capped.working_side_px(building) == 1000


def test_tiled_predictions_land_on_the_original_pixel_grid():
    segmenter = Segmenter(InkModel(), input_size=128, letterbox_max_px=800, overlap_px=32)
    image, ink = _room_grid((2500, 1800), 48, 4)
    labels = segmenter.predict(image)
    assert labels.shape == image.shape
    centres = np.arange(2, 2500, 48)  # middles of the lines, then of the rooms
    assert labels[np.ix_(centres[centres < 2500], np.arange(30, 1800, 48))].all()
    rooms = np.arange(26, 1800, 48)
    assert not labels[np.ix_(np.arange(26, 2500, 48), rooms)].any()
    assert (labels == ink).mean() > 0.9


def test_the_network_sees_dark_ink_on_white_paper_whatever_the_drawing_colours():
    drawing, ink = _room_grid((300, 400), 60, 2)
    assert ink_is_dark(drawing) and not ink_is_dark(255 - drawing)
    np.testing.assert_array_equal(on_white_paper(drawing), drawing)  # already so: unchanged
    np.testing.assert_array_equal(on_white_paper(255 - drawing), drawing)  # a negative
    filled = np.where(ink, 0, 200 + (np.arange(400) % 40)[None, :]).astype(np.uint8)
    np.testing.assert_array_equal(on_white_paper(filled), drawing)  # grey room fills go
    noisy = np.clip(drawing + np.random.default_rng(0).normal(0, 12, drawing.shape), 0, 255)
    noisy = noisy.astype(np.uint8)
    np.testing.assert_array_equal(on_white_paper(noisy), noisy)  # noise is not tint: as drawn
    blank = np.full((50, 50), 255, np.uint8)
    np.testing.assert_array_equal(on_white_paper(blank), blank)


def test_a_negative_drawing_is_labelled_like_the_drawing():
    segmenter = Segmenter(InkModel(), input_size=128)
    drawing, ink = _room_grid((300, 400), 60, 4)
    labels = segmenter.predict(255 - drawing)
    assert (labels == ink).mean() > 0.95
    raw = Segmenter(InkModel(), input_size=128, white_paper=False)
    assert (raw.predict(255 - drawing) == ink).mean() < 0.2  # the network alone inverts it


def test_a_drawing_in_light_grey_lines_is_labelled_like_the_drawing():
    segmenter = Segmenter(InkModel(), input_size=128)
    drawing, ink = _room_grid((300, 400), 60, 2)
    light = np.where(ink, 215, 255).astype(np.uint8)  # a CAD export's grey hairlines
    for image in (drawing, light):  # black names
        cv2.putText(image, "1711", (70, 95), cv2.FONT_HERSHEY_SIMPLEX, 0.4, 0, 1)
        cv2.putText(image, "1712", (130, 155), cv2.FONT_HERSHEY_SIMPLEX, 0.4, 0, 1)
    labels = segmenter.predict(drawing)
    assert labels[ink].mean() > 0.5  # hairlines shrunk 2.3 times: half of them still ink
    np.testing.assert_array_equal(segmenter.predict(light), labels)
    raw = Segmenter(InkModel(), input_size=128, white_paper=False)
    assert not raw.predict(light)[ink].any()  # the network alone sees no lines


def test_light_lines_are_made_dark_and_dark_ones_left_as_drawn():
    drawing, ink = _room_grid((120, 160), 40, 2)
    light = np.where(ink, 200, 255).astype(np.uint8)
    assert drawn_in_light_lines(light)
    np.testing.assert_array_equal(with_dark_ink(light), drawing)  # grey lines black, paper white
    assert not drawn_in_light_lines(drawing)
    assert with_dark_ink(drawing) is drawing
    greyed = np.where(ink, 100, 255).astype(np.uint8)  # dark grey lines are dark enough
    assert with_dark_ink(greyed) is greyed
    # black lines with much light grey furniture among them: the plan's own lines are dark
    furnished = drawing.copy()
    for row in range(8, 120, 40):
        for col in range(8, 160, 40):
            cv2.rectangle(furnished, (col, row), (col + 20, row + 20), 225, 2)
    assert not drawn_in_light_lines(furnished)


def test_a_small_plan_on_a_big_sheet_is_cropped_to_its_ink():
    sheet = np.full((1000, 800), 255, np.uint8)
    drawing, _ = _room_grid((200, 300), 50, 2)
    sheet[400:600, 250:550] = drawing  # ink spans 300 px of the sheet's 1000
    assert content_box(binarize(sheet)) == (391, 609, 241, 559)  # plus 3 % of 300 px on every side
    sheet[20, 20:30] = 0  # a mark far away widens the box to include it
    assert content_box(binarize(sheet)) == (3, 617, 3, 567)  # 17 px margins: 3 % of the 580 px span
    sheet[10:12, 10:790] = sheet[988:990, 10:790] = 0  # a frame round the sheet: ink spans
    sheet[10:990, 10:12] = sheet[10:990, 788:790] = 0  # most of it, nothing is cut
    assert content_box(binarize(sheet)) == (0, 1000, 0, 800)
    assert content_box(np.zeros((50, 60), bool)) == (0, 50, 0, 60)


class _LeftModel(nn.Module):
    """Class 1 on the left half of its input, class 0 on the right, whatever the input: a
    network whose answer depends on the drawing's orientation."""

    config = {"num_classes": 2}

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        n, _, h, w = x.shape
        left = (torch.arange(w) < w // 2).float().expand(n, 1, h, w)
        return torch.cat([1.0 - left, left], dim=1)


@pytest.mark.parametrize("views, left_share", [(1, 1.0), (2, 0.5), (4, 0.5), (8, 0.5)])
def test_views_average_the_logits_of_the_turned_and_mirrored_drawing(views, left_share):
    segmenter = Segmenter(_LeftModel(), input_size=64, views=views)
    logits = segmenter.predict_logits(np.full((64, 64), 255, np.uint8))
    # the drawing's left half: class 1 in the plain view, class 0 in the mirrored one, ...
    assert logits[1, :, :32].mean() == pytest.approx(left_share)
    assert logits[1, :, 32:].mean() == pytest.approx(1.0 - left_share)
    assert np.allclose(logits.sum(0), 1.0)


@pytest.mark.parametrize("views", [0, 3, 16])
def test_views_other_than_1_2_4_8_raise_value_error(views):
    with pytest.raises(ValueError, match="views"):
        Segmenter(InkModel(), input_size=64, views=views)


def test_real_network_predicts_class_ids_for_grey_and_colour_images():
    segmenter = Segmenter(
        DeepLabV3Plus(**TINY),
        input_size=128,
        letterbox_max_px=200,
        tile_max_side_px=256,
        overlap_px=32,
    )
    rng = np.random.default_rng(0)
    grey = rng.integers(0, 256, (90, 150), dtype=np.uint8)
    assert segmenter.predict(grey).shape == (90, 150)
    colour = rng.integers(0, 256, (400, 250, 3), dtype=np.uint8)  # tiled path
    labels = segmenter.predict(colour)
    assert labels.shape == (400, 250) and labels.max() < 10
    logits = segmenter.predict_logits(colour)
    assert logits.shape == (10, 400, 250)
    np.testing.assert_array_equal(logits.argmax(0), labels)
    same_labels, probabilities = segmenter.predict_with_probabilities(colour)
    np.testing.assert_array_equal(same_labels, labels)
    assert probabilities.shape == (10, 400, 250) and probabilities.dtype == np.float16
    np.testing.assert_allclose(probabilities.astype(np.float32).sum(0), 1.0, atol=5e-3)
    expected = torch.from_numpy(logits).softmax(0).numpy()
    np.testing.assert_allclose(probabilities, expected, atol=1e-3)


@pytest.mark.parametrize(
    "bad",
    [
        np.zeros((10, 10), np.float32),
        np.zeros((4, 50), np.uint8),
        np.zeros((20, 20, 2), np.uint8),
        "image.png",
    ],
)
def test_bad_images_raise_input_error(bad):
    with pytest.raises(InputError):
        to_grey(bad)


def test_shipped_weights_load_verified_and_match_their_model_card():
    from f2n_drake.models import model_path

    path = model_path("segmenter.pt")
    checkpoint = load_segmenter(path)  # raises if the sha256 record does not match
    assert path.stat().st_size <= 25 * 2**20
    assert count_parameters(checkpoint.model) <= 6_000_000
    assert checkpoint.classes[0] == "background" and checkpoint.classes[9] == "front_door"
    card = path.with_name("MODEL_CARD.md").read_text()
    assert f"sha256: `{checkpoint.sha256}`" in card


class _BandModel(nn.Module):
    """Class ``bands[i]`` in the i-th of four column bands of its input, whatever the input."""

    config = {"num_classes": 10}

    def __init__(self, bands: tuple[int, int, int, int]) -> None:
        super().__init__()
        self.bands = bands

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        n, _, h, w = x.shape
        band = torch.arange(w) * 4 // w
        classes = torch.tensor(self.bands)[band]
        logits = torch.nn.functional.one_hot(classes, 10).float().T[:, None, :]
        return logits.expand(10, h, w).expand(n, 10, h, w).clone()


def test_the_storage_network_decides_only_where_the_segmenter_reads_a_living_room_or_bedroom():
    living, bedroom, bathroom = (CLASS_ID[c] for c in ("living", "bedroom", "bathroom"))
    segmenter = _BandModel((living, bedroom, bathroom, living))
    storage = _BandModel((0, 0, 0, bedroom))  # storage (background) but in the last band
    labels = Segmenter(segmenter, input_size=64, views=1, storage_model=storage).predict(
        np.full((64, 64), 255, np.uint8)
    )
    assert (labels[:, :16] == 0).all() and (labels[:, 16:32] == 0).all()
    assert (labels[:, 32:48] == bathroom).all()  # a bathroom is never the storage network's
    assert (labels[:, 48:] == living).all()  # it only ever takes background from it
    alone = Segmenter(segmenter, input_size=64, views=1).predict(np.full((64, 64), 255, np.uint8))
    assert (alone[:, :16] == living).all()
    with pytest.raises(ValueError, match="classes"):
        Segmenter(segmenter, input_size=64, storage_model=InkModel())


def test_shipped_weights_come_with_the_storage_network_and_given_weights_without(tmp_path):
    from f2n_drake.models import model_path

    assert Segmenter.load().storage_model is not None
    assert Segmenter.load(model_path("segmenter.pt")).storage_model is None
    assert Segmenter.load(storage=False).storage_model is None
    assert Segmenter.load(model_path("segmenter.pt"), storage=True).storage_model is not None
    tampered = tmp_path / "storage.pt"
    tampered.write_bytes(model_path("storage.pt").read_bytes()[:-8] + b"\0" * 8)
    sha256_path(tampered).write_text(model_path("storage.sha256").read_text())
    with pytest.raises(InputError, match="sha256"):
        Segmenter.load(storage=tampered)
    card = model_path("MODEL_CARD.md").read_text()
    assert f"sha256: `{load_segmenter(model_path('storage.pt')).sha256}`" in card


def test_own_default_weights_run_alone_unless_their_folder_has_a_storage_network(
    tmp_path, monkeypatch
):
    from f2n_drake.models import model_path

    for name in ("segmenter.pt", "segmenter.sha256"):
        (tmp_path / name).write_bytes(model_path(name).read_bytes())
    monkeypatch.setenv("F2N_DRAKE_MODELS", str(tmp_path))
    assert Segmenter.load().storage_model is None
    for name in ("storage.pt", "storage.sha256"):
        (tmp_path / name).write_bytes(model_path(name).read_bytes())
    assert Segmenter.load().storage_model is not None


def test_a_tiled_drawing_takes_the_storage_network_in_every_tile():
    tiny = dict(input_size=128, letterbox_max_px=200, tile_max_side_px=256, overlap_px=32)
    colour = np.random.default_rng(0).integers(0, 256, (400, 250, 3), dtype=np.uint8)
    storage = _BandModel((0, 0, 0, 0))
    for said, expected in (("living", "background"), ("bathroom", "bathroom")):
        segmenter = _BandModel((CLASS_ID[said],) * 4)
        labels = Segmenter(segmenter, storage_model=storage, **tiny).predict(colour)
        assert labels.shape == (400, 250) and (labels == CLASS_ID[expected]).all()
