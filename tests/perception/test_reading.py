"""Reading the words on a plan: the lexicon, printed sizes, the text layer, names giving room
types and sizes giving the scale. Fast tests use a stub reader (boxes where the words are
drawn); the OCR model's own tests are marked slow."""

from __future__ import annotations

import json
from importlib.resources import files

import cv2
import numpy as np
import pytest
from helpers import Oracle, simple_plan

from f2n_drake.core.classes import CLASS_ID
from f2n_drake.core.text import TextBox
from f2n_drake.datasets.listing_text import SIZE_FORMATS, print_room_text, size_line
from f2n_drake.datasets.render import render
from f2n_drake.mapping.graph import build_connectivity_graph
from f2n_drake.outputs.exports import write_rooms_geojson
from f2n_drake.perception.printed_sizes import parse_size, printed_scale
from f2n_drake.perception.reading import joined_lines, place_texts, text_ink
from f2n_drake.perception.room_names import NO_CLASS, lexicon, room_class
from f2n_drake.perception.scale import resolve_scale
from f2n_drake.pipeline import parse_drawing


@pytest.mark.parametrize(
    ("name", "cls"),
    [
        ("Kitchen/Diner", "kitchen"),
        ("Great Room / Dining", "living"),
        ("Bedroom 3", "bedroom"),
        ("BEDROOMS", "bedroom"),
        ("Master Bedroom", "bedroom"),
        ("En-suite", "bathroom"),
        ("WC", "bathroom"),
        ("Schlafzimmer", "bedroom"),
        ("Küche", "kitchen"),
        ("Séjour", "living"),
        ("Salle d'eau", "bathroom"),
        ("Dormitorio", "bedroom"),
        ("Baño", "bathroom"),
        ("Bagno", "bathroom"),
        ("Soggiorno", "living"),
        ("Slaapkamer", "bedroom"),
        ("Sovrum", "bedroom"),
        ("Kök", "kitchen"),
        ("MH", "bedroom"),
        ("KH", "bathroom"),
        ("Parveke", "balcony"),
        ("Terrace", "balcony"),
        ("SitingRoom", "living"),  # a letter misread
        ("Hall", NO_CLASS),
        ("Walk-in closet", NO_CLASS),
        ("Utility", NO_CLASS),
        ("Garage", NO_CLASS),
        ("Study", NO_CLASS),
        ("4.50 x 2.08m", None),
        ("88 sf", None),
        ("All measurements are approximate", None),
    ],
)
def test_a_printed_name_gives_its_room_class(name, cls):
    assert room_class(name) == cls


def test_the_lexicon_is_a_data_file_of_eight_languages_and_the_ten_classes():
    text = files("f2n_drake.perception").joinpath("room_names.yaml").read_text()
    for language in ("en", "de", "fr", "es", "it", "nl", "sv", "fi"):
        assert f"  {language}: [" in text
    assert set(lexicon().values()) == {
        "living",
        "bedroom",
        "bathroom",
        "kitchen",
        "balcony",
        "none",
    }


@pytest.mark.parametrize(
    ("text", "area_m2", "sides_m"),
    [
        ("4.50 x 2.08m", 9.36, (4.5, 2.08)),
        ("3.66 x 2.59 m", 3.66 * 2.59, (3.66, 2.59)),
        ("4,50 x 2,08 m", 9.36, (4.5, 2.08)),
        ("4500 x 2080 mm", 9.36, (4.5, 2.08)),
        ("14'9\" x 6'10\"", 4.4958 * 2.0828, (4.4958, 2.0828)),
        ("13’4” x 9’1”", 4.064 * 2.7686, (4.064, 2.7686)),
        ("12.5 m²", 12.5, None),
        ("12.5 m2", 12.5, None),
        ("88 sf", 88 * 0.3048**2, None),
        ("Great Room / Dining 365 sf", 365 * 0.3048**2, None),
        ("Approx. 1295 sq. feet (120.31 sq. metres)", 120.31, None),
    ],
)
def test_printed_sizes_are_parsed_in_metres(text, area_m2, sides_m):
    size = parse_size(text)
    assert size.area_m2 == pytest.approx(area_m2, rel=1e-3)
    assert size.sides_m == (pytest.approx(sides_m, rel=1e-3) if sides_m else None)


@pytest.mark.parametrize("text", ["Bedroom 2", "12 x 10", "172× 112", "2", "0.1 x 0.1 m"])
def test_what_is_no_size_is_not_read_as_one(text):
    assert parse_size(text) is None


