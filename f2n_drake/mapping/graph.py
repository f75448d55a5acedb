"""The connectivity graph: spaces joined through connectors (doors, windows, openings).

Following FloorPlan2Nav, adjacency comes from morphological dilation: each connector's mask is
dilated by a small square kernel (by default 0.18 m, the paper's 5 px at 512 px for a ~17 m plan,
at least 3 px, widened to jump the drawn lines around connectors) and every space or the exterior
it then overlaps is a neighbour. Semantic filtering
keeps only space-connector and outside-connector edges, plus balcony-outside (``open_air``):
two doors never join, and two rooms only join through an ``opening`` connector.

Schema (planner, exports, simulation and CLI rely on it):

- node keys ``f"{class_name}_{k}"`` (k counts per class in instance order) and ``"outside"``;
- node attributes ``kind`` ("space" | "connector" | "outside"), ``class_name``, ``instance_id``
  (-1 for outside), ``centroid_px`` (col, row), ``centroid_m`` (x, y), ``area_m2``,
  ``confidence`` (mean probability of its class, None without one), ``name`` (the printed
  name read in it, None without one), ``polygon_m`` (shapely, metres), and for connectors
  ``width_m`` (clear width [m]) and ``sides`` (the keys it touches); metre values are None
  without a grid, and None everywhere for ``outside``;
  extras: ``area_px``, and ``width_px`` for connectors;
- edge attributes ``contact_px`` (touching pixels) and ``open_air`` (True only balcony-outside);
- graph attributes ``metres_per_px``, ``grid``, ``scale_source``, ``kernel_px``.
"""

from __future__ import annotations

import logging
import math

import cv2
import networkx as nx
import numpy as np
from scipy import ndimage

from f2n_drake.core.classes import CONNECTOR_CLASSES, OPENING, SPACE_CLASSES
from f2n_drake.core.parsed import Instance, ParsedPlan
from f2n_drake.core.raster import PixelGrid

log = logging.getLogger(__name__)

OUTSIDE = "outside"
OUTSIDE_ID = -1
"""Instance id of the exterior in :func:`contact_px` (and ``instance_id`` of the outside node)."""
KERNEL_M = 0.18
"""Default dilation kernel side [m]: enough to jump a drawn line between a room and a door."""
MIN_KERNEL_PX = 3
DEFAULT_KERNEL_PX = 5
"""Kernel side when the scale is unknown: the paper's 5 px."""
RELATIVE_CONTACT = 0.2
"""A side must touch at least this fraction of the connector's strongest contact."""

CONNECTOR_NODE_CLASSES: tuple[str, ...] = (*CONNECTOR_CLASSES, OPENING)


def kernel_size_px(
    grid: PixelGrid | None, kernel_m: float = KERNEL_M, line_gap_px: float = 0.0
) -> int:
    """Odd dilation kernel side [px]: ``kernel_m`` at the grid's scale (5 px without a grid),
    at least 3 px, and wide enough that its reach (half side) jumps a ``line_gap_px`` line."""
    k = DEFAULT_KERNEL_PX if grid is None else int(round(grid.length_px(kernel_m)))
    k = max(MIN_KERNEL_PX, k, 2 * int(math.ceil(line_gap_px)) + 3)  # reach gap + 1
    return k if k % 2 else k + 1


def line_gap_px(parsed: ParsedPlan, max_gap_px: float = 16.0) -> float:
    """Thickness [px] of the unlabelled lines between connectors and spaces (0 if none).

    Measured on row and column runs of instance-free pixels that start at a connector and end
    at a space (or the reverse), at most ``max_gap_px`` long: the drawn door/window outlines.
    The 75th percentile, so a blurred or anti-aliased line is jumped where it is thick too.
    Ground truth has no such runs (connectors touch spaces): 0. Measured once per plan
    (``ParsedPlan.derived``): the priors, the scale estimate, the graph and the planner all ask.
    """
    return parsed.derived(
        ("line_gap_px", max_gap_px), lambda: _measure_line_gap(parsed, max_gap_px)
    )


def _measure_line_gap(parsed: ParsedPlan, max_gap_px: float) -> float:
    ids = parsed.instance_ids
    n = int(ids.max()) + 1
    is_conn = np.zeros(n, bool)
    is_space = np.zeros(n, bool)
    for inst in parsed.instances:
        if inst.id < n:
            is_conn[inst.id] = inst.class_name in CONNECTOR_NODE_CLASSES
            is_space[inst.id] = inst.class_name in SPACE_CLASSES
    gaps = []
    for arr in (ids, ids.T):
        zero = np.pad(arr == 0, ((0, 0), (1, 1))).astype(np.int8)
        step = np.diff(zero, axis=1)  # +1 at the first zero of a run, -1 one past its last
        flat = np.flatnonzero(step)  # row-major: starts and ends alternate
        rows, starts = np.divmod(flat[0::2], step.shape[1])
        ends = flat[1::2] - rows * step.shape[1]
        inner = (starts > 0) & (ends < arr.shape[1]) & (ends - starts <= max_gap_px)
        rows, starts, ends = rows[inner], starts[inner], ends[inner]
        left, right = arr[rows, starts - 1], arr[rows, ends]
        joins = (is_conn[left] & is_space[right]) | (is_space[left] & is_conn[right])
        gaps.append(ends[joins] - starts[joins])
    gaps = np.concatenate(gaps)
    return float(np.percentile(gaps, 75)) if len(gaps) >= 4 else 0.0


