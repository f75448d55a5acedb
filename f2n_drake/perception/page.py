"""A page photographed at an angle, squared: its four corners made a rectangle's.

A phone photo of a drawing shows the page as a light quadrilateral on a darker table, its
rectangle foreshortened. :func:`find_page` looks for it on the drawing shrunk to
``_SAMPLED_PX``:

- paper is what is lighter than the Otsu cut of the blurred drawing; it is closed across the
  drawing's lines (``_CLOSE_SHARE`` of the long side) and its holes filled, and the largest piece
  is the page candidate;
- it is a photographed page when it covers at least ``MIN_PAGE_SHARE`` of the picture, is
  drawn on (``MIN_INK_SHARE`` of it darker than the paper) but mostly paper
  (``MIN_PAPER_SHARE``: a negative's light lines, closed, enclose mostly dark), at most
  ``MAX_BORDER_SHARE`` of the picture's border is paper (a scan's or a drawing's paper runs to
  its border on every side), and its convex hull is a quadrilateral: simplified to four
  corners, none on the picture's edge, the quadrilateral and the piece overlap by at least
  ``MIN_QUAD_IOU``, and it is not upright (a side more than ``UPRIGHT_DEG`` off the image's
  axes: an upright page has no angle to undo, and a light rectangle on dark that is no page,
  a house's floor on its lawn, is left alone).

:func:`squared_page` warps such a page to a rectangle as wide as its longer top or bottom edge
and as tall as its longer left or right edge, shrunk to at most ``MAX_SIDE_PX``; any other
drawing comes back unchanged (the same array).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

MIN_PAGE_SHARE = 0.2
"""Least share of the picture a photographed page covers."""
MAX_BORDER_SHARE = 0.5
"""Most of the picture's border that may be paper for the page to be a photographed one."""
MIN_QUAD_IOU = 0.9
"""Least overlap (intersection over union) of the page and its four-cornered outline."""
MIN_INK_SHARE = 0.001
"""Least share of the page that is drawn on (darker than the paper)."""
MAX_SIDE_PX = 2000
"""Longest side of a squared page [px]: a photo holds no detail finer than its blur, and a
4000 px page takes the parse ten times as long."""
UPRIGHT_DEG = 1.5
"""A page whose sides all lie within this of the image's axes is upright: no angle to undo (and
a light rectangle on dark that is no page, a house's floor on its lawn, is left alone)."""
MIN_PAPER_SHARE = 0.6
"""Least share of the page that is paper (a negative's lines, closed, enclose mostly dark)."""
_CORNER_MARGIN = 0.005  # a corner this close to the picture's edge (of its long side): cut off
_SAMPLED_PX = 600
_CLOSE_SHARE = 0.02


@dataclass(frozen=True)
class Page:
    """A photographed page: ``corners`` (4, 2) float [px of the picture, x y], top-left,
    top-right, bottom-right, bottom-left; ``size`` (width, height) of the squared page [px]."""

    corners: np.ndarray
    size: tuple[int, int]