def test_every_generated_size_format_parses_back_to_its_truth():
    for size_format in SIZE_FORMATS:
        size = parse_size(size_line((4.37, 2.91), 12.7, size_format))
        assert size.area_m2 == pytest.approx(4.37 * 2.91 if size.sides_m else 12.7, rel=0.01), (
            size_format
        )


def test_text_ink_is_the_strokes_wholly_inside_a_box():
    lines = np.zeros((60, 100), bool)
    lines[5, :] = True  # a wall running through the box
    cv2.putText(img := np.zeros((60, 100), np.uint8), "AB", (30, 30), 0, 0.6, 255, 1)
    lines |= img > 0
    ink = text_ink(lines, [TextBox("AB", 0.9, (28, 4, 60, 34))])
    assert ink[img > 0].all()
    assert not ink[5].any()


def test_a_stroke_joining_two_lines_of_text_is_text():
    lines = np.zeros((60, 100), bool)
    lines[10:40, 30] = True  # runs from the upper line's box into the lower one's
    boxes = [TextBox("Reception", 0.9, (20, 8, 80, 22)), TextBox("Room", 0.9, (20, 24, 80, 42))]
    assert text_ink(lines, boxes)[10:40, 30].all()
    assert not text_ink(lines, boxes[:1]).any()


def test_a_name_on_two_lines_is_read_as_one_and_sizes_are_never_joined():
    texts = [
        TextBox("Reception Room /", 0.97, (10, 10, 100, 20)),
        TextBox("Kitchen", 0.9, (30, 22, 80, 32)),
        TextBox("5.04m x 4.48m", 0.9, (20, 34, 90, 44)),
        TextBox("15'10 x 12'4", 0.9, (200, 10, 290, 20)),
        TextBox("+ wardrobe", 0.9, (210, 22, 280, 32)),
    ]
    joined = joined_lines(texts)
    assert [t.text for t in joined] == [
        "Reception Room / Kitchen",
        "5.04m x 4.48m",
        "15'10 x 12'4",
        "+ wardrobe",
    ]
    assert joined[0].box_px == (10, 10, 100, 32) and joined[0].confidence == 0.9
    assert room_class(joined[0].text) == "living"


def test_a_name_written_down_the_page_is_joined_to_no_line():
    texts = [
        TextBox("KITCHEN", 0.95, (40, 40, 141, 64)),
        TextBox("BEDROOM", 0.95, (35, 66, 61, 206)),  # a narrow room's name, written downward
    ]
    assert [t.text for t in joined_lines(texts)] == ["KITCHEN", "BEDROOM"]


def test_two_names_stacked_are_one_room_s_name():
    texts = [
        TextBox("RECEPTION ROOM", 0.95, (60, 227, 132, 238)),  # no "/": read without it
        TextBox("KITCHEN", 0.9, (76, 236, 117, 248)),
        TextBox("19'7 x 15'2", 0.9, (75, 250, 117, 260)),
        TextBox("Open", 0.9, (300, 128, 320, 143)),  # no name: stays a line of its own
        TextBox("Living", 0.9, (292, 146, 322, 164)),
        TextBox("Room/ Kitchen", 0.9, (294, 166, 324, 180)),
    ]
    joined = [t.text for t in joined_lines(texts)]
    assert joined == ["RECEPTION ROOM KITCHEN", "19'7 x 15'2", "Open", "Living Room/ Kitchen"]
    assert room_class(joined[0]) == "living" and room_class(joined[3]) == "living"


def _named_drawing(names: dict[str, tuple[str, float]], sizes: dict[str, str] | None = None):
    """simple_plan drawn at 400 px, and a stub reader finding ``names`` (class -> (text,
    confidence)) and ``sizes`` in the middle of the room of each class."""
    rendered = render(simple_plan(), 400)
    boxes = []
    for cls, (text, confidence) in names.items():
        rows, cols = np.nonzero(rendered.labels == CLASS_ID[cls])
        r, c = int(rows.mean()), int(cols.mean())
        boxes.append(TextBox(text, confidence, (c - 20, r - 8, c + 20, r + 2)))
        if sizes and cls in sizes:
            boxes.append(TextBox(sizes[cls], confidence, (c - 20, r + 6, c + 20, r + 16)))
    return rendered, lambda _grey: boxes


