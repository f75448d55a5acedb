"""Hierarchical planning: precomputed in-region distance fields joined through portal cells.

Precompute (constructor, :mod:`f2n_drake.planning.regions`), on the grid inflated by the robot
radius:

1. *Zones*: spaces joined by an ``opening`` (a kitchen open to the living room) are one zone,
   as are balconies open to the air and the ``outside`` (exterior pixels around the building,
   free for robots that traverse "outside").
2. *Regions*: a zone too big for one field per connector (building corridors, the outside) is
   cut into tiles; where two tiles meet become virtual connectors (seams).
3. *Portals*: doors, front doors, windows and seams are cut into short pieces; each piece's
   middle cell is a portal cell, and a portal is a (region, piece) pair. Per region, one
   compiled Dijkstra field (float32) from each of its portal cells over the region plus its
   connectors' cells.
4. *Portal graph*: portal i -> j in one region costs field i at cell j; crossing a piece between
   the regions it touches costs nothing (the same cell). Up to ``ALL_PAIRS_MAX_PORTALS``
   portals, all-pairs costs and predecessors (scipy's compiled Dijkstra) are kept.

Query (:meth:`HierarchicalPlanner.plan`): if the straight segment is clear, done. Otherwise the
start region's fields at the start cell, the goal region's at the goal cell and the portal
costs give min over (i, j) of d_s[i] + D[i, j] + d_g[j] (all-pairs look-ups, or an A* over the
portal graph for big buildings), against an in-region A* when both ends share a region; one
compiled kernel (:mod:`f2n_drake.planning.portal_query`) descends the fields into cells (the
raw path costs exactly the chosen total), shortcuts them and converts to metres.
``nodes_expanded`` counts portal-graph nodes, descended cells and A* cells; look-ups count 0.
"""

from __future__ import annotations

import copy
import math
import time
from collections.abc import Iterable

import networkx as nx
import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import shortest_path

from f2n_drake.core.errors import PlanningError
from f2n_drake.core.parsed import ParsedPlan
from f2n_drake.mapping.occupancy import build_grids
from f2n_drake.mapping.robots import RobotProfile, load_profile
from f2n_drake.planning.astar import astar, distance_field
from f2n_drake.planning.portal_query import finish_query, portal_query, portal_query_search
from f2n_drake.planning.regions import Regions, build_regions
from f2n_drake.planning.route import Endpoint, Route, erase_loops, global_search, resolve
from f2n_drake.planning.smoothing import segment_clear

_NO_CHAIN = np.zeros(0, np.int64)
CROSSING_COST = 1e-9
ALL_PAIRS_MAX_PORTALS = 2000
"""Up to this many portals the constructor keeps all-pairs portal costs (P x P float64 and
int64); beyond it (large buildings) each query runs an A* over the portal graph."""
"""Cost of the edge between two portals of one connector (scipy drops exact zeros)."""


def portal_graph(reg: Regions) -> csr_matrix:
    """(P, P) sparse costs between portals: in-region hops (field costs) and crossings of one
    connector piece between the regions it touches (a shared cell: ``CROSSING_COST``)."""
    n = len(reg.portal_region)
    cross_from, cross_to = [], []
    for portals in reg.connector_portals:
        for a in portals:
            for b in portals:
                if a != b:
                    cross_from.append(a)
                    cross_to.append(b)
    rows = np.concatenate([reg.edge_from, np.asarray(cross_from, np.int64)])
    cols = np.concatenate([reg.edge_to, np.asarray(cross_to, np.int64)])
    weights = np.concatenate([reg.edge_cost, np.full(len(cross_from), CROSSING_COST)])
    return csr_matrix((weights, (rows, cols)), shape=(n, n))


