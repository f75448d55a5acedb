"""``python -m f2n_drake.readme_figures --out docs/figures``: regenerate every README figure.

- ``data_comparison.png``: a generated plan and a real ResPlan plan, drawing | labels.
- ``example_segmentation.png``, ``example_route.png``: the bundled drawing parsed by the network,
  and its graph with the default ground route (what ``make run`` shows).
- ``listing_segmentation.png``: the bundled plan drawn with room names, areas and furniture, as a
  real-estate listing draws it, parsed by the network.
- ``sign_segmentation.png``: the bundled plan drawn as an evacuation sign, in colour, parsed.
- ``hatched_segmentation.png``: the bundled plan drawn with hatched walls, parsed.
- ``textured_segmentation.png``: the bundled plan with its floors painted with planks and tiles,
  parsed.
- ``squared_segmentation.png``: the bundled plan drawn on squared paper, parsed.
- ``routes_ground_uav.png``: balcony to front door for the ground robot and the drone (the paper's
  Figure 4 case) on generated plan 900051, where flying round the facade pays off.
- ``drift.png``: the same route driven with LiDAR correction off, paper and continuous.
- ``diagram.png``: the Drake Diagram from its Graphviz description (needs the ``dot`` program).
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np

from f2n_drake import build_graph, parse_drawing, plan_route, simulate
from f2n_drake.core.errors import InputError, run_cli
from f2n_drake.core.paths import REPO_ROOT
from f2n_drake.outputs import figures

EXAMPLE_PNG = REPO_ROOT / "examples" / "plan.png"
EXAMPLE_JSON = REPO_ROOT / "examples" / "plan.json"


def example_figures(out: Path) -> None:
    from f2n_drake.run import run

    scratch = out / ".example_run"
    run(EXAMPLE_PNG, out=scratch, simulate=False)
    shutil.move(scratch / "segmentation.png", out / "example_segmentation.png")
    shutil.move(scratch / "route.png", out / "example_route.png")
    shutil.rmtree(scratch)


def listing_figure(out: Path, seed: int = 0) -> None:
    """The bundled plan drawn as a listing draws it (room names and areas, furniture) and parsed:
    ``listing_segmentation.png``."""
    import cv2

    from f2n_drake.core.plan import FloorPlan
    from f2n_drake.datasets.looks import restyle
    from f2n_drake.datasets.render import render
    from f2n_drake.run import run

    rng = np.random.default_rng(seed)
    drawing = restyle(
        restyle(render(FloorPlan.load(EXAMPLE_JSON), 768), "labelled", rng), "furnished", rng
    )
    scratch = out / ".listing_run"
    scratch.mkdir(exist_ok=True)
    cv2.imwrite(str(scratch / "listing.png"), drawing.image)
    run(scratch / "listing.png", out=scratch / "run", simulate=False)
    shutil.move(scratch / "run" / "segmentation.png", out / "listing_segmentation.png")
    shutil.rmtree(scratch)


def sign_figure(out: Path, seed: int = 3) -> None:
    """The bundled plan drawn as an evacuation sign (escape route, arrows, extinguishers, "you
    are here", a legend, in colour) and parsed: ``sign_segmentation.png``."""
    from f2n_drake.core.plan import FloorPlan
    from f2n_drake.datasets.looks import restyle
    from f2n_drake.datasets.render import render

    rng = np.random.default_rng(seed)
    sign = restyle(render(FloorPlan.load(EXAMPLE_JSON), 768), "evacuation", rng).image
    fig = figures.plot_segmentation(sign, parse_drawing(sign), title="an evacuation sign")
    figures.save(fig, out / "sign_segmentation.png")


def hatched_figure(out: Path, seed: int = 0) -> None:
    """The bundled plan drawn with hatched walls, as architects draw cut walls, and parsed:
    ``hatched_segmentation.png``."""
    from f2n_drake.core.plan import FloorPlan
    from f2n_drake.datasets.looks import restyle
    from f2n_drake.datasets.render import render

    rng = np.random.default_rng(seed)
    drawing = restyle(render(FloorPlan.load(EXAMPLE_JSON), 1024), "hatched", rng).image
    fig = figures.plot_segmentation(drawing, parse_drawing(drawing), title="hatched walls")
    figures.save(fig, out / "hatched_segmentation.png")


def textured_figure(out: Path, seed: int = 0) -> None:
    """The bundled plan with its floors painted with planks and tiles, as a rendered listing
    paints them, and parsed: ``textured_segmentation.png``."""
    from f2n_drake.core.plan import FloorPlan
    from f2n_drake.datasets.looks import restyle
    from f2n_drake.datasets.render import render

    rng = np.random.default_rng(seed)
    drawing = restyle(render(FloorPlan.load(EXAMPLE_JSON), 768), "textured-floors", rng).image
    fig = figures.plot_segmentation(drawing, parse_drawing(drawing), title="textured floors")
    figures.save(fig, out / "textured_segmentation.png")


def squared_figure(out: Path) -> None:
    """The bundled plan printed on squared paper (lines 16 px apart at 768 px, grey 200), and
    parsed: ``squared_segmentation.png``."""
    from f2n_drake.core.plan import FloorPlan
    from f2n_drake.datasets.looks import on_squared_paper
    from f2n_drake.datasets.render import render

    drawing = on_squared_paper(render(FloorPlan.load(EXAMPLE_JSON), 768).image, 16)
    fig = figures.plot_segmentation(drawing, parse_drawing(drawing), title="on squared paper")
    figures.save(fig, out / "squared_segmentation.png")


ROUTES_SEED = 900051


def ground_truth_plan(seed: int | None = None):
    """(plan, rendering, ``PlanMap`` of its ground truth) of the bundled plan or a generated
    one, on the 512 px rendering's own raster."""
    from f2n_drake.core.plan import FloorPlan
    from f2n_drake.datasets.generator import generate_plan
    from f2n_drake.datasets.ground_truth import parse_ground_truth
    from f2n_drake.datasets.render import render

    plan = FloorPlan.load(EXAMPLE_JSON) if seed is None else generate_plan(seed)
    rendered = render(plan, 512)
    plan_map = build_graph(parse_ground_truth(plan, rendered.grid), planning_cell_m=None)
    return plan, rendered, plan_map


def routes_figure(out: Path) -> None:
    _, rendered, plan_map = ground_truth_plan(ROUTES_SEED)
    graph = plan_map.graph
    balcony = sorted(k for k, d in graph.nodes(data=True) if d.get("class_name") == "balcony")[0]
    routes = {
        robot: plan_route(plan_map, robot=robot, start=balcony, goal="front_door_0")
        for robot in ("ground", "uav")
    }
    title = "\n".join(
        f"{n}: {r.length_m:.1f} m via {', '.join(r.sequence[1:-1])}" for n, r in routes.items()
    )
    fig = figures.plot_graph(
        rendered.image,
        plan_map.parsed,
        graph,
        {n: r.waypoints_m for n, r in routes.items()},
        title=title,
    )
    figures.save(fig, out / "routes_ground_uav.png")


def drift_figure(out: Path, seed: int = 3) -> None:
    from f2n_drake.mapping.walls import PlanGeometry

    plan, _, plan_map = ground_truth_plan()
    route = plan_route(plan_map, robot="ground", start="front_door_0", goal="bedroom_0")
    runs = {
        mode: simulate(plan, route, correction=mode, seed=seed)
        for mode in ("off", "paper", "continuous")
    }
    title = "odometry noise 2 cm per 10 Hz step\n" + ", ".join(
        f"{m}: mean error {r.mean_error_m * 100:.1f} cm{' (collided)' if r.collided else ''}"
        for m, r in runs.items()
    )
    fig = figures.plot_drift(
        PlanGeometry.from_floorplan(plan).wall_segments(), route.waypoints_m, runs, title=title
    )
    figures.save(fig, out / "drift.png")


def diagram_figure(out: Path) -> None:
    from f2n_drake.core.plan import FloorPlan
    from f2n_drake.systems.diagram import MakeNavigationDiagram

    if shutil.which("dot") is None:
        raise InputError("the diagram figure needs Graphviz's `dot` (apt-get install graphviz)")
    plan = FloorPlan.load(EXAMPLE_JSON)
    xmin, ymin, _, _ = plan.bounds
    stub_route = np.array([[xmin + 1, ymin + 1], [xmin + 2, ymin + 1]])
    diagram = MakeNavigationDiagram(plan, stub_route, correction="continuous")
    subprocess.run(
        ["dot", "-Tpng", "-Gdpi=80", "-o", str(out / "diagram.png")],
        input=diagram.GetGraphvizString(max_depth=1),
        text=True,
        check=True,
    )


def data_figure(out: Path) -> None:
    from f2n_drake.datasets import cli as data

    if data.main(["figure", "--out", str(out / "data_comparison.png")]) != 0:
        raise InputError("data comparison figure failed")


FIGURES = {
    "data": data_figure,
    "example": example_figures,
    "listing": listing_figure,
    "sign": sign_figure,
    "hatched": hatched_figure,
    "textured": textured_figure,
    "squared": squared_figure,
    "routes": routes_figure,
    "drift": drift_figure,
    "diagram": diagram_figure,
}


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="python -m f2n_drake.readme_figures", description=__doc__.split("\n\n")[0]
    )
    p.add_argument("--out", default=str(REPO_ROOT / "docs" / "figures"))
    p.add_argument(
        "--only",
        choices=sorted(FIGURES),
        action="append",
        help="make only this figure (repeatable)",
    )
    args = p.parse_args(argv)
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise InputError(f"{out} exists and is not a directory")
    out.mkdir(parents=True, exist_ok=True)
    for name in args.only or FIGURES:
        FIGURES[name](out)
        print(f"made {name}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(run_cli(main))
