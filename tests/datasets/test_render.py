"""Tests of the drawing/label renderer on a hand-made plan and on the real ResPlan sample."""

from __future__ import annotations

import dataclasses

import cv2
import numpy as np
import pytest
from shapely.geometry import Polygon, box

from f2n_drake.core.classes import CLASS_ID, PALETTE, SPACE_CLASSES
from f2n_drake.core.errors import InputError
from f2n_drake.core.paths import resplan_sample_path
from f2n_drake.core.plan import FloorPlan
from f2n_drake.datasets.generator import generate_plan
from f2n_drake.datasets.listing_marks import FITTED_M, FURNITURE_M
from f2n_drake.datasets.looks import restyle
from f2n_drake.datasets.render import (
    DrawingStyle,
    colorize,
    render,
    render_drawing,
    render_labels,
)
from f2n_drake.datasets.resplan import load_resplan
from f2n_drake.perception.ink import binarize, free_marks

T = 0.2  # wall thickness [m]


def small_plan() -> FloorPlan:
    """Living (0.2..4.0) | bedroom (4.2..8.0) x (0.2..4.0), kitchen open to the living room
    above it (0.2..4.0 x 4.0..6.0 is not walled off from the living room), 0.2 m walls."""
    living, kitchen = box(0.2, 0.2, 4.0, 4.0), box(0.2, 4.0, 4.0, 6.0)
    bedroom = box(4.2, 0.2, 8.0, 4.0)
    door, front, window = box(4.0, 1.0, 4.2, 2.0), box(0.0, 1.5, 0.2, 2.5), box(5.0, 4.0, 6.5, 4.2)
    outer = box(0.0, 0.0, 8.2, 6.2).difference(box(0.2, 0.2, 8.0, 6.0))
    inner_walls = box(4.0, 0.2, 4.2, 6.0).union(box(4.2, 4.0, 8.0, 4.2))
    walls = outer.union(inner_walls).difference(door.union(front).union(window))
    storage = box(4.2, 4.2, 8.0, 6.0)  # an extra: drawn (its walls are the plan's), label 0
    return FloorPlan(
        {
            "living": [living],
            "kitchen": [kitchen],
            "bedroom": [bedroom],
            "door": [door],
            "front_door": [front],
            "window": [window],
            "wall": list(getattr(walls, "geoms", [walls])),
            "storage": [storage],
        },
        T,
        "test",
    )


def label_at(rendered, xy_m) -> int:
    col, row = np.round(rendered.grid.to_px(np.asarray(xy_m))).astype(int)
    return int(rendered.labels[row, col])


def white_components(image: np.ndarray, connectivity: int) -> np.ndarray:
    return cv2.connectedComponents((image > 127).astype(np.uint8), connectivity=connectivity)[1]


def test_labels_match_polygons():
    plan = small_plan()
    r = render(plan, 256)
    assert r.image.shape == r.labels.shape == (256, 256)
    assert r.image.dtype == r.labels.dtype == np.uint8
    for name, xy in [
        ("living", (2, 2)),
        ("bedroom", (6, 2)),
        ("kitchen", (2, 5)),
        ("door", (4.1, 1.5)),
        ("front_door", (0.1, 2.0)),
        ("window", (5.7, 4.1)),
        ("wall", (4.1, 3.0)),
        ("background", (6, 5)),
        ("background", (-0.3, 1)),
    ]:
        assert label_at(r, xy) == CLASS_ID[name], name
    px_area = r.grid.metres_per_px**2
    for name in ("living", "bedroom", "kitchen", "wall"):
        expected = sum(p.area for p in plan[name]) / px_area
        got = np.count_nonzero(r.labels == CLASS_ID[name])
        perimeter_px = sum(p.length for p in plan[name]) / r.grid.metres_per_px
        assert abs(got - expected) <= 0.6 * perimeter_px, name


def test_rooms_are_enclosed_white_regions_and_open_kitchen_merges():
    r = render(small_plan(), 256)
    for connectivity in (4, 8):
        comp = white_components(r.image, connectivity)

        def at(xy, comp=comp):
            col, row = np.round(r.grid.to_px(np.asarray(xy))).astype(int)
            return comp[row, col]

        outside, living, bedroom, kitchen = at((-0.3, 1)), at((2, 2)), at((6, 2)), at((2, 5))
        assert 0 not in (outside, living, bedroom, kitchen)  # all are white pixels
        assert len({outside, living, bedroom}) == 3
        assert kitchen == living


