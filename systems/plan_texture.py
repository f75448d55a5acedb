"""The plan as one picture on the floor of the meshcat scene: rooms tinted by class with their
names, doors and windows marked, walls dark.

A static replay cannot render text, so the labels are painted into a texture (matplotlib, Agg)
that lies on a quad over the plan's bounds (:func:`plan_floor_mesh`, a Wavefront OBJ with its
material and PNG, which Drake inlines into the scene). The texture is emissive, so it reads the
same under any light (its emissive strength, 1.3, makes white read white through meshcat's
tone mapping).
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import numpy as np  # noqa: E402
from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.patches import PathPatch  # noqa: E402
from matplotlib.path import Path as MplPath  # noqa: E402
from shapely.geometry import Polygon  # noqa: E402
from shapely.ops import polylabel  # noqa: E402

from f2n_drake.core.classes import CLASS_ID, PALETTE  # noqa: E402
from f2n_drake.core.plan import polygons_of  # noqa: E402
from f2n_drake.mapping.walls import PlanGeometry  # noqa: E402

TEXTURE_PX = 2048  # the texture's long side [px]
TINT = 0.7  # rooms: this much of the class colour, the rest white
LABEL_HEIGHT = 0.017  # room names: text height over the texture's long side
CHAR_WIDTH = 0.62  # a character's width over the font size (DejaVu Sans, about); names that
# would be wider than their room are set smaller
WALL_RGB = (0.25, 0.25, 0.28)


def class_rgb(name: str) -> np.ndarray:
    """The class colour of ``name`` (``f2n_drake.core.classes.PALETTE``) as RGB in [0, 1]."""
    return np.array(PALETTE[CLASS_ID.get(name, 0)]) / 255.0


def room_rgb(name: str) -> np.ndarray:
    """The tint of a room of class ``name`` in the texture: ``TINT`` of its class colour."""
    return TINT * class_rgb(name) + (1 - TINT)


def room_names(geometry: PlanGeometry) -> list[str]:
    """``"<class>_<k>"`` for each floor, k counting per class in order: the connectivity graph's
    node keys (``f2n_drake.mapping.graph.node_keys``) when the floors come from a parsed plan."""
    counts: dict[str, int] = {}
    names = []
    for name, _ in geometry.floors:
        names.append(f"{name}_{counts.get(name, 0)}")
        counts[name] = counts.get(name, 0) + 1
    return names


def _patch(poly: Polygon, **kwargs) -> PathPatch:
    rings = [np.asarray(r.coords)[:, :2] for r in (poly.exterior, *poly.interiors)]
    codes = [
        c
        for r in rings
        for c in [MplPath.MOVETO, *[MplPath.LINETO] * (len(r) - 2), MplPath.CLOSEPOLY]
    ]
    return PathPatch(MplPath(np.vstack(rings), codes), **kwargs)


def render_plan_texture(
    geometry: PlanGeometry, bounds_m: tuple[float, float, float, float]
) -> np.ndarray:
    """(H, W, 3) uint8 RGB picture of ``geometry`` over ``bounds_m`` (xmin, ymin, xmax, ymax)
    [m], north (+y) up, the long side ``TEXTURE_PX`` pixels."""
    xmin, ymin, xmax, ymax = bounds_m
    scale = TEXTURE_PX / max(xmax - xmin, ymax - ymin)  # [px/m]
    width_px = max(1, round((xmax - xmin) * scale))
    height_px = max(1, round((ymax - ymin) * scale))
    dpi = 100.0
    fig = Figure(figsize=(width_px / dpi, height_px / dpi), dpi=dpi, facecolor="white")
    ax = fig.add_axes((0.0, 0.0, 1.0, 1.0))
    ax.set_xlim(xmin, xmax)
    ax.set_ylim(ymin, ymax)
    ax.set_axis_off()
    for name, floor in geometry.floors:
        for poly in polygons_of(floor):
            ax.add_patch(_patch(poly, facecolor=room_rgb(name), edgecolor="none"))
    for poly in geometry.walls:
        ax.add_patch(_patch(poly, facecolor=WALL_RGB, edgecolor="none"))
    for name, connector in geometry.connectors:
        for poly in polygons_of(connector):
            ax.add_patch(_patch(poly, facecolor=class_rgb(name), edgecolor="none"))
    font_pt = LABEL_HEIGHT * TEXTURE_PX * 72.0 / dpi
    for label, (_, floor) in zip(room_names(geometry), geometry.floors, strict=True):
        parts = polygons_of(floor)
        if not parts:
            continue
        largest = max(parts, key=lambda p: p.area)
        at = polylabel(largest, tolerance=0.01)
        x0, _, x1, _ = largest.bounds
        fit_pt = 0.9 * (x1 - x0) * scale / (CHAR_WIDTH * len(label)) * 72.0 / dpi
        ax.text(
            at.x,
            at.y,
            label,
            ha="center",
            va="center",
            fontsize=min(font_pt, fit_pt),
            color="black",
            bbox={"boxstyle": "round,pad=0.2", "facecolor": "white", "alpha": 0.75, "lw": 0},
        )
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    rgba = np.asarray(canvas.buffer_rgba())
    return rgba[:, :, :3].copy()


def plan_floor_mesh(
    geometry: PlanGeometry, bounds_m: tuple[float, float, float, float], folder: Path
) -> Path:
    """Write ``plan_floor.obj`` (a quad over ``bounds_m`` at z = 0), its ``.mtl`` and the texture
    ``plan_floor.png`` (:func:`render_plan_texture`) into ``folder``; returns the OBJ path."""
    import cv2  # noqa: PLC0415

    folder = Path(folder)
    image = render_plan_texture(geometry, bounds_m)
    cv2.imwrite(str(folder / "plan_floor.png"), cv2.cvtColor(image, cv2.COLOR_RGB2BGR))
    (folder / "plan_floor.mtl").write_text(
        "newmtl plan_floor\nKa 0 0 0\nKd 0 0 0\nKe 1.3 1.3 1.3\nmap_Ke plan_floor.png\n"
    )
    xmin, ymin, xmax, ymax = bounds_m
    (folder / "plan_floor.obj").write_text(
        "mtllib plan_floor.mtl\n"
        f"v {xmin} {ymin} 0\nv {xmax} {ymin} 0\nv {xmax} {ymax} 0\nv {xmin} {ymax} 0\n"
        "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\nusemtl plan_floor\n"
        "f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n"
    )
    return folder / "plan_floor.obj"


__all__ = ["class_rgb", "plan_floor_mesh", "render_plan_texture", "room_names", "room_rgb"]
