"""Regions, connectors and distance fields: the precompute of the hierarchical planner.

A *zone* is a set of spaces the robot moves between without a door: spaces joined by a
traversable ``opening`` connector (with the opening's cells), and balconies joined to the
``outside`` by an open-air edge. Zones too big for one field per connector
(``FIELD_BUDGET_CELLS``: building corridors, the outside) are cut into
``TILE_PX`` square tiles; each (zone, tile) is a *region* (small zones are one region).
*Connectors* are the traversable doors, front doors and windows (their inflated-free cells)
plus virtual *seams*: the cells on both sides of every boundary between two regions; both
kinds are cut into pieces at most ``PIECE_PX`` / ``SEAM_PX`` long, and each piece's middle
cell is a *portal cell*. Every connector's cells belong to the masks of all regions it
touches, and each region keeps one distance field from each of its portal cells, so a route
through portal cells costs exactly what its cells cost (no teleport anywhere); against a free
crossing it loses at most half a piece of detour per crossing, which smoothing removes.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import cv2
import networkx as nx
import numpy as np
from scipy import ndimage

from f2n_drake.core.classes import OPENING
from f2n_drake.mapping.graph import OUTSIDE
from f2n_drake.mapping.occupancy import PlanningGrids
from f2n_drake.mapping.robots import RobotProfile, traversable_subgraph
from f2n_drake.planning.astar import distance_field

TILE_PX = 96
"""Side of the tiles large zones are cut into [px]."""
FIELD_BUDGET_CELLS = 4_000_000
"""Zones whose (connectors x bounding-box cells) exceed this are tiled."""
PIECE_PX = 8
"""Longest extent of one piece of a door, front door or window [px]."""
SEAM_PX = 24
"""Longest extent of one piece of a seam between two tiles [px]."""


@dataclass(frozen=True)
class Regions:
    """Flat arrays the queries index (P portals, R regions; cells are global (row, col)).

    Attributes:
        query_region: (H, W) int32 region of each inflated-free cell (a connector's cells map
            to one region it touches), -1 elsewhere.
        flat: all fields, float32, concatenated; field of portal p is
            ``flat[portal_offset[p]:][:h*w].reshape(portal_shape[p])`` with top-left cell
            ``portal_origin[p]`` [px x cost multiplier; inf where unreachable].
        portal_region, portal_local: (P,) region of each portal, index among its portals.
        portal_cell: (P, 2) the portal cell (its connector piece's middle cell).
        exit_base, exit_cells: cell of portal q's connector nearest (on p's field) to portal p
            is ``exit_cells[exit_base[p] + portal_local[q]]`` (p, q in one region).
        edge_from, edge_to, edge_cost: in-region portal-to-portal edges (finite costs).
        connector_portals: portals of each connector (crossing it costs nothing).
        region_portals, region_offsets, region_origin, region_shape, region_passable: per
            region: its portals, their field offsets, window top-left, window shape, window mask.
        expanded: cells expanded by the precompute's searches.
    """

    query_region: np.ndarray
    flat: np.ndarray
    portal_offset: np.ndarray
    portal_origin: np.ndarray
    portal_shape: np.ndarray
    portal_region: np.ndarray
    portal_local: np.ndarray
    portal_cell: np.ndarray
    exit_base: np.ndarray
    exit_cells: np.ndarray
    edge_from: np.ndarray
    edge_to: np.ndarray
    edge_cost: np.ndarray
    connector_portals: list[list[int]]
    region_portals: list[np.ndarray]
    region_offsets: list[np.ndarray]
    region_origin: list[tuple[int, int]]
    region_shape: list[tuple[int, int]]
    region_passable: list[np.ndarray]
    expanded: int

    def region_cost(self, region: int, cost: np.ndarray | None) -> np.ndarray | None:
        """The cost-multiplier window of ``region`` (None when costs are uniform)."""
        if cost is None:
            return None
        (r0, c0), (h, w) = self.region_origin[region], self.region_shape[region]
        return np.ascontiguousarray(cost[r0 : r0 + h, c0 : c0 + w])


def zone_lookup(grids: PlanningGrids, graph: nx.Graph, profile: RobotProfile) -> np.ndarray:
    """Instance id -> zone index (-1 for doors, windows, front doors and non-traversable ids)."""
    sub = traversable_subgraph(graph, profile)
    id_of = {key: iid for iid, key in grids.keys.items()}
    parent = {}
    for iid, key in grids.keys.items():
        d = sub.nodes[key] if key in sub else {}
        if key == OUTSIDE or d.get("kind") == "space" or d.get("class_name") == OPENING:
            parent[iid] = iid

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for iid, key in grids.keys.items():
        if key in sub and sub.nodes[key].get("class_name") == OPENING:
            for side in sub.neighbors(key):
                if id_of.get(side) in parent:
                    parent[find(id_of[side])] = find(iid)
    for u, v, d in sub.edges(data=True):
        if d.get("open_air") and id_of.get(u) in parent and id_of.get(v) in parent:
            parent[find(id_of[u])] = find(id_of[v])
    roots = sorted({find(i) for i in parent})
    index = {r: k for k, r in enumerate(roots)}
    lut = np.full(int(grids.owner.max()) + 1, -1, np.int64)
    for i in parent:
        if i < len(lut):
            lut[i] = index[find(i)]
    return lut


def _label_regions(cell_zone: np.ndarray, n_connectors: np.ndarray) -> np.ndarray:
    """(H, W) int32 region per zone cell: the zone, or (zone, tile) for zones whose
    ``n_connectors`` x bounding-box cells exceed FIELD_BUDGET_CELLS."""
    rows, cols = cell_zone.shape
    n_tiles = (-(-rows // TILE_PX)) * (-(-cols // TILE_PX)) + 1
    boxes = ndimage.find_objects(cell_zone + 1)
    tiled = np.array(
        [
            b is not None
            and (
                max(n_connectors[z], 1) * (b[0].stop - b[0].start) * (b[1].stop - b[1].start)
                > FIELD_BUDGET_CELLS
            )
            for z, b in enumerate(boxes)
        ],
        bool,
    )
    rr, cc = np.nonzero(cell_zone >= 0)
    zone = cell_zone[rr, cc].astype(np.int64)
    tile = (rr // TILE_PX) * (-(-cols // TILE_PX)) + cc // TILE_PX + 1
    key = zone * n_tiles + np.where(tiled[zone], tile, 0)
    _, inverse = np.unique(key, return_inverse=True)
    out = np.full(cell_zone.shape, -1, np.int32)
    out[rr, cc] = inverse.ravel()
    return out


def _seams(region: np.ndarray) -> list[tuple[np.ndarray, np.ndarray, tuple[int, int]]]:
    """Cells (both sides) where two regions touch side by side, in SEAM_PX pieces:
    [(cells (N, 2), middle cell, (region a, region b))]."""
    rows, cols = region.shape
    found_cells, found_keys = [], []
    for dr, dc in ((0, 1), (1, 0)):
        a = region[0 : rows - dr, max(0, -dc) : cols - max(0, dc)]
        b = region[dr:rows, max(0, dc) : cols - max(0, -dc)]
        hit = (a >= 0) & (b >= 0) & (a != b)
        r, c = np.nonzero(hit)
        c = c + max(0, -dc)
        ra, rb = a[hit].astype(np.int64), b[hit].astype(np.int64)
        lo, hi = np.minimum(ra, rb), np.maximum(ra, rb)
        for cr, ccol in ((r, c), (r + dr, c + dc)):
            found_cells.append(np.stack([cr, ccol], 1))
            found_keys.append(np.stack([lo, hi, cr // SEAM_PX, ccol // SEAM_PX], 1))
    if not found_cells:
        return []
    cells = np.concatenate(found_cells)
    keys = np.concatenate(found_keys)
    if len(cells) == 0:
        return []
    uniq, inverse = np.unique(keys, axis=0, return_inverse=True)
    inverse = inverse.ravel()
    order = np.argsort(inverse, kind="stable")
    bounds = np.searchsorted(inverse[order], np.arange(len(uniq) + 1))
    out = []
    for k in range(len(uniq)):
        piece = np.unique(cells[order[bounds[k] : bounds[k + 1]]], axis=0)
        out.append((piece, _middle(piece), (int(uniq[k, 0]), int(uniq[k, 1]))))
    return out


def _door_connectors(grids: PlanningGrids, lut: np.ndarray, region: np.ndarray):
    """[(cells (N, 2), middle cell, touching regions)] for the traversable non-zone connectors,
    cut along their longer side into PIECE_PX pieces."""
    clear_owner = np.where(grids.clear, grids.owner, 0)
    boxes = ndimage.find_objects(clear_owner)
    kernel = np.ones((3, 3), np.uint8)
    out = []
    for iid in grids.keys:
        if iid < len(lut) and lut[iid] >= 0 or iid > len(boxes) or boxes[iid - 1] is None:
            continue
        rs, cs = boxes[iid - 1]
        r0, c0 = max(rs.start - 1, 0), max(cs.start - 1, 0)
        win = (slice(r0, rs.stop + 1), slice(c0, cs.stop + 1))
        mask = clear_owner[win] == iid
        ring = (cv2.dilate(mask.astype(np.uint8), kernel) > 0) & ~mask
        touching = [int(t) for t in np.unique(region[win][ring]) if t >= 0]
        cells = np.argwhere(mask) + np.array([r0, c0])
        axis = int(np.ptp(cells[:, 1]) > np.ptp(cells[:, 0]))  # along the longer side
        piece = (cells[:, axis] - cells[:, axis].min()) // PIECE_PX
        for k in np.unique(piece):
            out.append((cells[piece == k], touching))
    return [(cells, _middle(cells), touching) for cells, touching in out]


def _middle(cells: np.ndarray) -> np.ndarray:
    """The cell of ``cells`` (N, 2) nearest their centroid."""
    return cells[int(np.argmin(((cells - cells.mean(0)) ** 2).sum(1)))]


def _region_fields(passable: np.ndarray, sources: list[np.ndarray], cost: np.ndarray | None):
    """Fields (k, h, w) float32, in-region cost matrix (k, k), exits (k, k, 2) local, expanded."""
    h, w = passable.shape
    k = len(sources)
    fields = np.empty((k, h, w), np.float32)
    costs = np.full((k, k), np.inf)
    exits = np.zeros((k, k, 2), np.int64)
    expanded = 0
    for i, src in enumerate(sources):
        fld = distance_field(passable, src, cost=cost)
        expanded += fld.expanded
        fields[i] = fld.cost.reshape(h + 2, w + 2)[1:-1, 1:-1]
    for i in range(k):
        for j in range(k):
            vals = fields[i][sources[j][:, 0], sources[j][:, 1]]
            best = int(np.argmin(vals))
            costs[i, j] = 0.0 if i == j else float(vals[best])
            exits[i, j] = sources[j][best]
    return fields, costs, exits, expanded


def build_regions(
    grids: PlanningGrids, graph: nx.Graph, profile: RobotProfile, *, workers: int = 1
) -> Regions:
    """Zones, regions, connectors and per-region distance fields for ``grids``."""
    lut = zone_lookup(grids, graph, profile)
    cell_zone = np.where(grids.clear, lut[grids.owner], -1).astype(np.int32)
    n_zones = int(cell_zone.max()) + 1
    per_zone = np.zeros(max(n_zones, 1), np.int64)
    for _, _, touching in _door_connectors(grids, lut, cell_zone):
        per_zone[touching] += 1
    region = _label_regions(cell_zone, per_zone)
    n_regions = int(region.max()) + 1
    connectors = _door_connectors(grids, lut, region)
    connectors += [(cells, mid, list(pair)) for cells, mid, pair in _seams(region)]
    query_region = region.copy()
    members: list[list[int]] = [[] for _ in range(n_regions)]
    for c, (cells, _, touching) in enumerate(connectors):
        for r in touching:
            members[r].append(c)
        if touching:
            own = query_region[cells[:, 0], cells[:, 1]] < 0
            query_region[cells[own, 0], cells[own, 1]] = touching[0]
    boxes = ndimage.find_objects(region + 1)
    jobs = []
    for r in range(n_regions):
        rs, cs = boxes[r]
        lo = np.array([rs.start, cs.start])
        hi = np.array([rs.stop, cs.stop])
        for c in members[r]:
            lo = np.minimum(lo, connectors[c][0].min(0))
            hi = np.maximum(hi, connectors[c][0].max(0) + 1)
        win = (slice(lo[0], hi[0]), slice(lo[1], hi[1]))
        passable = region[win] == r
        for c in members[r]:
            cells = connectors[c][0] - lo
            passable[cells[:, 0], cells[:, 1]] = True
        sources = [(connectors[c][1] - lo)[None, :] for c in members[r]]
        cost = None if grids.cost is None else np.ascontiguousarray(grids.cost[win])
        jobs.append((np.ascontiguousarray(passable), sources, cost, (int(lo[0]), int(lo[1]))))

    def run(job):
        return _region_fields(job[0], job[1], job[2])

    if workers > 1:
        with ThreadPoolExecutor(workers) as pool:
            results = list(pool.map(run, jobs))
    else:
        results = [run(job) for job in jobs]

    chunks, offsets, expanded = [], 0, 0
    p_off, p_org, p_shp, p_reg, p_loc, p_exit, p_cell = [], [], [], [], [], [], []
    exit_cells, e_from, e_to, e_cost = [], [], [], []
    conn_portals: list[list[int]] = [[] for _ in connectors]
    reg_portals, reg_offsets = [], []
    exit_total = 0
    for r, ((_, _, _, origin), (fields, costs, exits, n_exp)) in enumerate(
        zip(jobs, results, strict=True)
    ):
        expanded += n_exp
        k, h, w = fields.shape
        first = len(p_off)
        ids = np.arange(first, first + k)
        for i, c in enumerate(members[r]):
            conn_portals[c].append(first + i)
            p_off.append(offsets + i * h * w)
            p_org.append(origin)
            p_shp.append((h, w))
            p_reg.append(r)
            p_loc.append(i)
            p_exit.append(exit_total + i * k)
            p_cell.append(connectors[c][1])
        chunks.append(fields.ravel())
        offsets += fields.size
        exit_cells.append((exits + np.asarray(origin)).reshape(-1, 2))
        exit_total += k * k
        fi, fj = np.nonzero(np.isfinite(costs) & ~np.eye(k, dtype=bool))
        e_from.append(ids[fi])
        e_to.append(ids[fj])
        e_cost.append(np.maximum(costs[fi, fj], 1e-9))
        reg_portals.append(ids)
        reg_offsets.append(np.asarray(p_off[first : first + k], np.int64))
    empty = np.zeros(0, np.int64)
    return Regions(
        query_region=query_region,
        flat=np.concatenate(chunks) if chunks else np.zeros(0, np.float32),
        portal_offset=np.asarray(p_off, np.int64),
        portal_origin=np.asarray(p_org, np.int64).reshape(-1, 2),
        portal_shape=np.asarray(p_shp, np.int64).reshape(-1, 2),
        portal_region=np.asarray(p_reg, np.int64),
        portal_local=np.asarray(p_loc, np.int64),
        portal_cell=np.asarray(p_cell, np.int64).reshape(-1, 2),
        exit_base=np.asarray(p_exit, np.int64),
        exit_cells=np.concatenate(exit_cells) if exit_cells else np.zeros((0, 2), np.int64),
        edge_from=np.concatenate(e_from) if e_from else empty,
        edge_to=np.concatenate(e_to) if e_to else empty,
        edge_cost=np.concatenate(e_cost) if e_cost else np.zeros(0),
        connector_portals=conn_portals,
        region_portals=reg_portals,
        region_offsets=reg_offsets,
        region_origin=[job[3] for job in jobs],
        region_shape=[job[0].shape for job in jobs],
        region_passable=[job[0] for job in jobs],
        expanded=int(expanded),
    )
