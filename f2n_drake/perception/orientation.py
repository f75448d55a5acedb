"""A drawing lying on its side or upside down, turned upright.

A landscape sheet scanned or saved in portrait lies a quarter turn off: its room names and sizes
run up or down the page; a page fed upside down into a scanner lies a half turn off. The word
detector finds lines written down the page far less often than lines along it (on R3D's
development split turned a quarter turn, 50 of the 102 named rooms keep a name read), the
recogniser reads no line upside down, and the parse recovers fewer rooms (143 of 196 against 166
upright).

:func:`quarter_turns` asks the words. A drawing whose detected lines mostly run along its rows
(at least ``MIN_LINES`` of them, ``SIDEWAYS_RATIO`` times those running up or down) is upright or
upside down: its ``UPRIGHT_VOTING_LINES`` longest lines are read as they lie and turned a half
turn, each voting for the more confident reading, and it is turned when at least
``MIN_UPSIDE_DOWN_VOTES`` vote upside down and ``SIDEWAYS_RATIO`` times as many as vote upright.
Otherwise the detector looks at the drawing turned a quarter turn: a drawing on its side shows at
least ``MIN_LINES`` lines along the rows only when turned, and ``SIDEWAYS_RATIO`` times as many as
it shows as it lies (where a plan's own words mostly run along its rows, its dimension chains up
its sides). The turned drawing is then upright or upside down, told by its ``VOTING_LINES``
longest lines as above (``MIN_LINES`` votes at least). A drawing without words, or with as many
lines either way, is left as it lies. Only the first ``READ_HEIGHTS`` line heights of a voting
line are read. It costs one detection and eight short readings on a drawing with words (on a 2-core
CPU about 0.3 s for a 600 px listing), a second detection on one with few words or on its side.
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
"""Longest lines of a drawing on its side read both ways to tell which way it lies."""
UPRIGHT_VOTING_LINES = 4
"""Longest lines of a drawing whose words run along its rows read both ways (upside down?)."""
READ_HEIGHTS = 8
"""Longest part of a voting line read, in line heights (its first few words)."""
MIN_UPSIDE_DOWN_VOTES = 3
"""Fewest of those that must read better upside down to turn the drawing a half turn."""


def quarter_turns(image: np.ndarray) -> int:
    """Quarter turns counter-clockwise (``np.rot90``'s ``k``: 0 to 3) that set ``image`` (a
    drawing, grey or colour) upright: 0 unless its words clearly run up or down the page, or
    read upside down (module doc)."""
    grey = dark_on_light(as_grey(np.asarray(image)))
    lines = detected_lines(grey)
    along = [q for q in lines if not is_tall(q)]
    if len(along) >= max(MIN_LINES, SIDEWAYS_RATIO * (len(lines) - len(along))):
        # its words run along its rows: upright, or upside down
        return (
            2 if _reading_way(grey, along, UPRIGHT_VOTING_LINES, MIN_UPSIDE_DOWN_VOTES) < 0 else 0
        )
    turned = np.ascontiguousarray(np.rot90(grey))
    across = [q for q in detected_lines(turned) if not is_tall(q)]
    if len(across) < MIN_LINES or len(across) < SIDEWAYS_RATIO * len(along):
        return 0
    return {1: 1, -1: 3, 0: 0}[_reading_way(turned, across, VOTING_LINES, MIN_LINES)]


def _reading_way(grey: np.ndarray, lines: list[np.ndarray], n_lines: int, min_votes: int) -> int:
    """1 when the ``n_lines`` longest of ``lines`` (quads along the rows of ``grey``) read
    more confidently as they lie, -1 when turned a half turn, 0 when neither way wins
    ``SIDEWAYS_RATIO`` times the other's votes and at least ``min_votes``."""
    longest = sorted(lines, key=lambda q: -np.ptp(np.asarray(q)[:, 0]))[:n_lines]
    # a line's first words tell its way: a long line's crop is cut, which bounds the reading
    crops = [crop[:, : READ_HEIGHTS * crop.shape[0]] for crop in line_crops(grey, longest)]
    as_they_lie = np.array([c for _, c in recognised(crops)])
    half_turned = np.array([c for _, c in recognised([np.rot90(c, 2) for c in crops])])
    ahead, behind = int((as_they_lie > half_turned).sum()), int((half_turned > as_they_lie).sum())
    if ahead >= max(min_votes, SIDEWAYS_RATIO * behind):
        return 1
    if behind >= max(min_votes, SIDEWAYS_RATIO * ahead):
        return -1
    return 0


def turned(image: np.ndarray, turns: int) -> np.ndarray:
    """``image`` turned ``turns`` quarter turns counter-clockwise (exactly: no resampling)."""
    return np.ascontiguousarray(np.rot90(image, turns))
