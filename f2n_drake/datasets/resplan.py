"""Read ResPlan plans (pickled lists of dicts of shapely geometries) as ``FloorPlan`` in metres.

ResPlan (Abouagour & Garyfallidis 2025) stores each plan as a dict: shapely geometries per class
in plan units (the plan spans 256 units), ``wall_depth`` in plan units, ``area`` in m² and scalars
such as ``id`` and ``unitType``. ``area`` is the area of ``inner`` (rooms, storage and the interior
walls and doors, up to the inner face of the exterior wall), so metres per unit =
sqrt(area / inner.area). Some files spell ``balcony`` as ``balacony``.

**Security**: a pickle can execute arbitrary code when loaded; read trusted files only.
"""

from __future__ import annotations

import logging
import math
import pickle
from pathlib import Path
from typing import Any

import numpy as np
import shapely

from f2n_drake.core.classes import PLAN_CLASSES
from f2n_drake.core.errors import InputError
from f2n_drake.core.plan import FloorPlan, polygons_of

log = logging.getLogger(__name__)

KEY_ALIASES: dict[str, str] = {"balacony": "balcony"}
REQUIRED_KEYS: tuple[str, ...] = ("wall", "door", "window", "front_door")
"""Keys every record must have (room classes may be missing: they are then empty)."""
EXTRA_KEYS: tuple[str, ...] = ("storage", "stair", "garden", "pool", "parking", "veranda")
"""Optional keys kept as FloorPlan extras (drawn as outlines, labelled background)."""
METADATA_KEYS: tuple[str, ...] = ("id", "unitType", "area", "net_area")


def load_resplan(path: str | Path, *, metres_per_unit: float | None = None) -> list[FloorPlan]:
    """Read a ResPlan pickle (a list of plan dicts) as floor plans in metres.

    A pickle can execute arbitrary code when loaded: use trusted files only.

    Args:
        path: the ``.pkl`` file.
        metres_per_unit: scale [m / plan unit]; overrides the scale derived from ``area``/``inner``.

    Raises:
        InputError: the file is missing, unreadable or truncated, is not a list of dicts, or a
            record cannot be converted (see :func:`resplan_to_floorplan`).
    """
    path = Path(path)
    try:
        with path.open("rb") as f:
            data = pickle.load(f)  # noqa: S301 - trusted files only, documented above
    except OSError as exc:
        raise InputError(f"cannot read {path}: {exc.strerror or exc}") from exc
    except Exception as exc:  # noqa: BLE001 - unpickling can fail in many ways
        raise InputError(f"{path} is not a readable pickle ({type(exc).__name__}: {exc})") from exc
    if isinstance(data, dict):
        data = [data]
    if not isinstance(data, (list, tuple)) or not all(isinstance(r, dict) for r in data):
        raise InputError(
            f"{path} does not hold a list of ResPlan dicts (got {type(data).__name__})"
        )
    if not data:
        raise InputError(f"{path} holds no plans")
    plans = []
    for i, record in enumerate(data):
        try:
            plans.append(resplan_to_floorplan(record, metres_per_unit=metres_per_unit))
        except InputError as exc:
            raise InputError(f"{path} plan #{i}: {exc}") from exc
    return plans


def resplan_to_floorplan(
    record: dict[str, Any], *, metres_per_unit: float | None = None
) -> FloorPlan:
    """Convert one ResPlan dict to a ``FloorPlan`` in metres (y up, scaled about the origin).

    Scale: ``metres_per_unit`` if given, else sqrt(area / inner.area). Multi-polygons are split,
    empty parts dropped, invalid ones repaired; ``inner``, ``land``, ``neighbor`` and ``graph``
    are not kept as geometry; id, unitType, area, net_area and the scale go to ``metadata``.

    Raises:
        InputError: missing required keys, non-geometry values, no usable scale, or no geometry.
    """
    record = {KEY_ALIASES.get(k, k): v for k, v in record.items()}
    missing = [k for k in REQUIRED_KEYS if k not in record]
    if missing:
        raise InputError(f"ResPlan record is missing keys {missing}")
    scale, scale_source = _scale(record, metres_per_unit)
    polygons: dict[str, list] = {}
    for name in (*PLAN_CLASSES, *EXTRA_KEYS):
        if name not in record:
            continue
        geom = record[name]
        if geom is not None and not isinstance(geom, shapely.Geometry):
            raise InputError(f"ResPlan key {name!r} is a {type(geom).__name__}, not a geometry")
        polys = _to_metres(geom, scale)
        if polys or name in PLAN_CLASSES:
            polygons[name] = polys
    if not any(polygons.get(n) for n in PLAN_CLASSES):
        raise InputError("ResPlan record has empty geometry for every class")
    wall_depth = record.get("wall_depth")
    if wall_depth is not None and _positive(wall_depth):
        wall_thickness_m = float(wall_depth) * scale
    else:
        wall_thickness_m = _estimate_wall_thickness(polygons)
    metadata: dict[str, Any] = {k: _plain(record[k]) for k in METADATA_KEYS if k in record}
    metadata.update(metres_per_unit=scale, scale_source=scale_source)
    if wall_depth is not None:
        metadata["wall_depth_units"] = _plain(wall_depth)
    return FloorPlan(polygons, wall_thickness_m, "resplan", metadata)


def _scale(record: dict[str, Any], metres_per_unit: float | None) -> tuple[float, str]:
    if metres_per_unit is not None:
        if not _positive(metres_per_unit):
            raise InputError(f"metres_per_unit must be positive, got {metres_per_unit}")
        return float(metres_per_unit), "explicit"
    area, inner = record.get("area"), record.get("inner")
    if _positive(area) and isinstance(inner, shapely.Geometry) and inner.area > 0:
        return math.sqrt(float(area) / inner.area), "area/inner"
    raise InputError(
        "ResPlan record has no usable 'area' and 'inner' to derive its scale; give "
        "metres_per_unit (python -m f2n_drake.data render-resplan FILE --metres-per-unit M), "
        "then run the rendered drawing with --scale"
    )


def _to_metres(geom: Any, scale: float) -> list:
    if geom is None or geom.is_empty:
        return []
    geom = shapely.transform(geom, lambda xy: xy * scale)
    out = []
    for poly in polygons_of(geom):
        if not poly.is_valid:
            poly = shapely.make_valid(poly)
            out.extend(p for p in polygons_of(poly) if p.area > 0)
        elif poly.area > 0:
            out.append(poly)
    return out


def _estimate_wall_thickness(polygons: dict[str, list]) -> float:
    """Median short side of door/window rectangles: they exactly fill the wall gaps."""
    depths = []
    for name in ("door", "window", "front_door"):
        for poly in polygons.get(name, []):
            rect = np.asarray(poly.minimum_rotated_rectangle.exterior.coords)
            depths.append(float(np.linalg.norm(np.diff(rect, axis=0), axis=1).min()))
    depths = [d for d in depths if d > 0]
    if not depths:
        raise InputError("ResPlan record has no 'wall_depth' and no doors/windows to estimate it")
    log.info("no wall_depth: wall thickness estimated from %d openings", len(depths))
    return float(np.median(depths))


def _positive(value: Any) -> bool:
    try:
        return math.isfinite(float(value)) and float(value) > 0
    except (TypeError, ValueError):
        return False


def _plain(value: Any) -> Any:
    """numpy scalars -> Python scalars so metadata stays JSON-serialisable."""
    return value.item() if isinstance(value, np.generic) else value