class HierarchicalPlanner:
    """Room-level planner for one plan and one robot (see the module docstring).

    Args:
        parsed: the plan's instances and raster (needs a metric grid).
        graph: its connectivity graph (``build_connectivity_graph``).
        profile: the robot (or "ground"/"uav"/a YAML path).
        workers: threads for the field precompute (numba releases the GIL).

    Attributes: ``precompute_ms``, ``precompute_timings`` (ms per stage), ``precompute_expanded``
    (cells expanded by the precompute's searches), ``regions`` (:class:`Regions`).
    """

    def __init__(
        self, parsed: ParsedPlan, graph: nx.Graph, profile: RobotProfile | str, *, workers: int = 1
    ) -> None:
        t0 = time.perf_counter()
        self.parsed = parsed
        self.graph = graph
        self.profile = load_profile(profile)
        self.grids = build_grids(parsed, self.profile, graph)
        t1 = time.perf_counter()
        self.regions: Regions = build_regions(self.grids, graph, self.profile, workers=workers)
        t2 = time.perf_counter()
        reg = self.regions
        self.all_pairs = len(reg.portal_region) <= ALL_PAIRS_MAX_PORTALS
        self._use_portal_graph(portal_graph(reg))
        clear_cost = self.grids.cost[self.grids.clear] if self.grids.cost is not None else None
        self._h_scale = (
            float(clear_cost.min()) if clear_cost is not None and clear_cost.size else 1.0
        )
        self._cost = self.grids.cost if self.grids.cost is not None else np.ones((1, 1))
        self._uniform = self.grids.cost is None
        self._clear = np.ascontiguousarray(self.grids.clear)
        self._owner = np.ascontiguousarray(self.grids.owner)
        self._rtab = np.array(
            [
                (ids[0] if len(ids) else 0, len(ids), *org, shp[1])
                for ids, org, shp in zip(
                    reg.region_portals, reg.region_origin, reg.region_shape, strict=True
                )
            ],
            np.int64,
        ).reshape(-1, 5)
        self._pinfo = np.ascontiguousarray(
            np.column_stack(
                [
                    reg.portal_offset,
                    reg.portal_origin,
                    reg.portal_shape,
                    reg.portal_region,
                    reg.portal_local,
                    reg.exit_base,
                ]
            )
            .reshape(-1, 8)
            .astype(np.int64)
        )
        grid = parsed.grid
        # affine maps through the PixelGrid: metres -> (col, row) and (row, col) -> metres
        o = grid.to_px(np.zeros(2))
        self._to_px = tuple(
            tuple(float(v) for v in p)
            for p in (o, grid.to_px(np.array([1.0, 0.0])) - o, grid.to_px(np.array([0.0, 1.0])) - o)
        )
        m0 = grid.to_m(np.zeros(2))
        self._to_m = np.array(
            [grid.to_m(np.array([0.0, 1.0])) - m0, grid.to_m(np.array([1.0, 0.0])) - m0, m0]
        )
        t3 = time.perf_counter()
        self.precompute_ms = (t3 - t0) * 1e3
        self.precompute_timings = {
            "grids": (t1 - t0) * 1e3,
            "fields": (t2 - t1) * 1e3,
            "portal_graph": (t3 - t2) * 1e3,
        }
        self.precompute_expanded = reg.expanded

    def _use_portal_graph(self, graph_csr: csr_matrix) -> None:
        if self.all_pairs:  # a query is then a few look-ups
            dist, pred = shortest_path(
                graph_csr, method="D", directed=True, return_predecessors=True
            )
            self._dist, self._pred = np.ascontiguousarray(dist), pred.astype(np.int64)
        else:  # a query searches the portal graph
            self._csr = (
                graph_csr.indptr.astype(np.int64),
                graph_csr.indices.astype(np.int64),
                graph_csr.data.astype(np.float64),
            )

    def closing(self, connectors: Iterable[str]) -> HierarchicalPlanner:
        """This planner with the ``connectors`` (graph node keys) closed, sharing its precompute.

        The closed connectors' portals are cut from the portal graph (all-pairs costs redone:
        milliseconds for a flat) and their cells are no longer clear, so no query or shortcut
        goes through them. Keys that are no connector of this planner are ignored.
        """
        keys = set(connectors)
        ids = [iid for iid, key in self.grids.keys.items() if key in keys]
        if not ids:
            return self
        closed = copy.copy(self)
        reg = self.regions
        cut = np.isin(self._owner[reg.portal_cell[:, 0], reg.portal_cell[:, 1]], ids)
        edges = portal_graph(reg).tocoo()
        keep = ~(cut[edges.row] | cut[edges.col])
        n = len(reg.portal_region)
        closed._use_portal_graph(
            csr_matrix((edges.data[keep], (edges.row[keep], edges.col[keep])), shape=(n, n))
        )
        closed._clear = np.ascontiguousarray(self._clear & ~np.isin(self._owner, ids))
        return closed

    # -- queries ---------------------------------------------------------------------------------
    def _cell(self, point: Endpoint, what: str) -> tuple[int, int]:
        """Like :func:`resolve`, with a fast path for metric points on clear cells."""
        if not isinstance(point, str):
            (c0, r0), (cx, rx), (cy, ry) = self._to_px
            x, y = float(point[0]), float(point[1])
            r, c = round(r0 + rx * x + ry * y), round(c0 + cx * x + cy * y)
            rows, cols = self._clear.shape
            if 0 <= r < rows and 0 <= c < cols and self._clear[r, c]:
                return r, c
        return resolve(self.parsed, self.grids, self.graph, point, what)

    def _in_region(self, region: int, s: tuple[int, int], g: tuple[int, int]):
        reg = self.regions
        r0, c0 = reg.region_origin[region]
        cost = reg.region_cost(region, self.grids.cost)
        return astar(
            reg.region_passable[region], (s[0] - r0, s[1] - c0), (g[0] - r0, g[1] - c0), cost=cost
        ), np.array([r0, c0])

    def _repair(self, cells: np.ndarray, bad: np.ndarray) -> tuple[np.ndarray, int]:
        """Replace each unclear jump before ``cells[i]`` (i in ``bad``) by a windowed A*."""
        pieces, start, expanded = [], 0, 0
        for i in sorted(int(b) for b in bad):
            a, b = cells[i - 1], cells[i]
            pieces.append(cells[start:i])
            pad = int(np.abs(a - b).max()) + 8
            r0, c0 = np.maximum(np.minimum(a, b) - pad, 0)
            r1, c1 = np.maximum(a, b) + pad + 1
            found = astar(self._clear[r0:r1, c0:c1], (a[0] - r0, a[1] - c0), (b[0] - r0, b[1] - c0))
            expanded += found.expanded
            if not found.found:
                raise PlanningError(f"cannot join path pieces at cells {tuple(a)} and {tuple(b)}")
            pieces.append(found.cells[1:-1] + np.array([r0, c0]))
            start = i
        pieces.append(cells[start:])
        return np.concatenate(pieces), expanded

    def plan(self, start: Endpoint, goal: Endpoint) -> Route:
        """Route from ``start`` to ``goal`` ((x, y) metres or a node key), smoothed.

        Raises PlanningError for an invalid start/goal or when no route exists for this robot.
        """
        t0 = time.perf_counter()
        s = self._cell(start, "start")
        g = self._cell(goal, "goal")
        region = self.regions.query_region
        rs, rg = int(region[s]), int(region[g])
        if rs < 0 or rg < 0:
            raise PlanningError(
                f"{'start' if rs < 0 else 'goal'} is not in a room this robot can use"
            )
        bound, direct, expanded = math.inf, None, 0
        if rs == rg and not segment_clear(self._clear, s[0], s[1], g[0], g[1]):
            direct, origin = self._in_region(rs, s, g)
            expanded, bound = direct.expanded, direct.cost
        reg = self.regions
        if self.all_pairs:
            kind, cost, cells, bad, nbad, way, metres, owners, raw_px, smooth_px = portal_query(
                s[0],
                s[1],
                g[0],
                g[1],
                rs,
                rg,
                bound,
                self._rtab,
                reg.flat,
                self._pinfo,
                self._dist,
                self._pred,
                reg.exit_cells,
                self._cost,
                self._uniform,
                self._clear,
                self._owner,
                self._to_m,
            )
        else:
            kind, cost, cells, bad, nbad, way, metres, owners, raw_px, smooth_px, n = (
                portal_query_search(
                    s[0],
                    s[1],
                    g[0],
                    g[1],
                    rs,
                    rg,
                    bound,
                    self._rtab,
                    reg.flat,
                    self._pinfo,
                    *self._csr,
                    reg.portal_cell,
                    self._h_scale,
                    reg.exit_cells,
                    self._cost,
                    self._uniform,
                    self._clear,
                    self._owner,
                    self._to_m,
                )
            )
            expanded += n
        if kind == 3:
            raise PlanningError("internal error: a distance field could not be descended")
        if kind == 2:
            if direct is None or not direct.found:
                keys = self.grids.keys
                raise PlanningError(
                    f"no route from {keys.get(int(self.grids.owner[s]), '?')} to "
                    f"{keys.get(int(self.grids.owner[g]), '?')} for robot {self.profile.name!r}"
                )
            cells, cost, nbad = direct.cells + origin, bound, -1
        elif kind == 1:
            expanded += len(cells)
        if nbad:
            if nbad > 0:
                cells, n_fix = self._repair(cells, bad[:nbad])
                expanded += n_fix
            way, metres, owners, raw_px, smooth_px = finish_query(
                cells, self._clear, self._owner, self._to_m
            )
        keys = self.grids.keys
        mpp = self.grids.metres_per_px
        t1 = time.perf_counter()
        return Route(
            waypoints_m=metres,
            cells=cells,
            waypoint_cells=way,
            sequence=erase_loops([keys.get(o, "?") for o in owners.tolist()]),
            length_m=smooth_px * mpp,
            raw_length_m=raw_px * mpp,
            cost=(smooth_px if kind == 0 else cost) * mpp,
            timings={"precompute": self.precompute_ms, "query": (t1 - t0) * 1e3},
            nodes_expanded=expanded,
        )

    def plan_global(self, start: Endpoint, goal: Endpoint, *, smooth: bool = False) -> Route:
        """The baseline on this planner's grids: A* over the whole inflated free grid."""
        s = resolve(self.parsed, self.grids, self.graph, start, "start")
        g = resolve(self.parsed, self.grids, self.graph, goal, "goal")
        return global_search(self.parsed, self.grids, s, g, smooth=smooth)


