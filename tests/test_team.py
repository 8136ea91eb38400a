"""Team-safe plans: messages order the places robots share and the orders the mission requires.

The examples 07 (one-lane corridor) and 08 (an order between robots) are planned and simulated,
and their traces checked: every robot finishes, no two robots' footprints ever overlap, and the
executed word of mission events is a complete word of the global mission.
"""

from __future__ import annotations

import functools
import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from cosmop.cli import app
from cosmop.events import Primitive, message, parse_event
from cosmop.missions.mission import GlobalMission
from cosmop.planning import PlanSet, plan_from_actions
from cosmop.planning.plan_file import load_plan
from cosmop.planning.plan_types import RobotPlan, Step
from cosmop.planning.realisation import message_links
from cosmop.scenario import load_scenario, parse_scenario
from cosmop.sim import simulate
from cosmop.sim.recoordinate import (
    Remaining,
    message_due_in,
    orders_lost,
    recoordinate,
    reorder_world,
    unordered_now,
)
from cosmop.sim.result import SimSettings
from cosmop.sim.world import World
from cosmop.team.conflicts import ConflictSettings, conflicts, is_ordered, occupancies
from cosmop.team.loop import plan_team
from cosmop.team.precedence import Precedence
from cosmop.team.safe_plans import make_team_safe
from handmade_plans import R2_ACTIONS, R2_MISSION
from stale_order import run_out, stale_order_world
from team_checks import assert_complete_word, assert_no_overlap

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
runner = CliRunner()


@pytest.fixture(scope="module")
def corridor():
    scenario = load_scenario(EXAMPLES / "07_corridor" / "scenario.yaml")
    return scenario, plan_team(scenario)


@pytest.fixture(scope="module")
def ordered():
    scenario = load_scenario(EXAMPLES / "08_ordered" / "scenario.yaml")
    return scenario, plan_team(scenario)


def test_message_events_round_trip():
    event = parse_event("msg(R1, R2, clear1)")
    assert event == message("R1", "R2", "clear1") and event.name == "msg(R1,R2,clear1)"
    assert (event.sender, event.receiver, event.owners) == ("R1", "R2", frozenset({"R1", "R2"}))
    away = parse_event("away(O2,R1,R2)")  # the paper's message: R2 tells R1 that O2 is away
    assert (away.sender, away.receiver, away.is_message) == ("R2", "R1", True)


def test_corridor_conflicts_are_ordered_by_messages(corridor):
    scenario, result = corridor
    plans = result.plans
    assert plans.feasible and result.report.ok
    assert result.safety.conflicts > 0 and plans.messages
    assert all(m.kind == "conflict" and m.place is not None for m in plans.messages)
    # every conflict between the final plans is ordered, and the order cannot deadlock
    links = message_links(plans.robots)
    precedence = Precedence({r: p.horizon for r, p in plans.robots.items()}, links)
    assert precedence.complete
    items, problems = occupancies(scenario.scene, plans.robots, precedence)
    found = conflicts(items)
    assert found and not problems and all(is_ordered(c, precedence) for c in found)


def test_corridor_simulation_has_no_stand_off(corridor):
    scenario, result = corridor
    run = simulate(scenario, result.plans)
    assert run.completed and run.contacts_while_moving == 0 and run.replans == 0
    assert_no_overlap(scenario, run)
    assert_complete_word(scenario, run)
    x, y = run.frames["pose"][:, :, 0], run.frames["pose"][:, :, 1]
    inside = (np.abs(x) < 1500) & (np.abs(y) < 250)
    assert inside.any(axis=0).all()  # both robots crossed it
    assert not (inside.sum(axis=1) > 1).any()  # never both in the corridor
    for i in range(inside.shape[1]):  # nobody backs out: every crossing leaves on the far side
        edges = np.flatnonzero(np.diff(inside[:, i].astype(int)))
        for enter, leave in zip(edges[::2], edges[1::2], strict=False):
            assert np.sign(x[enter, i]) != np.sign(x[leave + 1, i])