@pytest.mark.usefixtures("drawings_at_own_size")
def test_a_confident_name_outweighs_the_pixels_and_a_doubtful_one_does_not():
    rendered, reader = _named_drawing({"bedroom": ("Schlafzimmer", 0.95)})
    wrong = np.where(rendered.labels == CLASS_ID["bedroom"], CLASS_ID["living"], rendered.labels)
    parsed = parse_drawing(rendered.image, segmenter=Oracle(wrong), reader=reader)
    (named,) = [i for i in parsed.instances if i.name]
    assert (named.name, named.class_name) == ("Schlafzimmer", "bedroom")
    assert parsed.texts[0].instance_id == named.id

    rendered, reader = _named_drawing({"bedroom": ("Schlafzimmer", 0.6)})
    parsed = parse_drawing(rendered.image, segmenter=Oracle(wrong), reader=reader)
    (named,) = [i for i in parsed.instances if i.name]
    assert named.class_name == "living"  # all its pixels say living


@pytest.mark.usefixtures("drawings_at_own_size")
def test_a_room_named_indoors_is_no_balcony():
    rendered, reader = _named_drawing({"living": ("Storage", 0.95)})
    room = rendered.labels == CLASS_ID["living"]  # the room with the window
    rows = np.nonzero(room.any(axis=1))[0]
    most = room & (np.arange(room.shape[0])[:, None] < np.percentile(rows, 70))
    labels = np.where(most, CLASS_ID["balcony"], rendered.labels)  # 30 % of it still living
    # no railing is drawn: the balconies prior would close it whatever its name
    plain = parse_drawing(rendered.image, segmenter=Oracle(labels), reader=None, balconies=False)
    assert len(plain.of_class("balcony")) == 1
    named = parse_drawing(rendered.image, segmenter=Oracle(labels), reader=reader, balconies=False)
    (storage,) = [i for i in named.instances if i.name == "Storage"]
    assert storage.class_name == "living"  # a storeroom, a hall, a study is indoors
    assert not named.of_class("balcony")


@pytest.mark.usefixtures("drawings_at_own_size")
def test_a_named_room_voted_background_becomes_an_instance():
    rendered, reader = _named_drawing({"bedroom": ("BEDROOM", 0.99)})
    wrong = np.where(rendered.labels == CLASS_ID["bedroom"], 0, rendered.labels)
    assert not parse_drawing(rendered.image, segmenter=Oracle(wrong), reader=None).of_class(
        "bedroom"
    )
    parsed = parse_drawing(rendered.image, segmenter=Oracle(wrong), reader=reader)
    assert [i.name for i in parsed.of_class("bedroom")] == ["BEDROOM"]


def test_a_drawing_with_no_words_parses_as_unread():
    rendered = render(simple_plan(), 400)
    unread = parse_drawing(rendered.image, segmenter=Oracle(rendered.labels), reader=None)
    read = parse_drawing(rendered.image, segmenter=Oracle(rendered.labels), reader=lambda g: [])
    assert read.texts == []
    assert [(i.id, i.class_name, i.area_px) for i in read.instances] == [
        (i.id, i.class_name, i.area_px) for i in unread.instances
    ]
    np.testing.assert_array_equal(read.instance_ids, unread.instance_ids)
    assert "door" in resolve_scale(read).scale_source


def test_the_words_of_a_negative_are_read_dark_on_light():
    rendered = render(simple_plan(), 400)
    seen = []

    def reader(grey):
        seen.append(grey)
        return []

    for image in (rendered.image, 255 - rendered.image):
        parse_drawing(image, segmenter=Oracle(rendered.labels), reader=reader)
    as_drawn, negative = seen
    assert np.median(as_drawn) == 255 and np.median(negative) == 255
    assert np.mean(np.abs(as_drawn.astype(int) - negative)) < 2


@pytest.mark.usefixtures("drawings_at_own_size")
def test_printed_sizes_give_the_scale_and_an_argument_still_wins(tmp_path):
    # living 3.9 x 4 m, bedroom 3.9 x 4 m, printed as listings print them
    rendered, reader = _named_drawing(
        {"living": ("Lounge", 0.9), "bedroom": ("Bedroom", 0.9)},
        {"living": "3.90 x 4.00m", "bedroom": "15.6 m2"},
    )
    parsed = parse_drawing(rendered.image, segmenter=Oracle(rendered.labels), reader=reader)
    scale = printed_scale(parsed)
    assert scale.n_rooms == 2
    assert scale.metres_per_px == pytest.approx(rendered.grid.metres_per_px, rel=0.03)
    resolved = resolve_scale(parsed)
    assert resolved.scale_source.startswith("from 2 printed room sizes, spread")
    assert resolve_scale(parsed, metres_per_px=0.05).scale_source == "argument"

    write_rooms_geojson(resolved, tmp_path / "rooms.geojson")
    features = json.loads((tmp_path / "rooms.geojson").read_text())["features"]
    assert {f["properties"]["class"]: f["properties"]["name"] for f in features}["living"] == (
        "Lounge"
    )
    graph = build_connectivity_graph(resolved)
    assert graph.nodes["bedroom_0"]["name"] == "Bedroom"


