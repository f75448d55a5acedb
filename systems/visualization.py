"""Meshcat helpers: the visualizer, polylines, LiDAR hits and a self-contained HTML replay.

The plan viewer (camera, plan, route, runs) is :mod:`f2n_drake.systems.viewer`.
"""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
from pydrake.geometry import (
    Meshcat,
    MeshcatVisualizer,
    MeshcatVisualizerParams,
    Rgba,
    Role,
    SceneGraph,
)
from pydrake.systems.framework import DiagramBuilder

from f2n_drake.systems.viewer import write_replay_html

log = logging.getLogger(__name__)

ROUTE_RGBA = Rgba(0.1, 0.3, 0.9, 1.0)
LIDAR_RGBA = Rgba(1.0, 0.0, 0.0, 1.0)
LINE_HEIGHT_M = 0.05  # lines float above the floor
REPLAY_FPS = 32.0  # the visualizer publishes, and a replay records, this many frames a second


def add_meshcat_visualizer(
    builder: DiagramBuilder,
    scene_graph: SceneGraph,
    meshcat: Meshcat,
    *,
    prefix: str = "visualizer",
) -> MeshcatVisualizer:
    """A MeshcatVisualizer of the illustration geometry under meshcat path ``prefix``, named
    ``"meshcat_visualizer"``."""
    params = MeshcatVisualizerParams(
        role=Role.kIllustration, publish_period=1 / REPLAY_FPS, prefix=prefix
    )
    visualizer = MeshcatVisualizer.AddToBuilder(builder, scene_graph, meshcat, params)
    visualizer.set_name("meshcat_visualizer")
    return visualizer


def draw_polyline(
    meshcat: Meshcat, path: str, xy_m: np.ndarray, rgba: Rgba = ROUTE_RGBA, width_px: float = 3.0
) -> None:
    """An (N, 2) polyline [m] drawn at ``LINE_HEIGHT_M`` above the floor at meshcat ``path``."""
    xy = np.asarray(xy_m, dtype=float).reshape(-1, 2)
    vertices = np.vstack([xy.T, np.full(len(xy), LINE_HEIGHT_M)])
    meshcat.SetLine(path, np.asfortranarray(vertices), width_px, rgba)


def draw_lidar_hits(
    meshcat: Meshcat, pose: np.ndarray, scan: np.ndarray, path: str = "/lidar_hits"
) -> None:
    """Beams with a return, as segments from the robot at ``pose`` [x, y, theta] to the hit."""
    angles = pose[2] + 2 * np.pi * np.arange(len(scan)) / len(scan)
    ok = np.isfinite(scan)
    ends = np.stack(
        [
            pose[0] + scan[ok] * np.cos(angles[ok]),
            pose[1] + scan[ok] * np.sin(angles[ok]),
            np.full(ok.sum(), LINE_HEIGHT_M),
        ]
    )
    starts = np.repeat(np.array([[pose[0]], [pose[1]], [LINE_HEIGHT_M]]), ok.sum(), axis=1)
    meshcat.SetLineSegments(
        path, np.asfortranarray(starts), np.asfortranarray(ends), 1.0, LIDAR_RGBA
    )


def save_recording_html(
    meshcat: Meshcat, visualizer: MeshcatVisualizer, html_path: str | Path
) -> Path:
    """Stop and publish the visualizer's recording, write ``meshcat.StaticHtml()`` to a file."""
    visualizer.StopRecording()
    path = write_replay_html(meshcat, html_path)
    log.info("wrote meshcat replay %s (%.1f MB)", path, path.stat().st_size / 1e6)
    return path
