"""Lifelong operation: orders released over time, served by a fleet that keeps working."""

from __future__ import annotations

import itertools
import json
from dataclasses import replace
from functools import lru_cache
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from cosmop.cli import app
from cosmop.errors import ScenarioError
from cosmop.events import Event, Primitive
from cosmop.lifelong import Failure, FleetSettings, run_fleet
from cosmop.lifelong.dispatch import Offer, choose_assignment, delivery_events
from cosmop.planning.primitive_effects import initial_state
from cosmop.scenario import load_orders, load_scenario, parse_scenario
from cosmop.scene import Order
from cosmop.sim.replan import grown, replan, rest_collisions, why_no_plan
from cosmop.traces import Trace
from run_2x2 import EXAMPLE

runner = CliRunner()


def _data(orders=None) -> dict:
    """The 2x2 warehouse with an order stream instead of a mission."""
    data = yaml.safe_load(EXAMPLE.read_text())
    del data["mission"]
    data["name"] = "lifelong-2x2"
    data["orders"] = orders or [
        {"at": 0, "object": "O1", "to": "W1"},
        {"at": 5, "object": "O2", "to": ["W2", "W1"]},
    ]
    return data


@lru_cache(maxsize=4)
def _run(failures: tuple[Failure, ...] = (), until: float = 150.0):
    scenario = parse_scenario(_data())
    return scenario, run_fleet(scenario, fleet=FleetSettings(until=until), failures=failures)


def test_a_scenario_may_hold_only_orders():
    scenario = parse_scenario(_data())
    assert scenario.mission is None
    assert [(o.at, o.object, o.to, o.by) for o in scenario.orders] == [
        (0.0, "O1", ("W1",), ("R1", "R2")),
        (5.0, "O2", ("W2", "W1"), ("R1", "R2")),
    ]


@pytest.mark.parametrize(
    ("orders", "field", "words"),
    [
        ([{"at": 0, "object": "O9", "to": "W1"}], "orders[0].object", "unknown object 'O9'"),
        ([{"at": -1, "object": "O1", "to": "W1"}], "orders[0].at", "a release time in seconds"),
        ([{"at": 0, "object": "O1", "to": ["W1", "W7"]}], "orders[0].to[1]", "unknown workspace 'W7'"),
        ([{"at": 0, "object": "O1", "to": "W1", "by": "R5"}], "orders[0].by[0]", "unknown robot 'R5'"),
        ([{"at": 0, "object": "O1"}], "orders[0].to", "missing required key 'to'"),
        (
            [{"at": 0, "object": "O1", "to": "W1"}, {"at": 9, "object": "O1", "to": "W2"}],
            "orders[1].object",
            "O1 is already ordered by orders[0]",
        ),
        (
            [{"at": 5, "object": "O1", "to": "W1"}, {"at": 2.5, "object": "O2", "to": "W2"}],
            "orders[1].at",
            "expected a release time >= 5 s, the time of orders[0] before it",
        ),
    ],
)
def test_a_bad_order_names_its_field(orders, field, words):
    with pytest.raises(ScenarioError) as info:
        parse_scenario(_data(orders))
    assert info.value.field == field and words in str(info.value)


def test_neither_mission_nor_orders_is_refused():
    data = _data()
    del data["orders"]
    with pytest.raises(ScenarioError, match=r"expected a mission .* or orders"):
        parse_scenario(data)