def exterior_mask(
    instance_ids: np.ndarray, kernel_px: int, labels: np.ndarray | None = None
) -> np.ndarray:
    """(H, W) bool: background pixels of no instance connected to the image border.

    Pixels labelled other than background (ink of filled walls) are not exterior. Thin
    unlabelled structures (drawn lines, rasterisation seams, narrower than the kernel) are
    removed first by a morphological opening, so the line network of a drawing, which touches
    the outer outline, does not carry the exterior into the rooms.
    """
    free = instance_ids == 0
    if labels is not None:
        free &= labels == 0
    free = free.astype(np.uint8)
    kernel = np.ones((kernel_px, kernel_px), np.uint8)
    opened = cv2.morphologyEx(free, cv2.MORPH_OPEN, kernel, borderType=cv2.BORDER_REPLICATE)
    n, comp = cv2.connectedComponents(opened, connectivity=4)
    border = np.concatenate([comp[0], comp[-1], comp[:, 0], comp[:, -1]])
    is_outer = np.zeros(n, bool)
    is_outer[border[border > 0]] = True
    return is_outer[comp]


def plan_exterior(parsed: ParsedPlan, kernel_px: int) -> np.ndarray:
    """:func:`exterior_mask` of a plan's instances and labels, found once per plan and kernel
    (read-only)."""

    def compute() -> np.ndarray:
        exterior = exterior_mask(parsed.instance_ids, kernel_px, parsed.labels)
        exterior.flags.writeable = False
        return exterior

    return parsed.derived(("exterior", kernel_px), compute)


