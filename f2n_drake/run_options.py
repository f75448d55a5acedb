"""The options of ``python -m f2n_drake.run PLAN`` (``f2n_drake.run``): the plan, the route's
ends, the robot, the scale, the correction, the outputs, the parse's priors and the building."""

from __future__ import annotations

import argparse

from f2n_drake.core.errors import (
    ArgumentParser,
    count_or_any,
    finite_float,
    non_negative_int,
    paper_scale,
    positive_int,
)
from f2n_drake.segmenter import DEFAULT_VIEWS, VIEW_COUNTS
from f2n_drake.world.options import add_world_options


def build_parser() -> argparse.ArgumentParser:
    p = ArgumentParser(
        prog="python -m f2n_drake.run",
        description="Floor plan in, robot navigation out. PLAN is a drawing (PNG/JPG or a PDF "
        "page), a ResPlan .pkl (pickle: trusted files only, it can run code) or a plan JSON.",
        epilog="exit codes: 0 done; 2 bad input (nothing written); 3 no route (the parse is "
        "written to --out, the error names the unreachable rooms); 4 the simulated robot did "
        "not reach its goal; 130/143 interrupted/terminated (nothing written)",
    )
    p.add_argument("plan", help="floor-plan drawing (image or PDF), ResPlan .pkl or plan .json")
    p.add_argument(
        "--start", help="room (e.g. living_0, kitchen) or X,Y in metres [default: the front door]"
    )
    p.add_argument("--goal", help="room or X,Y in metres [default: the farthest room]")
    p.add_argument("--robot", default="ground", help="ground, uav or a profile YAML [ground]")
    p.add_argument(
        "--scale",
        type=finite_float(0.0, 1e6, low_open=True),
        metavar="M_PER_PX",
        help="metres per pixel of the drawing, e.g. 0.02 [default: estimated from door widths]",
    )
    p.add_argument(
        "--correction",
        default="continuous",
        choices=["paper", "continuous", "off", "all"],
        help="LiDAR drift correction; 'all' drives the route once per mode and draws "
        "them together [continuous]",
    )
    p.add_argument("--seed", type=non_negative_int, default=0, help="simulation noise seed [0]")
    p.add_argument(
        "--out",
        default=None,
        help="output folder, replaced as a whole: new, empty or written by an earlier run "
        "[out/<the plan file's name>]",
    )
    p.add_argument(
        "--html",
        help="write a self-contained meshcat HTML replay here (opens framed on the plan; with "
        "--correction all each run is a folder under runs/ in the controls)",
    )
    p.add_argument(
        "--origin",
        metavar="LAT,LON",
        help="WGS84 position [deg] of the plan's (0, 0) m (the drawing's lower-left corner): "
        "also write rooms.geojson in longitude/latitude (rooms_m.json is always plan metres)",
    )
    p.add_argument(
        "--heading",
        type=finite_float(-360.0, 360.0),
        default=0.0,
        metavar="DEG",
        help="compass bearing of the drawing's up direction, clockwise from north [0]",
    )
    p.add_argument("--meshcat", action="store_true", help="open a live meshcat viewer")
    p.add_argument(
        "--unknown-start",
        action="store_true",
        help="the simulated robot does not know its start pose: it localizes itself on the plan "
        "(Monte Carlo localization, moving slowly and safely), then follows the route",
    )
    p.add_argument(
        "--replan",
        action="store_true",
        help="the simulated robot avoids what its LiDAR sees and the plan lacks and replans past "
        "closed doors (on by itself with --clutter, --people, --closed-doors, --deviation or "
        "--unknown-start)",
    )
    p.add_argument("--no-sim", action="store_true", help="stop after planning")
    p.add_argument(
        "--plan-index", type=non_negative_int, default=0, help="which plan of a .pkl [0]"
    )
    p.add_argument("--page", type=positive_int, default=1, help="which page of a PDF, from 1 [1]")
    p.add_argument(
        "--paper-scale",
        type=paper_scale,
        metavar="1:N",
        help="the PDF's drawing is at 1:N on its page (e.g. 1:100): the scale in metres, from the "
        "page size [default: estimated from door widths]",
    )
    p.add_argument(
        "--front-doors",
        type=count_or_any,
        default=1,
        metavar="N|any",
        help="front doors in a drawing: the N connectors most like one get the class; 'any' "
        "keeps the network's vote [1, an apartment]",
    )
    p.add_argument(
        "--kitchens",
        type=count_or_any,
        default=1,
        metavar="N|any",
        help="kitchens in a drawing at most: the N most kitchen-like keep the class, and a "
        "drawing with none gets its most kitchen-like room; 'any' keeps the network's vote "
        "[1, an apartment]",
    )
    p.add_argument(
        "--views",
        type=int,
        choices=VIEW_COUNTS,
        default=DEFAULT_VIEWS,
        help="views of a drawing (flips and quarter turns) whose segmentations are averaged; "
        f"network time grows with the count [{DEFAULT_VIEWS}]",
    )
    add_world_options(p)
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    return p
