"""Grid A*, hierarchical planning over the connectivity graph, robot profiles."""
