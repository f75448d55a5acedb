"""Hierarchical planning over the connectivity graph with precomputed in-room paths.

Precompute (constructor): for every room, a compiled Dijkstra distance field from each of its
connectors over the room and its connectors (on the grid inflated by the robot radius) gives the
shortest in-room path between each pair of connectors, from wherever it leaves one to wherever
it first reaches the other; the connector graph weights each pair by that real path cost. Rooms
are independent and may run on a thread pool (numba releases the GIL). Rooms too large to keep
fields for (``FIELD_BUDGET_CELLS``, building corridors) store only the pair paths.

Query (:meth:`HierarchicalPlanner.plan`): the start-to-connector costs of the start room and
connector-to-goal costs of the goal room are field look-ups (a multi-target Dijkstra for rooms
without fields), plus a direct in-room A* when both are in one room; then Dijkstra over
(connector, side entered from) states, so each connector is crossed from one side to the other;
the stored segments are joined inside each connector where the in-room paths naturally meet it
(never forced through its centre) and shortcut by line of sight on the inflated grid.
"""

from __future__ import annotations

import heapq
import math
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

import networkx as nx
import numpy as np
from scipy import ndimage

from f2n_drake.errors import PlanningError
from f2n_drake.parsed import ParsedPlan
from f2n_drake.planning.astar import DistanceField, astar, dijkstra_to_labels, distance_field
from f2n_drake.planning.grid import build_grids
from f2n_drake.planning.robots import RobotProfile, load_profile
from f2n_drake.planning.route import Endpoint, Route, global_search, make_route, resolve
from f2n_drake.planning.smoothing import segment_clear

FIELD_BUDGET_CELLS = 4_000_000
"""Largest (connectors x window cells) of a room whose per-connector distance fields are kept."""


@dataclass(frozen=True)
class _Region:
    """A search window: a room with its connectors, or a lone connector (start inside it)."""

    key: str
    origin: tuple[int, int]  # (row, col) of the window's top-left cell
    passable: np.ndarray  # window bool: inflated free cells of the room and its connectors
    labels: np.ndarray  # window int32: connector index per cell, -1 elsewhere
    cost: np.ndarray | None
    connectors: list[str]
    fields: list[DistanceField] = field(default_factory=list)  # per connector (rooms only)

    def local(self, cell: tuple[int, int]) -> tuple[int, int]:
        return cell[0] - self.origin[0], cell[1] - self.origin[1]