def warm_up_kernels() -> None:
    """Compile (or load from cache) the query kernels on a tiny field."""
    field = np.array([[0.0, 1.0], [1.0, 1.4142]], np.float32).ravel()
    pinfo = np.array([[0, 0, 0, 2, 2, 0, 0, 0]], np.int64)
    rtab = np.array([[0, 1, 0, 0, 2]], np.int64)
    clear = np.ones((2, 2), bool)
    clear[1, 0] = False
    owner = np.ones((2, 2), np.int32)
    common = (np.zeros((1, 2), np.int64), np.ones((1, 1)), True, clear, owner, np.zeros((3, 2)))
    for r, c in ((1, 1), (0, 1)):
        portal_query(
            r,
            c,
            0,
            0,
            0,
            0,
            np.inf,
            rtab,
            field,
            pinfo,
            np.zeros((1, 1)),
            np.zeros((1, 1), np.int64),
            *common,
        )
        portal_query_search(
            r,
            c,
            0,
            0,
            0,
            0,
            np.inf,
            rtab,
            field,
            pinfo,
            np.zeros(2, np.int64),
            np.zeros(0, np.int64),
            np.zeros(0),
            np.zeros((1, 2), np.int64),
            1.0,
            *common,
        )
    finish_query(np.array([[0, 0], [1, 1]]), clear, owner, np.zeros((3, 2)))
    distance_field(clear, np.array([[0, 0]]))


def plan_route(
    parsed: ParsedPlan,
    graph: nx.Graph,
    profile: RobotProfile | str,
    start: Endpoint,
    goal: Endpoint,
) -> Route:
    """Hierarchical route from ``start`` to ``goal`` (metres or node keys), smoothed.

    Builds the planner (the precompute) and runs one query; keep a
    :class:`~f2n_drake.planning.hierarchical.HierarchicalPlanner` to amortise the precompute.
    Raises PlanningError for an invalid start/goal or when no route exists for this robot.
    """
    return HierarchicalPlanner(parsed, graph, load_profile(profile)).plan(start, goal)