def test_drawing_outlines_connectors_not_rooms():
    r = render(small_plan(), 256)
    ink = r.image < 128
    # The open edge between kitchen and living room (y = 4, x in 0.5..3.5) carries no ink.
    edge_m = np.array([[x, 4.0] for x in np.linspace(0.5, 3.5, 20)])
    cols = np.round(r.grid.to_px(edge_m)).astype(int)
    assert not ink[cols[:, 1], cols[:, 0]].any()
    # Every ink pixel lies on or right beside a non-room label (wall, door, window, outside...).
    non_room = ~np.isin(r.labels, [1, 2, 3, 4])
    near_non_room = cv2.dilate(non_room.astype(np.uint8), np.ones((3, 3), np.uint8)) > 0
    assert np.all(near_non_room[ink])


def test_filled_walls_and_grey_ink():
    r = render(small_plan(), 256, style=DrawingStyle(filled_walls=True, grey_lines=100))
    wall = r.labels == CLASS_ID["wall"]
    assert np.mean(r.image[wall] == 100) > 0.9
    assert r.image.min() == 100


def test_rotation_moves_image_and_labels_together():
    plan = small_plan()
    style = DrawingStyle(rotation_deg=3.0, filled_walls=True)
    r = render(plan, 256, style=style)
    straight = render(plan, 256, style=DrawingStyle(filled_walls=True))
    wall = r.labels == CLASS_ID["wall"]
    assert np.mean(r.image[wall] < 128) > 0.9
    assert np.mean(r.labels != straight.labels) > 0.01
    # The rotated plan still fits in the image with a margin.
    assert not r.labels[:8].any() and not r.labels[-8:].any()
    assert not r.labels[:, :8].any() and not r.labels[:, -8:].any()


def test_polygon_hole_keeps_what_lies_under_it():
    room = box(0, 0, 4, 4)
    wall_with_hole = Polygon(box(-1, -1, 5, 5).exterior.coords, [box(0, 0, 4, 4).exterior.coords])
    r = render(FloorPlan({"bedroom": [room], "wall": [wall_with_hole]}, 1.0), 128)
    assert label_at(r, (2, 2)) == CLASS_ID["bedroom"]
    assert label_at(r, (-0.5, 2)) == CLASS_ID["wall"]
    labels = render_labels(FloorPlan({"wall": [wall_with_hole]}, 1.0), r.grid)
    assert labels[64, 64] == 0


def test_door_arcs_add_ink_in_rooms_only():
    plan = small_plan()
    clean = render(plan, 256)
    arcs = render(plan, 256, style=DrawingStyle(door_arcs=True))
    np.testing.assert_array_equal(arcs.labels, clean.labels)
    added = (arcs.image < 128) & (clean.image >= 128)
    assert added.sum() > 20
    assert np.all(np.isin(arcs.labels[added], [1, 2, 3, 4, 7, 9]))


def test_metres_per_px_sizes_image_to_plan():
    r = render(small_plan(), style=None, metres_per_px=0.05, margin_px=10)
    assert r.image.shape == (round(6.2 / 0.05) + 20, round(8.2 / 0.05) + 20)
    np.testing.assert_allclose(r.grid.to_px(np.array([0.0, 6.2])), [9.5, 9.5])
    with pytest.raises(InputError, match="limit"):
        render(small_plan(), metres_per_px=0.0001)


def test_degradations_and_determinism():
    plan = small_plan()
    style = DrawingStyle(
        blur_sigma_px=1.0,
        noise_std=8,
        jpeg_quality=40,
        antialias=True,
        line_width_px=3,
        door_arcs=True,
    )
    a = render(plan, 128, style=style, rng=np.random.default_rng(5))
    b = render(plan, 128, style=style, rng=np.random.default_rng(5))
    np.testing.assert_array_equal(a.image, b.image)
    clean = render(plan, 128)
    assert len(np.unique(a.image)) > 20 and len(np.unique(clean.image)) == 2
    np.testing.assert_array_equal(render_drawing(plan, clean.grid), clean.image)


def test_random_styles_are_valid_varied_and_seeded():
    styles = [DrawingStyle.random(np.random.default_rng(s)) for s in range(200)]
    assert styles[3] == DrawingStyle.random(np.random.default_rng(3))
    assert len(set(styles)) > 150
    clean = sum(
        s.noise_std == 0 and s.jpeg_quality is None and s.blur_sigma_px == 0 for s in styles
    )
    assert 40 < clean < 160  # mostly clean-ish, sometimes degraded
    assert {s.line_width_px for s in styles} == {1, 2, 3}
    assert all(abs(s.rotation_deg) <= 3 for s in styles)


