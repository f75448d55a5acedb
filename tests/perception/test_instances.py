"""Instances from hand-drawn synthetic drawings whose answers are known."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from helpers import BEDROOM, DOOR, KITCHEN, LIVING, WALL, classes, two_rooms

from f2n_drake.core.classes import CLASS_ID, OPENING
from f2n_drake.core.errors import InputError
from f2n_drake.core.raster import PixelGrid
from f2n_drake.perception.ink import ink_is_dark, stroke_width_px
from f2n_drake.perception.instances import (
    SplitOptions,
    _regions,
    binarize,
    extract_instances,
    vote_corrected_labels,
)


def open_plan(size: int = 200) -> tuple[np.ndarray, np.ndarray]:
    """One walled room: living on the left 60 %, kitchen on the right 40 %, no wall between."""
    img = np.full((size, size), 255, np.uint8)
    lab = np.zeros((size, size), np.uint8)
    lab[20:181, 20:181] = WALL
    lab[27:174, 27:115] = LIVING
    lab[27:174, 115:174] = KITCHEN
    cv2.rectangle(img, (20, 20), (180, 180), 0, 1)
    cv2.rectangle(img, (26, 26), (174, 174), 0, 1)
    return img, lab


def test_two_rooms_door_and_walls():
    img, lab = two_rooms()
    parsed = extract_instances(img, lab)
    assert classes(parsed) == ["bedroom", "door", "living", "wall", "wall", "wall"]
    by_class = {i.class_name: i for i in parsed.instances}
    living = by_class["living"]
    assert living.area_px == 70 * 147  # inside the outline: cols 27..96, rows 27..173
    # the contour runs through the boundary pixel centres of the region
    np.testing.assert_allclose(living.contour_px.min(axis=0), [27, 27])
    np.testing.assert_allclose(living.contour_px.max(axis=0), [96, 173])
    assert living.centroid_px == pytest.approx((61.5, 100.0))
    assert living.votes == {LIVING: living.area_px}
    # ids are consistent with the id image; line pixels and the outside have id 0
    for inst in parsed.instances:
        assert (parsed.instance_ids == inst.id).sum() == inst.area_px
    assert parsed.instance_ids[26, 50] == 0 and parsed.instance_ids[5, 5] == 0
    assert parsed.grid is None and parsed.scale_source == "unknown"


def test_border_region_and_specks_dropped():
    img, lab = two_rooms()
    lab[:] = np.where(lab == 0, LIVING, lab)  # the outside is predicted living: still dropped
    cv2.rectangle(img, (26, 60), (28, 62), 0, 1)  # a 1 px enclosed speck on the wall line
    cv2.rectangle(img, (60, 60), (62, 62), 0, 1)  # a free-standing speck: the room's paper
    parsed = extract_instances(img, lab, min_area_px=4)
    assert classes(parsed) == ["bedroom", "door", "living", "wall", "wall", "wall"]
    assert parsed.instance_ids[61, 27] == 0
    assert parsed.instance_ids[61, 61] == parsed.instance_ids[100, 60] > 0


def test_background_voted_region_dropped():
    img, lab = two_rooms()
    lab[27:174, 104:174] = 0  # right room is storage (background)
    parsed = extract_instances(img, lab)
    assert "bedroom" not in classes(parsed)
    assert parsed.instance_ids[100, 140] == 0


def test_vote_corrects_noisy_boundary():
    img, lab = two_rooms()
    rng = np.random.default_rng(0)
    noisy = lab.copy()
    # the network bleeds the wall class 3 px into the rooms and sprinkles 10 % random errors
    noisy[27:174, 27:30] = WALL
    noisy[27:174, 94:97] = DOOR
    flip = rng.random(lab.shape) < 0.10
    noisy[flip] = rng.integers(0, 10, flip.sum())
    parsed = extract_instances(img, noisy)
    assert classes(parsed) == ["bedroom", "door", "living", "wall", "wall", "wall"]
    assert parsed.labels is noisy or np.array_equal(parsed.labels, noisy)  # raw kept
    voted = vote_corrected_labels(parsed)
    inside = parsed.instance_ids > 0
    assert np.array_equal(voted[inside], lab[inside])
    lines = ~inside
    assert np.array_equal(voted[lines], noisy[lines])
    assert (voted == lab).mean() > (noisy == lab).mean()


def test_open_kitchen_is_split_with_an_opening():
    img, lab = open_plan()
    parsed = extract_instances(img, lab)
    assert classes(parsed) == ["kitchen", "living", OPENING, "wall"]
    by_class = {i.class_name: i for i in parsed.instances}
    kitchen, living, opening = by_class["kitchen"], by_class["living"], by_class[OPENING]
    # the cut follows the predicted boundary (between cols 114 and 115) and is 2 px wide
    cols = np.nonzero(parsed.instance_ids == opening.id)[1]
    assert set(cols.tolist()) == {114, 115}
    assert opening.area_px == 2 * 147
    assert kitchen.area_px == 59 * 147 - 147 and living.area_px == 88 * 147 - 147
    assert kitchen.votes == {KITCHEN: kitchen.area_px}
    assert opening.votes == {LIVING: 147, KITCHEN: 147}
    # the opening touches both spaces
    ring = cv2.dilate((parsed.instance_ids == opening.id).astype(np.uint8), np.ones((3, 3)))
    touched = set(np.unique(parsed.instance_ids[ring.astype(bool)]).tolist())
    assert {kitchen.id, living.id} <= touched
    voted = vote_corrected_labels(parsed)
    assert np.array_equal(voted[parsed.instance_ids > 0], lab[parsed.instance_ids > 0])


def test_vote_with_lines_covers_leftover_regions_and_connector_outlines():
    img, lab = two_rooms()
    window = CLASS_ID["window"]
    noisy = lab.copy()
    noisy[2:10, 2:60] = window  # network calls part of the outside a window
    noisy[27:174, 104:174] = 0  # the right room (a storeroom) mostly background ...
    noisy[27:80, 104:174] = KITCHEN  # ... and 36 % kitchen: voted background, no instance
    noisy[90, 97:104] = window  # the door's top outline called window
    lines = binarize(img)
    parsed = extract_instances(img, noisy, lines=lines)
    assert classes(parsed) == ["door", "living", "wall", "wall", "wall"]
    voted = vote_corrected_labels(parsed, lines)
    assert (voted[2:10, 2:60] == 0).all()  # the outside takes its majority: background
    assert (voted[27:174, 105:174] == 0).all()  # so does the storeroom
    assert (voted[90, 97:104] == DOOR).all()  # the outline follows the door's vote
    assert voted[20, 100] == WALL  # a wall line far from connectors keeps its label
    plain = vote_corrected_labels(parsed)  # without lines, only instances are voted
    assert (plain[2:10, 2:60] == window).all() and (plain[90, 97:104] == window).all()
    assert (plain[27:80, 105:174] == KITCHEN).all()
    with pytest.raises(InputError):
        vote_corrected_labels(parsed, lines[:-1])


def test_paper_of_no_instance_and_no_room_beside_is_background():
    img, lab = two_rooms()
    furniture = np.zeros(lab.shape, bool)
    furniture[27:174, 104:150] = True  # most of the bedroom is furniture's paper: no instance
    lines = binarize(img)
    parsed = extract_instances(img, lab, split=None, furniture=furniture, lines=lines)
    assert parsed.instance_ids[100, 160] == 0 and lab[100, 160] == BEDROOM
    voted = vote_corrected_labels(parsed, lines)
    assert (voted[27:174, 105:174] == 0).all()  # no room the graph lacks: background
    assert (voted[27:174, 27:97] == LIVING).all()
    bed = np.zeros(lab.shape, bool)
    bed[60:120, 130:160] = True  # a bed in the bedroom, its paper no instance
    cv2.rectangle(img, (129, 59), (160, 120), 0, 1)
    lines = binarize(img)
    furnished = extract_instances(img, lab, split=None, furniture=bed, lines=lines)
    assert furnished.instance_ids[90, 145] == 0 and furnished.instance_ids[150, 120] > 0
    assert vote_corrected_labels(furnished, lines)[90, 145] == BEDROOM  # the room's floor


def test_thin_outlines_go_to_the_class_painted_last():
    img, lab = two_rooms()  # 1 px outlines; labels rasterised door over wall over room
    lines = binarize(img)
    noisy = lab.copy()
    noisy[lines] = LIVING  # the network calls every outline living
    parsed = extract_instances(img, noisy, lines=lines)
    voted = vote_corrected_labels(parsed, lines)
    np.testing.assert_array_equal(voted[lines], lab[lines])
    assert (voted[90, 97:104] == DOOR).all() and voted[60, 97] == WALL and voted[20, 50] == WALL


def test_thick_outlines_keep_the_network_labels():
    img, lab = two_rooms()
    thick = cv2.erode(img, np.ones((3, 3), np.uint8))  # 3 px outlines
    lines = binarize(thick)
    assert stroke_width_px(lines) == 3
    noisy = np.where(lines, LIVING, lab).astype(np.uint8)
    parsed = extract_instances(thick, noisy, lines=lines)
    voted = vote_corrected_labels(parsed, lines)
    far = lines & (cv2.dilate((noisy == DOOR).astype(np.uint8), np.ones((9, 9))) == 0)
    assert far.sum() > 1000
    assert (voted[far] == LIVING).all()


def test_stroke_width_is_the_commonest_run_across_lines():
    lines = np.zeros((60, 80), bool)
    assert stroke_width_px(lines) == 0
    lines[10:50, 20:22] = True  # a 2 px vertical stroke
    lines[5:7, 10:70] = True  # a 2 px horizontal stroke
    lines[30:33, 40:43] = True  # a 3x3 blot
    assert stroke_width_px(lines) == 2
    lines[:, :] = True  # runs as long as the image are no strokes
    assert stroke_width_px(lines) == 0


def test_split_follows_network_boundary_despite_noise():
    img, lab = open_plan()
    noisy = lab.copy()
    rng = np.random.default_rng(1)
    region = noisy == LIVING
    flip = region & (rng.random(lab.shape) < 0.1)
    noisy[flip] = KITCHEN  # scattered kitchen votes inside the living part
    noisy[60:63, 40:100] = BEDROOM  # a thin bedroom stripe: noise, not a space
    parsed = extract_instances(img, noisy)
    assert classes(parsed) == ["kitchen", "living", OPENING, "wall"]
    opening = parsed.of_class(OPENING)[0]
    cols = np.nonzero(parsed.instance_ids == opening.id)[1]
    assert cols.min() >= 112 and cols.max() <= 117


def test_scattered_noise_does_not_split():
    img, lab = open_plan()
    lab[27:174, 27:174] = LIVING
    rng = np.random.default_rng(2)
    noisy = lab.copy()
    flip = (lab == LIVING) & (rng.random(lab.shape) < 0.35)
    noisy[flip] = KITCHEN  # 35 % kitchen votes, but scattered pixels
    for _ in range(40):  # and small kitchen blobs (3x3)
        r, c = rng.integers(30, 170, 2)
        noisy[r : r + 3, c : c + 3] = KITCHEN
    parsed = extract_instances(img, noisy)
    assert classes(parsed) == ["living", "wall"]


def test_small_compact_part_below_threshold_does_not_split():
    img, lab = open_plan()
    lab[27:174, 27:174] = LIVING
    lab[27:47, 27:47] = KITCHEN  # 400 px in a corner = 2 % of the room
    parsed = extract_instances(img, lab)
    assert classes(parsed) == ["living", "wall"]
    # with a grid, an absolute area threshold can still split it: 400 px at 0.1 m/px = 4 m^2
    grid = PixelGrid.from_scale(0.1, lab.shape)
    parsed = extract_instances(img, lab, grid=grid, split=SplitOptions(min_area_m2=3.0))
    assert classes(parsed) == ["kitchen", "living", OPENING, "wall"]
    assert parsed.scale_source == "argument"


def test_only_open_pairs_split():
    img, lab = open_plan()
    lab[lab == LIVING] = BEDROOM  # a bedroom the network 40 % calls kitchen: no open passage
    parsed = extract_instances(img, lab)
    assert classes(parsed) == ["bedroom", "wall"]
    pairs = SplitOptions(open_pairs=(("bedroom", "kitchen"),))
    assert classes(extract_instances(img, lab, split=pairs)) == [
        "bedroom",
        "kitchen",
        OPENING,
        "wall",
    ]
    with pytest.raises(ValueError, match="open_pairs"):
        SplitOptions(open_pairs=(("living", "door"),))
    with pytest.raises(ValueError, match="open_pairs"):
        SplitOptions(open_pairs=(("living", "living"),))


def test_no_split_option():
    img, lab = open_plan()
    parsed = extract_instances(img, lab, split=None)
    assert classes(parsed) == ["living", "wall"]
    assert parsed.instances[-1].votes[KITCHEN] == 59 * 147


def test_binarize_grey_antialiased_noisy_lines_do_not_leak():
    img, lab = two_rooms()
    # grey, anti-aliased lines on off-white paper with Gaussian noise and JPEG artefacts
    grey = np.where(img < 128, 110, 235).astype(np.uint8)
    grey = cv2.GaussianBlur(grey, (3, 3), 0.6)
    rng = np.random.default_rng(3)
    grey = np.clip(grey + rng.normal(0, 12, grey.shape), 0, 255).astype(np.uint8)
    ok, buf = cv2.imencode(".jpg", grey, [cv2.IMWRITE_JPEG_QUALITY, 40])
    grey = cv2.imdecode(buf, cv2.IMREAD_GRAYSCALE)
    parsed = extract_instances(grey, lab)
    # rooms and door come out whole; noise may cut a narrow wall interior into extra pieces
    assert [c for c in classes(parsed) if c != "wall"] == ["bedroom", "door", "living"]
    living = parsed.of_class("living")[0]
    assert abs(living.area_px - 70 * 147) < 0.1 * 70 * 147
    assert parsed.instance_ids[100, 60] == living.id


def test_binarize_uniform_and_inverted():
    assert not binarize(np.full((50, 50), 255, np.uint8)).any()
    assert not binarize(np.zeros((50, 50), np.uint8)).any()
    img, _ = two_rooms()
    np.testing.assert_array_equal(binarize(255 - img), binarize(img))
    assert binarize(img)[20, 100] and not binarize(img)[100, 60]


def test_binarize_dark_lines_on_grey_paper_with_a_white_margin():
    # a listing exported with mid-grey paper and a white strip beside it: most of the image is
    # darker than mid-grey, yet the lines are the black strokes, not the white margin
    img, _ = two_rooms()
    grey = np.where(img > 0, np.uint8(100), np.uint8(0))
    sheet = np.full((260, 200), 255, np.uint8)
    sheet[:200] = grey
    assert ink_is_dark(sheet) and not ink_is_dark(255 - sheet[:200])
    np.testing.assert_array_equal(binarize(sheet)[:200], binarize(img))
    assert not binarize(sheet)[200:].any()


def test_binarize_grey_room_fills_are_paper_not_ink():
    img, lab = two_rooms()
    filled = img.copy()
    filled[(lab == LIVING) & (img > 0)] = 172  # listing-style fills: the rooms are 45 % of the
    filled[(lab == BEDROOM) & (img > 0)] = 184  # image, more than ink ever is
    np.testing.assert_array_equal(binarize(filled), binarize(img))
    instances = extract_instances(filled, lab, lines=binarize(filled)).instances
    assert sorted(i.class_name for i in instances) == classes(extract_instances(img, lab))
    # black walls with noise are one dark tone, however much of the image they cover: all ink
    walls = np.full((100, 100), 255, np.uint8)
    walls[:, :40] = np.random.default_rng(0).integers(0, 50, (100, 40))
    assert binarize(walls)[:, 2:38].all() and not binarize(walls)[:, 45:].any()


def test_colour_input_and_bad_labels():
    img, lab = two_rooms()
    bgr = cv2.cvtColor(img, cv2.COLOR_GRAY2BGR)
    assert classes(extract_instances(bgr, lab)) == classes(extract_instances(img, lab))
    with pytest.raises(InputError, match="differ in size"):
        extract_instances(img, lab[:-1])
    with pytest.raises(InputError, match="not a class"):
        extract_instances(img, np.full_like(lab, 12))


def test_door_swing_arc_does_not_cut_the_room():
    img, lab = two_rooms()
    # a door leaf and quarter arc drawn into the living room from the door's left face (col 97)
    cv2.line(img, (96, 90), (66, 90), 0, 1)
    cv2.ellipse(img, (96, 90), (30, 30), 0, 90, 180, 0, 1)
    assert len(extract_instances(img, lab, split=None).instances) == 6
    living = [i for i in extract_instances(img, lab).instances if i.class_name == "living"]
    assert len(living) == 1
    assert living[0].area_px > 70 * 147 - 200  # the arc's own pixels join the room


def test_a_thick_door_swing_of_a_high_resolution_scan_does_not_cut_the_room():
    img, lab = (
        cv2.resize(a, None, fx=4, fy=4, interpolation=cv2.INTER_NEAREST) for a in two_rooms()
    )  # every stroke 4 px thick
    cv2.line(img, (384, 360), (264, 360), 0, 6)  # a leaf and arc 6 px thick in the living room
    cv2.ellipse(img, (384, 360), (120, 120), 0, 90, 180, 0, 6)
    # the labels call the swing's ink living, as the network does a room's furnishings
    living = [i for i in extract_instances(img, lab).instances if i.class_name == "living"]
    assert len(living) == 1


def test_faint_blurred_line_beside_filled_walls_still_separates():
    size = 200
    img = np.full((size, size), 255, np.uint8)
    lab = np.zeros((size, size), np.uint8)
    cv2.rectangle(img, (20, 20), (180, 180), 0, 8)  # heavy filled walls dominate the histogram
    cv2.line(img, (100, 24), (100, 176), 120, 1)  # a faint 1 px partition
    img = cv2.GaussianBlur(img, (0, 0), 1.2)
    lab[24:177, 24:100] = LIVING
    lab[24:177, 101:177] = BEDROOM
    assert 255 - img[100, 100] < 50  # under 20 % of the ink-paper contrast: Otsu misses it
    parsed = extract_instances(img, lab, split=None)
    assert classes(parsed) == ["bedroom", "living"]


def test_crisp_faint_hairline_beside_dark_text_still_separates():
    size = 200
    img = np.full((size, size), 255, np.uint8)
    lab = np.zeros((size, size), np.uint8)
    cv2.rectangle(img, (20, 20), (180, 180), 223, 1)  # a CAD export: 1 px light-grey walls
    cv2.line(img, (100, 20), (100, 180), 223, 1)
    cv2.putText(img, "1601", (40, 100), cv2.FONT_HERSHEY_SIMPLEX, 0.6, 0, 2)  # black room numbers
    cv2.putText(img, "1602", (120, 100), cv2.FONT_HERSHEY_SIMPLEX, 0.6, 0, 2)
    lab[21:180, 21:100] = LIVING
    lab[21:180, 101:180] = BEDROOM
    assert binarize(img)[60, 100] and binarize(img)[20, 60]  # blurred, the line is too faint
    parsed = extract_instances(img, lab, split=None)
    assert classes(parsed) == ["bedroom", "living"]


def test_connector_drawn_as_solid_ink_becomes_an_instance():
    size = 200
    img = np.full((size, size), 255, np.uint8)
    lab = np.zeros((size, size), np.uint8)
    lab[20:181, 20:181] = WALL
    lab[27:174, 27:95] = LIVING
    lab[27:174, 106:174] = BEDROOM
    cv2.rectangle(img, (20, 20), (180, 180), 0, 1)
    cv2.rectangle(img, (26, 26), (174, 174), 0, 1)
    img[26:175, 95:106] = 0  # thick outlines leave the middle wall and its door all ink
    lab[90:121, 95:106] = DOOR
    parsed = extract_instances(img, lab)
    (door,) = parsed.of_class("door")
    assert door.area_px == 31 * 11 and door.votes == {DOOR: 31 * 11}
    ring = cv2.dilate((parsed.instance_ids == door.id).astype(np.uint8), np.ones((7, 7)))
    ids = np.unique(parsed.instance_ids[ring > 0])
    touched = {parsed.by_id()[i].class_name for i in ids if i > 0}
    assert {"living", "bedroom", "door"} <= touched
    # a small connector blob (misread wall) or one joining no two rooms is not a door
    small = lab.copy()
    small[27:174, 95:106] = WALL
    small[100:106, 95:106] = DOOR  # 66 px < 100 px
    assert not extract_instances(img, small).of_class("door")
    # a long connector-labelled stroke on one outline of a hollow wall joins a room to the
    # wall's interior only: not a door
    hollow = img.copy()
    hollow[27:174, 97:104] = 255  # wall interior between outlines at cols 94-96 and 104
    hollow[26:175, 94:97] = 0
    one_side = lab.copy()
    one_side[27:174, 95:106] = WALL
    one_side[60:101, 94:97] = DOOR  # 123 px of ink
    parsed = extract_instances(hollow, one_side)
    assert not parsed.of_class("door") and len(parsed.of_class("wall")) >= 2


def test_a_hatched_balcony_is_one_instance_and_two_rooms_stay_two():
    img = np.full((200, 300), 255, np.uint8)
    lab = np.zeros((200, 300), np.uint8)
    cv2.rectangle(img, (20, 20), (280, 180), 0, 4)
    cv2.line(img, (150, 20), (150, 180), 0, 1)  # a thin partition, labelled as the rooms are
    lab[22:179, 22:279] = CLASS_ID["living"]
    rooms = extract_instances(img, lab, split=None)
    assert [i.class_name for i in rooms.instances] == ["living", "living"]
    for x in range(160, 278, 8):  # the right room's floor hatched in 1 px lines: 7 px cells
        cv2.line(img, (x, 22), (x, 177), 0, 1)
    for y in range(30, 178, 8):
        cv2.line(img, (152, y), (277, y), 0, 1)
    lab[22:179, 151:279] = CLASS_ID["balcony"]
    parsed = extract_instances(img, lab, split=None)
    balconies = [i for i in parsed.instances if i.class_name == "balcony"]
    assert len(balconies) == 1  # cells far smaller than a room: one floor
    assert balconies[0].area_px > 0.6 * 126 * 156


def test_a_region_in_pieces_keeps_every_piece():
    # furniture's paper taken out of a room can leave its region in two pieces; a swing's
    # sector beside one piece joins it, and the room keeps both pieces
    cc = np.zeros((60, 100), np.int32)
    cc[3:25, 5:45] = 1  # the room's larger piece
    cc[35:55, 5:45] = 1  # its smaller piece, below the furniture's paper
    cc[35:55, 47:52] = 2  # a swing's sector beside the smaller piece
    lines = cc == 0
    labels = np.where(cc > 0, LIVING, 0).astype(np.uint8)
    labels[35:55, 45:47] = LIVING  # the arc between them, labelled as the room
    stats = np.array(
        [cv2.boundingRect((cc == k).astype(np.uint8)) + (int((cc == k).sum()),) for k in range(3)]
    )
    keep, winner = np.array([False, True, True]), np.array([0, LIVING, LIVING])
    regions = list(_regions(cc, stats, keep, winner, labels, lines, bridge_px=3))
    covered = np.zeros(cc.shape, bool)
    for cls, (x0, y0, x1, y1), crop in regions:
        assert cls == LIVING
        assert not (covered[y0:y1, x0:x1] & crop).any()  # no pixel in two regions
        covered[y0:y1, x0:x1] |= crop
    assert covered[cc > 0].all()