def test_texts_are_placed_in_the_instance_under_most_of_their_box():
    ids = np.zeros((20, 40), np.int32)
    ids[:, :25] = 3
    ids[:, 25:] = 4
    texts = place_texts([TextBox("a", 1.0, (2, 2, 30, 10)), TextBox("b", 1.0, (0, 0, 0, 0))], ids)
    assert [t.instance_id for t in texts] == [3, None]


def test_generated_drawings_print_each_room_with_its_truth():
    rendered = render(simple_plan(), 400)
    image, printed = print_room_text(
        rendered.image, rendered.labels, rendered.grid, np.random.default_rng(0)
    )
    assert sorted(p.class_name for p in printed) == ["bedroom", "living"]
    assert (image < rendered.image).any()
    for room in printed:
        assert room_class(room.name) == room.class_name
        assert parse_size(room.size) is not None


def test_the_reader_ships_its_models():
    models = files("rapidocr_onnxruntime").joinpath("models")
    names = {p.name for p in models.iterdir()}
    assert {"ch_PP-OCRv4_det_infer.onnx", "ch_PP-OCRv4_rec_infer.onnx"} <= names


@pytest.mark.slow
def test_the_reader_reads_names_and_sizes_drawn_on_paper():
    from f2n_drake.perception.reading import read_words

    image = np.full((200, 400), 255, np.uint8)
    cv2.putText(image, "KITCHEN", (40, 80), cv2.FONT_HERSHEY_SIMPLEX, 1.0, 0, 2, cv2.LINE_AA)
    cv2.putText(image, "4.50 x 2.08m", (40, 140), cv2.FONT_HERSHEY_SIMPLEX, 1.0, 0, 2)
    texts = read_words(image)
    assert [t.text.replace(" ", "") for t in texts] == ["KITCHEN", "4.50x2.08m"]
    assert all(t.confidence > 0.8 for t in texts)
    c0, r0, c1, r1 = texts[0].box_px
    assert c0 <= 42 and r0 <= 60 and c1 >= 150 and r1 >= 78


@pytest.mark.slow
def test_names_written_up_or_down_a_narrow_room_are_read():
    from f2n_drake.perception.reading import read_words

    image = np.full((300, 300), 255, np.uint8)
    cv2.putText(image, "KITCHEN", (40, 60), cv2.FONT_HERSHEY_SIMPLEX, 0.8, 0, 2)
    word = np.full((60, 220), 255, np.uint8)
    cv2.putText(word, "BEDROOM", (10, 40), cv2.FONT_HERSHEY_SIMPLEX, 0.8, 0, 2)
    image[80:300, 20:80] = np.rot90(word, -1)  # written downward
    image[80:300, 200:260] = np.rot90(word, 1)  # written upward
    texts = read_words(image)
    assert sorted(t.text for t in texts) == ["BEDROOM", "BEDROOM", "KITCHEN"]  # none joined
    assert all(t.confidence > 0.8 for t in texts)
    down = next(t for t in texts if t.text == "BEDROOM" and t.box_px[0] < 100)
    c0, r0, c1, r1 = down.box_px
    assert c0 >= 20 and c1 <= 80 and r1 - r0 > 2 * (c1 - c0)


@pytest.mark.slow
def test_the_reading_cli_measures_scale_error_against_the_truth(capsys):
    from f2n_drake.evaluate import reading as reading_cli

    args = ["--synthetic", "1", "--seed", "3", "--size", "600", "--json"]
    assert reading_cli.main(args, segmenter_for=lambda r: Oracle(r.labels)) == 0
    summary = json.loads(capsys.readouterr().out)["summary"]
    assert summary["n_with_scale"] == 1
    assert abs(summary["scale_error_median"]) < 0.05
    assert summary["names_read"] > 0.5


def test_a_small_drawing_is_enlarged_for_detection():
    # letters 7 px high on a 500 px listing are too small for the detector at its own size
    from f2n_drake.perception.reading import _detection_input

    x = _detection_input(np.full((300, 500), 255, np.uint8))
    assert x.shape == (1, 3, 384, 640)  # 1.25 times larger, sides multiples of 32
    assert _detection_input(np.full((300, 700), 255, np.uint8)).shape == (1, 3, 320, 736)
    big = _detection_input(np.full((1500, 2000), 255, np.uint8))
    assert big.shape == (1, 3, 1120, 1504)  # a large one is shrunk to 0.75 of its size
