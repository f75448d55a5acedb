"""Localization against the plan: LiDAR scan geometry, the FloorPlan2Nav correction, ICP."""
