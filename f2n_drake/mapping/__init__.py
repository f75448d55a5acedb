"""Mapping: the planning resolution, the one occupancy map, the connectivity graph."""
