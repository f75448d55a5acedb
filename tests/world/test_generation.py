"""make_building on a two-room plan: furniture share, start-goal kept joined, closed doors,
displaced walls, people's walks."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from shapely.geometry import Point

from f2n_drake.core.errors import InputError
from f2n_drake.world.building import Building
from f2n_drake.world.free_space import FloorRaster, same_component
from f2n_drake.world.furniture import MIN_PIECE_AREA_M2
from f2n_drake.world.generation import END_CLEARANCE_M, make_building
from f2n_drake.world.options import WorldOptions
from f2n_drake.world.walkers import WALKING_SPEED_MPS, position_on_walk

ROBOT_RADIUS_M = 0.105


def pieces(building: Building) -> list:
    return [*building.furniture, *(c.footprint() for c in building.cylinders)]


def build(plan_and_graph, route, seed=0, **options) -> Building:
    plan, graph = plan_and_graph
    return make_building(plan, graph, route, WorldOptions(**options), np.random.default_rng(seed))


@pytest.mark.parametrize("fraction", [0.1, 0.2])
def test_furniture_covers_the_fraction_of_each_room(plan_and_graph, route, fraction):
    plan, _ = plan_and_graph
    building = build(plan_and_graph, route, clutter_fraction=fraction)
    assert building.furniture and building.cylinders  # boxes and round pieces
    for _, room in plan.floors:
        covered = sum(p.intersection(room).area for p in pieces(building))
        assert fraction * room.area - 2 * MIN_PIECE_AREA_M2 <= covered
        assert covered <= fraction * room.area + 1e-9


def test_furniture_is_reproducible_and_seeded(plan_and_graph, route):
    a, b = (build(plan_and_graph, route, seed=3, clutter_fraction=0.15) for _ in range(2))
    assert [p.wkt for p in a.furniture] == [p.wkt for p in b.furniture]
    assert a.cylinders == b.cylinders
    other = build(plan_and_graph, route, seed=4, clutter_fraction=0.15)
    assert [p.wkt for p in a.furniture] != [p.wkt for p in other.furniture]


@pytest.mark.parametrize("seed", range(6))
def test_furniture_never_blocks_the_way_or_the_doorway(plan_and_graph, route, seed):
    plan, graph = plan_and_graph
    building = build(plan_and_graph, route, seed=seed, clutter_fraction=0.35)
    start, goal = route.waypoints_m[0], route.waypoints_m[-1]
    door = graph.nodes[route.sequence[1]]["polygon_m"]
    for piece in pieces(building):
        assert piece.distance(Point(*start)) >= END_CLEARANCE_M - 1e-9
        assert piece.distance(Point(*goal)) >= END_CLEARANCE_M - 1e-9
        assert piece.distance(door) > 0.4
        assert shapely.union_all(plan.walls).distance(piece) > 0.01
    raster = FloorRaster.covering(plan.bounds(), cell_m=0.05)
    obstacles = shapely.union_all([*building.walls, *pieces(building)])
    inside = raster.cover(shapely.union_all([room for _, room in plan.floors] + [door]))
    free = ~raster.blocked_by(obstacles, ROBOT_RADIUS_M) & inside
    assert same_component(free, raster.cell_of(start), raster.cell_of(goal))


def test_the_routes_door_is_closed_first_and_recorded(plan_and_graph, route):
    _, graph = plan_and_graph
    building = build(plan_and_graph, route, closed_doors=1)
    door = route.sequence[1]
    assert building.closed_doors == (door,)
    (wall,) = building.door_walls
    assert wall in building.walls
    doorway = graph.nodes[door]["polygon_m"]
    assert wall.contains(doorway.buffer(-0.01)) and wall.area > doorway.area  # overlaps jambs


def test_displaced_walls_stay_within_the_deviation(plan_and_graph, route):
    plan, _ = plan_and_graph
    deviation = 0.1
    building = build(plan_and_graph, route, deviation_m=deviation)
    planned, built = shapely.union_all(plan.walls), shapely.union_all(building.walls)
    distance = planned.hausdorff_distance(built)
    assert 0.01 < distance <= deviation * np.sqrt(2) + 1e-9  # moved, and not far
    assert abs(built.area - planned.area) < 0.1 * planned.area
    assert built.is_valid and len(getattr(built, "geoms", [built])) == 1  # no gap opened


def test_people_walk_between_rooms_through_free_space(plan_and_graph, route):
    building = build(plan_and_graph, route, clutter_fraction=0.1, people=2)
    assert len(building.people) == 2
    obstacles = shapely.union_all([*building.walls, *pieces(building)])
    start = route.waypoints_m[0]
    for person in building.people:
        assert WALKING_SPEED_MPS[0] <= person.speed_mps <= WALKING_SPEED_MPS[1]
        walk = shapely.LineString(person.path_m)
        assert walk.distance(obstacles) >= person.radius_m
        ends = [Point(*person.path_m[0]), Point(*person.path_m[-1])]
        assert {bool(p.x < 3.1) for p in ends} == {True, False}  # one end in each room
        at = position_on_walk(person.path_m, [person.offset_m])[0]
        assert np.hypot(*(at - start)) > 1.0


def test_plain_options_give_the_plan_and_doors_need_a_graph(plan_and_graph, route):
    plan, _ = plan_and_graph
    building = make_building(plan, None, route, WorldOptions(), np.random.default_rng(0))
    assert building == Building.as_planned(plan)
    with pytest.raises(InputError, match="graph"):
        make_building(plan, None, route, WorldOptions(closed_doors=1), np.random.default_rng(0))


@pytest.mark.parametrize(
    "options",
    [
        {"clutter_fraction": -0.1},
        {"clutter_fraction": 0.9},
        {"people": -1},
        {"people": 1.5},
        {"closed_doors": True},
        {"deviation_m": float("nan")},
        {"deviation_m": 1.0},
    ],
)
def test_world_options_are_validated(options):
    with pytest.raises(InputError):
        WorldOptions(**options)
