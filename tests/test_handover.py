"""Relays: a robot picks goods where another robot has put them down, and the checker knows it."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest
import yaml

from cosmop.errors import ScenarioError
from cosmop.events import Primitive, parse_event
from cosmop.planning.plan_types import PlanMessage, PlanSet, RobotPlan, Step
from cosmop.planning.primitive_effects import plan_from_actions
from cosmop.planning.synthesis import synthesize
from cosmop.scenario import load_scenario, parse_scenario
from cosmop.team.handover import handovers
from cosmop.team.loop import plan_team
from cosmop.team.plan_set_checker import check_plan

RELAY = Path(__file__).resolve().parents[1] / "examples" / "12_relay" / "scenario.yaml"


def _words(text: dict[str, str]) -> dict[str, list]:
    return {r: [parse_event(e) for e in w.split()] for r, w in text.items()}


def test_a_drop_ordered_before_another_robots_pick_is_a_handover():
    relays = handovers(
        _words(
            {
                "R1": "pick(R1,O1) drop(R1,O1,H) msg(R1,R2,t) return(R1)",
                "R2": "msg(R1,R2,t) pick(R2,O1) drop(R2,O1,W) return(R2)",
            }
        )
    )
    (h,) = relays.items
    assert (h.giver, h.receiver, h.drop.name, h.nth) == ("R1", "R2", "drop(R1,O1,H)", 0)
    assert relays.refused == () and relays.unordered == ()
    assert relays.turns(("R2", "R1")) == ((("R1",), ()), (("R2",), ()))


def test_goods_met_again_after_another_robot_moved_them_are_refused():
    relays = handovers(
        _words(
            {
                "R1": "pick(R1,O1) drop(R1,O1,H) msg(R1,R2,a) msg(R2,R1,b) pick(R1,O1) drop(R1,O1,W)",
                "R2": "msg(R1,R2,a) pick(R2,O1) drop(R2,O1,G) msg(R2,R1,b)",
            }
        )
    )
    assert [h.receiver for h in relays.items] == ["R2"]
    assert relays.refused and "R1 picks O1 again after R2 has moved it" in relays.refused[0]


def test_unordered_handlings_are_reported_and_cycles_broken():
    loose = handovers(_words({"R1": "pick(R1,O1) drop(R1,O1,H)", "R2": "pick(R2,O1) drop(R2,O1,W)"}))
    assert loose.items == () and ("O1", ("R1", 0), ("R2", 0)) in loose.unordered
    swap = handovers(
        _words(
            {
                "R1": "pick(R1,O1) drop(R1,O1,H) msg(R1,R2,a) msg(R2,R1,b) pick(R1,O2) drop(R1,O2,W)",
                "R2": "pick(R2,O2) drop(R2,O2,H) msg(R2,R1,b) msg(R1,R2,a) pick(R2,O1) drop(R2,O1,W)",
            }
        )
    )
    assert {(h.giver, h.receiver) for h in swap.items} == {("R1", "R2"), ("R2", "R1")}
    (first, chosen), (second, none) = swap.turns(("R1", "R2"))
    assert first == ("R1",) and second == ("R2",) and none == ()
    assert [(h.giver, h.receiver) for h in chosen] == [("R2", "R1")]  # its spot is chosen for both


@pytest.fixture(scope="module")
def relay():
    scenario = load_scenario(RELAY)
    return scenario, plan_team(scenario, workers=1)


def _position(plan, primitive):
    return next(s for s in plan.steps if s.primitive == primitive).objects["O1"].position


def test_the_receiver_picks_where_the_giver_drops(relay):
    scenario, result = relay
    plans = result.plans
    assert plans.feasible and result.report.ok
    assert _position(plans.robots["R1"], "DropOff") == _position(plans.robots["R2"], "PickUp")
    assert scenario.scene.workspaces["H"].holds(*_position(plans.robots["R2"], "PickUp"), 200)


def test_the_checker_refuses_a_pick_where_the_goods_no_longer_lie(relay):
    scenario, result = relay
    plans = result.plans
    # R2 planned alone against the scene, as before hand-overs: it picks O1 at its shelf
    alone = synthesize(scenario.scene, "R2", plans.robots["R2"].mission, max_horizon=16)
    assert alone.feasible and _position(alone.plan, "PickUp") == (-2500.0, 1300.0)
    wrong = PlanSet(
        plans.scenario, True, {**plans.robots, "R2": alone.plan}, messages=plans.messages, added=plans.added
    )
    report = check_plan(scenario, wrong)
    assert not report.ok
    assert any(
        "R2 picks O1 at (-2500, 1300)" in v.message and "where R1 dropped them" in v.message
        for v in report.violations
    ), [v.message for v in report.violations]


def _with_message(plan: RobotPlan, at: int, primitive: Primitive, name: str) -> RobotPlan:
    """`plan` with a message step after its step `at` (from 1)."""
    state = plan.steps[at - 1].state
    step = Step(primitive, None, state.robot, state.objects, parse_event(name))
    return RobotPlan.from_steps(plan.mission, [*plan.steps[:at], step, *plan.steps[at:]])


def test_a_receiver_that_drives_over_the_goods_first_place_needs_an_order():
    # R2 knows O1 at the hand-over spot only; its drive over the shelf, where O1 still lies
    # until R1 picks it, is a conflict that no message orders
    scenario = load_scenario(RELAY)
    r1 = plan_from_actions(
        scenario.scene,
        "R1",
        [parse_event("pick(R1,O1)"), parse_event("drop(R1,O1,H)"), parse_event("msg(R1,R2,t)")],
        [
            ("GoTo", (-3720, 1905, 0)),
            ("GoTo", (-2500, 1600, 270)),
            ("PickUp", "O1"),
            ("GoTo", (-1300, 1901, 0)),
            ("GoTo", (-400, 281, 0)),
            ("DropOff", "O1"),
        ],
    )
    r1 = _with_message(r1, 6, Primitive.RES, "msg(R1,R2,t)")
    scene = scenario.scene
    moved = replace(
        scene, objects={**scene.objects, "O1": replace(scene.objects["O1"], position=(-100, 281))}
    )
    r2 = plan_from_actions(
        moved,
        "R2",
        [parse_event("msg(R1,R2,t)"), parse_event("pick(R2,O1)")],
        [
            ("GoTo", (1000, -250, 180)),
            ("GoTo", (-1000, -250, 180)),  # through the door
            ("GoTo", (-1000, 1300, 90)),
            ("GoTo", (-3000, 1300, 180)),  # over O1's shelf place, where O1 lies until R1 picks it
            ("GoTo", (-1000, 1300, 0)),
            ("GoTo", (-1000, -250, 270)),
            ("GoTo", (1000, -250, 0)),
            ("GoTo", (200, 281, 180)),
            ("PickUp", "O1"),
        ],
    )
    r2 = _with_message(r2, 8, Primitive.REQ, "msg(R1,R2,t)")
    messages = (PlanMessage(parse_event("msg(R1,R2,t)"), "order", "R2 picks O1 after R1 has dropped it"),)
    report = check_plan(scenario, PlanSet(scenario.name, True, {"R1": r1, "R2": r2}, messages=messages))
    texts = [v.message for v in report.violations]
    shelf = "O1 resting at (-2500, 1300) at its start"
    assert any(shelf in t and "R2's GoTo at instant 4" in t and "no message orders" in t for t in texts), (
        texts
    )
    assert not any("picks O1" in t for t in texts)  # it picks O1 where R1 puts it


def test_a_relay_in_task_lists_ordered_by_a_message_is_planned():
    data = yaml.safe_load(RELAY.read_text())
    data["mission"] = {
        "tasks": {
            "R1": ["pick O1", "drop O1 at H", "msg(R1,R2,handed)", "return"],
            "R2": ["msg(R1,R2,handed)", "pick O1", "drop O1 at W1", "return"],
        }
    }
    scenario = parse_scenario(data)
    result = plan_team(scenario, workers=1)
    assert result.plans.feasible and result.report.ok
    assert _position(result.plans.robots["R1"], "DropOff") == _position(result.plans.robots["R2"], "PickUp")
    data["mission"]["tasks"]["R1"].remove("msg(R1,R2,handed)")  # no message: no order
    data["mission"]["tasks"]["R2"].remove("msg(R1,R2,handed)")
    with pytest.raises(ScenarioError, match="with no order between them"):
        parse_scenario(data)


def test_robots_that_hand_goods_to_each_other_share_a_spot_chosen_for_both():
    data = yaml.safe_load(RELAY.read_text())
    walls = data["scene"]["obstacles"]
    walls[5] = [[0, 500], [0, 1500]]  # a second door, y in [1500, 2300], with a second area H2
    walls.append([[0, 2300], [0, 2500]])
    data["scene"]["objects"]["O2"] = {"size": 200, "position": [2500, -1300]}
    data["scene"]["workspaces"]["H2"] = {"x": [-300, 300], "y": [1550, 2250]}
    data["scene"]["workspaces"]["G"] = {"x": [-4500, -3500], "y": [1700, 2300]}
    chain = [  # both drop, then each picks what the other dropped
        "pick(R1,O1)", "drop(R1,O1,H)", "pick(R2,O2)", "drop(R2,O2,H2)",
        "pick(R2,O1)", "pick(R1,O2)", "drop(R2,O1,W1)", "drop(R1,O2,G)",
    ]  # fmt: skip
    data["mission"] = {
        "dfa": {"initial": "q0", "transitions": [[f"q{i}", e, f"q{i + 1}"] for i, e in enumerate(chain)]}
    }
    scenario = parse_scenario(data)
    result = plan_team(scenario, workers=1)
    assert result.plans.feasible, result.plans.reason
    assert result.report.ok
    robots = result.plans.robots
    for giver, receiver, obj in (("R1", "R2", "O1"), ("R2", "R1", "O2")):
        drop = next(s for s in robots[giver].steps if s.primitive == "DropOff" and s.object == obj)
        pick = next(s for s in robots[receiver].steps if s.primitive == "PickUp" and s.object == obj)
        assert drop.objects[obj].position == pick.objects[obj].position
