"""load_image / parse_drawing: the happy path with a stub segmenter, and every error path."""

from __future__ import annotations

import struct
import zlib

import cv2
import numpy as np
import pytest
from helpers import Oracle, two_rooms

from f2n_drake.core.errors import InputError
from f2n_drake.perception.image import has_enclosed_region, load_image
from f2n_drake.perception.ink import binarize
from f2n_drake.pipeline import parse_drawing


def png_header_only(width: int, height: int) -> bytes:
    """A PNG whose header claims ``width`` x ``height`` but holds almost no pixel data."""

    def chunk(kind: bytes, data: bytes) -> bytes:
        crc = zlib.crc32(kind + data) & 0xFFFFFFFF
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", crc)

    ihdr = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    return (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", ihdr)
        + chunk(b"IDAT", zlib.compress(b"\0" * 64))
        + chunk(b"IEND", b"")
    )


def test_load_image_grey_colour_alpha_16bit(tmp_path):
    img, _ = two_rooms()
    cv2.imwrite(str(tmp_path / "a.png"), img)
    np.testing.assert_array_equal(load_image(tmp_path / "a.png"), img)
    cv2.imwrite(str(tmp_path / "c.jpg"), cv2.cvtColor(img, cv2.COLOR_GRAY2BGR))
    assert load_image(tmp_path / "c.jpg").shape == img.shape
    # black lines on a transparent background: transparent pixels become white paper
    bgra = np.zeros((*img.shape, 4), np.uint8)
    bgra[..., 3] = np.where(img < 128, 255, 0)
    cv2.imwrite(str(tmp_path / "t.png"), bgra)
    np.testing.assert_array_equal(load_image(tmp_path / "t.png"), img)
    cv2.imwrite(str(tmp_path / "w.png"), img.astype(np.uint16) * 257)
    np.testing.assert_array_equal(load_image(tmp_path / "w.png"), img)


@pytest.mark.parametrize(
    ("name", "content", "message"),
    [
        ("missing.png", None, "not found"),
        ("empty.png", b"", "is empty"),
        ("notes.png", b"this is not an image at all", "not an image"),
        ("huge.png", png_header_only(20000, 20000), "too large|megapixel"),
        ("big.png", png_header_only(12000, 9000), "108000000|megapixel limit"),
    ],
)
def test_load_image_bad_files(tmp_path, name, content, message):
    path = tmp_path / name
    if content is not None:
        path.write_bytes(content)
    with pytest.raises(InputError, match=message):
        load_image(path)


@pytest.mark.parametrize(("value", "tone"), [(255, "white"), (0, "black"), (128, "grey")])
def test_load_image_blank(tmp_path, value, tone):
    cv2.imwrite(str(tmp_path / "b.png"), np.full((64, 64), value, np.uint8))
    with pytest.raises(InputError, match=f"blank.*{tone}"):
        load_image(tmp_path / "b.png")


def test_load_image_directory_and_tiny(tmp_path):
    with pytest.raises(InputError, match="not a file"):
        load_image(tmp_path)
    cv2.imwrite(str(tmp_path / "s.png"), np.eye(8, dtype=np.uint8) * 255)
    with pytest.raises(InputError, match="too small"):
        load_image(tmp_path / "s.png")


@pytest.mark.usefixtures("drawings_at_own_size")
def test_parse_drawing_with_stub_segmenter():
    img, lab = two_rooms()
    parsed = parse_drawing(img, segmenter=Oracle(lab), metres_per_px=0.05)
    assert sorted(i.class_name for i in parsed.instances) == [
        "bedroom",
        "door",
        "living",
        "wall",
        "wall",
        "wall",
    ]
    assert parsed.grid is not None and parsed.grid.metres_per_px == 0.05
    assert parsed.scale_source == "argument"
    living = parsed.of_class("living")[0]
    assert living.area_m2(parsed.grid) == pytest.approx(70 * 147 * 0.05**2)
    assert parse_drawing(img, segmenter=Oracle(lab)).grid is None


def test_parse_drawing_no_enclosed_regions_skips_the_network():
    img = np.full((100, 100), 255, np.uint8)
    cv2.line(img, (10, 50), (90, 50), 0, 1)  # a line encloses nothing
    stub = Oracle(np.ones((100, 100), np.uint8))
    with pytest.raises(InputError, match="no enclosed regions"):
        parse_drawing(img, segmenter=stub)
    assert stub.calls == 0


def test_parse_drawing_all_background_and_bad_inputs():
    img, lab = two_rooms()
    with pytest.raises(InputError, match="no enclosed regions"):
        parse_drawing(img, segmenter=Oracle(np.zeros_like(lab)))
    with pytest.raises(InputError, match="shape"):
        parse_drawing(img, segmenter=Oracle(lab[:50]))
    with pytest.raises(InputError, match="metres_per_px"):
        parse_drawing(img, segmenter=Oracle(lab), metres_per_px=-1.0)
    with pytest.raises(InputError, match="blank"):
        parse_drawing(np.full((64, 64), 255, np.uint8), segmenter=Oracle(lab))
    with pytest.raises(InputError, match="uint8"):
        parse_drawing(img.astype(np.float32), segmenter=Oracle(lab))


def test_parse_drawing_missing_weights(tmp_path, monkeypatch):
    import f2n_drake.models

    monkeypatch.setenv("F2N_DRAKE_MODELS", str(tmp_path))
    monkeypatch.setattr(f2n_drake.models, "SHIPPED", tmp_path)
    img, _ = two_rooms()
    with pytest.raises(InputError, match="weights"):
        parse_drawing(img)


@pytest.mark.usefixtures("drawings_at_own_size")
def test_parse_drawing_reads_hairlines_far_lighter_than_the_text():
    dark, lab = two_rooms()
    light = dark.copy()
    light[dark < 128] = 240  # the walls 15 grey levels below the paper: no closed outline
    for img in (dark, light):
        cv2.putText(img, "1711", (40, 60), cv2.FONT_HERSHEY_SIMPLEX, 0.5, 0, 2)  # black text
    assert not has_enclosed_region(binarize(light))
    assert has_enclosed_region(binarize(light, faint=True))
    classes = [
        sorted(i.class_name for i in parse_drawing(img, segmenter=Oracle(lab)).instances)
        for img in (dark, light)
    ]
    assert classes[0] == classes[1] and {"living", "bedroom", "door"} <= set(classes[1])
    with pytest.raises(InputError, match="no enclosed regions"):
        parse_drawing(light, segmenter=Oracle(lab), faint_lines=False)


@pytest.mark.usefixtures("drawings_at_own_size")
def test_parse_drawing_reads_a_drawing_in_light_lines_with_its_faint_strokes():
    dark, lab = two_rooms()
    light = np.where(dark < 128, 200, 255).astype(np.uint8)  # grey hairlines the cut still finds
    for img in (dark, light):
        cv2.putText(img, "1711", (40, 60), cv2.FONT_HERSHEY_SIMPLEX, 0.4, 0, 1)  # black names
        cv2.putText(img, "1712", (120, 60), cv2.FONT_HERSHEY_SIMPLEX, 0.4, 0, 1)
    assert has_enclosed_region(binarize(light))
    parsed = [parse_drawing(img, segmenter=Oracle(lab)) for img in (dark, light)]
    note = "drawn in light lines: faint strokes read as ink"
    assert note in parsed[1].drawing_notes and note not in parsed[0].drawing_notes
    assert sorted(i.class_name for i in parsed[0].instances) == sorted(
        i.class_name for i in parsed[1].instances
    )