@pytest.mark.parametrize(
    "bad",
    [
        dict(line_width_px=0),
        dict(line_width_px=4),
        dict(rotation_deg=10),
        dict(jpeg_quality=10),
        dict(grey_lines=200),
        dict(noise_std=-1),
    ],
)
def test_style_validation(bad):
    with pytest.raises(ValueError):
        DrawingStyle(**bad)


def test_empty_plan_and_tiny_size_raise():
    with pytest.raises(InputError, match="no geometry"):
        render(FloorPlan({}, 0.2))
    with pytest.raises(InputError, match="margin"):
        render(small_plan(), 32, margin_px=16)
    with pytest.raises(InputError, match="above the 16384 px limit"):
        render(small_plan(), 100_000)  # refused before any pixel is allocated


def test_colorize_uses_palette():
    labels = np.arange(10, dtype=np.uint8).reshape(2, 5)
    rgb = colorize(labels)
    assert rgb.shape == (2, 5, 3) and rgb.dtype == np.uint8
    assert tuple(rgb[1, 2]) == PALETTE[7]
    with pytest.raises(ValueError):
        colorize(np.array([[12]], np.uint8))


@pytest.fixture(scope="module")
def resplan_plans():
    return {p.metadata["id"]: p for p in load_resplan(resplan_sample_path())}


@pytest.mark.parametrize("plan_id", [13, 0])
def test_resplan_rooms_are_enclosed_regions(resplan_plans, plan_id):
    plan = resplan_plans[plan_id]
    r = render(plan, 512)
    comp = white_components(r.image, 8)
    border = set(np.unique(np.concatenate([comp[0], comp[-1], comp[:, 0], comp[:, -1]]))) - {0}
    region = {}
    for name in ("living", "bedroom", "bathroom", "kitchen"):
        for i, poly in enumerate(plan[name]):
            if poly.area < 1.0:  # plan 0 has two living slivers < 0.3 m²
                continue
            col, row = np.round(r.grid.to_px(np.asarray(poly.representative_point().coords[0])))
            c = comp[int(row), int(col)]
            assert c != 0 and c not in border, (name, i)
            region[name, i] = c
    if plan_id == 13:  # open kitchen: one white region with the living room
        assert region["kitchen", 0] == region["living", 0]
    bedrooms = [c for (n, _), c in region.items() if n == "bedroom"]
    assert len(set(bedrooms)) == len(bedrooms)
    assert not set(bedrooms) & {region["living", 0]}