def find_page(grey: np.ndarray) -> Page | None:
    """The photographed page of a grey picture (see module doc), or None."""
    h, w = grey.shape
    shrink = min(1.0, _SAMPLED_PX / max(h, w))
    small = cv2.resize(grey, None, fx=shrink, fy=shrink, interpolation=cv2.INTER_AREA)
    small = cv2.GaussianBlur(small, (5, 5), 0)
    _, light = cv2.threshold(small, 0, 1, cv2.THRESH_BINARY + cv2.THRESH_OTSU)
    side = max(3, round(_CLOSE_SHARE * max(small.shape)) | 1)
    paper = cv2.morphologyEx(light, cv2.MORPH_CLOSE, np.ones((side, side), np.uint8))
    n, pieces, stats, _ = cv2.connectedComponentsWithStats(paper, connectivity=4)
    if n < 2:
        return None
    largest = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
    page = (pieces == largest).astype(np.uint8)
    contours, _ = cv2.findContours(page, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
    outline = max(contours, key=cv2.contourArea)
    page = cv2.drawContours(np.zeros_like(page), [outline], -1, 1, cv2.FILLED)  # holes filled
    drawn_on = np.count_nonzero(page & (1 - light)) / max(np.count_nonzero(page), 1)
    if page.mean() < MIN_PAGE_SHARE or not MIN_INK_SHARE <= drawn_on <= 1 - MIN_PAPER_SHARE:
        return None
    border = np.concatenate([page[0], page[-1], page[:, 0], page[:, -1]])
    if border.mean() > MAX_BORDER_SHARE:
        return None
    hull = cv2.convexHull(outline)
    perimeter = cv2.arcLength(hull, True)
    quad = None
    for share in (0.01, 0.02, 0.03, 0.05, 0.08):
        approx = cv2.approxPolyDP(hull, share * perimeter, True)
        if len(approx) == 4:
            quad = approx[:, 0, :].astype(np.float32)
            break
    if quad is None:
        return None
    drawn = cv2.fillConvexPoly(np.zeros_like(page), quad.round().astype(np.int32), 1)
    overlap = np.count_nonzero(drawn & page) / max(np.count_nonzero(drawn | page), 1)
    if overlap < MIN_QUAD_IOU:
        return None
    sh, sw = page.shape
    margin = _CORNER_MARGIN * max(sh, sw)
    if not (
        quad.min() >= margin
        and (quad[:, 0] <= sw - 1 - margin).all()
        and (quad[:, 1] <= sh - 1 - margin).all()
    ):
        return None  # a corner on the picture's edge: the page runs off it
    corners = _ordered(quad) / shrink
    if _upright(corners):
        return None  # nothing to undo: a light rectangle on dark (a house on its lawn, a card)
    top, bottom = (np.linalg.norm(corners[i] - corners[j]) for i, j in ((0, 1), (3, 2)))
    left, right = (np.linalg.norm(corners[i] - corners[j]) for i, j in ((0, 3), (1, 2)))
    width, height = max(top, bottom), max(left, right)
    scale = min(1.0, MAX_SIDE_PX / max(width, height))
    return Page(corners, (round(scale * width), round(scale * height)))


def squared_page(
    image: np.ndarray, luminance: np.ndarray | None = None
) -> tuple[np.ndarray, Page | None]:
    """``image`` (grey or colour) warped so that its photographed page is a rectangle, and the
    page; ``(image, None)`` unchanged when it shows no such page. The page is looked for on
    ``luminance`` when given (the picture's plain grey, of ``image``'s size: a grey drawing
    whose coloured marks were made paper has made a wooden table paper too)."""
    if luminance is None:
        luminance = image if image.ndim == 2 else cv2.cvtColor(image[..., :3], cv2.COLOR_BGR2GRAY)
    page = find_page(luminance)
    if page is None:
        return image, None
    width, height = page.size
    target = np.float32([[0, 0], [width - 1, 0], [width - 1, height - 1], [0, height - 1]])
    warp = cv2.getPerspectiveTransform(page.corners.astype(np.float32), target)
    squared = cv2.warpPerspective(
        image, warp, (width, height), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE
    )
    return squared, page


def _upright(corners: np.ndarray) -> bool:
    """Whether the four corners (ordered) are an upright rectangle's: every side within
    ``UPRIGHT_DEG`` of the image's rows or columns."""
    sides = np.roll(corners, -1, axis=0) - corners
    angles = np.degrees(np.arctan2(np.abs(sides[:, 1]), np.abs(sides[:, 0])))
    return bool(np.all(np.minimum(angles, 90 - angles) <= UPRIGHT_DEG))


def _ordered(quad: np.ndarray) -> np.ndarray:
    """(4, 2) corners in clockwise order on the image (y down) from the top-left one (the
    smallest x + y), so that a page turned by any angle keeps its corners apart."""
    centre = quad.mean(axis=0)
    turn = np.arctan2(quad[:, 1] - centre[1], quad[:, 0] - centre[0])
    clockwise = quad[np.argsort(turn)]  # increasing angle is clockwise with y pointing down
    first = int(np.argmin(clockwise.sum(axis=1)))
    return np.roll(clockwise, -first, axis=0).astype(np.float64)