class HierarchicalPlanner:
    """Room-level planner for one plan and one robot.

    Args:
        parsed: the plan's instances and raster (needs a metric grid).
        graph: its connectivity graph (``build_connectivity_graph``).
        profile: the robot (or "ground"/"uav"/a YAML path).
        workers: threads for the precompute (default 1; see the benchmark for whether 2 help).
    """

    def __init__(self, parsed: ParsedPlan, graph: nx.Graph, profile: RobotProfile | str,
                 *, workers: int = 1) -> None:
        t0 = time.perf_counter()
        self.parsed = parsed
        self.graph = graph
        self.profile = load_profile(profile)
        self.grids = build_grids(parsed, self.profile, graph)
        self._id_of = {key: iid for iid, key in self.grids.keys.items()}
        self._kind = {key: graph.nodes[key]["kind"] for key in self._id_of}
        self._slices = ndimage.find_objects(self.grids.owner * self.grids.clear)
        self.regions: dict[str, _Region] = {}
        for key, kind in self._kind.items():
            if kind == "space":
                conns = [c for c in graph.neighbors(key) if self._kind.get(c) == "connector"]
                region = self._make_region(key, conns)
            else:
                region = self._make_region(key, [key], own=False)
            if region is not None:
                self.regions[key] = region
        t_grids = time.perf_counter()
        rooms = [r for k, r in self.regions.items() if self._kind[k] == "space"]
        if workers > 1 and len(rooms) > 1:
            with ThreadPoolExecutor(workers) as pool:
                results = list(pool.map(self._room_segments, rooms))
        else:
            results = [self._room_segments(r) for r in rooms]
        # (room, connector) -> [(next connector, cost)]; (room, a, b) -> cells from a to b
        self.segments: dict[tuple[str, str, str], np.ndarray] = {}
        self.adjacency: dict[tuple[str, str], list[tuple[str, float]]] = {}
        self.rooms_of: dict[str, list[str]] = {}
        for region, found in zip(rooms, results, strict=True):
            for conn in region.connectors:
                self.rooms_of.setdefault(conn, []).append(region.key)
            for (a, b), (cells, cost) in found.items():
                self.segments[(region.key, a, b)] = cells
                self.segments[(region.key, b, a)] = cells[::-1]
                self.adjacency.setdefault((region.key, a), []).append((b, cost))
                self.adjacency.setdefault((region.key, b), []).append((a, cost))
        t1 = time.perf_counter()
        self.precompute_ms = (t1 - t0) * 1e3
        self.precompute_timings = {"grids": (t_grids - t0) * 1e3, "segments": (t1 - t_grids) * 1e3}

    # -- precompute ------------------------------------------------------------------------------
    def _make_region(self, key: str, connectors: list[str], own: bool = True) -> _Region | None:
        members = ([key] if own else []) + connectors
        slices = [self._slices[self._id_of[m] - 1] for m in members
                  if self._id_of[m] - 1 < len(self._slices)]
        slices = [s for s in slices if s is not None]
        if not slices:
            return None
        r0 = min(s[0].start for s in slices)
        r1 = max(s[0].stop for s in slices)
        c0 = min(s[1].start for s in slices)
        c1 = max(s[1].stop for s in slices)
        owner = self.grids.owner[r0:r1, c0:c1]
        clear = self.grids.clear[r0:r1, c0:c1]
        passable = clear & np.isin(owner, [self._id_of[m] for m in members])
        labels = np.full(owner.shape, -1, np.int32)
        usable = []
        for conn in connectors:
            cells = passable & (owner == self._id_of[conn])
            if cells.any():
                labels[cells] = len(usable)
                usable.append(conn)
        cost = None if self.grids.cost is None else np.ascontiguousarray(
            self.grids.cost[r0:r1, c0:c1])
        return _Region(key, (r0, c0), np.ascontiguousarray(passable), labels, cost, usable)

    def _room_segments(self, region: _Region) -> dict[tuple[str, str], tuple[np.ndarray, float]]:
        """Shortest in-room path between each pair of connectors (a, b): cells, cost.

        Small rooms keep one distance field per connector (``region.fields``) so queries only
        look costs up; rooms over ``FIELD_BUDGET_CELLS`` (building corridors) run searches."""
        origin = np.asarray(region.origin)
        rows, cols = region.passable.shape
        k = len(region.connectors)
        out = {}
        if k * rows * cols > FIELD_BUDGET_CELLS:
            for i in range(k - 1):
                targets = np.where(region.labels > i, region.labels - i - 1, -1).astype(np.int32)
                paths, _ = dijkstra_to_labels(region.passable, np.argwhere(region.labels == i),
                                              targets, k - i - 1, cost=region.cost)
                for j, path in enumerate(paths, start=i + 1):
                    if path.found:
                        out[(region.connectors[i], region.connectors[j])] = (
                            path.cells + origin, path.cost)
            return out
        padded = [(np.argwhere(region.labels == i) + 1) @ np.array([cols + 2, 1])
                  for i in range(k)]
        for i, conn in enumerate(region.connectors):
            fld = distance_field(region.passable, np.argwhere(region.labels == i),
                                 cost=region.cost)
            region.fields.append(fld)
            for j in range(i):
                best = int(np.argmin(fld.cost[padded[j]]))
                cost = float(fld.cost[padded[j][best]])
                if np.isfinite(cost):
                    end = divmod(int(padded[j][best]), cols + 2)
                    cells = fld.path_from((end[0] - 1, end[1] - 1)) + origin  # from j to i
                    out[(region.connectors[j], conn)] = (cells, cost)
        return out

    # -- queries ---------------------------------------------------------------------------------
    def _region_of(self, cell: tuple[int, int], what: str) -> _Region:
        key = self.grids.keys.get(int(self.grids.owner[cell]))
        if key is None or key not in self.regions:
            raise PlanningError(f"{what} is not in a room this robot can use")
        return self.regions[key]

    def _local(self, region: _Region, cell: tuple[int, int]) -> tuple[dict, int]:
        """Connector -> (cost, cells from ``cell`` to it) for each reachable connector."""
        origin = np.asarray(region.origin)
        local = region.local(cell)
        if region.fields:  # a room: look the precomputed fields up
            out = {}
            for conn, fld in zip(region.connectors, region.fields, strict=True):
                cost = fld.cost_at(local)
                if np.isfinite(cost):
                    out[conn] = (cost, (fld, local))
            return out, 0
        paths, expanded = dijkstra_to_labels(region.passable, np.array([local]), region.labels,
                                             len(region.connectors), cost=region.cost)
        return {c: (p.cost, p.cells + origin) for c, p in zip(region.connectors, paths, strict=True)
                if p.found}, expanded

    def _local_cells(self, region: _Region, found) -> np.ndarray:
        """Cells from the query point to a connector for an entry of :meth:`_local`."""
        if isinstance(found, tuple):
            fld, local = found
            return fld.path_from(local) + np.asarray(region.origin)
        return found

    def _join(self, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, int]:
        """Cells after ``a`` leading to ``b`` (inclusive): a straight line when clear, else A*
        in a window around both."""
        if np.array_equal(a, b):
            return np.empty((0, 2), np.int64), 0
        if segment_clear(self.grids.clear, int(a[0]), int(a[1]), int(b[0]), int(b[1])):
            return b[None, :], 0
        pad = int(np.abs(a - b).max()) + 8
        r0, c0 = np.maximum(np.minimum(a, b) - pad, 0)
        r1, c1 = np.maximum(a, b) + pad + 1
        window = self.grids.clear[r0:r1, c0:c1]
        found = astar(window, (a[0] - r0, a[1] - c0), (b[0] - r0, b[1] - c0))
        if not found.found:
            raise PlanningError(f"cannot join path pieces at cells {tuple(a)} and {tuple(b)}")
        return found.cells[1:] + np.array([r0, c0]), found.expanded

    def _connector_search(self, rs: _Region, rg: _Region, start: dict, goal: dict, best: float):
        """Dijkstra over (connector, room it was entered from): a route crosses each connector
        from one side to another. Returns (cost, chain of states) or (best, None)."""
        start_room = rs.key if self._kind[rs.key] == "space" else None
        goal_room = rg.key if self._kind[rg.key] == "space" else None
        dist = {(c, start_room): cost for c, (cost, _) in start.items()}
        prev: dict = {}
        heap = [(d, c, r) for (c, r), d in dist.items()]
        heapq.heapify(heap)
        best_end = None
        while heap:
            d, c, came = heapq.heappop(heap)
            if d > dist[(c, came)]:
                continue
            if d >= best:
                break
            if c in goal and came != goal_room and d + goal[c][0] < best:
                best, best_end = d + goal[c][0], (c, came)
            for room in self.rooms_of.get(c, ()):
                if room == came:
                    continue
                for nxt, w in self.adjacency.get((room, c), ()):
                    state = (nxt, room)
                    if d + w < dist.get(state, math.inf):
                        dist[state] = d + w
                        prev[state] = (c, came)
                        heapq.heappush(heap, (d + w, nxt, room))
        if best_end is None:
            return best, None
        chain = [best_end]
        while chain[-1] in prev:
            chain.append(prev[chain[-1]])
        return best, chain[::-1]

    def plan(self, start: Endpoint, goal: Endpoint) -> Route:
        """Route from ``start`` to ``goal`` ((x, y) metres or a node key), smoothed.

        Raises PlanningError for an invalid start/goal or when no route exists for this robot.
        """
        t0 = time.perf_counter()
        s = resolve(self.parsed, self.grids, self.graph, start, "start")
        g = resolve(self.parsed, self.grids, self.graph, goal, "goal")
        rs, rg = self._region_of(s, "start"), self._region_of(g, "goal")
        from_start, n_s = self._local(rs, s)
        to_goal, n_g = self._local(rg, g)
        expanded = n_s + n_g
        best, direct = math.inf, None
        if rs.key == rg.key:
            direct = astar(rs.passable, rs.local(s), rs.local(g), cost=rs.cost)
            expanded += direct.expanded
            best = direct.cost
        t_local = time.perf_counter()
        best, chain = self._connector_search(rs, rg, from_start, to_goal, best)
        t_graph = time.perf_counter()
        if best == math.inf:
            raise PlanningError(
                f"no route from {rs.key} to {rg.key} for robot {self.profile.name!r}")
        if chain is None:  # the direct in-room path wins
            pieces, sequence = [direct.cells + np.asarray(rs.origin)], [rs.key]
        else:
            first, last = chain[0][0], chain[-1][0]
            pieces = [self._local_cells(rs, from_start[first][1])]
            sequence = [rs.key, first]
            for (a, _), (b, room) in zip(chain, chain[1:], strict=False):
                pieces.append(self.segments[(room, a, b)])
                sequence += [room, b]
            pieces.append(self._local_cells(rg, to_goal[last][1])[::-1])
            sequence.append(rg.key)
        cells = [pieces[0]]
        for piece in pieces[1:]:
            joint, n = self._join(cells[-1][-1], piece[0])
            expanded += n
            cells += [joint, piece[1:]]
        cells = np.concatenate(cells)
        sequence = [k for i, k in enumerate(sequence) if i == 0 or k != sequence[i - 1]]
        t_assemble = time.perf_counter()
        timings = {
            "precompute": self.precompute_ms,
            "local": (t_local - t0) * 1e3,
            "graph": (t_graph - t_local) * 1e3,
            "assemble": (t_assemble - t_graph) * 1e3,
        }
        route = make_route(self.parsed, self.grids, cells, sequence, best, timings, expanded)
        route.timings["query"] = (time.perf_counter() - t0) * 1e3
        return route

    def plan_global(self, start: Endpoint, goal: Endpoint, *, smooth: bool = False) -> Route:
        """The baseline on this planner's grids: A* over the whole inflated free grid."""
        s = resolve(self.parsed, self.grids, self.graph, start, "start")
        g = resolve(self.parsed, self.grids, self.graph, goal, "goal")
        return global_search(self.parsed, self.grids, s, g, smooth=smooth)
