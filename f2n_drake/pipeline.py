"""The pipeline in one place: a drawing in, a parsed plan, its graph, a route and a drive out.

    from f2n_drake import build_graph, parse_drawing, plan_route, simulate

    parsed = parse_drawing(image)                 # segmenter, instances, apartment priors
    plan_map = build_graph(parsed)                # planning resolution, connectivity graph
    route = plan_route(plan_map, robot="ground")  # front door to the farthest room
    result = simulate(plan_map, route)            # Drake: odometry, LiDAR, correction

``parse_drawing`` keeps only the plans on the sheet (``perception.sheet``: legends and title
blocks left out, ``ParsedPlan.sheet_note`` says which part was taken; a drawing whose
ink then closes no outline is read again with its faint strokes as ink), then reads the
words on the drawing (``perception.reading``): their ink is taken off the lines and out of the
network's view (text is never a wall, a room boundary or an obstacle). It runs the segmenter
(labels and probabilities, around furniture drawn against the walls; regions named by their
words take the named class: ``segment_drawing``), then
``f2n_drake.perception.instances.extract_instances`` (majority vote, soft scores, the doorways
the ink leaves open closed, open-passage split), the apartment priors of
``f2n_drake.perception.priors.chain`` (one front door, no door or window wider than one can be,
balconies open to the air, one kitchen, no room without a door) and the room names (each word
placed in its instance, ``perception.priors.named_rooms``): ``parse_steps``. Printed sizes give
the scale later (``perception.scale.resolve_scale``). A drawing without words parses as it would
unread. The segmentation evaluation calls the same two functions, so every step of the parse is
measured.
"""

from __future__ import annotations

import dataclasses
import logging
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Literal

import networkx as nx
import numpy as np

from f2n_drake.core.errors import InputError, PlanningError
from f2n_drake.core.parsed import ParsedPlan
from f2n_drake.core.plan import FloorPlan
from f2n_drake.core.raster import PixelGrid
from f2n_drake.core.text import TextBox
from f2n_drake.mapping.graph import build_connectivity_graph
from f2n_drake.mapping.occupancy import occupancy_map
from f2n_drake.mapping.resolution import PLANNING_CELL_M, at_planning_resolution
from f2n_drake.mapping.robots import RobotProfile, load_profile
from f2n_drake.mapping.walls import PlanGeometry
from f2n_drake.perception.fine_drawings import on_drawing_grid as on_fine_drawing_grid
from f2n_drake.perception.fine_drawings import reduction, shrunk
from f2n_drake.perception.fixture_pieces import join_fixture_pieces
from f2n_drake.perception.floor_textures import without_floor_textures
from f2n_drake.perception.furniture import segment_around_furniture
from f2n_drake.perception.image import (
    LabelPredictor,
    Prediction,
    check_drawing,
    has_enclosed_region,
    predict_labels,
)
from f2n_drake.perception.ink import as_grey, binarize, dark_on_light
from f2n_drake.perception.instances import DEFAULT_SPLIT, SplitOptions, extract_instances
from f2n_drake.perception.lighting import evenly_lit
from f2n_drake.perception.opening_depth import fill_wall_depth, join_depth_pieces
from f2n_drake.perception.opening_piers import part_at_piers
from f2n_drake.perception.paper_grid import without_paper_grid
from f2n_drake.perception.preparation import (
    content_box,
    drawn_in_light_lines,
    on_white_paper,
    without_marks,
)
from f2n_drake.perception.priors.chain import PRIORS, prior_stages
from f2n_drake.perception.priors.named_rooms import label_named_regions, name_rooms
from f2n_drake.perception.reading import TextReader, place_texts, read_words, text_ink
from f2n_drake.perception.scale import resolve_scale
from f2n_drake.perception.sheet import PlanOnSheet, only_the_plan
from f2n_drake.perception.small_drawings import (
    enlarged,
    enlargement,
    on_drawing_grid,
    read_at_drawing_size,
)
from f2n_drake.perception.stairs import stairs_are_circulation
from f2n_drake.perception.window_inserts import wall_bands
from f2n_drake.planning.endpoints import (
    GOAL_TRIES,
    default_start,
    goal_candidates,
    resolve_node,
)
from f2n_drake.planning.hierarchical import HierarchicalPlanner
from f2n_drake.planning.replanning import Replanner
from f2n_drake.planning.route import Route