def test_an_orders_file_is_read_against_the_scene(tmp_path):
    scenario = load_scenario(EXAMPLE)
    path = tmp_path / "orders.yaml"
    path.write_text("orders:\n  - {at: 1.5, object: O1, to: W1, by: R1}\n  - {at: 3, object: O2, to: W2}\n")
    assert [(o.at, o.object, o.by) for o in load_orders(path, scenario)] == [
        (1.5, "O1", ("R1",)),
        (3.0, "O2", ("R1", "R2")),
    ]
    path.write_text("orders:\n  - {at: 3, object: O2, to: W9}\n")
    with pytest.raises(ScenarioError) as info:
        load_orders(path, scenario)
    assert str(info.value).startswith(f"{path}: orders[0].to[0]: unknown workspace 'W9'")
    path.write_text("orders: [{at: 0, object: O1, to: W1}]\nfoo: 1\n")  # an orders file's keys
    with pytest.raises(ScenarioError) as info:
        load_orders(path, scenario)
    assert str(info.value) == f"{path}: foo: unknown key 'foo'; expected one of: orders (line 2, column 1)"


def test_the_fleet_delivers_the_stream_safely_and_ships_the_goods():
    _, result = _run()
    # each delivery's events are a word of its order's delivery mission (issue 37's check)
    assert [[e.name for e in o.word] for o in result.orders] == [
        ["pick(R1,O1)", "drop(R1,O1,W1)"],
        ["pick(R2,O2)", "drop(R2,O2,W2)"],
    ]
    assert all(o.as_ordered for o in result.orders) and not result.not_as_ordered
    summary = result.summary()
    assert summary["orders"] == {"released": 2, "delivered": 2, "lost": 0, "pending": 0}
    assert summary["contacts_while_moving"] == 0 and summary["messages"] > 0  # ordered by messages
    assert summary["deliveries_per_hour"] == pytest.approx(2 * 3600 / result.until)
    waits = [o.wait for o in result.orders]
    assert summary["wait_s"]["max"] == pytest.approx(max(waits), abs=1e-3)
    assert all(0 < u < 1 for u in summary["utilisation"].values())
    assert [o.robot for o in result.orders] == ["R1", "R2"]  # each to the idle robot nearest its work
    trace = result.trace()
    back = Trace.from_json(json.loads(json.dumps(trace.to_json())))
    assert back.robot_ids == ("R1", "R2")
    shipped = trace.object_ids.index("O1")
    after = np.searchsorted(trace.t, result.orders[0].delivered) + 1
    assert np.isnan(trace.objects[after:, shipped]).all()  # delivered goods leave the world


def test_a_robot_failing_with_the_goods_loses_the_order_and_says_where():
    _, result = _run((Failure("R1", 25.0),))
    failure = result.failures["R1"]
    assert failure["carrying"] == ["O1"] and failure["t"] == pytest.approx(25.0)
    lost = result.orders[0]
    assert lost.lost == "R1 failed at 25.0 s carrying O1" and lost.delivered is None
    assert result.orders[1].delivered is not None and result.contacts_while_moving == 0


def test_a_robot_failing_before_it_picks_returns_the_order_to_the_pool():
    _, result = _run((Failure("R2", 6.0),))
    assert result.failures["R2"]["carrying"] == []
    order = result.orders[1]  # R2 had taken it at 5.2 s
    assert order.assigned is None or order.robot == "R1"
    tries = [e for e in result.dispatch_log if e["order"] == 1]
    assert len(tries) >= 2 and tries[0]["robot"] == "R2"  # given again after R2 failed


LIFELONG = Path(__file__).resolve().parent / "data" / "lifelong_2x2.yaml"  # the first example's scene
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@lru_cache(maxsize=2)
def _run_lifelong_example(failure: Failure):
    return run_fleet(load_scenario(LIFELONG), fleet=FleetSettings(until=200.0), failures=(failure,))


def _picking(robot: str, pose: tuple[float, float]) -> float:
    """The middle of the time `robot` stands at `pose` in the example's run without failures (s)."""
    run = run_fleet(load_scenario(LIFELONG), fleet=FleetSettings(until=60.0))
    xy = run.frames["pose"][:, run.robot_ids.index(robot), :2]
    there = np.flatnonzero(np.hypot(*(xy - np.asarray(pose)).T) < 1.0)
    assert there.size, f"{robot} never stands at {pose}"
    return float(run.frames["t"][there].mean())


