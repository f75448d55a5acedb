"""Figures people would rather look at than read: segmentation overlay, graph and routes, drift.

Every function draws into a new matplotlib Figure (Agg, headless) and returns it; ``save`` writes a
PNG. Plots are in metres when the plan's scale is known.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import networkx as nx  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402

from f2n_drake.core.classes import CLASS_ID, CLASS_NAMES, OPENING, PALETTE  # noqa: E402
from f2n_drake.core.parsed import UNSURE_BELOW, ParsedPlan  # noqa: E402
from f2n_drake.datasets.render import colorize  # noqa: E402

ROUTE_COLOURS = {"ground": "#1f4e9c", "uav": "#c2185b"}
DRIFT_COLOURS = {"off": "#d62728", "paper": "#ff7f0e", "continuous": "#2ca02c"}
OPENING_COLOUR = "#ff00ff"
"""Outline of an ``opening`` instance (an open passage: no pixel class of its own)."""


def class_legend(
    ax, class_ids: Sequence[int] | None = None, openings: bool = False, **kwargs
) -> None:
    """A legend of the pixel classes (``class_ids``, default all but background), and of the
    openings' outline when ``openings``."""
    ids = range(1, len(CLASS_NAMES)) if class_ids is None else class_ids
    handles = [Patch(color=np.array(PALETTE[i]) / 255, label=CLASS_NAMES[i]) for i in ids]
    if openings:
        handles.append(Line2D([], [], color=OPENING_COLOUR, lw=2.0, label="opening (outline)"))
    ax.legend(handles=handles, fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0), **kwargs)


def _extent(parsed: ParsedPlan) -> list[float] | None:
    """imshow extent [left, right, bottom, top] in metres, or None for pixel axes."""
    if parsed.grid is None:
        return None
    g = parsed.grid
    h, w = parsed.instance_ids.shape
    x0, y0 = g.origin_m
    return [x0, x0 + w * g.metres_per_px, y0 - h * g.metres_per_px, y0]


def _points(parsed: ParsedPlan, px: np.ndarray) -> np.ndarray:
    """Pixel coordinates -> plot coordinates (metres when known)."""
    return parsed.grid.to_m(px) if parsed.grid is not None else np.asarray(px, float)


def plot_segmentation(image: np.ndarray, parsed: ParsedPlan, *, title: str = "") -> Figure:
    """Drawing (grey, or BGR colour) | network labels | instances after the majority vote, with
    contours; instances whose confidence is below ``UNSURE_BELOW`` are outlined in red, dashed,
    with their score."""
    voted = np.zeros_like(parsed.labels)
    for inst in parsed.instances:
        if inst.class_name in CLASS_ID:
            voted[parsed.instance_ids == inst.id] = CLASS_ID[inst.class_name]
    fig, axes = plt.subplots(1, 3, figsize=(15, 5.4), constrained_layout=True)
    extent = _extent(parsed)
    panels = [
        (image[..., 2::-1] if image.ndim == 3 else image, "drawing", "gray"),
        (colorize(parsed.labels), "network labels", None),
        (colorize(voted), "instances (majority vote)", None),
    ]
    for ax, (img, name, cmap) in zip(axes, panels, strict=True):
        # a drawing shown smaller than drawn keeps its 1 px lines only when averaged, not sampled
        smooth = "antialiased" if cmap == "gray" else "nearest"
        ax.imshow(img, cmap=cmap, extent=extent, interpolation=smooth)
        ax.set_title(name)
        ax.set_xlabel("x [m]" if extent else "col [px]")
    n_unsure = 0
    for inst in parsed.instances:
        c = _points(parsed, np.vstack([inst.contour_px, inst.contour_px[:1]]))
        unsure = inst.confidence is not None and inst.confidence < UNSURE_BELOW
        if unsure:
            n_unsure += 1
            axes[2].plot(c[:, 0], c[:, 1], lw=1.5, c="#e00000", ls="--")
            x, y = _points(parsed, np.asarray(inst.centroid_px))
            axes[2].annotate(
                f"{100 * inst.confidence:.0f}%", (x, y), color="#e00000", fontsize=7, ha="center"
            )
            continue
        opening = inst.class_name == OPENING
        axes[2].plot(
            c[:, 0], c[:, 1], lw=2.0 if opening else 0.6, c=OPENING_COLOUR if opening else "k"
        )
    if n_unsure:
        axes[2].set_title(
            f"instances (majority vote); red dashed: {n_unsure} below "
            f"{100 * UNSURE_BELOW:.0f} % confidence",
            fontsize=9,
        )
    class_legend(axes[2], openings=any(i.class_name == OPENING for i in parsed.instances))
    if title:
        fig.suptitle(title)
    return fig