def test_an_order_between_robots_is_kept_by_a_message(ordered):
    scenario, result = ordered
    plans = result.plans
    assert plans.feasible and result.report.ok
    kinds = {m.event: m.kind for m in plans.messages}
    (order,) = [event for event, kind in kinds.items() if kind == "order"]
    assert order.sender == "R1" and order.receiver == "R2"
    r1, r2 = plans.robots["R1"].mission, plans.robots["R2"].mission
    assert r1.index(order) == r1.index(parse_event("drop(R1,O1,W1)")) + 1  # sent right after the drop
    assert r2.index(order) == r2.index(parse_event("pick(R2,O2)")) - 1  # awaited right before the pick
    run = simulate(scenario, plans)
    assert run.completed and run.contacts_while_moving == 0
    when = {event: t for t, _, event in run.events}
    assert when["pick(R2,O2)"] > when["drop(R1,O1,W1)"]
    assert_no_overlap(scenario, run)
    assert_complete_word(scenario, run)


def test_the_executed_word_check_can_fail(ordered):
    scenario, _ = ordered
    mission = GlobalMission.from_scenario(scenario)
    word = ["pick(R2,O2)", "pick(R1,O1)", "drop(R1,O1,W1)", "drop(R2,O2,W2)", "return(R1)", "return(R2)"]
    assert not mission.is_complete_word(word)  # R2 picked first
    assert not mission.is_complete_word(word[2:])  # not complete
    assert mission.is_complete_word([word[1], word[2], word[0], word[3], word[4], word[5]])


def _parking_swap(tmp_path: Path) -> Path:
    """Two robots in a one-lane corridor, each told to park where the other starts."""
    data = {
        "name": "swap",
        "scene": {
            "obstacles": [
                [[-3000, -250], [3000, -250]],
                [[3000, -250], [3000, 250]],
                [[3000, 250], [-3000, 250]],
                [[-3000, 250], [-3000, -250]],
            ],
            "robots": {"R1": {"size": 400, "pose": [-2500, 0, 0]}, "R2": {"size": 400, "pose": [2500, 0, 0]}},
            "objects": {
                "O1": {"size": 100, "position": [-2050, 0]},
                "O2": {"size": 100, "position": [2950, 0]},
            },
            "workspaces": {"W1": {"point": [2550, 0]}, "W2": {"point": [-1950, 0]}},
        },
        "mission": {"tasks": {"R1": ["pick O1", "drop O1 at W1"], "R2": ["pick O2", "drop O2 at W2"]}},
    }
    path = tmp_path / "swap.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def test_conflicts_no_order_resolves_exit_1_naming_robots_steps_and_place(tmp_path):
    path = _parking_swap(tmp_path)
    out = tmp_path / "plan.json"
    result = runner.invoke(app, ["plan", str(path), "-o", str(out)], env={"COLUMNS": "250"})
    assert result.exit_code == 1, result.output
    plans = load_plan(out)
    assert not plans.feasible
    reason = plans.reason
    assert "R1" in reason and "R2" in reason and "share the space" in reason
    assert "instant" in reason and "x in [" in reason


def test_a_replan_mid_run_is_ordered_again(corridor):
    # R1, still at home, gets a new plan straight through the corridor to the east room and back;
    # the rest of both plans is ordered again, with new messages, never deadlocking
    scenario, result = corridor
    plans = result.plans.robots
    scene = scenario.scene
    start = {r: Remaining(tuple(p.steps), tuple(p.mission), _initial(scenario, r)) for r, p in plans.items()}
    conflict_names = {m.event for m in result.plans.messages if m.kind == "conflict"}
    used = {e for p in plans.values() for e in p.mission if e.kind == "msg"}
    outcome = recoordinate(
        scene,
        start,
        "R1",
        sent=(),
        conflict_messages=conflict_names,
        used=used,
        positions={o: tuple(spec.position) for o, spec in scene.objects.items()},
    )
    assert outcome.accepted and outcome.messages
    assert set(outcome.dropped) == {e for e in conflict_names if "R1" in e.owners}
    assert {m.event for m in outcome.messages}.isdisjoint(conflict_names)  # fresh names
    links = message_links(outcome.plans)
    precedence = Precedence({r: p.horizon for r, p in outcome.plans.items()}, links)
    assert precedence.complete
    items, _ = occupancies(scene, outcome.plans, precedence)
    assert all(is_ordered(c, precedence) for c in conflicts(items))