def test_goods_beside_a_robot_that_failed_at_them_are_delivered_by_another():
    # R2 fails at the pose where it picks O2 (its order since 10 s), touching the goods: its
    # grown box must not cover them, nor its standing there make them unpickable
    result = _run_lifelong_example(Failure("R2", _picking("R2", (1650.0, -2000.0))))
    failure = result.failures["R2"]
    assert failure["carrying"] == [] and failure["at"] == pytest.approx([1650.0, -2000.0], abs=1.0)
    o2 = next(o for o in result.orders if o.object == "O2")
    assert o2.delivered is not None and o2.robot == "R1"
    assert result.lost == 0 and result.contacts_while_moving == 0


def test_an_order_only_failed_robots_may_serve_says_so():
    result = _run_lifelong_example(Failure("R2", 3.0))
    o4 = next(o for o in result.orders if o.object == "O4")  # by: R2 in the example
    assert o4.delivered is None and o4.lost is None
    assert o4.refused == "no robot may serve it: only R2 may, and R2 failed at 3.0 s"
    assert all(o.delivered is not None for o in result.orders if o is not o4)
    assert not any(e["order"] == o4.index for e in result.dispatch_log)  # never handed over


def test_cosmop_run_writes_the_summary_and_refuses_bad_options(tmp_path):
    scenario = tmp_path / "s.yaml"
    scenario.write_text(yaml.safe_dump(_data()))
    summary, trace = tmp_path / "sum.json", tmp_path / "t.json"
    ran = runner.invoke(
        app, ["run", str(scenario), "--until", "120", "--summary", str(summary), "--trace", str(trace)]
    )
    assert ran.exit_code == 0, ran.output
    data = json.loads(summary.read_text())
    assert data["format"] == "cosmop.run/1" and data["orders"]["delivered"] == 2
    assert data["reorders"]["tried"] == len(data["reorder_log"])  # waits re-ordered, if any
    assert data["reorders"]["shortened"] == sum(r["shortened"] for r in data["reorder_log"])
    assert {"p50", "p95", "max"} <= set(data["wait_s"]) and "deliveries_per_hour" in data
    assert "2 of 2 orders delivered" in " ".join(ran.stdout.split())
    view = runner.invoke(app, ["view", str(scenario), "--trace", str(trace), "-o", str(tmp_path / "v.html")])
    assert view.exit_code == 0, view.output
    bad = runner.invoke(app, ["run", str(scenario), "--until", "60", "--fail", "R1-600"])
    assert bad.exit_code == 2 and "ROBOT@SECONDS" in bad.stderr
    negative = runner.invoke(app, ["run", str(scenario), "--until", "60", "--reorder-after", "-1"])
    assert negative.exit_code == 2 and "--reorder-after" in negative.stderr
    for reveal in ("-0.5", "nan"):
        refused = runner.invoke(app, ["run", str(scenario), "--until", "60", "--reveal", reveal])
        assert refused.exit_code == 2 and "--reveal" in refused.stderr
    unknown = runner.invoke(app, ["run", str(scenario), "--until", "60", "--fail", "R9@6"])
    assert unknown.exit_code == 2 and "R9 is not a robot" in unknown.stderr
    plan = runner.invoke(app, ["plan", str(scenario), "-o", str(tmp_path / "p.json")])
    assert plan.exit_code == 2 and "cosmop run" in plan.stderr


def test_a_robot_with_work_waiting_takes_it_at_the_dock_not_after_going_home():
    orders = [
        {"at": 0, "object": "O1", "to": "W1", "by": "R1"},
        {"at": 0, "object": "O2", "to": "W2", "by": "R1"},
    ]
    scenario = parse_scenario(_data(orders))
    result = run_fleet(scenario, fleet=FleetSettings(until=150.0))
    assert all(o.delivered is not None for o in result.orders)
    first, second = sorted(result.orders, key=lambda o: o.delivered)
    given = [e for e in result.dispatch_log if e["order"] == second.index and e["accepted"]]
    # handed over in the cycle that recorded the drop, from the dock
    assert given and given[0]["t"] == pytest.approx(first.delivered, abs=0.11)
    assert all(e["wall_s"] >= 0 for e in result.dispatch_log)
    assert result.summary()["handover_wall_s"]["p50"] is not None
    assert result.contacts_while_moving == 0


