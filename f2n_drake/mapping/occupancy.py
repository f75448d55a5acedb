"""Occupancy grids for planning: free space of a parsed plan, its inflation by the robot radius,
and the region (instance) that owns each free cell.

Grids are (rows, cols) arrays on the ``ParsedPlan`` raster; cells are (row, col). Metres enter
and leave only through the plan's :class:`~f2n_drake.core.raster.PixelGrid`.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

import cv2
import networkx as nx
import numpy as np

from f2n_drake.core.classes import SPACE_CLASSES
from f2n_drake.core.errors import PlanningError
from f2n_drake.core.parsed import ParsedPlan
from f2n_drake.mapping.graph import DEFAULT_KERNEL_PX, OUTSIDE, exterior_mask, line_gap_px
from f2n_drake.mapping.robots import RobotProfile, traversable_subgraph

MAX_GAP_PX = 3
"""Longest run of drawn-line pixels (instance id 0) closed between two traversable instances."""

_DIRECTIONS = ((0, 1), (1, 0), (1, 1), (1, -1))


def _shift(a: np.ndarray, dr: int, dc: int) -> np.ndarray:
    """``out[r, c] = a[r + dr, c + dc]``, False beyond the border."""
    out = np.zeros_like(a)
    rows, cols = a.shape
    out[max(0, -dr) : rows - max(0, dr), max(0, -dc) : cols - max(0, dc)] = a[
        max(0, dr) : rows - max(0, -dr), max(0, dc) : cols - max(0, -dc)
    ]
    return out


def close_line_gaps(
    free: np.ndarray,
    gap: np.ndarray,
    max_gap_px: int = MAX_GAP_PX,
    rooms: np.ndarray | None = None,
) -> np.ndarray:
    """Close runs of ``gap`` cells at most ``max_gap_px`` long with ``free`` cells at both ends.

    A directional morphological closing: along rows, columns and both diagonals, a straight run
    of 1..max_gap_px ``gap`` cells bounded by free cells on both sides becomes free. Cells that are
    not ``gap`` (walls, windows, non-traversable instances) are never filled, and longer runs
    (a wall drawn >= max_gap_px + 1 px thick) stay blocked. Given ``rooms`` ((H, W) int, a room's
    instance id on its cells, 0 elsewhere), a run between two different rooms stays blocked too:
    rooms meet only through connectors, and a thin line between two rooms is a wall.
    """
    free = np.asarray(free, bool)
    gap = np.asarray(gap, bool) & ~free
    out = free.copy()
    for dr, dc in _DIRECTIONS:
        for length in range(1, max_gap_px + 1):
            # run occupies offsets 0..length-1 from its first cell p; free at -1 and length
            run = _shift(free, -dr, -dc) & _shift(free, length * dr, length * dc)
            if rooms is not None:
                before, after = _shift(rooms, -dr, -dc), _shift(rooms, length * dr, length * dc)
                run &= (before == 0) | (after == 0) | (before == after)
            for i in range(length):
                run &= _shift(gap, i * dr, i * dc)
            for i in range(length):
                out |= _shift(run, -i * dr, -i * dc)
    return out


def free_space(
    parsed: ParsedPlan,
    traversable_classes: Iterable[str],
    *,
    instance_ids: Iterable[int] | None = None,
    max_gap_px: int = MAX_GAP_PX,
) -> np.ndarray:
    """(H, W) bool, read-only: cells a point robot may occupy.

    Pixels of instances whose class is a space or in ``traversable_classes`` (connector classes
    such as "door", "opening"), or, when ``instance_ids`` is given, exactly of those instances;
    plus the thin drawn-line gaps (instance id 0, at most ``max_gap_px`` across) between them,
    but not between two rooms (a thin wall).
    Built once per plan and set of instances (``ParsedPlan.derived``): the planner, the Nav2 map
    and the simulated walls of a run read the same array.
    """
    ids = parsed.instance_ids
    if instance_ids is None:
        allowed = set(SPACE_CLASSES) | set(traversable_classes)
        instance_ids = [inst.id for inst in parsed.instances if inst.class_name in allowed]
    n = int(ids.max()) + 1
    keep = frozenset(int(i) for i in instance_ids if 0 < i < n)

    def build() -> np.ndarray:
        lut = np.zeros(n, bool)
        lut[list(keep)] = True
        spaces = np.zeros(n, np.int32)
        for inst in parsed.instances:
            if inst.class_name in SPACE_CLASSES and inst.id in keep:
                spaces[inst.id] = inst.id
        free = close_line_gaps(lut[ids], ids == 0, max_gap_px, rooms=spaces[ids])
        free.setflags(write=False)
        return free

    return parsed.derived(("free_space", keep, max_gap_px), build)


def occupancy_map(parsed: ParsedPlan, traversable_classes: Iterable[str]) -> np.ndarray:
    """(H, W) bool, read-only: the free-space map of a robot passing ``traversable_classes``.

    Spaces and the connectors of those classes, with the drawn lines between them bridged as far
    as the planner bridges them (``bridge_px``): the map the Nav2 export writes and the simulated
    walls are cut from; the planner searches the same array whenever every such connector is wide
    enough for its robot (``build_grids``).
    """
    return free_space(parsed, traversable_classes, max_gap_px=bridge_px(parsed))


def clearance_px(free: np.ndarray) -> np.ndarray:
    """(H, W) float32: distance from each free cell centre to the nearest blocked cell centre
    (image border counts as blocked) [px]; 0 on blocked cells."""
    padded = np.pad(np.asarray(free, np.uint8), 1)
    dist = cv2.distanceTransform(padded, cv2.DIST_L2, cv2.DIST_MASK_PRECISE)
    return dist[1:-1, 1:-1]


def inflate(free: np.ndarray, radius_px: float) -> np.ndarray:
    """(H, W) bool: free cells whose centre is at least ``radius_px`` from every blocked pixel's
    edge (centre distance >= radius_px + 0.5), i.e. where a disc robot's centre may go."""
    if radius_px <= 0:
        return np.asarray(free, bool).copy()
    return clearance_px(free) >= radius_px + 0.5