def contact_px(
    instance_ids: np.ndarray,
    instance_id: int,
    spaces: set[int],
    exterior: np.ndarray,
    kernel_px: int,
    slices: list | None = None,
) -> dict[int, int]:
    """Pixels of each space (instance id) and of the exterior (``OUTSIDE_ID``) inside the
    ``kernel_px`` dilation ring of an instance; only those it touches.

    Args:
        instance_ids: (H, W) instance id image; ``exterior``: (H, W) bool, see
            :func:`exterior_mask`.
        slices: ``ndimage.find_objects(instance_ids)``, to reuse across calls.
    """
    if slices is None:
        slices = ndimage.find_objects(instance_ids)
    if instance_id > len(slices) or slices[instance_id - 1] is None:
        return {}
    window = grown_window(slices[instance_id - 1], kernel_px // 2 + 1, instance_ids.shape)
    crop = instance_ids[window]
    mask = crop == instance_id
    kernel = np.ones((kernel_px, kernel_px), np.uint8)
    ring = (cv2.dilate(mask.astype(np.uint8), kernel) > 0) & ~mask
    counts = np.bincount(crop[ring], minlength=1)
    contacts = {int(j): int(c) for j, c in enumerate(counts) if c and int(j) in spaces}
    outside = int(np.count_nonzero(exterior[window] & ring))
    if outside:
        contacts[OUTSIDE_ID] = outside
    return contacts


def joined(contacts: dict[int, int], kernel_px: int) -> list[int]:
    """The sides a connector joins, strongest first: the contacts of at least the kernel side
    (``MIN_KERNEL_PX`` at least) and ``RELATIVE_CONTACT`` of the strongest contact. A corner
    that merely grazes a room is no side of it."""
    strongest = max(contacts.values(), default=0)
    least = max(kernel_px, MIN_KERNEL_PX, RELATIVE_CONTACT * strongest)
    return sorted((j for j, c in contacts.items() if c >= least), key=lambda j: -contacts[j])


def clear_width_px(mask: np.ndarray) -> float:
    """Longer side of the minimum rotated rectangle around a mask's pixels [px] (pixel extent,
    i.e. a 25 x 6 px rectangle is 25 px wide)."""
    pts = np.argwhere(mask)[:, ::-1].astype(np.float32)
    if len(pts) == 0:
        return 0.0
    (_, _), (w, h), _ = cv2.minAreaRect(pts)
    return float(max(w, h)) + 1.0


def node_keys(parsed: ParsedPlan) -> dict[int, str]:
    """Instance id -> node key for the instances that become graph nodes (spaces, connectors)."""
    counts: dict[str, int] = {}
    keys = {}
    for inst in parsed.instances:
        if inst.class_name in SPACE_CLASSES or inst.class_name in CONNECTOR_NODE_CLASSES:
            k = counts.get(inst.class_name, 0)
            counts[inst.class_name] = k + 1
            keys[inst.id] = f"{inst.class_name}_{k}"
    return keys


def build_connectivity_graph(
    parsed: ParsedPlan, *, kernel_px: int | None = None, kernel_m: float = KERNEL_M
) -> nx.Graph:
    """The space/connector graph of a parsed plan (schema in the module docstring).

    Args:
        parsed: instances; its grid (if any) gives metre attributes and the kernel scale.
        kernel_px: dilation kernel side [px]; default ``kernel_size_px(grid, kernel_m,
            line_gap_px(parsed))``: ``kernel_m`` at the grid's scale, widened where the drawn
            lines between connectors and spaces are thicker than its reach.
        kernel_m: kernel side [m] used when ``kernel_px`` is None.
    """
    grid = parsed.grid
    if kernel_px is None:
        k = kernel_size_px(grid, kernel_m, line_gap_px(parsed))
    else:
        k = int(kernel_px)
    if k < 1:
        raise ValueError(f"kernel_px must be >= 1, got {kernel_px}")
    ids = parsed.instance_ids
    keys = node_keys(parsed)
    graph = nx.Graph(
        metres_per_px=grid.metres_per_px if grid else None,
        grid=grid,
        scale_source=parsed.scale_source,
        kernel_px=k,
    )
    slices = parsed.boxes()
    exterior = plan_exterior(parsed, k)

    for inst in parsed.instances:
        if inst.id in keys:
            graph.add_node(keys[inst.id], **_node_attrs(inst, grid))
    graph.add_node(
        OUTSIDE,
        kind="outside",
        class_name=OUTSIDE,
        instance_id=OUTSIDE_ID,
        centroid_px=None,
        centroid_m=None,
        area_m2=None,
        area_px=None,
        polygon_m=None,
    )

    spaces = {inst.id for inst in parsed.instances if inst.class_name in SPACE_CLASSES}
    for inst in parsed.instances:
        is_connector = inst.class_name in CONNECTOR_NODE_CLASSES
        if not (is_connector or inst.class_name == "balcony"):
            continue
        if inst.id > len(slices) or slices[inst.id - 1] is None:
            continue
        contacts = contact_px(ids, inst.id, spaces, exterior, k, slices)
        node = keys[inst.id]
        if not is_connector:  # a balcony: open to the air if it touches the exterior
            outside_px = contacts.get(OUTSIDE_ID, 0)
            if outside_px >= max(k, MIN_KERNEL_PX):
                graph.add_edge(node, OUTSIDE, contact_px=outside_px, open_air=True)
            continue
        width_px = clear_width_px(ids[slices[inst.id - 1]] == inst.id)
        graph.nodes[node]["width_px"] = width_px
        graph.nodes[node]["width_m"] = width_px * grid.metres_per_px if grid else None
        sides = []
        for j in joined(contacts, k):
            sides.append(OUTSIDE if j == OUTSIDE_ID else keys[j])
            graph.add_edge(node, sides[-1], contact_px=contacts[j], open_air=False)
        graph.nodes[node]["sides"] = tuple(sides)

    log.debug(
        "graph: %d nodes, %d edges, kernel %d px",
        graph.number_of_nodes(),
        graph.number_of_edges(),
        k,
    )
    return graph


def _node_attrs(inst: Instance, grid: PixelGrid | None) -> dict:
    is_connector = inst.class_name in CONNECTOR_NODE_CLASSES
    attrs = {
        "kind": "connector" if is_connector else "space",
        "class_name": inst.class_name,
        "instance_id": int(inst.id),
        "centroid_px": (float(inst.centroid_px[0]), float(inst.centroid_px[1])),
        "centroid_m": tuple(float(v) for v in inst.centroid_m(grid)) if grid else None,
        "area_m2": float(inst.area_m2(grid)) if grid else None,
        "area_px": int(inst.area_px),
        "polygon_m": inst.polygon_m(grid) if grid else None,
        "confidence": inst.confidence,
        "name": inst.name,
    }
    if is_connector:
        attrs.update(width_m=None, width_px=0.0, sides=())
    return attrs


def grown_window(
    sl: tuple[slice, slice], margin: int, shape: tuple[int, ...]
) -> tuple[slice, slice]:
    """The (rows, cols) slices ``sl`` grown by ``margin`` px on every side, clipped to ``shape``."""
    rows, cols = sl
    return (
        slice(max(0, rows.start - margin), min(shape[0], rows.stop + margin)),
        slice(max(0, cols.start - margin), min(shape[1], cols.stop + margin)),
    )