def test_the_dispatcher_gives_a_robot_the_order_of_least_work_in_its_window():
    scene = parse_scenario(_data()).scene
    far = Offer(Order(0.0, "O1", ("W1",), ("R1", "R2")), (2000.0, -1000.0))
    near = Offer(Order(1.0, "O2", ("W1",), ("R1", "R2")), (-1800.0, -1000.0))
    idle = [("R2", (-2000.0, -2000.0))]
    assert choose_assignment(scene, [far, near], idle) == (1, "R2")  # least work, not the oldest
    assert choose_assignment(scene, [far], idle) == (0, "R2")  # a window of one: oldest first
    # an order passed over too often is served first, the oldest of those
    assert choose_assignment(scene, [replace(far, overdue=True), near], idle) == (0, "R2")
    # of two idle robots, the nearer one; an order no idle robot may serve is not given
    idle = [("R1", (1800.0, -900.0)), ("R2", (-2000.0, -2000.0))]
    assert choose_assignment(scene, [far], idle) == (0, "R1")
    only_r3 = Offer(Order(0.0, "O1", ("W1",), ("R3",)), (2000.0, -1000.0))
    assert choose_assignment(scene, [only_r3], idle) is None
    assert choose_assignment(scene, [only_r3, near], idle) == (1, "R2")


def test_a_robot_freed_takes_the_order_nearest_to_it_and_none_waits_for_ever():
    # one robot may serve four orders released at once: O1 lies far, the others near its home.
    # With a window (two orders for two robots) it serves the near ones first, but O1, passed
    # over twice (as often as the window holds orders), is served before the last one
    data = _data([{"at": 0, "object": o, "to": "W1", "by": "R1"} for o in ("O1", "O2", "O3", "O4")])
    objects = data["scene"]["objects"]
    objects["O1"]["position"] = [2000, -1000]
    for k, o in enumerate(("O2", "O3", "O4")):
        objects[o] = {"size": 100, "position": [-1500, -1500 + 350 * k]}
    scenario = parse_scenario(data)
    fifo = run_fleet(scenario, fleet=FleetSettings(until=240.0, reveal=0.0))
    window = run_fleet(scenario, fleet=FleetSettings(until=240.0, reveal=1.0))
    given = [[e["order"] for e in r.dispatch_log if e["accepted"]] for r in (fifo, window)]
    assert given[0] == [0, 1, 2, 3]
    assert given[1][:3] == [1, 2, 0]
    assert (fifo.summary()["dispatch_window"], window.summary()["dispatch_window"]) == (1, 2)
    assert window.contacts_while_moving == 0 and not window.not_as_ordered


def test_refused_hand_overs_keep_the_order_and_wait_longer_each_time(monkeypatch):
    import cosmop.lifelong.fleet as fleet_module

    real, refusals = fleet_module.recoordinate_world, []

    def refuse_three_times(world, agent, plan, start):
        if len(refusals) < 3:  # the world says "not now" three times
            refusals.append(world.t)
            return False, "a test refusal", []
        return real(world, agent, plan, start)

    monkeypatch.setattr(fleet_module, "recoordinate_world", refuse_three_times)
    orders = [{"at": 0, "object": "O1", "to": "W1", "by": "R1"}]
    result = run_fleet(parse_scenario(_data(orders)), fleet=FleetSettings(until=150.0))
    (order,) = result.orders
    assert order.lost is None and order.delivered is not None  # refusals alone lose nothing
    gaps = [b - a for a, b in itertools.pairwise(refusals)]
    # 5 s, then twice that, each to the next dispatch (one a second)
    assert 5 <= gaps[0] <= 6.01 and 10 <= gaps[1] <= 11.01
    assert (
        order.refused is not None and order.refused.startswith("R1 at ") and "a test refusal" in order.refused
    )
    assert [e["accepted"] for e in result.dispatch_log] == [False, False, False, True]


