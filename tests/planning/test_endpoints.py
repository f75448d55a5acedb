"""Where routes start and end: rooms drawn apart from the start's plan."""

from __future__ import annotations

import networkx as nx
from shapely.geometry import box

from f2n_drake.planning.endpoints import spaces_apart


def two_floors() -> nx.Graph:
    """Ground floor: living and kitchen joined by a door in a 0.2 m wall; first floor, drawn
    3 m to the right: a bedroom. An outside node has no polygon."""
    g = nx.Graph()
    rooms = {
        "living_0": box(0, 0, 4, 3),
        "kitchen_0": box(4.2, 0, 7, 3),
        "bedroom_0": box(10, 0, 13, 3),
    }
    for key, polygon in rooms.items():
        g.add_node(key, kind="space", class_name=key[:-2], polygon_m=polygon)
    g.add_node("door_0", kind="connector", class_name="door", polygon_m=box(4, 1, 4.2, 2))
    g.add_node("outside", kind="outside", class_name="outside", polygon_m=None)
    return g


def test_rooms_on_another_plan_are_told_apart():
    g = two_floors()
    assert spaces_apart(g, "living_0", ["kitchen_0", "bedroom_0"]) == ["bedroom_0"]
    assert spaces_apart(g, "bedroom_0", ["living_0", "kitchen_0"]) == ["living_0", "kitchen_0"]
    assert spaces_apart(g, (1.0, 1.0), ["bedroom_0"]) == ["bedroom_0"]  # a point in the living
    assert spaces_apart(g, "living_0", ["bedroom_0"], gap_m=4.0) == []  # within the gap: one plan
    g.remove_node("bedroom_0")
    assert spaces_apart(g, "living_0", ["kitchen_0"]) == []  # one plan
