"""``FloorPlan``: a floor plan as polygons per class, in metres, with JSON round trip.

The JSON form is a GeoJSON FeatureCollection: one Feature per polygon with its class in
``properties.class``; the plan's own fields sit in the collection's ``properties``. Coordinates
are written with Python's shortest exact float repr, so a round trip is lossless.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import shapely
from shapely.geometry import MultiPolygon, Polygon, mapping, shape

from f2n_drake.core.classes import EXTRA_PLAN_KEYS, PLAN_CLASSES, SPACE_CLASSES
from f2n_drake.core.errors import InputError

FORMAT = "f2n_drake.floorplan/1"


@dataclass(frozen=True)
class FloorPlan:
    """Polygons per class in metres (x right, y up).

    Attributes:
        polygons: class name -> list of polygons [m]. Always has every key of
            ``PLAN_CLASSES`` (possibly empty lists); may have keys of ``EXTRA_PLAN_KEYS``.
        wall_thickness_m: nominal wall thickness [m].
        source: provenance, e.g. ``"synthetic"`` or ``"resplan"``.
        metadata: JSON-serialisable details (seed, ResPlan id, metres per plan unit, ...).
    """

    polygons: dict[str, list[Polygon]]
    wall_thickness_m: float
    source: str = "unknown"
    metadata: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        unknown = set(self.polygons) - set(PLAN_CLASSES) - set(EXTRA_PLAN_KEYS)
        if unknown:
            raise InputError(f"unknown floor-plan classes: {sorted(unknown)}")
        for name in PLAN_CLASSES:
            self.polygons.setdefault(name, [])
        if not (math.isfinite(self.wall_thickness_m) and self.wall_thickness_m > 0):
            raise InputError(f"wall thickness must be positive, got {self.wall_thickness_m}")

    # -- queries ---------------------------------------------------------------------------
    def __getitem__(self, name: str) -> list[Polygon]:
        return self.polygons.get(name, [])

    def union(self, *names: str) -> MultiPolygon | Polygon:
        """Union of the polygons of the given classes."""
        return shapely.union_all([p for n in names for p in self[n]])

    def spaces(self) -> list[tuple[str, Polygon]]:
        """(class, polygon) of every functional space."""
        return [(n, p) for n in SPACE_CLASSES for p in self[n]]

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax) [m] of everything labelled."""
        geoms = [p for n in PLAN_CLASSES for p in self[n]]
        if not geoms:
            raise InputError("floor plan has no geometry")
        return tuple(shapely.total_bounds(geoms).tolist())

    def counts(self) -> dict[str, int]:
        return {n: len(ps) for n, ps in self.polygons.items()}

    # -- JSON --------------------------------------------------------------------------------
    def to_json_dict(self) -> dict[str, Any]:
        features = [
            {"type": "Feature", "properties": {"class": name}, "geometry": mapping(poly)}
            for name, polys in self.polygons.items()
            for poly in polys
        ]
        return {
            "type": "FeatureCollection",
            "properties": {
                "format": FORMAT,
                "units": "m",
                "wall_thickness_m": self.wall_thickness_m,
                "source": self.source,
                "metadata": self.metadata,
                "classes": list(self.polygons),
            },
            "features": features,
        }

    @classmethod
    def from_json_dict(cls, data: dict[str, Any]) -> FloorPlan:
        """Raises InputError on anything that is not a floor-plan FeatureCollection."""
        try:
            props = data["properties"]
            if props.get("format") != FORMAT:
                raise InputError(f"not a floor-plan JSON (format {props.get('format')!r})")
            polygons: dict[str, list[Polygon]] = {n: [] for n in props.get("classes", [])}
            for feature in data["features"]:
                geom = shape(feature["geometry"])
                if geom.geom_type != "Polygon" or geom.is_empty:
                    raise InputError(f"feature is a {geom.geom_type}, expected a non-empty Polygon")
                polygons.setdefault(feature["properties"]["class"], []).append(geom)
            return cls(
                polygons,
                float(props["wall_thickness_m"]),
                props.get("source", "unknown"),
                dict(props.get("metadata", {})),
            )
        except (KeyError, TypeError, AttributeError, ValueError) as exc:
            if isinstance(exc, InputError):
                raise
            raise InputError(f"malformed floor-plan JSON: {type(exc).__name__}: {exc}") from exc

    def save(self, path: str | Path) -> None:
        Path(path).write_text(json.dumps(self.to_json_dict()))

    @classmethod
    def load(cls, path: str | Path) -> FloorPlan:
        """Read a plan JSON; raises InputError if it is missing, truncated or malformed."""
        try:
            text = Path(path).read_text()
        except OSError as exc:
            raise InputError(f"cannot read {path}: {exc.strerror}") from exc
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise InputError(f"{path} is not valid JSON ({exc.msg} at line {exc.lineno})") from exc
        if not isinstance(data, dict):
            raise InputError(f"{path} is not a floor-plan JSON object")
        return cls.from_json_dict(data)


def polygons_of(geometry: Any) -> list[Polygon]:
    """The non-empty polygons of a shapely Polygon/MultiPolygon/GeometryCollection."""
    if geometry is None or geometry.is_empty:
        return []
    if geometry.geom_type == "Polygon":
        return [geometry]
    return [g for part in getattr(geometry, "geoms", []) for g in polygons_of(part)]