if TYPE_CHECKING:
    from pydrake.geometry import Meshcat

    from f2n_drake.systems.simulation import NavigationResult

log = logging.getLogger(__name__)

PARSE_STEPS: tuple[str, ...] = ("instances", *PRIORS, "named_rooms")
"""The steps of ``parse_steps`` in order; the last one is the parse."""

Place = str | tuple[float, float]
"""A route end: a node key ("bedroom_1"), a class name ("kitchen": its first instance), or
(x, y) [m]."""


@dataclass(frozen=True)
class Segmentation:
    """What the segmenter makes of a drawing.

    Attributes:
        labels: (H, W) uint8 class per pixel (regions named by a word take the named class).
        probabilities: (C, H, W) float class probabilities, or None.
        furniture: (H, W) bool paper of furniture drawn against the walls (an obstacle).
        texts: the words read on the drawing (none when it was not read).
    """

    labels: np.ndarray
    probabilities: np.ndarray | None
    furniture: np.ndarray
    texts: list[TextBox] = field(default_factory=list)


def without_text(
    grey: np.ndarray, lines: np.ndarray, texts: Sequence[TextBox]
) -> tuple[np.ndarray, np.ndarray]:
    """``grey`` and its ``lines`` with the ink of ``texts`` taken off (``perception.reading``):
    what the network and the instances see of a drawing whose words were read."""
    if not texts:
        return grey, lines
    ink = text_ink(lines, list(texts))
    return without_marks(grey, lines, ink), lines & ~ink


def segment_drawing(
    grey: np.ndarray,
    lines: np.ndarray,
    predict: Callable[[np.ndarray], Prediction],
    texts: Sequence[TextBox] = (),
) -> Segmentation:
    """Segment ``grey`` with ``predict``, again with the furniture found against the walls
    painted over (``perception.furniture.segment_around_furniture``); the regions ``texts`` name
    take the named class (``perception.priors.named_rooms.label_named_regions``). ``grey`` and
    ``lines`` are the drawing without its words (``without_text``)."""
    (labels, probabilities), furniture = segment_around_furniture(grey, lines, predict)
    if texts:
        labels = label_named_regions(labels, lines, list(texts), grey)
    return Segmentation(labels, probabilities, furniture, list(texts))


def parse_steps(
    grey: np.ndarray,
    segmentation: Segmentation,
    *,
    lines: np.ndarray,
    grid: PixelGrid | None = None,
    split: SplitOptions | None = DEFAULT_SPLIT,
    front_doors: int | None = 1,
    kitchens: int | None = 1,
    sealed_rooms: bool = True,
    balconies: bool = True,
    connector_sizes: bool = True,
) -> dict[str, ParsedPlan]:
    """The plan after each step of the parse, keyed in ``PARSE_STEPS`` order: ``instances``
    (``extract_instances``, a room's fixture pieces joined to it by
    ``perception.fixture_pieces.join_fixture_pieces``, a bedroom or bathroom holding a flight of
    stairs made circulation by ``perception.stairs.stairs_are_circulation``, each door and window
    grown to its gap in the wall by ``perception.opening_depth.fill_wall_depth``, its pieces
    across the wall's depth joined by ``perception.opening_depth.join_depth_pieces``, and cut at
    the piers between side-by-side openings by ``perception.opening_piers.part_at_piers``), each
    prior of ``perception.priors.chain``, then ``named_rooms`` (the words of ``segmentation``
    placed in their instances, which take the names' classes; the step before when nothing was
    read). The arguments are ``parse_drawing``'s; a prior switched off leaves its step equal to
    the one before."""
    voted = extract_instances(
        grey,
        segmentation.labels,
        grid=grid,
        split=split,
        lines=lines,
        probabilities=segmentation.probabilities,
        furniture=segmentation.furniture,
    )
    voted = join_fixture_pieces(voted, lines, segmentation.texts, segmentation.probabilities)
    voted = stairs_are_circulation(voted, lines, grey)
    walls = wall_bands(as_grey(grey), lines, voted.labels)  # the labels both steps keep
    voted = fill_wall_depth(voted, grey, lines, segmentation.probabilities, walls=walls)
    voted = join_depth_pieces(voted, segmentation.probabilities)
    voted = part_at_piers(voted, grey, lines, segmentation.probabilities, walls=walls)
    stages = prior_stages(
        voted,
        front_doors=front_doors,
        connector_sizes=connector_sizes,
        balconies=balconies,
        kitchens=kitchens,
        sealed_rooms=sealed_rooms,
    )
    named = stages[PRIORS[-1]]
    if segmentation.texts:
        texts = place_texts(segmentation.texts, named.instance_ids)
        named = name_rooms(dataclasses.replace(named, texts=texts), lines, grey)
    return {"instances": voted, **stages, "named_rooms": named}