def test_a_new_order_that_would_make_a_robot_at_speed_wait_before_it_can_stop_is_refused():
    # a hand-over re-orders every robot's rest; a wait added (or moved closer) within the stopping
    # distance of a robot driving at speed cannot be kept: it brakes past it, into a place the plans give
    # another, and creeping back it can box in a robot that waits for it (a stall found in an
    # hour-long run)
    from cosmop.planning.plan_types import PlanMessage, PlanSet, RobotPlan, Step
    from cosmop.sim.recoordinate import Recoordination, _too_late_to_stop
    from cosmop.sim.result import SimSettings
    from cosmop.sim.world import World

    scenario = load_scenario(LIFELONG)
    world = World(scenario, PlanSet(scenario.name, True, {}), 0, SimSettings())
    i = world.robot_ids.index("R1")
    world.pose[i] = (-2000.0, -1000.0, 0.0)
    new = Event("msg", "R1", responder="R2", tag="c1")
    drive = Step(Primitive.GOTO, None, (-1700.0, -1000.0, 0.0), {})
    wait = Step(Primitive.REQ, None, (-1700.0, -1000.0, 0.0), {}, message=new)
    plans = {"R1": RobotPlan.from_steps((new,), (drive, wait)), "R2": RobotPlan.from_steps((), ())}
    result = Recoordination(True, plans, (PlanMessage(new, "conflict", "a test"),), ())
    world.v[i] = 0.0  # standing: any wait will do
    assert _too_late_to_stop(world, result) is None
    world.v[i] = 750.0  # at top speed it needs 685 mm to stop (the window's worst case): 300 is too close
    why = _too_late_to_stop(world, result)
    assert why is not None and why.startswith("R1, driving at 750 mm/s, would have to wait 300 mm ahead")
    agent = world.agents[i]
    agent.steps = [drive, wait]  # a wait it already had there: it is braking for it already
    assert _too_late_to_stop(world, result) is None
    agent.steps = [Step(Primitive.GOTO, None, (-1000.0, -1000.0, 0.0), {}), wait]  # had it 1 m ahead
    assert _too_late_to_stop(world, result) == why  # the new cuts moved it closer: refused
    world.pose[i] = (-3000.0, -1000.0, 0.0)  # 1300 mm ahead: it can stop
    assert _too_late_to_stop(world, result) is None


def test_a_robot_that_stands_long_for_a_message_has_its_conflicts_ordered_again():
    # the fleet notes since when each robot stands for a conflict message; past
    # `reorder_after` seconds its conflicts are ordered again from the times expected now
    from cosmop.lifelong.fleet import _note_waits, _reorder_long_waits, _Run
    from cosmop.sim.simulation import advance
    from stale_order import stale_order_world

    for after, reordered in ((5.0, True), (None, False)):
        world = stale_order_world()
        run = _Run(world, [], FleetSettings(until=60.0, reorder_after=after))
        for _ in range(40):  # 4 s: R2 stands for R1's message, not yet long enough
            advance(world)
            _note_waits(run)
        _reorder_long_waits(run)
        assert run.waits == {"R2": (0, pytest.approx(0.1))} and run.reorders == []
        for _ in range(20):
            advance(world)
            _note_waits(run)
        _reorder_long_waits(run)
        assert [(r["robot"], r["accepted"]) for r in run.reorders] == ([("R2", True)] if reordered else [])
        assert world.agents[1].waiting is not reordered  # the new order lets it go at once
        if reordered:  # it went: the wait was shortened, to nothing
            assert run.reorders[0]["shortened"] and run.reorders[0]["due_after_s"] is None


