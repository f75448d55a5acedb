"""A hand-made two-room plan, its graph and a route through its door, for the world tests."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
import shapely
from shapely.geometry import box

from f2n_drake.core.plan import FloorPlan
from f2n_drake.datasets.ground_truth import parse_ground_truth
from f2n_drake.mapping.graph import build_connectivity_graph
from f2n_drake.mapping.walls import PlanGeometry

BEDROOM, LIVING, DOOR = box(0, 0, 3, 3), box(3.2, 0, 6.2, 3), box(3.0, 1.2, 3.2, 2.0)
ROUTE = np.array([(1.0, 1.0), (2.5, 1.6), (3.7, 1.6), (5.2, 0.8)])


def two_rooms() -> FloorPlan:
    """Two 3 x 3 m rooms, 0.2 m walls, joined by a 0.8 m door."""
    walls = box(-0.2, -0.2, 6.4, 3.2).difference(shapely.union_all([BEDROOM, LIVING, DOOR]))
    polygons = {"bedroom": [BEDROOM], "living": [LIVING], "wall": [walls], "door": [DOOR]}
    return FloorPlan(polygons, 0.2, "test")


@pytest.fixture(scope="session")
def plan_and_graph():
    """(PlanGeometry, connectivity graph) of :func:`two_rooms`."""
    plan = two_rooms()
    graph = build_connectivity_graph(parse_ground_truth(plan, size_px=256))
    return PlanGeometry.from_floorplan(plan), graph


@pytest.fixture(scope="session")
def route(plan_and_graph):
    """The route from the bedroom through the door to the living room, as a Route-like."""
    _, graph = plan_and_graph
    door = next(k for k, d in graph.nodes(data=True) if d["class_name"] == "door")
    return SimpleNamespace(waypoints_m=ROUTE, sequence=["bedroom_0", door, "living_0"])
