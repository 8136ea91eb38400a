"""The fast unreachability test: sound (never refuses what the solver can plan) and useful."""

from __future__ import annotations

import itertools
import math
import random
from dataclasses import replace

import pytest
import shapely

import cosmop.planning.synthesis as synthesis_module
from cosmop.errors import ScenarioError
from cosmop.events import Event
from cosmop.planning.checker import check_robot_plan
from cosmop.planning.reach import event_place, least_drives, least_route, unreachable
from cosmop.planning.specification import MOTION_MARGIN
from cosmop.planning.synthesis import synthesize
from cosmop.scenario import load_scenario, parse_scenario
from cosmop.scene import Wall

ROOM = [
    [[-3000, -2000], [3000, -2000]],
    [[3000, -2000], [3000, 2000]],
    [[3000, 2000], [-3000, 2000]],
    [[-3000, 2000], [-3000, -2000]],
]


def _scene(walls, robot=(-2000, 0), obj=(2000, 0)):
    return parse_scenario(
        {
            "name": "reach",
            "scene": {
                "obstacles": ROOM + walls,
                "robots": {"R1": {"size": 400, "pose": [*robot, 0]}},
                "objects": {"O1": {"size": 200, "position": list(obj)}},
                "workspaces": {"W1": {"x": [-2800, -2200], "y": [1000, 1800]}},
            },
            "mission": {"tasks": {"R1": ["return"]}},
        }
    ).scene


PICK = (Event("pick", "R1", obj="O1"), Event("drop", "R1", obj="O1", workspace="W1"), Event("return", "R1"))


def _random_shelves(rng):
    """The room with one to three random shelves and the goods somewhere, or None when a shelf
    runs through the goods or the robot."""
    walls = []
    for _ in range(rng.randint(1, 3)):
        x = rng.randrange(-2000, 2001, 250)
        y0 = rng.choice([-2000, rng.randrange(-1500, 0, 250)])
        walls.append([[x, y0], [x, rng.choice([2000, rng.randrange(0, 1500, 250)])]])
    try:
        return _scene(walls, obj=(rng.randrange(-1000, 2500, 250), rng.randrange(-1500, 1500, 250)))
    except ScenarioError:
        return None


def test_a_wall_without_a_door_is_proved_at_once():
    scene = _scene([[[0, -2000], [0, 2000]]])
    why = unreachable(scene, "R1", PICK)
    assert why is not None and "pick(R1,O1)" in why and "walls separate" in why
    result = synthesize(scene, "R1", PICK, max_horizon=16)
    assert not result.feasible and result.reason == why and result.solve_s < 1.0


def test_a_door_exactly_one_robot_wide_stays_open():
    # touching both door posts is geometry the exact planner allows (margin 0) ...
    scene = _scene([[[0, -2000], [0, -200]], [[0, 200], [0, 2000]]])  # 400 mm door, 400 mm robot
    assert unreachable(scene, "R1", PICK) is None
    assert synthesize(scene, "R1", PICK, max_horizon=12, margin=0).feasible
    # ... but no controller drives through it: by default a motion keeps its margin between its ends
    assert not synthesize(scene, "R1", PICK, max_horizon=12).feasible


def test_a_door_with_the_margin_on_both_sides_is_planned():
    side = 400 + 2 * MOTION_MARGIN
    scene = _scene([[[0, -2000], [0, -side / 2]], [[0, side / 2], [0, 2000]]])
    result = synthesize(scene, "R1", PICK, max_horizon=12)
    assert result.feasible
    assert not check_robot_plan(scene, "R1", result.plan)


def test_a_drop_out_of_reach_is_named():
    # W1 lies in a closed box: the object could be picked but never dropped there
    scene = _scene(
        [[[-2900, 900], [-2100, 900]], [[-2100, 900], [-2100, 1900]], [[-2100, 1900], [-2900, 1900]]]
    )
    why = unreachable(scene, "R1", PICK)
    assert why is not None and "drop(R1,O1,W1)" in why and "event 2" in why


def test_every_example_mission_passes():
    from pathlib import Path

    from cosmop.missions.mission import GlobalMission

    for path in sorted((Path(__file__).resolve().parents[1] / "examples").glob("*/scenario*.yaml")):
        scenario = load_scenario(path)
        if scenario.mission is None:  # an order stream (examples/13_lifelong): no mission to test
            continue
        mission = GlobalMission.from_scenario(scenario)
        for robot in scenario.scene.robots:
            mine = [e for e in mission.events.values() if robot in e.owners and e.kind in ("pick", "drop")]
            if scenario.mission.form == "tasks":
                assert unreachable(scenario.scene, robot, mine) is None, (path, robot)