def test_a_reordering_that_does_not_shorten_a_wait_is_tried_again_less_and_less_often(monkeypatch):
    # a re-ordering that leaves the robot's message as far away (here: one that changes
    # nothing) doubles the time before the same wait is tried again: 4 s, then 8 s, then 16 s
    from cosmop.lifelong import fleet as fleet_module
    from cosmop.lifelong.fleet import _note_waits, _reorder_long_waits, _Run
    from cosmop.sim.simulation import advance
    from stale_order import stale_order_world

    for changes_nothing in (True, False):
        world = stale_order_world()
        run = _Run(world, [], FleetSettings(until=60.0, reorder_after=4.0))
        if changes_nothing:
            monkeypatch.setattr(fleet_module, "reorder_world", lambda world, agent: (True, "", []))
        else:
            monkeypatch.undo()
        for _ in range(400):
            advance(world)
            _note_waits(run)
            _reorder_long_waits(run)
        times = [r["t"] for r in run.reorders]
        if changes_nothing:  # R1's message still ~30 s away at the first try, ~5 s at the third
            assert [r["shortened"] for r in run.reorders] == [False] * 3
            assert [round(b - a, 1) for a, b in itertools.pairwise(times)] == [8.1, 16.0]
            assert all(r["due_after_s"] == r["due_in_s"] for r in run.reorders)
        else:  # the real re-ordering lets R2 go at once: one try
            assert len(times) == 1 and run.reorders[0]["shortened"]


def test_a_delivery_that_breaks_its_order_is_not_as_ordered():
    # the check can fail: the goods dropped by another robot than picked them, at a dock the
    # order does not name, by a robot it does not allow, or picked and never dropped
    _, result = _run()
    good = result.orders[0]
    pick, drop = good.word
    other = Event("drop", "R2", obj="O1", workspace="W1")
    elsewhere = Event("drop", "R1", obj="O1", workspace="W2")
    for word, by in [
        ((pick, other), ("R1", "R2")),
        ((pick, elsewhere), ("R1", "R2")),
        ((pick, drop), ("R2",)),
        ((pick,), ("R1", "R2")),
        ((pick, drop, Event("pick", "R2", obj="O1")), ("R1", "R2")),
    ]:
        assert replace(good, word=word, by=by).as_ordered is False, word
    assert replace(good, delivered=None).as_ordered is None  # not delivered: nothing to check
    broken = replace(result, orders=(replace(good, word=(pick, other)), *result.orders[1:]))
    assert broken.not_as_ordered == (broken.orders[0],)
    assert broken.summary()["as_ordered"] == {"checked": 2, "broken": 1}


def _walled_data() -> dict:
    """R1 beside the goods but behind a wall with one gap at its far end; R2 farther, in the open."""
    return {
        "name": "walled",
        "scene": {
            "obstacles": [
                [[-3000, -2000], [3000, -2000]],
                [[3000, -2000], [3000, 2000]],
                [[3000, 2000], [-3000, 2000]],
                [[-3000, 2000], [-3000, -2000]],
                [[0, -2000], [0, 1400]],
            ],
            "robots": {
                "R1": {"size": 400, "pose": [-500, -1500, 0]},
                "R2": {"size": 400, "pose": [2400, 1400, 0]},
            },
            "objects": {"O1": {"size": 100, "position": [700, -1500]}},
            "workspaces": {"W1": {"x": [2000, 2600], "y": [-1800, -1200]}},
        },
        "orders": [{"at": 0, "object": "O1", "to": "W1"}],
    }


