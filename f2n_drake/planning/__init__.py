"""Grid A* and hierarchical planning over the connectivity graph."""

from f2n_drake.planning.astar import astar, warm_up
from f2n_drake.planning.hierarchical import HierarchicalPlanner
from f2n_drake.planning.route import Route

__all__ = ["HierarchicalPlanner", "Route", "astar", "warm_up"]
