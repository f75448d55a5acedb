"""A cell layout: axis-aligned rectangles on a centimetre grid, grouped into rooms.

Wall centre lines are the cell boundaries. ``boundary_segments`` finds every straight piece of
boundary between two different rooms (or a room and the outside), so walls, doors and windows
can be placed with exact integer arithmetic before anything becomes a shapely polygon.
"""

from __future__ import annotations

from bisect import bisect_right
from collections import defaultdict
from dataclasses import dataclass, field

Rect = tuple[int, int, int, int]
"""(x0, y0, x1, y1) [cm], x0 < x1, y0 < y1."""

OUTSIDE = -1


@dataclass(frozen=True)
class Segment:
    """A straight piece of wall centre line between two rooms.

    Attributes:
        axis: 0 for a horizontal line ``y = c``, 1 for a vertical line ``x = c``.
        c: the line's constant coordinate [cm].
        lo, hi: extent along the line [cm].
        low, high: room id below/left and above/right of the line (``OUTSIDE`` = -1).
    """

    axis: int
    c: int
    lo: int
    hi: int
    low: int
    high: int

    @property
    def length(self) -> int:
        return self.hi - self.lo

    @property
    def exterior(self) -> bool:
        return self.low == OUTSIDE or self.high == OUTSIDE

    @property
    def room(self) -> int:
        """The inside room of an exterior segment."""
        return self.high if self.low == OUTSIDE else self.low

    @property
    def outward(self) -> int:
        """-1 if the outside is below/left of an exterior segment, +1 if above/right."""
        return -1 if self.low == OUTSIDE else 1


@dataclass
class Layout:
    """Cells, their rooms and the plan's wall thicknesses.

    Attributes:
        rects: cells [cm].
        rect_room: room id of each cell.
        room_types: class name of each room ("living", "bedroom", ..., "storage").
        t_int, t_ext: interior and exterior wall thickness [m].
        open_pairs: room pairs (sorted tuples) joined with no wall between them.
    """

    rects: list[Rect]
    rect_room: list[int]
    room_types: list[str]
    t_int: float
    t_ext: float
    open_pairs: set[tuple[int, int]] = field(default_factory=set)
    segments: list[Segment] = field(default_factory=list)

    def compute_segments(self) -> None:
        self.segments = boundary_segments(self.rects, self.rect_room)

    def thickness(self, seg: Segment) -> float:
        """Wall thickness [m] on a segment."""
        return self.t_ext if seg.exterior else self.t_int

    def margin_cm(self) -> int:
        """Clearance [cm] an opening keeps from the ends of its segment."""
        return int(round(self.t_ext * 50)) + 10

    def pair_segments(self) -> dict[tuple[int, int], list[int]]:
        """Sorted room pair -> indices of the interior segments between them."""
        pairs: dict[tuple[int, int], list[int]] = defaultdict(list)
        for i, s in enumerate(self.segments):
            if not s.exterior:
                pairs[(min(s.low, s.high), max(s.low, s.high))].append(i)
        return pairs

    def exterior_segments(self) -> dict[int, list[int]]:
        """Room id -> indices of its exterior segments."""
        rooms: dict[int, list[int]] = defaultdict(list)
        for i, s in enumerate(self.segments):
            if s.exterior:
                rooms[s.room].append(i)
        return rooms


def boundary_segments(rects: list[Rect], rect_room: list[int]) -> list[Segment]:
    """Maximal straight boundary pieces between different rooms or a room and the outside."""
    lines: dict[tuple[int, int], tuple[list, list]] = defaultdict(lambda: ([], []))
    for (x0, y0, x1, y1), room in zip(rects, rect_room, strict=True):
        lines[(0, y0)][1].append((x0, x1, room))
        lines[(0, y1)][0].append((x0, x1, room))
        lines[(1, x0)][1].append((y0, y1, room))
        lines[(1, x1)][0].append((y0, y1, room))
    segments: list[Segment] = []
    for (axis, c), (lows, highs) in sorted(lines.items()):
        lows.sort()
        highs.sort()
        low_starts = [iv[0] for iv in lows]
        high_starts = [iv[0] for iv in highs]
        points = sorted({p for a, b, _ in lows + highs for p in (a, b)})
        current: list | None = None
        for a, b in zip(points[:-1], points[1:], strict=True):
            key = (_owner(lows, low_starts, a), _owner(highs, high_starts, a))
            if key[0] == key[1]:
                key = None
            if current is not None and key == current[2] and current[1] == a:
                current[1] = b
                continue
            if current is not None:
                segments.append(Segment(axis, c, current[0], current[1], *current[2]))
            current = [a, b, key] if key is not None else None
        if current is not None:
            segments.append(Segment(axis, c, current[0], current[1], *current[2]))
    return segments


def _owner(intervals: list, starts: list[int], at: int) -> int:
    """Room of the interval covering [at, at+) on one side of a line, or OUTSIDE."""
    i = bisect_right(starts, at) - 1
    if i >= 0 and intervals[i][1] > at:
        return intervals[i][2]
    return OUTSIDE


def free_interval(
    used: list[tuple[int, int]], lo: int, hi: int, width: int, gap: int, rng
) -> tuple[int, int] | None:
    """A random [a, a+width] inside [lo, hi] keeping ``gap`` cm from every used interval."""
    blocked = sorted((a - gap - width, b + gap) for a, b in used)
    # candidate start positions: [lo, hi - width] minus the open intervals in `blocked`
    free: list[tuple[int, int]] = []
    start = lo
    for a, b in blocked:
        if a > start:
            free.append((start, min(a, hi - width)))
        start = max(start, b)
    free.append((start, hi - width))
    free = [(a, b) for a, b in free if b >= a]
    if not free:
        return None
    a, b = free[int(rng.integers(len(free)))]
    pos = int(rng.integers(a, b + 1))
    return pos, pos + width