def test_an_order_a_robot_cannot_plan_goes_to_another_and_the_refusal_says_why():
    # the dispatcher's estimate (L1) puts R1 nearest, but within 7 steps R1 cannot go round the
    # wall and back: it says why once, and the order goes to R2 instead of R1 over and over
    scenario = parse_scenario(_walled_data())
    result = run_fleet(scenario, fleet=FleetSettings(until=60.0, max_horizon=7))
    tries = [(e["robot"], e["accepted"]) for e in result.dispatch_log]
    assert tries == [("R1", False), ("R2", True)]
    why = result.dispatch_log[0]["why"]
    assert why.startswith("R1 cannot reach") and "within 7 steps" in why
    order = result.orders[0]
    assert order.robot == "R2" and order.delivered is not None and order.as_ordered
    assert result.contacts_while_moving == 0


def test_a_failed_robot_is_named_in_the_reason_no_plan_is_found():
    data = _walled_data()
    data["scene"]["obstacles"][4] = [[0, -1200], [1500, -1200]]  # a shelf over the goods
    scenario = parse_scenario(data)
    scene, order = scenario.scene, scenario.orders[0]
    events = delivery_events(scene, "R2", order, scene.objects["O1"].position)
    start = initial_state(scene, "R2")
    # R1 failed off the goods' south-west corner, its box grown past their west face (as the
    # growth did before it stopped short of both sides): R2 can stand east of the goods but not
    # reach them from there, the box's top side between its gripper and them
    box, label = [(100.0, -2000.0, 749.0, -1551.0)], ["R1, failed at 3.0 s"]
    assert replan(scene, "R2", events, start, box, labels=label) is None
    why = why_no_plan(scene, "R2", events, start, box, labels=label)
    assert why.startswith("R2 cannot reach pick(R2,O1)") and "gripper clear of R1, failed at 3.0 s" in why


def test_a_robot_grown_round_goods_off_its_corner_leaves_them_reachable_from_the_far_sides():
    # goods diagonally beyond the square's north-east corner: both sides stop short of them,
    # else the east side's growth runs below the goods and walls off their east face
    box = grown((0.0, 0.0, 200.0), 100.0, np.array([[251.0, 313.0, 50.0]]))
    assert box == (-300.0, -300.0, 200.0, 262.0)


def test_robots_whose_routes_run_through_a_failed_robot_are_replanned_round_it():
    # found by benchmarks/sweep_lifelong.py, seed 5: R4 failed at 74 s in the aisle R1's route
    # ran through; no order kept them apart, and R1, R2 and R3 stood for R4's messages for
    # the rest of the run.  Now the others are ordered round the failed robot once it has
    # braked to a stop, the robot in its way re-planned around it, its messages dropped.
    # (Hand-overs take other plans as short since 2026-12-07: R3 failing at 88 s is the case.)
    scenario = load_scenario(EXAMPLES / "13_lifelong" / "scenario.yaml")
    orders = [
        Order(0.0, "O23", ("W2",), ("R1", "R2", "R3", "R4")),
        Order(39.9, "O14", ("W3",), ("R1", "R2", "R3", "R4")),
        Order(43.3, "O10", ("W1",), ("R1", "R2", "R3", "R4")),
        Order(49.3, "O22", ("W1",), ("R1", "R2", "R3", "R4")),
    ]
    result = run_fleet(scenario, orders, fleet=FleetSettings(until=120.0), failures=[Failure("R3", 88.0)])
    failure = result.failures["R3"]
    assert failure["recoordinated"] is True and failure["carrying"] == ["O22"]
    assert failure["replanned"] == ["R1", "R2"]  # the nearest first, until the fleet could be ordered
    final = result.frames["pose"][-1, result.robot_ids.index("R3"), :2]
    assert failure["at"] == pytest.approx(final, abs=1e-3)  # where it came to rest, after braking
    o10 = next(o for o in result.orders if o.object == "O10")
    assert o10.robot == "R1" and o10.delivered is not None and o10.as_ordered
    assert result.lost == 1 and result.contacts_while_moving == 0