def _relay_of_orders():
    """R1 crosses the room on y = 0, then tells R2; R2 drives, then tells R3; R3 then crosses
    R1's path on x = 0.  Only the chain through R2 orders R1's drive before R3's."""
    scenario = parse_scenario(
        {
            "name": "relay",
            "scene": {
                "obstacles": [],
                "robots": {
                    "R1": {"size": 400, "pose": [-3000, 0, 0]},
                    "R2": {"size": 400, "pose": [0, 4000, 0]},
                    "R3": {"size": 400, "pose": [0, -3000, 90]},
                },
                "objects": {},
                "workspaces": {},
            },
            "mission": {"tasks": {"R1": ["return"], "R2": ["return"], "R3": ["return"]}},
        }
    )
    m1, m2 = message("R1", "R2", "clear1"), message("R2", "R3", "clear2")
    go = functools.partial(Step, Primitive.GOTO, None, objects={})
    plans = {
        "R1": RobotPlan.from_steps(
            (m1,), (go((3000.0, 0.0, 0.0)), Step(Primitive.RES, None, (3000.0, 0.0, 0.0), {}, message=m1))
        ),
        "R2": RobotPlan.from_steps(
            (m1, m2),
            (
                Step(Primitive.REQ, None, (0.0, 4000.0, 0.0), {}, message=m1),
                go((2000.0, 4000.0, 0.0)),
                Step(Primitive.RES, None, (2000.0, 4000.0, 0.0), {}, message=m2),
            ),
        ),
        "R3": RobotPlan.from_steps(
            (m2,), (Step(Primitive.REQ, None, (0.0, -3000.0, 90.0), {}, message=m2), go((0.0, 2000.0, 90.0)))
        ),
    }
    return scenario, plans, {m1, m2}


def test_a_replan_keeps_the_orders_between_others_that_passed_through_it():
    # R2 replans (a drive west, no message): its messages go, and with them the only order
    # between R1's drive and R3's, which cross at the origin; they are ordered again
    scenario, plans, names = _relay_of_orders()
    scene = scenario.scene
    starts = {r: _initial(scenario, r) for r in plans}
    old = {r: Remaining(p.steps, p.mission, starts[r]) for r, p in plans.items()}
    new = RobotPlan.from_steps((), (Step(Primitive.GOTO, None, (-2000.0, 4000.0, 0.0), {}),))
    lost = orders_lost(scene, plans, names, "R2", starts=starts, positions={})
    assert lost == {("R1", "R3")}
    outcome = recoordinate(
        scene,
        {**old, "R2": Remaining(new.steps, new.mission, starts["R2"])},
        "R2",
        sent=(),
        conflict_messages=names,
        used=set(names),
        positions={},
        replaced=old["R2"],
    )
    assert outcome.accepted and set(outcome.dropped) == names
    assert {frozenset(m.event.owners) for m in outcome.messages} == {frozenset({"R1", "R3"})}
    precedence = Precedence({r: p.horizon for r, p in outcome.plans.items()}, message_links(outcome.plans))
    items, _ = occupancies(scene, outcome.plans, precedence, starts=starts)
    found = conflicts(items)
    assert any(c.robots == ("R1", "R3") for c in found)
    assert all(is_ordered(c, precedence) for c in found)
    # a replan whose messages order nothing between the others loses nothing
    assert orders_lost(scene, plans, {message("R2", "R3", "x")}, "R2", starts=starts, positions={}) == set()