def plot_graph(
    image: np.ndarray,
    parsed: ParsedPlan,
    graph: nx.Graph,
    routes: Mapping[str, np.ndarray] | None = None,
    *,
    title: str = "",
    ax=None,
) -> Figure:
    """The connectivity graph over the drawing, with optional routes (name -> (N, 2) metres)."""
    fig = ax.figure if ax is not None else plt.figure(figsize=(8.5, 7.5), constrained_layout=True)
    ax = ax or fig.add_subplot()
    extent = _extent(parsed)
    ax.imshow(image, cmap="gray", extent=extent, alpha=0.55, interpolation="antialiased")
    xy = {}
    for key, data in graph.nodes(data=True):
        if data.get("centroid_px") is not None:
            xy[key] = _points(parsed, np.asarray(data["centroid_px"], float))
    if "outside" in graph and extent is not None:
        xy["outside"] = np.array([extent[0] + 0.3, extent[3] - 0.3])
    elif "outside" in graph:
        xy["outside"] = np.array([5.0, 5.0])
    for u, v in graph.edges():
        if u in xy and v in xy:
            style = ":" if "outside" in (u, v) else "-"
            p = np.vstack([xy[u], xy[v]])
            ax.plot(p[:, 0], p[:, 1], style, c="#555555", lw=1.0, zorder=2)
    for key, data in graph.nodes(data=True):
        if key not in xy:
            continue
        cls = data.get("class_name", "outside")
        colour = np.array(PALETTE[CLASS_ID[cls]]) / 255 if cls in CLASS_ID else (0.6, 0.1, 0.6)
        is_space = data.get("kind") == "space"
        ax.scatter(
            *xy[key],
            s=140 if is_space else 45,
            c=[colour],
            edgecolors="k",
            marker="o" if is_space else "s",
            zorder=3,
        )
        if is_space or key == "outside":
            ax.annotate(
                key, xy[key], xytext=(4, 4), textcoords="offset points", fontsize=7, zorder=4
            )
    for name, path in (routes or {}).items():
        path = np.asarray(path, float)
        if path.size:
            ax.plot(path[:, 0], path[:, 1], lw=2.2, c=ROUTE_COLOURS.get(name), label=name, zorder=5)
            ax.scatter(*path[0], marker="^", s=80, c="k", zorder=6)
            ax.scatter(*path[-1], marker="*", s=140, c="gold", edgecolors="k", zorder=6)
    if routes:
        ax.legend(loc="lower right", fontsize=8)
    ax.set_xlabel("x [m]" if extent else "col [px]")
    ax.set_ylabel("y [m]" if extent else "row [px]")
    ax.set_title(title or "connectivity graph")
    return fig


def plot_drift(
    wall_segments_m: np.ndarray,
    planned_m: np.ndarray,
    runs: Mapping[str, object],
    *,
    title: str = "",
) -> Figure:
    """Planned vs driven (true) and estimated paths per correction mode, and error over time.

    ``runs`` maps a mode name to an object with ``true_path`` and ``estimated_path`` ((N, 3) or
    (N, >=2) arrays in metres) — a ``NavigationResult``.
    """
    fig, (ax, ax_err) = plt.subplots(
        1, 2, figsize=(14, 6), constrained_layout=True, gridspec_kw={"width_ratios": [1.4, 1]}
    )
    for x0, y0, x1, y1 in np.asarray(wall_segments_m).reshape(-1, 4):
        ax.plot([x0, x1], [y0, y1], c="k", lw=0.8)
    planned_m = np.asarray(planned_m, float)
    ax.plot(planned_m[:, 0], planned_m[:, 1], "--", c="#1f4e9c", lw=1.5, label="planned")
    for mode, run in runs.items():
        true = np.asarray(run.true_path)
        est = np.asarray(run.estimated_path)
        colour = DRIFT_COLOURS.get(mode)
        ax.plot(true[:, 0], true[:, 1], c=colour, lw=1.6, label=f"{mode}: driven")
        ax.plot(est[:, 0], est[:, 1], ":", c=colour, lw=1.0, label=f"{mode}: estimated")
        n = min(len(true), len(est))
        err = np.linalg.norm(true[:n, :2] - est[:n, :2], axis=1)
        ax_err.plot(
            np.arange(n) * getattr(run, "sample_period_s", 0.1), err * 100, c=colour, label=mode
        )
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.legend(fontsize=7, loc="best")
    ax.set_title(title or "driven vs planned path")
    ax_err.set_xlabel("time [s]")
    ax_err.set_ylabel("position error |true - estimated| [cm]")
    ax_err.legend()
    ax_err.grid(alpha=0.3)
    return fig


def save(fig: Figure, path: str | Path, dpi: int = 110) -> Path:
    path = Path(path)
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path
