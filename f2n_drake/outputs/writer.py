"""The files a run writes to ``--out``: exports (graph, rooms, Nav2 map, route) and figures.

Everything is written into a scratch folder that replaces ``out`` only when all of it succeeded
(``f2n_drake.core.errors.atomic_output_dir``), so a failed run leaves nothing half-written.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from f2n_drake.core.errors import atomic_output_dir


def write_outputs(
    out: Path,
    loaded,
    parsed,
    graph,
    route,
    profile,
    results,
    *,
    free: np.ndarray | None = None,
    world=None,
) -> list[str]:
    """Exports (graph.json, graph.graphml, rooms.geojson, map.pgm/yaml, route.json) and figures
    (segmentation.png, route.png, drive.png when ``results`` holds simulations) of one run;
    ``loaded`` is the run's ``LoadedPlan`` (its drawing and parse at the drawing's resolution),
    ``parsed`` the plan the run planned on (``mapping.resolution.at_planning_resolution``).
    ``free``: the run's occupancy map (default ``occupancy_map(parsed, profile.traversable)``),
    written as the Nav2 map; ``world``: the simulated walls (``mapping.walls.PlanGeometry``,
    default cut from ``free`` or taken from the ground-truth plan), drawn under the drives.
    Returns the written paths."""
    from f2n_drake.mapping.occupancy import occupancy_map
    from f2n_drake.mapping.walls import PlanGeometry
    from f2n_drake.outputs import exports, figures

    if free is None:
        free = occupancy_map(parsed, profile.traversable)

    with atomic_output_dir(out) as tmp:
        exports.write_graph_json(graph, tmp / "graph.json")
        exports.write_graphml(graph, tmp / "graph.graphml")
        exports.write_rooms_geojson(parsed, tmp / "rooms.geojson")
        exports.write_nav2_map(free, parsed.grid, tmp / "map.pgm", tmp / "map.yaml")
        (tmp / "route.json").write_text(
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
        figures.save(
            figures.plot_segmentation(loaded.image, loaded.parsed, title=loaded.perception),
            tmp / "segmentation.png",
        )
        figures.save(
            figures.plot_graph(loaded.image, parsed, graph, {profile.name: route.waypoints_m}),
            tmp / "route.png",
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
                tmp / "drive.png",
            )
        names = sorted(p.name for p in tmp.iterdir())
    if not results:  # a drive figure left by an earlier run would show another route
        (out / "drive.png").unlink(missing_ok=True)
    return [str(out / n) for n in names]
