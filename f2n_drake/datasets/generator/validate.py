"""``validate_plan``: the structural rules every generated plan must satisfy.

Rules: finite coordinates and valid polygons; no two polygons overlap (beyond 1e-6 m²); every
space is big enough (>= 2 m², >= 1 m narrow side; balconies >= 1 m deep); every door touches
exactly two spaces; every front door touches exactly one living space and the outside; every
window touches a room; every space is reachable from a front door through doors or open
passages (two spaces sharing >= 0.6 m of boundary). Storage counts as a space here.
"""

from __future__ import annotations

from collections import deque

import numpy as np
import shapely
from shapely.geometry import Polygon

from f2n_drake.core.classes import SPACE_CLASSES
from f2n_drake.core.plan import FloorPlan

AREA_TOL_M2 = 1e-6
MIN_AREA_M2 = 2.0
MIN_WIDTH_M = 1.0
OPEN_PASSAGE_M = 0.6
CONTACT_M = 0.4  # a connector touches a space if they share at least this much boundary
_EPS = 1e-4  # buffer width [m] used to measure shared boundary length


def _shared_length(a: Polygon, b: Polygon) -> float:
    """Approximate length [m] of the boundary two polygons share."""
    return float(
        shapely.area(shapely.intersection(a, shapely.buffer(b, _EPS, join_style="mitre"))) / _EPS
    )


def validate_plan(plan: FloorPlan) -> list[str]:
    """Problems found in ``plan`` (empty list = valid), one short string each."""
    problems: list[str] = []
    space_names = (*SPACE_CLASSES, "storage")
    items = [
        (name, i, poly) for name, polys in plan.polygons.items() for i, poly in enumerate(polys)
    ]
    if not items:
        return ["plan has no polygons"]
    geoms = np.array([p for _, _, p in items], dtype=object)
    label = [f"{n}[{i}]" for n, i, _ in items]

    coords = shapely.get_coordinates(geoms)
    if not np.isfinite(coords).all():
        problems.append("non-finite coordinates")
        return problems
    for k in np.flatnonzero(~shapely.is_valid(geoms) | shapely.is_empty(geoms)):
        problems.append(f"{label[k]} is invalid or empty")
    if problems:
        return problems

    tree = shapely.STRtree(geoms)
    left, right = tree.query(geoms, predicate="intersects")
    keep = left < right
    left, right = left[keep], right[keep]
    overlap = shapely.area(shapely.intersection(geoms[left], geoms[right]))
    for a, b, area in zip(left, right, overlap, strict=True):
        if area > AREA_TOL_M2:
            problems.append(f"{label[a]} overlaps {label[b]} by {area:.4f} m²")

    space_idx = [k for k, (n, _, _) in enumerate(items) if n in space_names]
    for k in space_idx:
        poly = geoms[k]
        if items[k][0] != "balcony" and poly.area < MIN_AREA_M2:
            problems.append(f"{label[k]} is too small ({poly.area:.2f} m²)")
        if shapely.buffer(poly, -MIN_WIDTH_M / 2 + 1e-3, join_style="mitre").is_empty:
            problems.append(f"{label[k]} is narrower than {MIN_WIDTH_M} m")

    # contacts between spaces and everything else
    is_space = np.zeros(len(items), dtype=bool)
    is_space[space_idx] = True
    touching: dict[int, list[int]] = {k: [] for k in range(len(items))}
    grown = shapely.buffer(geoms, _EPS, join_style="mitre")
    near_l, near_r = tree.query(grown, predicate="intersects")
    for a, b in zip(near_l, near_r, strict=True):
        if a != b and is_space[b]:
            touching[a].append(b)

    graph: dict[int, set[int]] = {k: set() for k in space_idx}
    starts: list[int] = []
    for k, (name, _, poly) in enumerate(items):
        if name not in ("door", "front_door", "window"):
            continue
        spaces = [s for s in touching[k] if _shared_length(geoms[s], poly) >= CONTACT_M]
        if name == "door":
            if len(spaces) != 2:
                problems.append(f"{label[k]} touches {len(spaces)} spaces, expected 2")
                continue
            graph[spaces[0]].add(spaces[1])
            graph[spaces[1]].add(spaces[0])
        elif name == "front_door":
            kinds = [items[s][0] for s in spaces]
            if kinds != ["living"]:
                problems.append(f"{label[k]} touches {kinds}, expected exactly one living space")
                continue
            if not _touches_outside(poly, [geoms[j] for j in tree.query(grown[k]) if j != k]):
                problems.append(f"{label[k]} does not reach the outside")
                continue
            starts.append(spaces[0])
        elif not any(items[s][0] != "balcony" for s in spaces):
            problems.append(f"{label[k]} touches no room")

    for a in space_idx:
        for b in touching[a]:
            if a < b and _shared_length(geoms[a], geoms[b]) >= OPEN_PASSAGE_M:
                graph[a].add(b)
                graph[b].add(a)

    if not starts:
        problems.append("no usable front door")
        return problems
    seen = set(starts)
    queue = deque(starts)
    while queue:
        for nxt in graph[queue.popleft()]:
            if nxt not in seen:
                seen.add(nxt)
                queue.append(nxt)
    for k in space_idx:
        if k not in seen:
            problems.append(f"{label[k]} is not reachable from the front door")
    return problems


def _touches_outside(poly: Polygon, neighbours: list[Polygon]) -> bool:
    """Whether some of ``poly``'s boundary (>= CONTACT_M) borders no polygon at all."""
    ring = shapely.difference(shapely.buffer(poly, _EPS, join_style="mitre"), poly)
    if neighbours:
        ring = shapely.difference(ring, shapely.union_all(neighbours))
    return ring.area / _EPS >= CONTACT_M
