"""Goods that block a robot and that no mission moves get a helper that sets them aside.

A crate C9 stands in the door between two rooms; it can be handled from its east side only
(from the right-hand room).  R1, in the left room, must fetch O1 from the right room: it asks
for C9 to be moved away.  No mission moves C9 and R1 cannot reach its east side, so R2, in the
right room, gets the added task, answers R1's request, and the plan file says so.  With both
robots in the left room nobody can set C9 aside: the plan is infeasible and says why, per robot.
"""

from __future__ import annotations

import pytest
from shapely import LineString

from cosmop.events import parse_event
from cosmop.planning.plan_file import PlanError, load_plan, read_plan
from cosmop.planning.plan_types import AddedTask, PlanSet
from cosmop.planning.primitive_effects import plan_from_actions
from cosmop.scenario import parse_scenario
from cosmop.sim.simulation import simulate
from cosmop.squares import square, swept_square
from cosmop.team.aside import ROOM, place_aside
from cosmop.team.loop import plan_team
from cosmop.team.plan_set_checker import check_plan
from cosmop.team.requests import _with_task
from rooms import box_walls


def _door(r2_pose):
    return parse_scenario(
        {
            "name": "crate-in-door",
            "scene": {
                "obstacles": [
                    *box_walls(-2000, -1000, 2000, 1000),
                    [[0, -1000], [0, -300]],  # the dividing wall and its 600 mm door
                    [[0, 300], [0, 1000]],
                ],
                "robots": {"R1": {"size": 400, "pose": [-1500, 0, 0]}, "R2": {"size": 400, "pose": r2_pose}},
                "objects": {
                    "C9": {"size": 300, "position": [0, 0], "sides": ["east"]},
                    "O1": {"size": 100, "position": [1500, 300]},
                },
                "workspaces": {"W1": {"x": [-1900, -1300], "y": [400, 900]}},
            },
            "mission": {"tasks": {"R1": ["pick O1", "drop O1 at W1"]}},
        }
    )


@pytest.fixture(scope="module")
def helped():
    scenario = _door([1500, -600, 0])
    return scenario, plan_team(scenario, max_horizon=8, workers=1)


def test_a_robot_that_can_reach_the_crate_sets_it_aside_and_tells_the_requester(helped):
    scenario, result = helped
    plans = result.plans
    assert plans.feasible and check_plan(scenario, plans).ok
    (task,) = plans.added
    assert (task.robot, task.object, task.workspace) == ("R2", "C9", "aside_C9")
    assert "R1 needs C9 moved out of its way" in task.why and "tells R1" in task.why
    assert [e.name for e in plans.robots["R2"].mission[:1]] == ["pick(R2,C9)"]
    assert "drop(R2,C9,aside_C9)" in [e.name for e in plans.robots["R2"].mission]
    assert [(c.object, c.requester, c.responder) for c in plans.coordination] == [("C9", "R1", "R2")]
    # the place is in the right-hand room, clear of the door and of the walls by the room kept
    x, y = task.point
    assert x - 150 >= 40 and not (-300 - 150 - 40 < y < 300 + 150 + 40 and x - 150 < 40 + 400)


def test_the_simulator_executes_the_added_task(helped):
    scenario, result = helped
    run = simulate(scenario, result.plans)
    assert run.completed and run.contacts_while_moving == 0
    assert all(run.objects_in_workspaces(scenario, result.plans).values())
    (x, y), _ = run.objects["C9"]
    assert (x, y) == pytest.approx(result.plans.added[0].point)
    assert "pick(R2,C9)" not in run.executed_word() and "pick(R1,O1)" in run.executed_word()


def test_the_plan_file_keeps_the_added_task_and_the_checker_needs_it(helped, tmp_path):
    scenario, result = helped
    path = tmp_path / "plan.json"
    result.plans.save(path)
    loaded = load_plan(path)
    assert loaded.added == result.plans.added
    without = PlanSet(loaded.scenario, True, loaded.robots, loaded.coordination, None, loaded.messages)
    rules = {v.rule for v in check_plan(scenario, without).violations}
    assert "mission" in rules  # unknown place aside_C9 and events no task names
    clash = AddedTask("R2", "C9", "W1", (300, -600), "reuses a workspace id")
    report = check_plan(
        scenario, PlanSet(loaded.scenario, True, loaded.robots, loaded.coordination, added=(clash,))
    )
    assert any("has a workspace W1 already" in v.message for v in report.violations)
    with pytest.raises(PlanError, match=r"added\[0\]\.point"):
        read_plan({**result.plans.to_dict(), "added": [{**clash.to_dict(), "point": [1]}]})


def test_when_no_robot_can_set_it_aside_the_reason_names_the_goods_and_each_robot_tried():
    result = plan_team(_door([-1500, -600, 0]), max_horizon=8, workers=1)
    assert not result.plans.feasible
    reason = result.plans.reason
    assert reason.startswith("R1 needs C9 moved away, but no mission moves it and no robot can set it aside")
    assert "R1: cannot move it" in reason and "R2: cannot move it" in reason
    assert "sides of C9 tried: east" in reason


def test_the_helper_never_takes_goods_while_it_carries_others():
    events = tuple(parse_event(e) for e in ("pick(R1,O1)", "drop(R1,O1,W1)", "pick(R1,O2)", "drop(R1,O2,W2)"))
    task = AddedTask("R1", "C9", "aside_C9", (0, 0), "test")
    names = [e.name for e in _with_task(events, task, 3)]  # the request prepared drop(R1,O2,W2)
    assert names == [
        "pick(R1,O1)",
        "drop(R1,O1,W1)",
        "pick(R1,C9)",
        "drop(R1,C9,aside_C9)",
        "pick(R1,O2)",
        "drop(R1,O2,W2)",
    ]
    assert [e.name for e in _with_task(events, task, 2)][2:4] == ["pick(R1,C9)", "drop(R1,C9,aside_C9)"]


def test_the_place_aside_keeps_room_and_can_be_docked_at():
    scenario = _door([1500, -600, 0])
    scene = scenario.scene
    through = plan_from_actions(scene, "R1", [], [("GoTo", (1200, 0, 0))])  # R1 drives through the door
    x, y = place_aside(scene, "C9", "R2", {"R1": through})
    grown = square(x, y, 300 + 2 * ROOM)
    assert not any(grown.intersects(LineString([w.start, w.end])) for w in scene.obstacles)
    assert not grown.intersects(square(1500, 300, 100 + 2 * 400))  # O1 stays dockable on every side
    assert not grown.intersects(swept_square((-1500, 0), (1200, 0), 400))  # off R1's route
    assert abs(x) + abs(y) <= 1000  # and near where the crate was
    # a small room whose floor other goods (each kept dockable) leave no room on: no place at all
    goods = {f"G{k}": {"size": 100, "position": [600 * (k % 3 - 1), 600 * (k // 3 - 1)]} for k in range(9)}
    goods["C9"] = {"size": 300, "position": goods.pop("G4")["position"]}
    crowded = parse_scenario(
        {
            "name": "crowded",
            "scene": {
                "obstacles": box_walls(-800, -800, 800, 800),
                "robots": {"R1": {"size": 400, "pose": [-350, -350, 0]}},
                "objects": goods,
                "workspaces": {},
            },
            "mission": {"tasks": {"R1": ["return"]}},
        }
    )
    assert place_aside(crowded.scene, "C9", "R1", {}) is None