def bridge_px(parsed: ParsedPlan) -> int:
    """Longest run of drawn-line pixels the planner bridges between traversable instances [px].

    The drawn lines between rooms and doors, one pixel thicker than ``line_gap_px`` measures them
    (its 75th percentile), at least ``MAX_GAP_PX``: the graph's dilation reaches that far too, so
    every edge of the graph can be crossed. The slack matters on scans: a blurred line turned by a
    degree or two is a staircase, a pixel thicker in some columns than in others, and a door whose
    outline is bridged only where it is thin is too narrow for the robot. Walls (thicker, or wall
    instances) stay blocked.
    """
    return max(MAX_GAP_PX, math.ceil(line_gap_px(parsed)) + 1)


def region_owner(parsed: ParsedPlan, free: np.ndarray, max_gap_px: int = MAX_GAP_PX) -> np.ndarray:
    """(H, W) int32: instance id owning each free cell (0 on blocked cells).

    Instance pixels own themselves; closed gap cells take a neighbouring free instance's id
    (grown ``max_gap_px`` times by a 3x3 maximum filter).
    """
    ids = parsed.instance_ids
    owner = np.where(free & (ids > 0), ids, 0).astype(np.int32)
    missing = free & (owner == 0)
    kernel = np.ones((3, 3), np.uint8)
    for _ in range(max_gap_px):
        if not missing.any():
            break
        grown = cv2.dilate(owner.astype(np.float32), kernel).astype(np.int32)
        owner = np.where(missing, grown, owner)
        missing = free & (owner == 0)
    return owner


def to_cell(parsed: ParsedPlan, xy_m: tuple[float, float], what: str = "point") -> tuple[int, int]:
    """(row, col) of the cell containing ``xy_m`` [m]. Raises PlanningError outside the raster."""
    if parsed.grid is None:
        raise PlanningError("the plan has no metric scale; planning needs metres per pixel")
    col, row = np.rint(parsed.grid.to_px(np.asarray(xy_m, float))).astype(int)
    rows, cols = parsed.instance_ids.shape
    if not (0 <= row < rows and 0 <= col < cols):
        raise PlanningError(f"{what} ({xy_m[0]:.2f}, {xy_m[1]:.2f}) m lies outside the plan")
    return int(row), int(col)


def to_metres(parsed: ParsedPlan, cells: np.ndarray) -> np.ndarray:
    """(N, 2) (row, col) cells -> (N, 2) (x, y) metres of their centres."""
    cells = np.asarray(cells, float).reshape(-1, 2)
    return parsed.grid.to_m(cells[:, ::-1])


@dataclass(frozen=True)
class PlanningGrids:
    """Everything both planners search on, for one plan and one robot.

    Attributes:
        free: (H, W) bool, un-inflated free space (the wall-crossing reference).
        clear: (H, W) bool, ``free`` inflated by the robot radius: where the centre may go.
        owner: (H, W) int32, instance id owning each free cell, 0 elsewhere.
        cost: (H, W) float64 per-cell cost multiplier, or None when all are 1.
        keys: instance id -> graph node key of the traversable spaces and connectors.
        radius_px: robot radius [px].
        metres_per_px: grid scale [m].
    """

    free: np.ndarray
    clear: np.ndarray
    owner: np.ndarray
    cost: np.ndarray | None
    keys: dict[int, str]
    radius_px: float
    metres_per_px: float