def test_a_running_world_is_audited_for_unordered_conflicts():
    # the relay's plans as committed: every conflict ordered; without their messages, R1's
    # drive and R3's cross unordered (what an audit of a lifelong run looks for)
    scenario, plans, _ = _relay_of_orders()
    world = World(scenario, PlanSet(scenario.name, True, plans), 0, SimSettings())
    assert unordered_now(world) == []
    bare = {r: RobotPlan.from_steps((), [s for s in p.steps if s.message is None]) for r, p in plans.items()}
    world = World(scenario, PlanSet(scenario.name, True, bare), 0, SimSettings())
    assert [c.robots for c in unordered_now(world)] == [("R1", "R3")]


def test_a_robot_held_back_by_a_stale_order_goes_first_when_reordered():
    kept, world = stale_order_world(), stale_order_world()
    waiting = world.agents[1]
    due = message_due_in(world, waiting)  # R1's drives to its message, at the expected times
    assert message_due_in(world, world.agents[0]) is None  # R1 waits for nothing
    accepted, why, added = reorder_world(world, waiting)
    assert accepted, why
    # the robot at the crossing first goes first: R1 now waits before its drive across
    assert [(m.sender, m.receiver) for m in added] == [("R2", "R1")]
    assert Primitive.REQ not in [s.primitive for s in waiting.steps]
    assert any(s.primitive == Primitive.REQ and s.message == added[0] for s in world.agents[0].steps)
    assert unordered_now(world) == []
    run_out(kept)
    run_out(world)
    ends = {w: {a.id: a.step_log[-1][3] for a in w.agents} for w in (kept, world)}
    assert ends[world]["R2"] < ends[kept]["R2"] - 10.0  # R2 no longer waits for R1's long drive
    assert due == pytest.approx(kept.agents[1].step_log[0][3], abs=3.0)  # as long as it waited
    assert max(ends[world].values()) <= max(ends[kept].values()) + 1.0
    assert not world.contacts


def test_a_robot_beside_its_line_is_reordered_on_its_plan():
    # A robot tracks its plan within centimetres.  Re-ordered mid-drive, the rest of its drive
    # was cut on the line from where it really was, a line no check had seen (30 mm beside an
    # aisle lined with goods, it ran into them); the rest now starts on the plan's own segment.
    world = stale_order_world()
    r1, r2 = world.agents
    r1.step_index = 2  # R1 drives across, from (-3000, 0) to (3000, 0), 30 mm off its line
    world.pose[r1.index] = [-1000.0, 30.0, 0.0]
    accepted, why, _ = reorder_world(world, r2)
    assert accepted, why
    drives = [s.robot for s in r1.steps[2:] if s.primitive == Primitive.GOTO]
    assert len(drives) >= 2  # cut where it crosses R2's way
    assert all(abs(y) < 1e-9 for _, y, _ in drives)
    assert unordered_now(world) == []


def test_a_robot_told_to_wait_part_way_along_a_drive_waits_there_in_its_rest():
    # R1 stopped 2.4 m along its drive across is re-ordered behind R2: its wait stands where it
    # is, and a later re-ordering starts its rest there, not back at the drive's start (from
    # where R2, backed off, would be expected at the crossing first)
    world = stale_order_world()
    r1, r2 = world.agents
    r1.step_index, r2.step_index = 2, 1
    world.pose[r1.index] = [-560.0, 30.0, 0.0]
    world.pose[r2.index] = [0.0, -450.0, math.pi / 2]
    accepted, why, _ = reorder_world(world, r2)
    assert accepted, why
    assert r1.step.primitive == Primitive.REQ and r1.step.robot[:2] == (-560.0, 0.0)
    world.pose[r2.index] = [0.0, -1600.0, math.pi / 2]  # R2 now farther from the crossing
    accepted, why, _ = reorder_world(world, r1)
    assert accepted, why
    assert r1.step.primitive == Primitive.GOTO  # R1, nearer, goes first
    assert any(s.primitive == Primitive.REQ for s in r2.steps[r2.step_index :])
    assert unordered_now(world) == []


def _initial(scenario, robot):
    from cosmop.planning.primitive_effects import initial_state

    return initial_state(scenario.scene, robot)


