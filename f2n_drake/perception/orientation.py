"""A drawing lying on its side, turned upright.

A landscape sheet scanned or saved in portrait lies a quarter turn off: its room names and sizes
run up or down the page. The word detector finds lines written down the page far less often than
lines along it (on R3D's development split turned a quarter turn, 50 of the 102 named rooms keep
a name read), and the parse recovers fewer rooms (143 of 196 against 165 upright).

:func:`quarter_turns` asks the words. The detector looks at the drawing as it lies and turned a
quarter turn: a drawing on its side shows at least ``MIN_LINES`` lines along the rows only when
turned, and ``SIDEWAYS_RATIO`` times as many as it shows as it lies (where a plan's own words
mostly run along its rows, its dimension chains up its sides). The turned drawing is then either
upright or upside down: its longest lines (``VOTING_LINES``) are read both ways, and each votes
for the way it reads more confidently; one way must win ``SIDEWAYS_RATIO`` times the other's
votes, and at least ``MIN_LINES`` of them. A drawing without words, or with as many lines either
way, is left as it lies. A drawing whose detected lines mostly run along its rows (at least
``MIN_LINES`` of them, ``SIDEWAYS_RATIO`` times those running up or down) is upright without the
turned detection. It costs one detection on such a drawing (0.15-0.35 s for 600-1300 px, 1.5 s
for a 2500 px sheet), and on one with few words or on its side a second one and the reading of a
few lines. A page upside down is left as it lies.
"""

from __future__ import annotations

import numpy as np

from f2n_drake.perception.ink import as_grey, dark_on_light
from f2n_drake.perception.reading import detected_lines, is_tall, line_crops, recognised

MIN_LINES = 4
"""Fewest lines along the turned drawing's rows, and fewest votes, that turn a drawing."""
SIDEWAYS_RATIO = 2.0
"""How many times as many lines the turned drawing must show, and votes the winning way win."""
VOTING_LINES = 8
"""Longest lines read both ways to tell upright from upside down."""


def quarter_turns(image: np.ndarray) -> int:
    """Quarter turns counter-clockwise (``np.rot90``'s ``k``: 0, 1 or 3) that set ``image`` (a
    drawing, grey or colour) upright: 0 unless its words clearly run up or down the page
    (module doc)."""
    grey = dark_on_light(as_grey(np.asarray(image)))
    lines = detected_lines(grey)
    along = [q for q in lines if not is_tall(q)]
    if len(along) >= max(MIN_LINES, SIDEWAYS_RATIO * (len(lines) - len(along))):
        return 0  # its words mostly run along its rows: upright, one detection spent
    turned = np.ascontiguousarray(np.rot90(grey))
    across = [q for q in detected_lines(turned) if not is_tall(q)]
    if len(across) < MIN_LINES or len(across) < SIDEWAYS_RATIO * len(along):
        return 0
    longest = sorted(across, key=lambda q: -np.ptp(np.asarray(q)[:, 0]))[:VOTING_LINES]
    crops = line_crops(turned, longest)
    as_turned = np.array([c for _, c in recognised(crops)])
    upside_down = np.array([c for _, c in recognised([np.rot90(c, 2) for c in crops])])
    votes_1, votes_3 = int((as_turned > upside_down).sum()), int((upside_down > as_turned).sum())
    if votes_1 >= max(MIN_LINES, SIDEWAYS_RATIO * votes_3):
        return 1
    if votes_3 >= max(MIN_LINES, SIDEWAYS_RATIO * votes_1):
        return 3
    return 0


def turned(image: np.ndarray, turns: int) -> np.ndarray:
    """``image`` turned ``turns`` quarter turns counter-clockwise (exactly: no resampling)."""
    return np.ascontiguousarray(np.rot90(image, turns))