def build_grids(
    parsed: ParsedPlan, profile: RobotProfile, graph: nx.Graph | None = None
) -> PlanningGrids:
    """Free, inflated and ownership grids for ``profile`` on ``parsed``.

    With ``graph``, the traversable instances are exactly the space and connector nodes of
    ``traversable_subgraph(graph, profile)`` (narrow connectors dropped), and connector cells cost
    ``profile.connector_factor``; without it, every space and every connector of a class in
    ``profile.traversable`` (multipliers from ``profile.cost_multipliers``).
    """
    if parsed.grid is None:
        raise PlanningError("the plan has no metric scale; planning needs metres per pixel")
    factors: dict[int, float] = {}
    if graph is not None:
        sub = traversable_subgraph(graph, profile)
        keys = {
            int(d["instance_id"]): n
            for n, d in sub.nodes(data=True)
            if d.get("kind") in ("space", "connector") and d.get("instance_id", -1) > 0
        }
        for iid, n in keys.items():
            d = sub.nodes[n]
            if d["kind"] == "connector":
                factors[iid] = profile.connector_factor(d["class_name"], d.get("width_m"))
        ids = parsed.instance_ids
        if OUTSIDE in sub:
            outside_id = int(ids.max()) + 1
            exterior = exterior_mask(
                ids, int(graph.graph.get("kernel_px") or DEFAULT_KERNEL_PX), parsed.labels
            )
            ids = np.where(exterior, outside_id, ids).astype(np.int32)
            keys[outside_id] = OUTSIDE
            factors[outside_id] = profile.cost_multipliers.get(OUTSIDE, 1.0)
            parsed = ParsedPlan(
                ids, parsed.labels, parsed.instances, parsed.grid, parsed.scale_source
            )
    else:
        allowed = set(SPACE_CLASSES) | set(profile.traversable)
        insts = [i for i in parsed.instances if i.class_name in allowed]
        keys = {i.id: f"{i.class_name}#{i.id}" for i in insts}
        factors = {i.id: profile.cost_multipliers.get(i.class_name, 1.0) for i in insts}
    max_gap_px = bridge_px(parsed)
    free = free_space(parsed, (), instance_ids=keys, max_gap_px=max_gap_px)
    # The robot's centre keeps its radius plus a safety margin from every wall: the margin absorbs
    # localization error and the corner-cutting of path following.
    radius_px = parsed.grid.length_px(profile.radius_m + profile.clearance_margin_m)
    clear = inflate(free, radius_px)
    owner = region_owner(parsed, free, max_gap_px)
    cost = None
    if any(f != 1.0 for f in factors.values()):
        lut = np.ones(int(owner.max()) + 1)
        for iid, f in factors.items():
            if iid < len(lut):
                lut[iid] = f
        cost = lut[owner]
    return PlanningGrids(free, clear, owner, cost, keys, radius_px, parsed.grid.metres_per_px)


def endpoint_cell(
    parsed: ParsedPlan, grids: PlanningGrids, xy_m: tuple[float, float], what: str
) -> tuple[int, int]:
    """The cell of a start/goal given in metres, checked free for the robot.

    Raises PlanningError outside the plan, inside a wall/non-traversable area, or closer than
    the robot radius to an obstacle.
    """
    row, col = to_cell(parsed, xy_m, what)
    where = f"{what} ({xy_m[0]:.2f}, {xy_m[1]:.2f}) m"
    if not grids.free[row, col]:
        raise PlanningError(f"{where} is inside a wall or outside the spaces this robot can use")
    if not grids.clear[row, col]:
        radius_m = grids.radius_px * grids.metres_per_px
        raise PlanningError(f"{where} is closer than the robot radius {radius_m:.3f} m to a wall")
    return row, col


def node_cell(grids: PlanningGrids, graph: nx.Graph, key: str) -> tuple[int, int]:
    """A free cell standing for graph node ``key``: for a space, its cell farthest from any
    obstacle; for a connector, the reachable cell of it or its sides nearest its centroid."""
    if key not in graph or graph.nodes[key].get("instance_id", -1) <= 0:
        raise PlanningError(f"unknown node {key!r} (no such room or connector in the plan)")
    data = graph.nodes[key]
    iid = int(data["instance_id"])
    if iid not in grids.keys:
        raise PlanningError(f"{key} is not traversable for this robot")
    if data["kind"] == "space":
        mask = (grids.owner == iid) & grids.clear
        if not mask.any():
            raise PlanningError(f"{key} has no cell where this robot fits")
        depth = np.where(mask, clearance_px(grids.free), -1.0)
        return tuple(int(v) for v in np.unravel_index(int(np.argmax(depth)), depth.shape))
    near = [iid] + [
        int(graph.nodes[s]["instance_id"])
        for s in data.get("sides", ())
        if s in graph and graph.nodes[s].get("instance_id", -1) > 0
    ]
    mask = np.isin(grids.owner, near) & grids.clear
    if not mask.any():
        raise PlanningError(f"{key} has no cell where this robot fits")
    rows, cols = np.nonzero(mask)
    col0, row0 = data["centroid_px"]
    k = int(np.argmin((rows - row0) ** 2 + (cols - col0) ** 2))
    return int(rows[k]), int(cols[k])