@pytest.mark.parametrize("seed", range(4))
def test_whatever_it_refuses_the_solver_cannot_plan(seed, monkeypatch):
    # random shelves; whenever the test says "unreachable", the solver alone finds no plan
    rng = random.Random(seed)
    found = 0
    for _ in range(40):
        scene = _random_shelves(rng)
        if scene is None:  # a shelf through the object or the robot: not a scene at all
            continue
        if unreachable(scene, "R1", PICK[:1]) is None:
            continue
        found += 1
        monkeypatch.setattr(synthesis_module, "unreachable", lambda *a, **k: None)
        assert not synthesize(scene, "R1", PICK[:1], max_horizon=5, explain=False).feasible
        monkeypatch.undo()
        if found == 2:
            break
    assert found >= 1


def _places(scene, events):
    return [event_place(scene, "R1", e) for e in events]


def test_least_drives_counts_the_turns_the_walls_force():
    open_room = _scene([])
    assert least_drives(open_room, "R1", _places(open_room, PICK)) == 3  # each place seen from the last
    # a shelf between the robot and the goods, open at the top: to the goods and back home, two each
    shelf = _scene([[[0, -2000], [0, 1000]]])
    assert least_drives(shelf, "R1", _places(shelf, PICK)) == 2 + 2 + 1
    assert least_drives(shelf, "R1", []) == 0  # nowhere to go
    assert least_drives(shelf, "R1", _places(shelf, PICK[2:])) == 0  # already home
    result = synthesize(shelf, "R1", PICK, max_horizon=12)
    assert result.feasible and result.horizon >= 2 + 5  # the pick and the drop, and five drives
    # goods picked again where the mission put them are not counted (their place is not known)
    again = (*PICK[:2], Event("pick", "R1", obj="O1"))
    assert synthesize(shelf, "R1", again, max_horizon=3, explain=False).checks > 0
    # a horizon shorter than that is refused by counting, without the solver
    short = synthesize(shelf, "R1", PICK, max_horizon=6)
    assert not short.feasible and short.checks == 0
    assert "needs at least 7 steps" in short.reason and "--max-horizon" in short.reason


@pytest.mark.parametrize("seed", range(3))
def test_the_counted_drives_never_exceed_a_plan(seed):
    # random shelves: every plan the solver finds drives at least as often as counted
    rng = random.Random(100 + seed)
    compared = 0
    while compared < 3:
        scene = _random_shelves(rng)
        if scene is None:  # a shelf through the object or the robot: not a scene at all
            continue
        result = synthesize(scene, "R1", PICK, max_horizon=9, explain=False)
        if not result.feasible:
            continue
        drives = sum(1 for step in result.plan.steps if step.primitive == "GoTo")
        assert least_drives(scene, "R1", _places(scene, PICK)) <= drives
        compared += 1


def test_a_way_round_far_outside_the_places_is_still_found():
    # a long shelf between the robot and the goods, open only far below both: the free space
    # near them does not join them, the whole map does
    room = [[[-3000, -9000], [3000, -9000]], [[3000, -9000], [3000, 2000]], [[-3000, -9000], [-3000, 2000]]]
    scene = parse_scenario(
        {
            "name": "reach",
            "scene": {
                "obstacles": [*ROOM[2:3], *room, [[0, -7500], [0, 2000]]],
                "robots": {"R1": {"size": 400, "pose": [-2000, 0, 0]}},
                "objects": {"O1": {"size": 200, "position": [2000, 0]}},
                "workspaces": {"W1": {"x": [-2800, -2200], "y": [1000, 1800]}},
            },
            "mission": {"tasks": {"R1": ["return"]}},
        }
    ).scene
    assert unreachable(scene, "R1", PICK) is None
    closed = replace(scene, obstacles=(*scene.obstacles, Wall((0.0, -9000.0), (0.0, -7500.0))))
    assert unreachable(closed, "R1", PICK) is not None


@pytest.mark.parametrize("seed", range(20))
def test_least_route_is_the_least_manhattan_length_through_boxes(seed):
    # brute force: on each axis an optimal route turns only at the boxes' edges or the start,
    # so trying every such coordinate for every place finds the least length
    rng = random.Random(seed)
    boxes = []
    for _ in range(rng.randint(1, 3)):
        place = []
        for _ in range(rng.randint(1, 3)):
            x, y = rng.uniform(-5000, 5000), rng.uniform(-5000, 5000)
            width, height = rng.choice([0, rng.uniform(0, 2000)]), rng.uniform(0, 2000)
            place.append(shapely.box(x, y, x + width, y + height))
        boxes.append(place)
    start = (rng.uniform(-5000, 5000), rng.uniform(-5000, 5000))
    places = [shapely.GeometryCollection(place) if len(place) > 1 else place[0] for place in boxes]
    best = math.inf
    for choice in itertools.product(*boxes):
        total = 0.0
        for axis in (0, 1):
            cuts = sorted({start[axis], *(c for b in choice for c in b.bounds[axis::2])})
            options = [[c for c in cuts if b.bounds[axis] <= c <= b.bounds[axis + 2]] for b in choice]
            total += min(
                sum(abs(q - p) for p, q in itertools.pairwise([start[axis], *zs]))
                for zs in itertools.product(*options)
            )
        best = min(best, total)
    assert least_route(places, start) == pytest.approx(best)
