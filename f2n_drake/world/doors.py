"""Closed doors: which doors of the plan are shut in the building, and the wall each becomes.

A closed door is chosen among the graph's ``door`` and ``front_door`` connectors (an opening
has no leaf to close); the doors the planned route passes through come first, in route order,
then the others in a seeded random order. A door whose polygon lies within ``clearance_m`` of
the route's start or goal is never closed (the robot would start or end inside a wall).
"""

from __future__ import annotations

import networkx as nx
import numpy as np
from shapely import affinity
from shapely.geometry import Point, Polygon

CLOSABLE_CLASSES = ("door", "front_door")
DOOR_OVERLAP_M = 0.05
"""A closed door's wall reaches this far into the wall on each side of the doorway [m]."""


def closable_doors(
    graph: nx.Graph, keep_clear_xy: list[np.ndarray], clearance_m: float = 0.3
) -> list[str]:
    """Node keys of the doors that may be closed: ``door`` or ``front_door`` with a polygon
    farther than ``clearance_m`` [m] from every point of ``keep_clear_xy``."""
    keys = []
    for key, data in graph.nodes(data=True):
        polygon = data.get("polygon_m")
        if data.get("class_name") not in CLOSABLE_CLASSES or polygon is None:
            continue
        if all(polygon.distance(Point(*xy)) > clearance_m for xy in keep_clear_xy):
            keys.append(key)
    return sorted(keys)


def doors_to_close(
    graph: nx.Graph,
    sequence: list[str],
    count: int,
    rng: np.random.Generator,
    keep_clear_xy: list[np.ndarray],
) -> list[str]:
    """Up to ``count`` closable door keys: the route's (``sequence`` of node keys) first, then
    the others in random order."""
    closable = closable_doors(graph, keep_clear_xy)
    on_route = [k for k in dict.fromkeys(sequence) if k in closable]
    others = [k for k in closable if k not in on_route]
    others = [others[i] for i in rng.permutation(len(others))]
    return (on_route + others)[:count]


def door_wall(polygon: Polygon, overlap_m: float = DOOR_OVERLAP_M) -> Polygon:
    """The wall that fills a closed door: its smallest rotated rectangle lengthened by
    ``overlap_m`` [m] at both ends of its long side, so it overlaps the walls at the jambs."""
    rectangle = polygon.minimum_rotated_rectangle
    xy = np.asarray(rectangle.exterior.coords)[:4]
    sides = np.hypot(*np.diff(np.vstack([xy, xy[:1]]), axis=0).T)
    long_side = float(max(sides[0], sides[1]))
    if long_side <= 0:
        return rectangle
    factor = (long_side + 2 * overlap_m) / long_side
    along = xy[1] - xy[0] if sides[0] >= sides[1] else xy[2] - xy[1]
    angle = float(np.degrees(np.arctan2(along[1], along[0])))
    centre = rectangle.centroid
    turned = affinity.rotate(rectangle, -angle, origin=centre)
    return affinity.rotate(affinity.scale(turned, factor, 1.0, origin=centre), angle, origin=centre)


__all__ = ["CLOSABLE_CLASSES", "closable_doors", "door_wall", "doors_to_close"]