def test_user_written_messages_order_a_tasks_mission():
    data = yaml.safe_load((EXAMPLES / "08_ordered" / "scenario.yaml").read_text())
    data["mission"] = {
        "tasks": {
            "R1": ["pick O1", "drop O1 at W1", "msg(R1,R2,stocked)", "return"],
            "R2": ["msg(R1,R2,stocked)", "pick O2", "drop O2 at W2", "return"],
        }
    }
    result = plan_team(parse_scenario(data))
    assert result.plans.feasible and result.report.ok
    kinds = {m.event.name: m.kind for m in result.plans.messages}
    assert kinds["msg(R1,R2,stocked)"] == "mission"
    run = simulate(parse_scenario(data), result.plans)
    when = {event: t for t, _, event in run.events}
    assert run.completed and when["pick(R2,O2)"] >= when["drop(R1,O1,W1)"]


class _Conflict:
    """A stand-in conflict: two robots and a name (what `_give_way` reads)."""

    def __init__(self, name: str, robots: tuple[str, str]) -> None:
        self.name, self.robots = name, robots

    def describe(self) -> str:
        return self.name


class _Safety:
    """A stand-in TeamSafety whose `detours` (rank, robot, space to avoid) are given, best first."""

    def __init__(self, ways: dict) -> None:
        self.ways = ways

    def detours(self, conflict):
        return self.ways[conflict]


def test_two_robots_never_give_way_around_each_other_in_one_round():
    from cosmop.team.detours import _give_way

    # R1's and R2's goods on one dock spot (either may drop elsewhere), and R2's drive through
    # R1's good (only R2 may move, the best kind of detour): R2 drives around; R1 avoiding R2
    # at the dock spot would make the two avoid each other, so that waits for the next round
    spot = _Conflict("goods on one spot", ("R1", "R2"))
    drive = _Conflict("R2 drives through O1", ("R2", "R1"))
    safety = _Safety(
        {spot: [(2, "R1", "O2's spot"), (2, "R2", "O1's spot")], drive: [(0, "R2", "O1's spot")]}
    )
    assert _give_way(safety, [spot, drive]) == {"R2": [(drive, "O1's spot")]}
    # when R2 cannot keep clear, R1 gives way where it can, R2 keeps its plan
    assert _give_way(safety, [spot, drive], {"R2"}) == {"R1": [(spot, "O2's spot")]}
    # a third robot's conflict with R1 goes ahead: no two robots avoid each other
    other = _Conflict("R3 and R1", ("R3", "R1"))
    safety.ways[other] = [(1, "R1", "R3's drive"), (1, "R3", "R1's drive")]
    assert _give_way(safety, [spot, drive, other]) == {
        "R2": [(drive, "O1's spot")],
        "R1": [(other, "R3's drive")],
    }
    # alone, a conflict goes ahead with its best way
    assert _give_way(safety, [spot]) == {"R1": [(spot, "O2's spot")]}


def test_goods_shipped_on_drop_still_need_their_drop_spot_free_while_dropped():
    """A lifelong run ships delivered goods, but they appear on the drop spot while the gripper
    lets go: a robot planned to stand there then must be ordered (else the drop waits for it
    while it waits for the dropper's message, for ever)."""
    scenario = load_scenario(EXAMPLES / "01_warehouse_2x2" / "scenario.yaml")
    scene = scenario.scene
    # R1 ends diagonally beside where R2 drops O2 (1250, 2050), its grown square 40 mm into it
    r1 = plan_from_actions(scene, "R1", [], [("GoTo", (1250 + 260, 2050 + 260, 90))])
    r2 = plan_from_actions(scene, "R2", list(R2_MISSION), R2_ACTIONS)
    plans = PlanSet(scenario.name, True, {"R1": r1, "R2": r2}).robots
    precedence = Precedence({r: p.horizon for r, p in plans.items()}, message_links(plans))
    for shipped in (False, True):
        items, _ = occupancies(scene, plans, precedence, ConflictSettings(shipped_on_drop=shipped))
        (held,) = [o for o in items if o.what == "O2" and o.first == ("R2", 4)]
        assert held.last == (("R2", 4) if shipped else None)  # the drop's interval, or for good
        found = [c for c in conflicts(items) if {c.a.what, c.b.what} == {"O2", "R1"}]
        assert found and not any(is_ordered(c, precedence) for c in found)
    # ordered by messages; the goods' conflict with R1 is among those ordered
    shipped = ConflictSettings(shipped_on_drop=True)
    safe = make_team_safe(scene, plans, settings=shipped).plans
    precedence = Precedence({r: p.horizon for r, p in safe.items()}, message_links(safe))
    found = conflicts(occupancies(scene, safe, precedence, shipped)[0])
    assert any({c.a.what, c.b.what} == {"O2", "R1"} for c in found)
    assert precedence.complete and all(is_ordered(c, precedence) for c in found)


