"""Writing results for other tools: graph JSON/GraphML, rooms (plan metres, or GeoJSON when
georeferenced), the parse as a class-id PNG, a Nav2 occupancy map.

The Nav2 map follows ``nav2_map_server``'s format: a binary PGM (row 0 at the top) and a YAML
whose ``origin`` is the position [m] of the image's lower-left corner. With ``negate: 0`` a pixel
value v reads as occupancy (255 - v) / 255, so free=254 -> 0.004, occupied=0 -> 1.0 and
unknown=205 -> 0.196; ``free_thresh`` is 0.196 (the value ROS map_saver writes) so that unknown
cells stay unknown (with 0.25 they would load as free).
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import networkx as nx
import numpy as np
import shapely
import yaml
from shapely.geometry import MultiPolygon, Polygon, mapping
from shapely.geometry.polygon import orient

from f2n_drake.core.classes import CLASS_ID
from f2n_drake.core.errors import InputError
from f2n_drake.core.parsed import ParsedPlan
from f2n_drake.core.plan import polygons_of
from f2n_drake.core.raster import PixelGrid

FREE, OCCUPIED, UNKNOWN = 254, 0, 205
OCCUPIED_THRESH, FREE_THRESH = 0.65, 0.196


def _plain(value: Any) -> Any:
    """A JSON-ready copy of an attribute value (polygons as coordinate lists, grid as a dict)."""
    if isinstance(value, Polygon):
        return {
            "exterior": [list(map(float, xy[:2])) for xy in value.exterior.coords],
            "holes": [[list(map(float, xy[:2])) for xy in r.coords] for r in value.interiors],
        }
    if hasattr(value, "geom_type"):  # other shapely geometry
        return mapping(value)
    if isinstance(value, PixelGrid):
        return value.to_dict()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, (list, tuple, set, frozenset)):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def graph_to_json_dict(graph: nx.Graph) -> dict[str, Any]:
    """networkx node-link data of the graph with every attribute made JSON-plain (metres)."""
    plain = nx.Graph()
    plain.graph.update({k: _plain(v) for k, v in graph.graph.items()})
    for n, d in graph.nodes(data=True):
        plain.add_node(n, **{k: _plain(v) for k, v in d.items()})
    for u, v, d in graph.edges(data=True):
        plain.add_edge(u, v, **{k: _plain(x) for k, x in d.items()})
    return nx.node_link_data(plain, edges="edges")


def write_graph_json(graph: nx.Graph, path: str | Path) -> None:
    """Write the connectivity graph as node-link JSON; polygons as {exterior, holes} lists [m]."""
    Path(path).write_text(json.dumps(graph_to_json_dict(graph), indent=1))


def write_graphml(graph: nx.Graph, path: str | Path) -> None:
    """Write the graph as GraphML with scalar attributes only (centroid_m -> centroid_x_m,
    centroid_y_m; sides -> a comma-separated string; polygons, grids and None dropped)."""
    out = nx.Graph()
    out.graph.update(_scalars(graph.graph))
    for n, d in graph.nodes(data=True):
        attrs = _scalars(d)
        if d.get("centroid_m") is not None:
            attrs["centroid_x_m"], attrs["centroid_y_m"] = map(float, d["centroid_m"])
        if d.get("sides") is not None:
            attrs["sides"] = ",".join(d["sides"])
        out.add_node(n, **attrs)
    for u, v, d in graph.edges(data=True):
        out.add_edge(u, v, **_scalars(d))
    nx.write_graphml(out, str(path))


def _scalars(attrs: dict[str, Any]) -> dict[str, Any]:
    out = {}
    for k, v in attrs.items():
        if isinstance(v, np.generic):
            v = v.item()
        if isinstance(v, (bool, int, float, str)):
            out[k] = v
    return out


EARTH_RADIUS_M = 6_378_137.0
"""WGS84 equatorial radius [m], for the local tangent-plane georeference."""


@dataclass(frozen=True)
class Georeference:
    """Where the plan lies on Earth: the plan point (0, 0) m (a drawing's lower-left corner) at
    ``latitude_deg``, ``longitude_deg`` (WGS84), and the plan's +y axis (up on the drawing)
    pointing ``heading_deg`` clockwise from north. Across a building the tangent-plane
    approximation is good to well under a millimetre."""

    latitude_deg: float
    longitude_deg: float
    heading_deg: float = 0.0

    def __post_init__(self) -> None:
        if not (
            math.isfinite(self.heading_deg)
            and math.isfinite(self.latitude_deg)
            and math.isfinite(self.longitude_deg)
            and -85.0 <= self.latitude_deg <= 85.0
            and -180.0 <= self.longitude_deg <= 180.0
        ):
            raise InputError(
                f"--origin {self.latitude_deg},{self.longitude_deg} --heading {self.heading_deg}:"
                " latitude must be in -85..85, longitude in -180..180, heading finite [deg]"
            )

    def lon_lat(self, xy_m: np.ndarray) -> np.ndarray:
        """(N, 2) plan metres -> (N, 2) longitude, latitude [deg]."""
        h = math.radians(self.heading_deg)
        x, y = np.asarray(xy_m, float)[:, 0], np.asarray(xy_m, float)[:, 1]
        east = x * math.cos(h) + y * math.sin(h)
        north = -x * math.sin(h) + y * math.cos(h)
        lat = self.latitude_deg + np.degrees(north / EARTH_RADIUS_M)
        lon = self.longitude_deg + np.degrees(
            east / (EARTH_RADIUS_M * math.cos(math.radians(self.latitude_deg)))
        )
        return np.stack([lon, lat], axis=1)


def parse_origin(text: str) -> tuple[float, float]:
    """``"LAT,LON"`` in degrees -> (lat, lon). Raises InputError otherwise."""
    try:
        lat, lon = (float(v) for v in text.split(","))
    except ValueError:
        raise InputError(f"--origin {text!r}: expected LAT,LON in degrees") from None
    return lat, lon


def rooms_feature_collection(
    parsed: ParsedPlan, georeference: Georeference | None = None
) -> dict[str, Any]:
    """Every instance as a polygon feature with ``class``, ``instance_id``, ``area_m2``,
    ``confidence`` (mean probability of its class; null when the segmenter gave none) and
    ``name`` (the room's printed name; null when none was read).

    Exterior rings run counter-clockwise and holes clockwise (RFC 7946). Without
    ``georeference`` the coordinates are plan metres (x right, y up), which is not GeoJSON's
    longitude/latitude: the collection says so in ``coordinates``.

    Raises:
        InputError: the plan has no scale (resolve it first).
    """
    if parsed.grid is None:
        raise InputError("cannot write rooms in metres: the plan has no scale")
    features = []
    for inst in parsed.instances:
        poly = inst.polygon_m(parsed.grid)
        if poly.is_empty:
            continue
        if georeference is not None:
            poly = shapely.transform(poly, georeference.lon_lat)
        parts = [orient(p, sign=1.0) for p in polygons_of(poly)]
        poly = parts[0] if len(parts) == 1 else MultiPolygon(parts)
        features.append(
            {
                "type": "Feature",
                "properties": {
                    "class": inst.class_name,
                    "instance_id": int(inst.id),
                    "area_m2": float(inst.area_m2(parsed.grid)),
                    "confidence": inst.confidence,
                    "name": inst.name,
                },
                "geometry": mapping(poly),
            }
        )
    data: dict[str, Any] = {"type": "FeatureCollection", "features": features}
    if georeference is None:
        data["coordinates"] = "plan metres: x right, y up; not longitude/latitude"
    else:
        data["georeference"] = dataclasses.asdict(georeference)
    return data


def write_rooms_geojson(
    parsed: ParsedPlan, path: str | Path, *, georeference: Georeference | None = None
) -> None:
    """Write :func:`rooms_feature_collection` as JSON: RFC 7946 GeoJSON with ``georeference``,
    else plan metres (the run writes that one as ``rooms_m.json``, not ``.geojson``)."""
    Path(path).write_text(json.dumps(rooms_feature_collection(parsed, georeference)))


def write_labels_png(parsed: ParsedPlan, path: str | Path) -> None:
    """Write the parse as an 8-bit PNG of class ids (``f2n_drake.core.classes``) on the
    drawing's own grid: each instance's pixels its class, the network's wall pixels 6 (wall),
    all else 0 (background). Openings are no pixel class and keep what lies under them."""
    labels = np.where(parsed.labels == CLASS_ID["wall"], CLASS_ID["wall"], 0).astype(np.uint8)
    lookup = np.zeros(int(parsed.instance_ids.max(initial=0)) + 1, np.uint8)
    owned = np.zeros(lookup.shape, bool)
    for inst in parsed.instances:
        if inst.class_name in CLASS_ID and inst.id < len(lookup):
            lookup[inst.id], owned[inst.id] = CLASS_ID[inst.class_name], True
    ids = parsed.instance_ids
    where = owned[ids]
    labels[where] = lookup[ids[where]]
    if not cv2.imwrite(str(path), labels):
        raise InputError(f"cannot write {path}")


def write_nav2_map(
    free: np.ndarray,
    grid: PixelGrid,
    pgm_path: str | Path,
    yaml_path: str | Path,
    *,
    unknown: np.ndarray | None = None,
) -> None:
    """Write a Nav2 ``map_server`` map: ``free`` cells 254, others 0, ``unknown`` cells 205.

    Args:
        free: (H, W) bool, True where the robot may be; row 0 is the top of the image.
        grid: the raster of ``free`` (resolution and placement).
        pgm_path, yaml_path: outputs; the YAML names the image relative to its own folder.
        unknown: optional (H, W) bool of cells to mark unknown (wins over ``free``).

    Raises:
        InputError: ``free``/``unknown`` are not 2-D or do not match ``grid.shape``.
    """
    free = np.asarray(free)
    if free.ndim != 2 or tuple(free.shape) != tuple(grid.shape):
        raise InputError(f"free mask shape {free.shape} does not match the grid {grid.shape}")
    image = np.where(free.astype(bool), FREE, OCCUPIED).astype(np.uint8)
    if unknown is not None:
        unknown = np.asarray(unknown, dtype=bool)
        if unknown.shape != free.shape:
            raise InputError(f"unknown mask shape {unknown.shape} does not match {free.shape}")
        image[unknown] = UNKNOWN
    rows, cols = image.shape
    pgm_path, yaml_path = Path(pgm_path), Path(yaml_path)
    with open(pgm_path, "wb") as fh:
        fh.write(f"P5\n{cols} {rows}\n255\n".encode("ascii"))
        fh.write(image.tobytes())
    lower_left = (grid.origin_m[0], grid.origin_m[1] - rows * grid.metres_per_px)
    spec = {
        "image": os.path.relpath(pgm_path.resolve(), yaml_path.resolve().parent),
        "mode": "trinary",
        "resolution": float(grid.metres_per_px),
        "origin": [float(lower_left[0]), float(lower_left[1]), 0.0],
        "negate": 0,
        "occupied_thresh": OCCUPIED_THRESH,
        "free_thresh": FREE_THRESH,
    }
    yaml_path.write_text(yaml.safe_dump(spec, sort_keys=False))


def read_pgm(path: str | Path) -> np.ndarray:
    """Read a binary (P5, 8-bit) PGM as an (H, W) uint8 array."""
    data = Path(path).read_bytes()
    fields: list[bytes] = []
    pos = 0
    while len(fields) < 4:
        while data[pos : pos + 1].isspace():
            pos += 1
        if data[pos : pos + 1] == b"#":
            pos = data.index(b"\n", pos) + 1
            continue
        end = pos
        while not data[end : end + 1].isspace():
            end += 1
        fields.append(data[pos:end])
        pos = end
    if fields[0] != b"P5" or int(fields[3]) > 255:
        raise InputError(f"{path} is not an 8-bit binary PGM")
    cols, rows = int(fields[1]), int(fields[2])
    return np.frombuffer(data, np.uint8, rows * cols, pos + 1).reshape(rows, cols)
