"""The files a run writes to ``--out``: the parse, exports (graph, rooms, Nav2 map, route) and
figures.

The run writes them into the scratch folder of a ``f2n_drake.core.output_dir.StagedDir``, which
replaces ``--out`` as a whole only when all of it succeeded. A parse with no route still writes
the parse (``segmentation.png``, ``labels.png``, rooms, graph, map), so the user can see why.
"""

from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np

PARSE_FILES = (
    "graph.json",
    "graph.graphml",
    "rooms_m.json",
    "labels.png",
    "map.pgm",
    "map.yaml",
    "segmentation.png",
    "route.png",
    "summary.json",
)
"""Written by every run whose parse succeeded; ``route.json`` joins them when a route was
planned, ``drive.png`` when it was driven, ``rooms.geojson`` when the run is georeferenced,
``page.png`` (the drawing the outputs lie on) when a photographed page was squared or a drawing
askew, on its side or upside down turned upright."""


def write_outputs(
    folder: Path,
    loaded,
    parsed,
    graph,
    route,
    profile,
    results,
    *,
    free: np.ndarray | None = None,
    world=None,
    georeference=None,
) -> list[str]:
    """Write one run's files into ``folder`` (the scratch folder of the output) and return their
    names.

    ``loaded`` is the run's ``LoadedPlan`` (its drawing and parse at the drawing's resolution),
    ``parsed`` the plan the run planned on (``mapping.resolution.at_planning_resolution``),
    ``route`` None when no route was planned, ``results`` the simulations by correction mode.
    ``free``: the run's occupancy map (default ``occupancy_map(parsed, profile.traversable)``),
    written as the Nav2 map; ``world``: the simulated walls (``mapping.walls.PlanGeometry``,
    default cut from ``free`` or taken from the ground-truth plan), drawn under the drives;
    ``georeference`` (``outputs.exports.Georeference``) adds WGS84 ``rooms.geojson``.
    """
    from f2n_drake.mapping.occupancy import occupancy_map
    from f2n_drake.mapping.walls import PlanGeometry
    from f2n_drake.outputs import exports, figures

    if free is None:
        free = occupancy_map(parsed, profile.traversable)
    exports.write_graph_json(graph, folder / "graph.json")
    exports.write_graphml(graph, folder / "graph.graphml")
    exports.write_rooms_geojson(parsed, folder / "rooms_m.json")
    if georeference is not None:
        exports.write_rooms_geojson(parsed, folder / "rooms.geojson", georeference=georeference)
    exports.write_labels_png(loaded.parsed, folder / "labels.png")
    if loaded.squared:
        cv2.imwrite(str(folder / "page.png"), loaded.image)
    exports.write_nav2_map(free, parsed.grid, folder / "map.pgm", folder / "map.yaml")
    figures.save(
        figures.plot_segmentation(loaded.image, loaded.parsed, title=loaded.perception),
        folder / "segmentation.png",
    )
    routes = {} if route is None else {profile.name: route.waypoints_m}
    figures.save(figures.plot_graph(loaded.image, parsed, graph, routes), folder / "route.png")
    if route is not None:
        (folder / "route.json").write_text(
            json.dumps(
                {
                    "robot": profile.name,
                    "sequence": list(route.sequence),
                    "waypoints_m": np.round(route.waypoints_m, 4).tolist(),
                    "length_m": float(route.length_m),
                },
                indent=1,
            )
        )
    if results:
        if world is None:
            world = (
                PlanGeometry.from_floorplan(loaded.floorplan)
                if loaded.floorplan is not None
                else PlanGeometry.from_parsed(parsed, free)
            )
        figures.save(
            figures.plot_drift(world.wall_segments(), route.waypoints_m, results),
            folder / "drive.png",
        )
    return sorted([*(p.name for p in folder.iterdir()), "summary.json"])