def test_a_planner_rewound_to_a_checkpoint_forgets_what_was_tried_since_but_keeps_its_answers(corridor):
    from cosmop.planning.plan_types import AddedTask
    from cosmop.planning.synthesis import Synthesis
    from cosmop.scene import Wall
    from cosmop.team.planner import Planner

    scenario, _ = corridor
    planner = Planner(scenario)
    planner.forbid("R1", frozenset({"O1"}))
    planner.spots["R2"] = {parse_event("drop(R2,O2,W2)"): (1.0, 2.0)}
    mark, key = planner.checkpoint(), planner.key("R2", ())
    planner.forbid("R1", frozenset({"O2"}))
    planner.forbid("R2", frozenset({"O1"}))
    planner.wall_off("R2", (Wall((0.0, 0.0), (1.0, 0.0), "a trial"),))
    before = planner.key("R2", ())
    planner.added.append(AddedTask("R2", "O1", "aside_O1", (5.0, 5.0), "a trial"))
    planner.scenario = PlanSet(scenario.name, True, added=tuple(planner.added)).extend(scenario)
    assert planner.key("R2", ()) != before  # asked again once the goods it sets aside lie elsewhere
    planner.placed["R1"] = {"O2": (3.0, 4.0)}
    planner.spots["R2"][parse_event("drop(R2,O1,W1)")] = (6.0, 7.0)
    planner.cache[("an answer",)] = Synthesis("R1", False, None, None, reason="a trial")
    planner.rewind(mark)
    assert planner.forbidden == {"R1": frozenset({"O1"})}
    assert planner.obstacles == {} and planner.added == [] and planner.placed == {}
    assert planner.scenario is scenario
    assert planner.spots == {"R2": {parse_event("drop(R2,O2,W2)"): (1.0, 2.0)}}
    assert ("an answer",) in planner.cache  # what was solved since stays solved
    assert planner.key("R2", ()) == key


def test_a_robots_states_made_when_read_are_its_plans_states(corridor):
    from cosmop.team.conflicts import _States

    _, team = corridor
    plan = team.plans.robots["R1"]
    start = plan.steps[-1].state  # any state does for the start
    states, listed = _States(start, plan), [start, *(step.state for step in plan.steps)]
    assert len(states) == len(listed) == plan.horizon + 1
    every = range(-len(listed), len(listed))
    assert [states[k] for k in every] == [listed[k] for k in every]
    assert states[1:3] == listed[1:3] and states[::-1] == listed[::-1] and list(states) == listed
    for k in (len(listed), -len(listed) - 1):
        with pytest.raises(IndexError):
            states[k]


def test_the_occupancies_of_some_robots_are_those_of_all_of_them_but_the_others(corridor):
    scenario, team = corridor
    plans = dict(team.plans.robots)
    order = Precedence({r: p.horizon for r, p in plans.items()}, message_links(plans))
    every, _ = occupancies(scenario.scene, plans, order)
    robots = set(plans)
    for some in ({"R1"}, {"R2"}, set(), robots):
        items, _ = occupancies(scenario.scene, plans, order, robots=some)
        assert items == [i for i in every if i.what in some or i.what not in robots]
    assert any(i.what not in robots for i in every)  # goods among them, made for every choice
