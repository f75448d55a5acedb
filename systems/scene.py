"""The plan in SceneGraph: walls as anchored boxes, floors coloured by room class.

:func:`AddPlanGeometry` registers a :class:`~f2n_drake.mapping.walls.PlanGeometry` (walls and
floors in metres) with a SceneGraph, each polygon cut into boxes
(:func:`~f2n_drake.mapping.walls.decompose_rectangles`).
"""

from __future__ import annotations

import numpy as np
from pydrake.geometry import (
    Box,
    GeometryInstance,
    MakePhongIllustrationProperties,
    ProximityProperties,
    SceneGraph,
    SourceId,
)
from pydrake.math import RigidTransform, RotationMatrix

from f2n_drake.core.classes import CLASS_ID, PALETTE
from f2n_drake.mapping.walls import PlanGeometry, Rectangle, decompose_rectangles

WALL_RGBA = np.array([0.35, 0.35, 0.38, 1.0])
FLOOR_THICKNESS_M = 0.01


def AddPlanGeometry(
    scene_graph: SceneGraph,
    geometry: PlanGeometry,
    *,
    wall_height_m: float = 2.5,
    illustration: bool = True,
) -> SourceId:
    """Register walls (proximity + illustration) and floors (illustration only) as anchored boxes.

    Walls stand on z = 0 up to ``wall_height_m``; floors are 1 cm slabs just below z = 0. With
    ``illustration=False`` only the walls' proximity geometry is registered (the plan viewer,
    ``f2n_drake.systems.viewer``, draws the plan itself). Returns the SourceId named ``"plan"``.
    """
    source_id = scene_graph.RegisterSource("plan")
    for i, poly in enumerate(geometry.walls):
        for j, rect in enumerate(decompose_rectangles(poly)):
            instance = _box_instance(rect, f"wall_{i}_{j}", 0.0, wall_height_m)
            instance.set_proximity_properties(ProximityProperties())
            if illustration:
                instance.set_illustration_properties(MakePhongIllustrationProperties(WALL_RGBA))
            scene_graph.RegisterAnchoredGeometry(source_id, instance)
    for i, (name, poly) in enumerate(geometry.floors if illustration else []):
        rgba = np.array([*PALETTE[CLASS_ID.get(name, 0)], 255.0]) / 255.0
        for j, rect in enumerate(decompose_rectangles(poly, resolution_m=0.05)):
            instance = _box_instance(rect, f"floor_{name}_{i}_{j}", -FLOOR_THICKNESS_M, 0.0)
            instance.set_illustration_properties(MakePhongIllustrationProperties(rgba))
            scene_graph.RegisterAnchoredGeometry(source_id, instance)
    return source_id


def _box_instance(rect: Rectangle, name: str, z0: float, z1: float) -> GeometryInstance:
    x, y, length, width, yaw = rect
    X_WG = RigidTransform(RotationMatrix.MakeZRotation(yaw), [x, y, (z0 + z1) / 2])
    return GeometryInstance(X_WG, Box(length, width, z1 - z0), name)


__all__ = ["AddPlanGeometry"]
