"""Goods that several robots drop into one workspace get a slot each; a reason when there is no room."""

from __future__ import annotations

from pathlib import Path

import yaml

from cosmop.missions.mission import GlobalMission
from cosmop.planning.specification import ObstaclePart, corner_clearance_key, wall_key
from cosmop.planning.synthesis import _as_written
from cosmop.scenario import load_scenario, parse_scenario
from cosmop.scene import Wall
from cosmop.sim import footprint_overlaps, simulate
from cosmop.team.aside import dock_slots
from cosmop.team.loop import plan_team

DOCK = Path(__file__).parent / "data" / "shared_dock.yaml"


def _drops(plans):
    return {
        s.object: s.objects[s.object].position
        for p in plans.robots.values()
        for s in p.steps
        if s.primitive == "DropOff"
    }


def test_goods_for_one_dock_are_packed_into_slots_a_robot_can_dock_to():
    scenario = load_scenario(DOCK)
    packing = dock_slots(scenario.scene, "W1", {"O1": "R1", "O2": "R2", "O3": "R3"})
    assert packing.left_out == () and len(packing.slots) == 3
    squares = [(x - 100, y - 100, x + 100, y + 100) for _, (x, y) in packing.slots]
    for i, a in enumerate(squares):
        assert scenario.scene.workspaces["W1"].holds((a[0] + a[2]) / 2, (a[1] + a[3]) / 2, 200)
        for b in squares[i + 1 :]:  # side by side: they may touch, never overlap
            assert a[2] <= b[0] or b[2] <= a[0] or a[3] <= b[1] or b[3] <= a[1]


def test_a_shared_dock_is_planned_and_executed():
    scenario = load_scenario(DOCK)
    result = plan_team(scenario, workers=1)
    assert result.plans.feasible, result.plans.reason
    assert result.report.ok
    dropped = _drops(result.plans)
    assert len(set(dropped.values())) == 3
    run = simulate(scenario, result.plans)
    assert run.completed and run.contacts_while_moving == 0
    assert GlobalMission.from_scenario(scenario).is_complete_word(run.executed_word())
    assert not footprint_overlaps(scenario.scene, run)


def test_a_dock_without_room_says_how_many_goods_it_holds():
    data = yaml.safe_load(DOCK.read_text())
    # a 500 mm bay: a 400 mm robot docks one 200 mm good from the front, and has no room
    # beside a good inside the bay to dock another
    data["scene"]["workspaces"]["W1"] = {"x": [-250, 250], "y": [1650, 1950]}
    data["scene"]["obstacles"][-2:] = [[[-250, 1600], [-250, 2000]], [[250, 1600], [250, 2000]]]
    scenario = parse_scenario(data)
    result = plan_team(scenario, workers=1)
    assert not result.plans.feasible
    assert "W1 holds 1 of the 3 goods dropped there" in result.plans.reason


def test_reasons_name_walls_the_planner_adds_by_what_they_keep_out():
    scenario = load_scenario(DOCK)
    walls = scenario.scene.obstacles
    n = len(walls)
    added = (Wall((0, 0), (1, 0), "the space of R2 standing at (0, 0)"),)
    scene = type(scenario.scene)(walls + added, scenario.scene.robots, scenario.scene.objects)
    parts = (
        ObstaclePart(wall_key(n), wall_key(n).text, after=" [[0.0, 0.0], [1.0, 0.0]]"),
        ObstaclePart(
            corner_clearance_key(wall_key(n)), f"wall {n} past its ends", after=" [[0.0, 0.0], [1.0, 0.0]]"
        ),
        ObstaclePart(wall_key(n, handling=True), wall_key(n).text, "gripper clear of "),
        ObstaclePart(wall_key(1, handling=True), wall_key(1).text, "gripper clear of "),
    )
    assert [part.text for part in parts] == [
        f"wall {n} [[0.0, 0.0], [1.0, 0.0]]",
        f"wall {n} past its ends [[0.0, 0.0], [1.0, 0.0]]",
        f"gripper clear of wall {n}",
        "gripper clear of wall 1",
    ]
    space = "the space of R2 standing at (0, 0)"
    named = _as_written(scene, parts)
    assert named == (space, f"{space} past its ends", f"gripper clear of {space}", "gripper clear of wall 1")
