"""A terrace or a balcony named on the drawing, and open to the outside: its extent.

A balcony lies outside the flat's walls, and drawings often leave it without a closing wall: a
grey or dotted tone with no outline, hatching that cuts it into cells, a railing drawn as a thin
line. The paper around its name then runs into the outside (or is one cell of the hatching), and
the walls that bound rooms do not bound it. What bounds it is the drawing itself:

- the plan's outline: the drawing's extent is everything its marks (the ink, and the paper
  toned darker than the sheet) enclose, what the paper of the sheet cannot reach from the image
  border;
- the flat's walls (``perception.fixture_pieces.wall_ink``: the ink at least 3 px
  thick, and what the network labels wall, window or door), their gaps (a wide
  door at most) closed, part it from the rooms; thin lines (hatching, a railing, the tone's
  dots) do not.

:func:`balcony_extent` is the piece of the drawing's extent, less the walls and their gaps,
under a balcony's name; none when it reaches the image border or holds a name of another room
class.
"""

from __future__ import annotations

from collections.abc import Sequence

import cv2
import numpy as np

from f2n_drake.core.text import TextBox
from f2n_drake.perception.doorways import max_gap_px
from f2n_drake.perception.fixture_pieces import wall_ink
from f2n_drake.perception.wall_gaps import collinear_gaps

TONE_DEPTH = 20
"""Paper at least this much darker than the sheet (median grey level, 5 x 5 median filtered) is
toned: part of the drawing."""

HELD = 0.25
"""A piece covering this share of the box of a name of another class holds that name."""


def drawing_extent(grey: np.ndarray | None, lines: np.ndarray) -> np.ndarray:
    """(H, W) bool: what the drawing's marks (``lines``, and paper toned ``TONE_DEPTH`` darker
    than the sheet in ``grey``; ``lines`` alone without it) enclose, marks included."""
    marks = lines.copy()
    if grey is not None:
        smooth = cv2.medianBlur(grey, 5)
        marks |= smooth.astype(np.int16) < int(np.median(grey)) - TONE_DEPTH
    _, paper = cv2.connectedComponents((~marks).astype(np.uint8), connectivity=4)
    border = np.unique(np.concatenate([paper[0], paper[-1], paper[:, 0], paper[:, -1]]))
    return ~np.isin(paper, border[border > 0])


def balcony_extent(
    extent: np.ndarray, walls: np.ndarray, text: TextBox, others: Sequence[TextBox] = ()
) -> np.ndarray | None:
    """(H, W) bool: the piece of the drawing's ``extent`` less ``walls`` (walls and their closed
    gaps) under most of ``text``'s box; None when there is none, it reaches the image border,
    or it holds one of ``others`` (names of rooms of other classes, ``HELD`` of the box: the
    walls left a room open to it)."""
    _, pieces = cv2.connectedComponents((extent & ~walls).astype(np.uint8), connectivity=4)
    c0, r0, c1, r1 = text.box_px
    under = pieces[r0:r1, c0:c1]
    under = under[under > 0]
    if not under.size:
        return None
    piece = int(np.bincount(under).argmax())
    border = np.concatenate([pieces[0], pieces[-1], pieces[:, 0], pieces[:, -1]])
    mask = pieces == piece
    if (border == piece).any() or any(_holds(mask, t) for t in others):
        return None
    return mask


def _holds(mask: np.ndarray, text: TextBox) -> bool:
    """Whether ``mask`` covers ``HELD`` of ``text``'s box or more."""
    c0, r0, c1, r1 = text.box_px
    box = mask[r0:r1, c0:c1]
    return box.size > 0 and np.count_nonzero(box) >= HELD * box.size


def named_balconies(
    texts: Sequence[TextBox],
    others: Sequence[TextBox],
    lines: np.ndarray,
    labels: np.ndarray,
    grey: np.ndarray | None,
) -> list[tuple[TextBox, np.ndarray]]:
    """Each balcony name of ``texts`` (on paper open to the outside, or on a cell) with its
    :func:`balcony_extent` in the drawing (``lines``, ``grey``) whose walls are ``wall_ink`` of
    the network's ``labels``, their gaps closed; ``others`` are the names of other classes. A
    name whose piece is none, or overlaps one found before, is left out."""
    if not texts:
        return []
    walls = wall_ink(lines, labels)
    widest = max_gap_px(walls)
    walls |= collinear_gaps(walls, max_gap_px=widest, min_run_px=max(3, widest // 2))
    extent = drawing_extent(grey, lines)
    found: list[tuple[TextBox, np.ndarray]] = []
    for text in texts:
        mask = balcony_extent(extent, walls, text, others)
        if mask is not None and not any((m & mask).any() for _, m in found):
            found.append((text, mask))
    return found