def test_restyle_negative_and_room_fills():
    drawn = render(generate_plan(0), 256)
    rng = np.random.default_rng(0)
    negative = restyle(drawn, "negative", rng)
    np.testing.assert_array_equal(negative.image, 255 - drawn.image)
    np.testing.assert_array_equal(negative.labels, drawn.labels)
    fills = restyle(drawn, "room-fills", rng).image
    rooms = np.isin(drawn.labels, [CLASS_ID[n] for n in SPACE_CLASSES])
    paper = drawn.image == 255
    assert (fills[rooms & paper] < 236).all() and (fills[rooms & paper] >= 170).all()
    np.testing.assert_array_equal(fills[~rooms], drawn.image[~rooms])  # walls, outside as drawn
    assert (fills <= drawn.image).all()  # ink stays as dark as it was
    assert restyle(drawn, "drawn", rng).image is drawn.image
    wide = restyle(drawn, "wide-margins", rng)
    pad = 192  # 0.75 x 256 px
    assert wide.image.shape == wide.labels.shape == wide.grid.shape == (256 + 2 * pad,) * 2
    np.testing.assert_array_equal(wide.image[pad:-pad, pad:-pad], drawn.image)
    np.testing.assert_array_equal(wide.labels[pad:-pad, pad:-pad], drawn.labels)
    assert (wide.image[:pad] == 255).all() and (wide.labels[:, -pad:] == 0).all()
    corner = np.array([[1.0, 2.0]])  # the same point of the plan, moved by the padding
    np.testing.assert_allclose(wide.grid.to_px(corner), drawn.grid.to_px(corner) + pad)
    shaded = restyle(drawn, "shaded", rng).image.astype(float)
    paper = drawn.image == 255
    assert shaded[paper].max() >= 250 and 150 <= shaded[paper].min() <= 180  # 60-70 % light
    assert (shaded <= drawn.image).all()
    hatched = restyle(drawn, "hatched", rng)
    walls = drawn.labels == CLASS_ID["wall"]
    np.testing.assert_array_equal(hatched.image[~walls], drawn.image[~walls])
    assert (hatched.image[walls] < drawn.image[walls]).mean() > 0.2  # lines across the walls
    big = render(generate_plan(0), 512)  # letters 0.2-0.35 m high: 5 px and more
    labelled = restyle(big, "labelled", rng)
    np.testing.assert_array_equal(labelled.labels, big.labels)
    written = labelled.image < big.image
    assert written.sum() > 100
    assert np.isin(big.labels[written], [CLASS_ID[n] for n in SPACE_CLASSES]).all()  # in rooms
    lines = binarize(labelled.image)
    assert free_marks(lines).annotation[lines & written].all()  # free-standing: touching no outline
    furnished = restyle(big, "furnished", rng)
    drawn_in = furnished.image < big.image
    assert drawn_in.sum() > 100
    assert np.isin(big.labels[drawn_in], [CLASS_ID[n] for n in FURNITURE_M]).all()
    lines = binarize(furnished.image)
    assert free_marks(lines).ink[lines & drawn_in].all()  # standing free in the rooms
    fitted = restyle(big, "fitted", rng)  # furniture against the walls: part of the plan's ink
    drawn_in = fitted.image < big.image
    assert drawn_in.sum() > 100
    assert np.isin(big.labels[drawn_in], [CLASS_ID[n] for n in (*FITTED_M, "wall")]).all()
    lines = binarize(fitted.image)
    assert not free_marks(lines).ink[lines & drawn_in].any()
    sheet = restyle(big, "sheet", rng)  # title block, scale bar, dimension chains round the plan
    near, far = round(0.12 * 512), round(0.3 * 512)
    plain = np.pad(big.image, ((near, far), (near, far)), constant_values=255)
    np.testing.assert_array_equal(sheet.labels, np.pad(big.labels, ((near, far), (near, far))))
    drawn_on = sheet.image < plain
    assert drawn_on.sum() > 500 and (sheet.labels[drawn_on] == 0).all()  # all on the paper
    lines = binarize(sheet.image)
    assert free_marks(lines).annotation[lines & drawn_on].all()  # the sheet's, not the plan's
    sign = restyle(big, "evacuation", rng)  # routes, arrows, extinguishers, a legend, in colour
    far = round(0.45 * 512)
    assert sign.image.shape == (512, 512 + far, 3) and sign.labels.shape == (512, 512 + far)
    np.testing.assert_array_equal(sign.labels[:, :512], big.labels)
    chroma = sign.image.max(axis=2).astype(int) - sign.image.min(axis=2)
    assert (chroma[:, :512] > 100).sum() > 200 and (chroma[:, 512:] > 100).sum() > 50
    with pytest.raises(InputError, match="unknown look"):
        restyle(drawn, "sepia", rng)


def test_a_faint_drawing_goes_on_a_sheet_too():
    rendered = render(generate_plan(0), 256)
    faint = dataclasses.replace(rendered, image=(128 + rendered.image // 2).astype(np.uint8))
    sheet = restyle(faint, "sheet", np.random.default_rng(0))  # lines no darker than grey 128
    near, far = round(0.12 * 256), round(0.3 * 256)
    assert sheet.image.shape == (256 + near + far, 256 + near + far)
    plain = np.pad(faint.image, ((near, far), (near, far)), constant_values=255)
    assert (sheet.image < plain).sum() > 100  # the chains, title block and scale bar drawn


def test_restyle_textured_floors_paints_planks_and_tiles_under_the_lines():
    drawn = render(generate_plan(0), 512)
    textured = restyle(drawn, "textured-floors", np.random.default_rng(0))
    np.testing.assert_array_equal(textured.labels, drawn.labels)
    assert (textured.image <= drawn.image).all()  # lines on top, as dark as drawn
    painted = [CLASS_ID[n] for n in ("living", "bedroom", "kitchen", "bathroom")]
    floors = np.isin(drawn.labels, painted)
    np.testing.assert_array_equal(textured.image[~floors], drawn.image[~floors])
    for name in ("living", "bathroom"):
        paper = (drawn.labels == CLASS_ID[name]) & (drawn.image == 255)
        assert 150 <= np.median(textured.image[paper]) <= 236
        assert np.ptp(textured.image[paper]) > 20  # plank edges or tile joints