def test_a_robot_whose_home_a_failed_robot_takes_delivers_and_stays_at_the_dock():
    # R3 fails at 90 s on R1's home while R1 carries O10 to its dock: no plan of R1 ends at
    # home any more, so the fleet was never ordered around R3 and O10 was never delivered.
    # Now R1 is re-planned first, without the way home, and stays where its plan ends.
    scenario = load_scenario(EXAMPLES / "13_lifelong" / "scenario.yaml")
    everyone = ("R1", "R2", "R3", "R4")
    orders = [
        Order(0.0, "O23", ("W2",), everyone),
        Order(39.9, "O14", ("W3",), everyone),
        Order(43.3, "O10", ("W1",), everyone),
        Order(49.3, "O22", ("W1",), everyone),
    ]
    result = run_fleet(scenario, orders, fleet=FleetSettings(until=130.0), failures=[Failure("R3", 90.0)])
    failure = result.failures["R3"]
    assert failure["homes_taken"] == ["R1"] and failure["recoordinated"] is True
    assert failure["replanned"] == ["R1"]
    o10 = next(o for o in result.orders if o.object == "O10")
    assert o10.robot == "R1" and o10.delivered is not None and o10.as_ordered
    assert result.lost == 1 and result.contacts_while_moving == 0  # O22, which R3 carries


def test_a_robot_standing_in_the_only_way_is_named_as_what_separates():
    # R9 (not of this scene: a label only) stands in the one gap of the wall between R1 and
    # the goods: no plan at any horizon, and the reason names it, not "walls"
    scenario = parse_scenario(_walled_data())
    scene, order = scenario.scene, scenario.orders[0]
    events = delivery_events(scene, "R1", order, scene.objects["O1"].position)
    start = initial_state(scene, "R1")
    box, label = [(-400.0, 1300.0, 400.0, 2100.0)], ["R9, failed at 3.0 s"]
    why = why_no_plan(scene, "R1", events, start, box, labels=label, max_horizon=16)
    assert why.startswith("R1 cannot reach pick(R1,O1) (event 1 of its mission) at any horizon: ")
    assert "R9, failed at 3.0 s, separates its start (-500, -1500)" in why
    assert why_no_plan(scene, "R1", events, start, max_horizon=7).startswith("R1 cannot reach")  # no label
    # among many labelled boxes (ten robots idle along the far wall), the nearest are tried
    idle = [(-2950.0, -1900.0 + 350.0 * k, -2700.0, -1650.0 + 350.0 * k) for k in range(10)]
    labels = [f"R{10 + k}, standing idle" for k in range(10)]
    why = why_no_plan(scene, "R1", events, start, box + idle, labels=label + labels, max_horizon=16)
    assert "R9, failed at 3.0 s, separates its start (-500, -1500)" in why


def test_every_rest_a_recoordination_installs_passes_the_exact_checker(monkeypatch):
    # found on a 50-robot stream: a fleet re-ordered while a robot drove cut the rest of its
    # drive on the line from where it really was (30 mm beside its plan's), a line nobody
    # checked, which ran into goods along the aisle (the case: test_team's
    # test_a_robot_beside_its_line_is_reordered_on_its_plan).  The audit of a running fleet:
    # each rest installed is checked from its step's origin, with the goods where they are now.
    import cosmop.sim.recoordinate as recoordinate

    take, installs, violations = recoordinate._take, [], []

    def audited(world, result, splits, new):
        out = take(world, result, splits, new)
        if out[0]:
            installs.append(world.t)
            violations.extend(v.message for v in rest_collisions(world))
        return out

    monkeypatch.setattr(recoordinate, "_take", audited)
    scenario = load_scenario(EXAMPLES / "13_lifelong" / "scenario.yaml")
    result = run_fleet(scenario, fleet=FleetSettings(until=240.0))
    assert len(installs) >= 10 and result.contacts_while_moving == 0
    assert violations == []