def parse_drawing(
    image: np.ndarray,
    *,
    segmenter: LabelPredictor | None = None,
    metres_per_px: float | None = None,
    split: SplitOptions | None = DEFAULT_SPLIT,
    front_doors: int | None = 1,
    kitchens: int | None = 1,
    sealed_rooms: bool = True,
    balconies: bool = True,
    connector_sizes: bool = True,
    reader: TextReader | None = read_words,
    leave_out_sheet: bool = True,
    even_lighting: bool = True,
    faint_lines: bool = True,
    floor_textures: bool = True,
    paper_grid: bool = True,
    enlarge_small: bool = True,
    shrink_fine: bool = True,
    progress: Callable[[str], None] | None = None,
) -> ParsedPlan:
    """Read and segment a drawing and turn it into labelled instances.

    Furniture drawn against the walls is found from a first segmentation, and the drawing is
    segmented again with its outline painted over (``perception.furniture``); its paper is no
    instance, an obstacle.

    Args:
        image: (H, W) uint8 grey (or BGR/BGRA) drawing, dark lines on light paper.
        segmenter: anything with ``predict(image) -> (H, W) uint8 labels``; default the shipped
            ``Segmenter.load()``.
        metres_per_px: scale, if known [m/px]; sets ``grid`` (``scale_source="argument"``).
        split: open-passage split options, None to disable.
        front_doors: how many front doors the plan has (1 for an apartment); the connectors most
            like one get the class (``perception.priors.front_doors``). None keeps the vote.
        kitchens: how many kitchens the plan has at most (1 for an apartment); the others are
            undone, and a plan with none gets its most kitchen-like room
            (``perception.priors.kitchens``). None keeps the plain vote.
        sealed_rooms: where a group of rooms has no door to the rest, the most door-like wall
            between them becomes a door (``perception.priors.sealed_rooms``); False keeps the
            vote.
        balconies: a balcony that touches no exterior takes its runner-up room class
            (``perception.priors.balconies``); False keeps the vote.
        connector_sizes: a door or window wider than one can be is wall
            (``perception.priors.connector_sizes``); False keeps the vote.
        reader: reads the words on the drawing (``perception.reading.read_words``, RapidOCR);
            None reads none (``ParsedPlan.texts`` empty, names and printed sizes unused).
        leave_out_sheet: parse only the plans on the sheet, leaving out legends and title
            blocks (``perception.sheet``; ``sheet_note`` on the result says which part was
            taken, and how many plans it holds); False parses the whole drawing.
        even_lighting: a drawing lit unevenly (a photographed page) is divided by its paper's
            light first (``perception.lighting``); False reads it as it comes.
        faint_lines: a drawing whose ink closes no outline is read again with its faint strokes
            as ink (``binarize(faint=True)``: light hairlines saved as JPEG or shrunk); False
            refuses it.
        floor_textures: floors painted with a texture (planks, tiles, grain) are made plain
            fills first (``perception.floor_textures``); False reads them as drawn.
        paper_grid: a drawing on squared paper has the paper's printed grid painted out first
            (``perception.paper_grid``); False reads the grid as lines.
        enlarge_small: a drawing under ``SMALL_DRAWING_PX`` on its longer side (a listing's
            thumbnail) is parsed enlarged and the parse brought back onto its own grid
            (``perception.small_drawings``); False parses it at its own size.
        shrink_fine: a plan over ``FINE_PLAN_PX`` long on the sheet (a fine scan, a large
            export) is parsed shrunk and the parse brought back onto its own grid
            (``perception.fine_drawings``); False parses it at its own size.
        progress: called with the name of each step as it starts (``core.progress.Progress``).

    Raises:
        InputError: bad image, no enclosed regions (checked before the network runs), missing or
            corrupt segmenter weights, or a segmenter returning labels of the wrong shape.
    """
    step = progress or (lambda name: None)
    step("preparing the drawing")
    grey = as_grey(np.asarray(image))
    check_drawing(grey)
    prepared = []  # what was done to the drawing before it was read, as run reports it
    factor = enlargement(grey.shape) if enlarge_small else 1
    if factor > 1:
        height, width = grey.shape
        prepared.append(f"a small drawing ({width}x{height} px): parsed enlarged {factor} times")
        grey = enlarged(grey, factor)
    if even_lighting:
        lit = evenly_lit(grey)
        if lit is not grey:
            prepared.append("lit unevenly: divided by its paper's light")
        grey = lit
    if paper_grid:
        plain = without_paper_grid(grey)
        if plain is not grey:
            prepared.append("drawn on squared or ruled paper: its printed lines painted out")
        grey = plain
    if floor_textures:
        plain = without_floor_textures(grey)
        if plain is not grey:
            prepared.append("floors drawn with a texture (planks, tiles): read as plain fills")
        grey = plain
    if metres_per_px is not None and not (np.isfinite(metres_per_px) and metres_per_px > 0):
        raise InputError(f"metres_per_px must be a positive number, got {metres_per_px}")
    if metres_per_px is not None:
        metres_per_px /= factor
    drawing, faint = grey, False
    grey, lines, plan = _plan_lines(drawing, leave_out_sheet, faint=False)
    enclosed = has_enclosed_region(lines)
    if faint_lines and not enclosed:  # lines far lighter than the text?
        prepared.append("no closed outline at the default ink cut: faint strokes read as ink")
        faint = True
    elif faint_lines and drawn_in_light_lines(on_white_paper(grey, lines)):
        prepared.append("drawn in light lines: faint strokes read as ink")
        faint = True
    if faint:
        grey, lines, plan = _plan_lines(drawing, leave_out_sheet, faint=True)
        enclosed = has_enclosed_region(lines)
    if not enclosed:
        raise InputError("no enclosed regions found: the drawing has no closed outlines")
    if reader is not None:
        step("reading the words")
    texts = reader(dark_on_light(grey)) if reader is not None else []
    drawing_shape = grey.shape
    shrink = 1.0
    if shrink_fine and factor == 1:
        shrink = reduction(lines, plan.box if plan is not None else content_box(lines))
    if shrink > 1:
        height, width = grey.shape
        prepared.append(f"a fine drawing ({width}x{height} px): parsed shrunk {shrink:.2f} times")
        grey = shrunk(grey, shrink)
        lines = binarize(grey, faint=faint)
        texts = [text.scaled(shrink) for text in texts]
        if metres_per_px is not None:
            metres_per_px *= shrink
    grey, lines = without_text(grey, lines, texts)
    if segmenter is None:
        from f2n_drake.segmenter.inference import Segmenter

        segmenter = Segmenter.load()
    predict = partial(predict_labels, segmenter)
    if factor > 1:  # the network reads the drawing at its own size
        predict = read_at_drawing_size(predict, factor)
    step("segmenting the drawing")
    segmentation = segment_drawing(grey, lines, predict, texts)
    step("closing rooms at their doorways, voting their classes")
    grid = PixelGrid.from_scale(metres_per_px, grey.shape) if metres_per_px else None
    steps = parse_steps(
        grey,
        segmentation,
        lines=lines,
        grid=grid,
        split=split,
        front_doors=front_doors,
        kitchens=kitchens,
        sealed_rooms=sealed_rooms,
        balconies=balconies,
        connector_sizes=connector_sizes,
    )
    parsed = steps[PARSE_STEPS[-1]]
    if not parsed.instances:
        raise InputError("no enclosed regions found: every closed region was classed as background")
    parsed = on_drawing_grid(parsed, factor)
    if shrink > 1:
        parsed = on_fine_drawing_grid(parsed, drawing_shape)
    if plan is not None and (plan.left_out or plan.plans > 1):
        plan = dataclasses.replace(plan, box=tuple(side // factor for side in plan.box))
        parsed = dataclasses.replace(parsed, sheet_note=plan.describe(), plans=plan.plans)
    for note in prepared:
        log.info(note)
    log.info("parsed %d instances", len(parsed.instances))
    return dataclasses.replace(parsed, drawing_notes=tuple(prepared))


def _plan_lines(
    grey: np.ndarray, leave_out_sheet: bool, faint: bool
) -> tuple[np.ndarray, np.ndarray, PlanOnSheet | None]:
    """The drawing with only its plan kept (``perception.sheet``), its ink (``binarize``, read
    ``faint`` or not), and what was left out."""
    lines = binarize(grey, faint=faint)
    if not leave_out_sheet:
        return grey, lines, None
    grey, plan = only_the_plan(grey, lines)
    if plan.left_out:
        lines = binarize(grey, faint=faint)
    return grey, lines, plan


@dataclass(frozen=True)
class PlanMap:
    """A parsed plan at planning resolution and its connectivity graph: what routes are planned
    on and driven in.

    Attributes:
        parsed: the plan the graph was built from (``mapping.resolution``), with a metric grid
            for planning and simulation.
        graph: its connectivity graph (schema in ``f2n_drake.mapping.graph``).
    """

    parsed: ParsedPlan
    graph: nx.Graph

    def occupancy(self, robot: str | Path | RobotProfile = "ground") -> np.ndarray:
        """(H, W) bool, read-only: the free-space map of ``robot`` on ``parsed``
        (``mapping.occupancy.occupancy_map``), built once per plan and robot classes."""
        return occupancy_map(self.parsed, load_profile(robot).traversable)

    def walls(self, robot: str | Path | RobotProfile = "ground") -> PlanGeometry:
        """Walls and floors [m] cut from ``occupancy(robot)``: the simulated world."""
        return PlanGeometry.from_parsed(self.parsed, self.occupancy(robot))


def build_graph(parsed: ParsedPlan, *, planning_cell_m: float | None = PLANNING_CELL_M) -> PlanMap:
    """The connectivity graph of a parsed plan, on the plan coarsened to cells of at most
    ``planning_cell_m`` [m] (None: on the plan's own raster), as routes are planned.

    Rooms and connectors are nodes, joined where a connector's dilated mask touches a space
    (``mapping.graph.build_connectivity_graph``). A plan parsed without a scale gets one from
    its door widths first (``perception.scale.resolve_scale``).

    Raises:
        InputError: no scale, and no door to estimate one from.
    """
    parsed = resolve_scale(parsed)
    if planning_cell_m is not None:
        parsed = at_planning_resolution(parsed, planning_cell_m)
    return PlanMap(parsed, build_connectivity_graph(parsed))


def route_ends(
    plan_map: PlanMap,
    profile: RobotProfile,
    start: Place | None = None,
    goal: Place | None = None,
) -> tuple[Place, list[Place]]:
    """``start`` resolved to a node key or (x, y) [m] (a class name becomes its first instance;
    by default the front door, else the largest room), and the goals to try in turn: ``goal``
    resolved the same way, or by default the rooms farthest from the start through the graph,
    farthest first (``GOAL_TRIES`` of ``planning.endpoints.goal_candidates``: the graph may join
    a room through a doorway too narrow for the robot, or one it cannot cross). Raises
    InputError for an unknown name."""
    graph = plan_map.graph
    if start is None:
        start = default_start(graph, profile)
    if isinstance(start, str):
        start = resolve_node(graph, start)
    if goal is None:
        return start, goal_candidates(graph, profile, start)[:GOAL_TRIES]
    return start, [resolve_node(graph, goal) if isinstance(goal, str) else goal]


def plan_route(
    plan_map: PlanMap,
    *,
    robot: str | Path | RobotProfile = "ground",
    start: Place | None = None,
    goal: Place | None = None,
) -> Route:
    """A hierarchical route for ``robot`` from ``start`` to ``goal``, smoothed.

    Args:
        plan_map: ``build_graph``'s result.
        robot: "ground", "uav", a robot YAML file or a ``RobotProfile``.
        start, goal: node keys, class names or (x, y) [m]; defaults as ``route_ends`` (with no
            goal given, the first of its goals a route reaches).

    Raises:
        InputError: unknown robot or place. PlanningError: no route for this robot.
    """
    profile = load_profile(robot)
    start, goals = route_ends(plan_map, profile, start, goal)
    planner = HierarchicalPlanner(plan_map.parsed, plan_map.graph, profile)
    failure = None
    for candidate in goals:
        try:
            return planner.plan(start, candidate)
        except PlanningError as exc:
            failure = failure or exc
    raise failure


Correction = Literal["paper", "continuous", "off"]


def simulate(
    plan: PlanMap | FloorPlan | ParsedPlan | PlanGeometry,
    route: Route | np.ndarray,
    *,
    correction: Correction = "continuous",
    seed: int = 0,
    meshcat: Meshcat | None = None,
    html_path: str | Path | None = None,
    replan: bool = False,
    **options,
) -> NavigationResult:
    """Drive ``route`` with the simulated TurtleBot3 Burger in Drake until it is done, collides
    or runs out of time (``f2n_drake.systems.simulation.simulate_navigation``).

    Args:
        plan: a ``PlanMap`` or a ``ParsedPlan`` with a scale (walls cut from the ground robot's
            occupancy map), a ground-truth ``FloorPlan`` (its wall polygons) or the walls
            themselves (``PlanGeometry``).
        route: ``plan_route``'s result or (N, 2) waypoints [m].
        correction: LiDAR drift correction: "paper", "continuous" or "off".
        seed: odometry and LiDAR noise seed.
        meshcat: show the run live; ``html_path``: save a self-contained replay there.
        replan: avoid what the LiDAR sees and the plan lacks, and replan past closed doors
            (``planning.replanning.Replanner`` built from the ``PlanMap`` for the ground robot;
            needs a ``PlanMap``); the run also ends when no route is left
            (``NavigationResult.message`` says why).
        options: further keyword arguments of ``simulate_navigation`` (time limit, odometry
            noise, start pose, goal tolerance, waypoint spacing, the ``building``, a
            ``replanner``, ``unknown_start``: localize on the plan first).
    """
    from f2n_drake.systems.simulation import simulate_navigation

    if replan and "replanner" not in options:
        if not isinstance(plan, PlanMap):
            raise InputError(f"replanning needs a PlanMap, got a {type(plan).__name__}")
        options["replanner"] = Replanner.from_plan(plan.parsed, plan.graph, "ground")

    world = plan.walls() if isinstance(plan, PlanMap) else plan
    return simulate_navigation(
        world,
        route,
        correction=correction,
        seed=seed,
        meshcat=meshcat,
        html_path=html_path,
        **options,
    )
