"""The plan in SceneGraph: walls as anchored boxes, floors coloured by room class; and what the
building has that the plan lacks.

:func:`AddPlanGeometry` registers a :class:`~f2n_drake.mapping.walls.PlanGeometry` (walls and
floors in metres) with a SceneGraph, each polygon cut into boxes
(:func:`~f2n_drake.mapping.walls.decompose_rectangles`). :func:`AddFurniture` registers a
:class:`~f2n_drake.world.building.Building`'s furniture (anchored boxes and cylinders) and marks
its closed doors.
"""

from __future__ import annotations

import numpy as np
from pydrake.geometry import (
    Box,
    Cylinder,
    GeometryInstance,
    MakePhongIllustrationProperties,
    ProximityProperties,
    SceneGraph,
    SourceId,
)
from pydrake.math import RigidTransform, RotationMatrix

from f2n_drake.core.classes import CLASS_ID, PALETTE
from f2n_drake.mapping.walls import PlanGeometry, Rectangle, decompose_rectangles
from f2n_drake.world.building import Building

WALL_RGBA = np.array([0.35, 0.35, 0.38, 1.0])
FLOOR_THICKNESS_M = 0.01
FURNITURE_RGBA = np.array([0.6, 0.42, 0.25, 1.0])
ROUND_FURNITURE_RGBA = np.array([0.85, 0.65, 0.3, 1.0])
CLOSED_DOOR_RGBA = np.array([0.85, 0.1, 0.1, 1.0])
FURNITURE_HEIGHT_M, ROUND_FURNITURE_HEIGHT_M = 0.8, 0.7


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


def AddFurniture(
    scene_graph: SceneGraph, building: Building, *, door_height_m: float = 0.35
) -> SourceId:
    """Register the building's furniture: boxes (``FURNITURE_HEIGHT_M`` tall) and cylinders
    (``ROUND_FURNITURE_HEIGHT_M``), anchored, with proximity (the LiDAR and the collision check
    see them) and illustration; and each closed door as an illustration-only red box
    ``door_height_m`` tall, above the plan viewer's low walls (its proximity box is among the
    walls). Returns the SourceId named
    ``"furniture"``."""
    source_id = scene_graph.RegisterSource("furniture")
    for i, poly in enumerate(building.furniture):
        for j, rect in enumerate(decompose_rectangles(poly)):
            instance = _box_instance(rect, f"furniture_{i}_{j}", 0.0, FURNITURE_HEIGHT_M)
            instance.set_proximity_properties(ProximityProperties())
            instance.set_illustration_properties(MakePhongIllustrationProperties(FURNITURE_RGBA))
            scene_graph.RegisterAnchoredGeometry(source_id, instance)
    for i, cylinder in enumerate(building.cylinders):
        height = ROUND_FURNITURE_HEIGHT_M
        X_WG = RigidTransform([*cylinder.centre_m, height / 2])
        instance = GeometryInstance(X_WG, Cylinder(cylinder.radius_m, height), f"round_{i}")
        instance.set_proximity_properties(ProximityProperties())
        instance.set_illustration_properties(MakePhongIllustrationProperties(ROUND_FURNITURE_RGBA))
        scene_graph.RegisterAnchoredGeometry(source_id, instance)
    for i, poly in enumerate(building.door_walls):
        for j, rect in enumerate(decompose_rectangles(poly)):
            instance = _box_instance(rect, f"closed_door_{i}_{j}", 0.0, door_height_m)
            instance.set_illustration_properties(MakePhongIllustrationProperties(CLOSED_DOOR_RGBA))
            scene_graph.RegisterAnchoredGeometry(source_id, instance)
    return source_id


def _box_instance(rect: Rectangle, name: str, z0: float, z1: float) -> GeometryInstance:
    x, y, length, width, yaw = rect
    X_WG = RigidTransform(RotationMatrix.MakeZRotation(yaw), [x, y, (z0 + z1) / 2])
    return GeometryInstance(X_WG, Box(length, width, z1 - z0), name)


__all__ = ["AddFurniture", "AddPlanGeometry"]
