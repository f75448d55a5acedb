"""Where a route starts and ends: places given as room names or X,Y metres, and the defaults
(the front door; the room farthest from the start through the connectivity graph)."""

from __future__ import annotations

import math

import numpy as np

from f2n_drake.core.errors import InputError, PlanningError

GOAL_TRIES = 5
"""Default goals tried, farthest first, before no route is reported (``goal_candidates``)."""
PLAN_GAP_M = 1.0
"""Instances this far [m] from every instance of a plan are drawn apart from it: another plan
on the sheet (another floor), which no route reaches."""


def parse_place(text: str | None) -> str | tuple[float, float] | None:
    """``"x,y"`` in metres -> tuple; a room key or class name -> str; None stays None."""
    if text is None:
        return None
    parts = text.split(",")
    if len(parts) == 2:
        try:
            xy = float(parts[0]), float(parts[1])
        except ValueError:
            return text.strip()
        if not all(math.isfinite(v) for v in xy):
            raise InputError(f"place {text!r} is not a finite X,Y in metres")
        return xy
    return text.strip()


def resolve_node(graph, name: str) -> str:
    """A node key ("bedroom_1") or a class name ("kitchen": its first instance)."""
    if name in graph:
        return name
    matches = sorted(k for k, d in graph.nodes(data=True) if d.get("class_name") == name)
    if matches:
        return matches[0]
    spaces = sorted(k for k, d in graph.nodes(data=True) if d.get("kind") == "space")
    raise InputError(f"no room or connector named {name!r}; rooms are {', '.join(spaces)}")


def default_start(graph, profile) -> str:
    """The front door leading into the most room area the robot can reach, else (no front door,
    or one read on a window or a cupboard that leads into no room) the largest room of the
    largest group of rooms the robot can move between."""
    import networkx as nx

    from f2n_drake.mapping.robots import traversable_subgraph

    sub = traversable_subgraph(graph, profile)
    spaces = {k for k, d in sub.nodes(data=True) if d.get("kind") == "space"}
    if not spaces:
        raise PlanningError(f"no room found in the plan that the {profile.name} robot can use")
    group_of = {k: group for group in nx.connected_components(sub) for k in group}

    def room_area(keys) -> tuple[float, int]:
        rooms = [k for k in keys if k in spaces]
        return sum(sub.nodes[k].get("area_m2") or 0.0 for k in rooms), len(rooms)

    fronts = sorted(k for k, d in sub.nodes(data=True) if d.get("class_name") == "front_door")
    entered = [k for k in fronts if room_area(group_of[k])[1]]
    if entered:
        return max(entered, key=lambda k: room_area(group_of[k]))
    largest = max((group_of[k] for k in sorted(spaces)), key=room_area)
    return max(sorted(largest & spaces), key=lambda k: room_area([k]))


def default_goal(graph, profile, start: str | tuple[float, float]) -> str:
    """The room farthest from ``start`` through the graph (centroid-to-centroid metres), among
    those the robot fits in (:func:`fits_in`) when there are any: the first of
    :func:`goal_candidates`."""
    return goal_candidates(graph, profile, start)[0]


def goal_candidates(graph, profile, start: str | tuple[float, float]) -> list[str]:
    """The rooms reachable from ``start`` through the graph, the ones the robot fits in
    (:func:`fits_in`) first, each group farthest first (centroid-to-centroid metres through the
    graph). Raises PlanningError when there is none."""
    import networkx as nx

    from f2n_drake.mapping.robots import traversable_subgraph

    sub = traversable_subgraph(graph, profile)
    spaces = [k for k, d in sub.nodes(data=True) if d.get("kind") == "space"]
    if not isinstance(start, str):  # a point: measure from the room containing it, if any
        start = nearest_space(sub, spaces, start)

    def distance(u, v, _):
        a, b = sub.nodes[u].get("centroid_m"), sub.nodes[v].get("centroid_m")
        return 0.0 if a is None or b is None else float(np.hypot(*(np.subtract(a, b))))

    lengths = nx.single_source_dijkstra_path_length(sub, start, weight=distance)
    reachable = [k for k in spaces if k in lengths and k != start]
    if not reachable:
        raise PlanningError(f"no room reachable from {start} for robot {profile.name}")
    return sorted(
        reachable, key=lambda k: (not fits_in(sub.nodes[k].get("area_m2"), profile), -lengths[k])
    )


def fits_in(area_m2: float | None, profile) -> bool:
    """Whether a room of ``area_m2`` can hold the robot with its clearance: at least the square
    round its inflated disc (a sliver the parse cut off a room cannot); True when unknown."""
    side = 2 * (profile.radius_m + profile.clearance_margin_m)
    return area_m2 is None or area_m2 >= side * side


def unreachable_spaces(graph, profile, start: str | tuple[float, float]) -> list[str]:
    """Spaces (rooms, balconies) the robot cannot reach from ``start`` through connectors it may
    use: a door the segmenter missed leaves its room cut off."""
    import networkx as nx

    from f2n_drake.mapping.robots import traversable_subgraph

    sub = traversable_subgraph(graph, profile)
    spaces = [k for k, d in graph.nodes(data=True) if d.get("kind") == "space"]
    if not isinstance(start, str):
        start = nearest_space(sub, [k for k in spaces if k in sub], start)
    reached = nx.node_connected_component(sub, start) if start in sub else set()
    return sorted(k for k in spaces if k not in reached)


def spaces_apart(
    graph, start: str | tuple[float, float], spaces: list[str], gap_m: float = PLAN_GAP_M
) -> list[str]:
    """Of ``spaces``, those on another plan than ``start``: the plans are the groups of
    instances (rooms and connectors, by their polygons) drawn within ``gap_m`` of each other."""
    from shapely.ops import unary_union

    polygons = {
        key: data["polygon_m"]
        for key, data in graph.nodes(data=True)
        if data.get("polygon_m") is not None
    }
    if not isinstance(start, str):
        rooms = [k for k, d in graph.nodes(data=True) if d.get("kind") == "space" and k in polygons]
        start = nearest_space(graph, rooms, start) if rooms else None
    if start not in polygons:
        return []
    drawn = unary_union([polygon.buffer(gap_m / 2) for polygon in polygons.values()])
    plans = getattr(drawn, "geoms", [drawn])
    if len(plans) < 2:
        return []
    home = next((plan for plan in plans if plan.intersects(polygons[start])), None)
    if home is None:  # an empty outline
        return []
    return [k for k in spaces if k in polygons and not home.intersects(polygons[k])]


def nearest_space(graph, spaces: list[str], xy: tuple[float, float]) -> str:
    """The space whose polygon contains ``xy`` [m], else the one with the nearest centroid."""
    from shapely.geometry import Point

    point = Point(xy)
    for key in spaces:
        polygon = graph.nodes[key].get("polygon_m")
        if polygon is not None and polygon.contains(point):
            return key
    if not spaces:
        raise InputError("no rooms found in the plan")
    return min(
        spaces, key=lambda k: float(np.hypot(*np.subtract(graph.nodes[k]["centroid_m"], xy)))
    )
