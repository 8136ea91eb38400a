"""Lazy geometry gives the eager encoding's shortest horizon and fewest requests.

`synthesize(lazy=True)` starts the solver with the obstacles near the robot's route and adds
those a plan breaks (:mod:`cosmop.planning.obstacles`).  Each case is solved both ways and
must agree on feasibility, the horizon K and the number of requests (the objects requested
too where the minimum is unique in practice), and the lazy plan must pass the exact checker.
The generated scenes are shelf rooms with goods against shelf faces, some boxed in so that a
request is needed; "nothing near" holds back every obstacle at the start, so that every wall
the plan needs is found by the loop.
"""

from __future__ import annotations

import random
from pathlib import Path

import pytest

from cosmop.automata import DFA
from cosmop.planning import obstacles
from cosmop.planning.checker import check_robot_plan
from cosmop.planning.obstacles import obstacle_of
from cosmop.planning.plan import State
from cosmop.planning.synthesis import synthesize
from cosmop.scenario import load_scenario, parse_scenario
from rooms import box_walls, branching_words, room

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = [
    "01_warehouse_2x2",
    "02_warehouse_10x10",
    "04_doorway_2x2",
    "07_corridor",
    "09_blocked_bay",
    "10_grid_map",
]
FETCH = ("pick(R1,O1)", "drop(R1,O1,W1)", "return(R1)")


def shelves(seed: int) -> dict:
    """A 12 m x 6 m room with shelf blocks in a 4 x 2 grid of bays; one robot fetches a good
    lying against a shelf face (boxed in by other goods one time in three, so that it needs a
    request) and brings it to a
    dock across the room."""
    rng = random.Random(seed)
    walls = box_walls(0, 0, 12000, 6000)
    bays = [(bx, by) for bx in range(4) for by in range(2)]
    rng.shuffle(bays)
    for bx, by in bays[:5]:  # a shelf block of 1 m x 1.6 m in five of the eight bays
        x0, y0 = 3000 * bx + 1000, 3000 * by + 700
        walls += box_walls(x0, y0, x0 + 1000, y0 + 1600)
    shelf = bays[0]
    x0, y0 = 3000 * shelf[0] + 1000, 3000 * shelf[1] + 700
    gy = y0 + 350 + 100 * rng.randrange(0, 10)
    objects = {"O1": {"size": 100, "position": [x0 + 1050, gy]}}  # against the block's east face
    if seed % 3 == 0:  # goods above and below leave no room there; the one in front must go
        objects |= {
            "O2": {"size": 100, "position": [x0 + 1050, gy + 300]},
            "O3": {"size": 100, "position": [x0 + 1050, gy - 300]},
            "O4": {"size": 100, "position": [x0 + 1150, gy]},
        }
    free = bays[5:]
    (rx, ry), (dx, dy) = free[0], free[-1]
    robot = [3000 * rx + 1500, 3000 * ry + 1500, rng.choice([0, 90, 180, 270])]
    dock = {"x": [3000 * dx + 1000, 3000 * dx + 2000], "y": [3000 * dy + 1000, 3000 * dy + 2000]}
    return {
        "name": f"shelves-{seed}",
        "scene": {
            "obstacles": walls,
            "robots": {"R1": {"size": 400, "pose": robot}},
            "objects": objects,
            "workspaces": {"W1": dock},
        },
        "mission": {"tasks": {"R1": ["pick O1", "drop O1 at W1", "return"]}},
    }


def _agree(scene, robot, mission, **options) -> tuple:
    lazy = synthesize(scene, robot, mission, lazy=True, **options)
    eager = synthesize(scene, robot, mission, lazy=False, **options)
    assert (lazy.feasible, lazy.horizon, len(lazy.requests)) == (
        eager.feasible,
        eager.horizon,
        len(eager.requests),
    )
    assert sorted(lazy.requests) == sorted(eager.requests)
    if lazy.feasible:
        assert check_robot_plan(scene, robot, lazy.plan, options.get("start")) == []
    return lazy, eager


@pytest.mark.parametrize("name", EXAMPLES)
def test_the_examples_get_the_same_horizons_and_requests(name):
    scenario = load_scenario(ROOT / "examples" / name / "scenario.yaml")
    for robot, tasks in scenario.mission.tasks.items():
        _agree(scenario.scene, robot, tasks, max_horizon=12)


@pytest.fixture(params=["box", "nothing near"])
def start(request, monkeypatch):
    if request.param == "nothing near":
        monkeypatch.setattr(obstacles, "_near_route", lambda p: set())
    return request.param


def test_thirty_generated_shelf_rooms_agree(start):
    """Fifteen rooms each way (thirty in all; ``benchmarks/sweep_lazy.py`` runs more)."""
    admitted, requested, feasible = 0, 0, 0
    for seed in range(15) if start == "box" else range(15, 30):
        scene = parse_scenario(shelves(seed)).scene
        lazy, _ = _agree(scene, "R1", FETCH, max_horizon=12)
        feasible += lazy.feasible
        admitted += lazy.admitted
        requested += bool(lazy.requests)
    assert feasible >= 12 and requested >= 2  # some rooms need a request: the minimum is compared too
    if start == "nothing near":
        assert admitted >= 15  # every wall the plans need was found by the loop


def test_a_branching_mission_gets_the_same_horizon(start):
    scene = parse_scenario(room(5)).scene
    _agree(scene, "R1", DFA.from_words(branching_words()), max_horizon=20)


def test_a_replan_from_a_state_mid_run_gets_the_same_horizon(start):
    scenario = load_scenario(ROOT / "examples" / "10_grid_map" / "scenario.yaml")
    first = synthesize(scenario.scene, "R1", scenario.mission.tasks["R1"])
    k = next(k for k, step in enumerate(first.plan.steps) if step.primitive == "PickUp")
    picked = first.plan.steps[k]  # where the robot stands once it holds its good, as a replan sees it
    middle = State(picked.robot, picked.objects)
    _agree(scenario.scene, "R1", scenario.mission.tasks["R1"][1:], start=middle)


def test_a_horizon_too_short_is_infeasible_both_ways(start):
    scene = parse_scenario(shelves(0)).scene
    lazy, eager = _agree(scene, "R1", FETCH, max_horizon=3)
    assert not lazy.feasible and lazy.reason == eager.reason


def test_parts_are_named_after_their_obstacle():
    assert obstacle_of("wall 12 [[0, 0], [1, 0]]") == "wall 12"
    assert obstacle_of("gripper clear of wall 4") == "wall 4"
    assert obstacle_of("O1 dropped clear of wall 0") == "wall 0"
    assert obstacle_of("object O7") == "object O7"
    assert obstacle_of("room from O2 while handling O1") == "object O2"
    assert obstacle_of("O1 dropped clear of O2") == "object O2"
    assert obstacle_of("Req O2") is None and obstacle_of("mission") is None
