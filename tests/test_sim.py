"""The simulator: the examples complete, people never meet a moving robot, files, CLI."""

from __future__ import annotations

import json
import math
import multiprocessing
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from cosmop.cli import app
from cosmop.control.geometry import box_gaps, point_segment_linf
from cosmop.control.paths import GlobalPath
from cosmop.events import Primitive, parse_event
from cosmop.planning import PlanSet
from cosmop.planning.messages import cut_drives
from cosmop.planning.plan_file import load_plan
from cosmop.planning.plan_types import ObjectState, Pose, RobotPlan, Step
from cosmop.scenario import load_scenario, parse_scenario
from cosmop.scene import Mission
from cosmop.sim import SIM_FORMAT, TRACE_FORMAT, SimSettings, simulate, time_limit
from cosmop.sim.motion import crawl, creep_is_safe
from cosmop.sim.world import World
from cosmop.team.loop import plan_team
from cosmop.traces import Trace, TraceError, _rounded, as_trace, load_trace
from team_checks import assert_complete_word, assert_no_overlap

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
DATA = Path(__file__).resolve().parent / "data"
runner = CliRunner()


def _planned(name: str):
    scenario = load_scenario(EXAMPLES / name / "scenario.yaml")
    return scenario, plan_team(scenario).plans


@pytest.fixture(scope="module")
def warehouse_2x2():
    return _planned("01_warehouse_2x2")


@pytest.fixture(scope="module")
def people_2x2():
    return _planned("03_people_2x2")


def _assert_done(result, scenario, plans) -> None:
    assert result.completed, result.finished
    assert all(result.finished.values())
    assert result.contacts_while_moving == 0
    delivered = result.objects_in_workspaces(scenario, plans)
    assert delivered and all(delivered.values()), delivered
    for rid, (pose, _) in result.robots.items():  # every mission ends with return
        home = scenario.scene.robots[rid].pose
        assert abs(pose[0] - home[0]) <= 20 and abs(pose[1] - home[1]) <= 20, (rid, pose)
    assert_complete_word(scenario, result)
    assert_no_overlap(scenario, result)


def _planned_messages(plans) -> set[str]:
    """Every message the plans send: away answers and msg events."""
    return {pair.event.name for pair in plans.coordination} | {m.event.name for m in plans.messages}


def test_2x2_completes_with_its_messages(warehouse_2x2):
    scenario, plans = warehouse_2x2
    result = simulate(scenario, plans)
    _assert_done(result, scenario, plans)
    assert {m.event for m in result.messages} == _planned_messages(plans)
    assert "away(O2,R1,R2)" in {m.event for m in result.messages}
    assert result.contacts == ()  # nobody else walks here: no contact at all
    assert result.replan_attempts == 0  # the conflicts are ordered: nobody stalls
    # R1 asked first and waited: it cannot leave home before R2 answered.
    i = result.robot_ids.index("R1")
    left = result.frames["t"][np.argmax(np.any(result.frames["v"][:, [i]] > 0, axis=1))]
    assert left >= result.messages[0].t


def test_10x10_completes():
    scenario, plans = _planned("02_warehouse_10x10")
    result = simulate(scenario, plans)
    _assert_done(result, scenario, plans)
    assert len(result.messages) == len(plans.coordination) + len(plans.messages)
    assert {m.event for m in result.messages} == _planned_messages(plans)
    # the warehouse is wider than a robot's reach, so the neighbourhood cut-off drops walls and
    # robots from each window: scoring everything against everything moves every robot the same
    full = simulate(scenario, plans, settings=SimSettings(max_time=40.0, neighbourhood=False))
    n = len(full.frames["t"])
    np.testing.assert_array_equal(result.frames["pose"][:n], full.frames["pose"])


def test_the_time_limit_grows_with_the_planned_makespan(warehouse_2x2):
    scenario, plans = warehouse_2x2
    makespan = plans.itinerary.makespan
    assert 0 < makespan < 300  # the 2x2: the least limit holds
    assert time_limit(scenario, plans) == 900.0
    assert time_limit(scenario, plans, SimSettings(max_time=12.5)) == 12.5
    # the same plans expected to take ten times as long: three times that
    slow = replace(
        plans,
        itinerary=replace(
            plans.itinerary,
            times={
                r: tuple((a * 10, b * 10) for a, b in slots) for r, slots in plans.itinerary.times.items()
            },
        ),
    )
    assert time_limit(scenario, slow) == pytest.approx(30 * makespan)
    short = simulate(scenario, slow, settings=SimSettings(max_time=5.0))
    assert not short.completed and short.sim_time_s == pytest.approx(5.0)


def test_static_gaps_measure_near_walls_first_and_give_the_gaps_to_every_wall():
    # a map of 26 x 16 walls a metre apart: most walls are far from most points
    rows = [((x, y), (x + 800.0, y)) for x in range(0, 26_000, 1000) for y in range(0, 16_000, 1000)]
    data = {
        "name": "many walls",
        "scene": {
            "obstacles": [[list(a), list(b)] for a, b in rows],
            "robots": {"R1": {"size": 400, "pose": [500, 500, 0]}},
            "objects": {"O1": {"size": 100, "position": [7500, 4500]}},
            "workspaces": {"W1": {"x": [9100, 9900], "y": [9100, 9900]}},
        },
        "mission": {"tasks": {"R1": ["pick O1", "drop O1 at W1", "return"]}},
    }
    world = World(parse_scenario(data), PlanSet("many walls", True, {}), 0, SimSettings())
    rng = np.random.default_rng(5)
    for spread in (1.0, 80.0, 900.0, 3000.0, 40_000.0):  # one point, a way out's fan, the map
        centre = rng.uniform(0, 26_000, 2)
        points = centre + rng.uniform(-spread, spread, (60, 2))
        brute = np.minimum(
            (point_segment_linf(points, world.walls) - 200.0).min(axis=1),
            box_gaps(points, 200.0, world.resting_boxes()).min(axis=1),
        )
        np.testing.assert_array_equal(world.static_gaps(points, 200.0), brute)


def test_static_gaps_remembered_are_forgotten_when_an_object_is_picked_or_moved():
    data = {
        "name": "one object",
        "scene": {
            "obstacles": [[[0, 0], [4000, 0]]],
            "robots": {"R1": {"size": 400, "pose": [500, 2000, 0]}},
            "objects": {"O1": {"size": 100, "position": [2000, 1000]}},
            "workspaces": {"W1": {"x": [3000, 3900], "y": [3000, 3900]}},
        },
        "mission": {"tasks": {"R1": ["pick O1", "drop O1 at W1", "return"]}},
    }
    world = World(parse_scenario(data), PlanSet("one object", True, {}), 0, SimSettings())
    beside = np.array([[2000.0, 1400.0]])  # 150 mm from the object, 1.2 m from the wall
    assert world.static_gaps(beside, 200.0)[0] == pytest.approx(150.0)
    world.static_gaps(beside, 200.0)[0] = -1.0  # a caller's copy: the memory is not touched
    assert world.static_gaps(beside, 200.0)[0] == pytest.approx(150.0)
    assert world.static_gaps(beside, 100.0)[0] == pytest.approx(250.0)  # another robot's size
    world.carried_by[0] = 0  # picked up: only the wall is left
    assert world.static_gaps(beside, 200.0)[0] == pytest.approx(1200.0)
    world.carried_by[0] = -1
    world.object_xy[0] = (2000.0, 1700.0)  # dropped elsewhere, closer
    assert world.static_gaps(beside, 200.0)[0] == pytest.approx(50.0)


def _run_seed(job):
    scenario, plans, seed = job
    result = simulate(scenario, plans, seed=seed, settings=SimSettings(max_time=600))
    delivered = result.objects_in_workspaces(scenario, plans)
    return result.completed, result.contacts_while_moving, all(delivered.values()), len(result.contacts)


def test_seeded_runs_with_people_crossing(people_2x2):
    # a sample of 6 seeds; benchmarks/sweep_people.py runs 200 (200 of 200 complete)
    scenario, plans = people_2x2
    jobs = [(scenario, plans, seed) for seed in range(6)]
    with multiprocessing.get_context("fork").Pool(2) as pool:
        outcomes = pool.map(_run_seed, jobs)
    assert all(completed for completed, _, _, _ in outcomes)
    assert sum(moving for _, moving, _, _ in outcomes) == 0
    assert all(delivered for _, _, delivered, _ in outcomes)
    # The people did meet the robots (they walk into standing ones): the test is not vacuous.
    assert sum(contacts for _, _, _, contacts in outcomes) > len(jobs)


def test_person_in_the_doorway_makes_r1_wait():
    scenario, plans = _planned("04_doorway_2x2")
    result = simulate(scenario, plans)
    _assert_done(result, scenario, plans)
    frames, i = result.frames, result.robot_ids.index("R1")
    entered = frames["t"][np.argmax(frames["pose"][:, i, 1] > 0)]  # into the left room, above y = 0
    stands = scenario.scene.humans["H1"].path[0][2]
    assert entered >= stands  # only once the person has left the doorway
    assert result.replan_attempts >= 1  # it stalled and looked for another way (there is none)
    free, free_plans = _planned("01_warehouse_2x2")
    plain = simulate(free, free_plans)
    plain_entered = plain.frames["t"][np.argmax(plain.frames["pose"][:, i, 1] > 0)]
    assert entered - plain_entered > 20  # it waited


def test_same_seed_same_run(people_2x2):
    scenario, plans = people_2x2
    a = simulate(scenario, plans, seed=7, settings=SimSettings(max_time=40))
    b = simulate(scenario, plans, seed=7, settings=SimSettings(max_time=40))
    c = simulate(scenario, plans, seed=8, settings=SimSettings(max_time=40))
    assert np.array_equal(a.frames["pose"], b.frames["pose"])
    assert np.array_equal(a.frames["humans"], b.frames["humans"])
    assert not np.array_equal(a.frames["humans"], c.frames["humans"])


def test_summary_and_trace_files(tmp_path, people_2x2):
    scenario, plans = people_2x2
    result = simulate(scenario, plans, seed=3, settings=SimSettings(max_time=30))
    result.save_summary(tmp_path / "s.json")
    result.save_trace(tmp_path / "t.json")
    summary = json.loads((tmp_path / "s.json").read_text())
    assert summary["format"] == SIM_FORMAT
    for key, kind in {
        "completed": bool,
        "sim_time_s": float,
        "wall_time_s": float,
        "contacts": int,
        "contacts_while_moving": int,
        "replans": int,
    }.items():
        assert isinstance(summary[key], kind), key
    assert summary["completed"] is False and summary["sim_time_s"] == pytest.approx(30.0)
    assert set(summary["objects"]) == {"O1", "O2"}
    assert set(summary["objects"]["O1"]) == {"position", "carried_by"}
    assert set(summary["robots"]["R1"]) == {"pose", "distance_mm"}
    trace = json.loads((tmp_path / "t.json").read_text())
    assert trace["format"] == TRACE_FORMAT and trace["dt"] == pytest.approx(0.1)
    assert len(trace["frames"]) == result.cycles + 1  # instant 0 and every cycle
    frame = trace["frames"][-1]
    assert set(frame) == {"t", "robots", "humans", "objects"}
    assert set(frame["robots"]["R1"]) >= {"pose", "v", "w", "carrying"}
    assert set(frame["humans"]) == {"H1", "H2"}
    # the run's Trace is the one its file reads back, array for array
    run, back = result.trace(), load_trace(tmp_path / "t.json")
    assert back.to_json() == run.to_json() == trace
    for name in ("t", "poses", "v", "w", "carrying", "waiting", "humans", "objects"):
        assert np.array_equal(getattr(back, name), getattr(run, name)), name
    names = np.array(run.primitive_names, dtype=object)[run.primitive]
    assert (names == np.array(back.primitive_names, dtype=object)[back.primitive]).all()
    assert not run.poses.flags.writeable and result.frames["pose"].flags.writeable


@settings(max_examples=300)
@given(
    values=st.lists(
        st.one_of(
            st.floats(allow_nan=True, allow_infinity=True),
            st.integers(-(10**9), 10**9).map(lambda k: k / 2000),  # ties at the third decimal
            st.integers(-(10**9), 10**9).map(lambda k: k / 2_000_000),  # and at the sixth
        ),
        min_size=1,
        max_size=40,
    ),
    digits=st.sampled_from([3, 6]),
)
def test_trace_values_are_rounded_exactly_as_round_rounds_them(values, digits):
    # the files keep their bytes: the vectorised rounding must be Python's round, ties included
    out = _rounded(np.array(values, dtype=float), digits)
    for x, y in zip(values, out.tolist(), strict=True):
        expected = round(x, digits) if np.isfinite(x) else x
        assert (y == expected and np.signbit(y) == np.signbit(expected)) or (np.isnan(x) and np.isnan(y))


def _frame(t, robots, humans=None, objects=None):
    return {"t": t, "robots": robots, "humans": humans or {}, "objects": objects or {}}


def test_a_trace_of_another_tool_may_name_other_things_in_other_frames(tmp_path):
    data = {
        "format": TRACE_FORMAT,
        "frames": [
            _frame(0, {"R2": {"pose": [0, 0, 90]}}, objects={"O1": [5, 5]}),
            _frame(
                1, {"R1": {"pose": [1, 2, 3], "carrying": "O9"}, "R2": {"pose": [1, 0, 90]}}, {"H1": [7, 8]}
            ),
        ],
    }
    trace = as_trace(data)
    assert trace.robot_ids == ("R2", "R1") and trace.human_ids == ("H1",)
    assert trace.object_ids == ("O1", "O9")  # O9 is only ever carried
    assert np.isnan(trace.poses[0, 1]).all() and trace.poses[1, 1].tolist() == [1, 2, 3]
    assert np.isnan(trace.humans[0, 0]).all() and np.isnan(trace.objects[1]).all()
    assert trace.carrying.tolist() == [[-1, -1], [-1, 1]] and trace.v is None and trace.waiting is None
    assert list(trace.robots_at(0)) == ["R2"] and trace.carried_at(1) == {"O9": "R1"}
    assert trace.dt is None and trace.scenario is None and as_trace(trace) is trace
    # written back: what each frame showed (an unsaid cargo is none), and no more
    expected = _frame(0.0, {"R2": {"pose": [0.0, 0.0, 90.0], "carrying": None}}, {}, {"O1": [5.0, 5.0]})
    assert trace.to_json()["frames"][0] == expected
    assert trace.to_json()["frames"][1]["robots"]["R1"] == {"pose": [1.0, 2.0, 3.0], "carrying": "O9"}
    trace.save(tmp_path / "t.json")
    assert load_trace(tmp_path / "t.json").to_json() == trace.to_json()
    with pytest.raises(ValueError, match="read-only"):
        trace.poses[0, 0, 0] = 1.0


def test_a_long_trace_is_written_block_by_block_as_one_document(tmp_path, people_2x2, monkeypatch):
    # frames go to the file a block at a time; the bytes are those of the whole document at
    # once, across blocks with and without frames that leave a robot or a speed out
    import cosmop.traces as traces

    scenario, plans = people_2x2
    data = simulate(scenario, plans, seed=3, settings=SimSettings(max_time=12)).trace().to_json()
    for frame in data["frames"][30:45]:  # frames of the second and third blocks below
        del frame["robots"]["R1"]
        frame["robots"]["R2"].pop("v")
    trace = as_trace(data)
    monkeypatch.setattr(traces, "_FRAMES_PER_BLOCK", 17)
    trace.save(tmp_path / "t.json")
    whole = json.dumps(trace.to_json(), separators=(",", ":")) + "\n"
    assert (tmp_path / "t.json").read_bytes() == whole.encode()  # newlines as written
    assert len(trace.t) > 3 * 17 and "R1" not in json.loads(whole)["frames"][40]["robots"]


def test_a_bad_trace_names_the_file_and_the_field(tmp_path):
    bad = {"format": TRACE_FORMAT, "frames": [_frame(0, {"R1": {"pose": [0, 0, 0], "v": "fast"}})]}
    (tmp_path / "bad.json").write_text(json.dumps(bad))
    with pytest.raises(TraceError, match=r"bad\.json: frames\[0\]\.robots\.R1\.v: expected a speed"):
        load_trace(tmp_path / "bad.json")
    with pytest.raises(ValueError, match="frames"):  # a TraceError is a ValueError too
        as_trace({"format": TRACE_FORMAT, "frames": []})
    with pytest.raises(ValueError, match=r"Trace\.poses must have the shape \(2, 1, 3\)"):
        Trace(t=[0.0, 1.0], robot_ids=("R1",), poses=np.zeros((2, 2, 3)))


def test_plans_are_executed_as_written(warehouse_2x2):
    # the messages that keep robots apart sit where the plan put them: every robot realises
    # its plan's mission -- its events, the messages it sends and awaits -- in the plan's order
    scenario, plans = warehouse_2x2
    result = simulate(scenario, plans)
    for rid, plan in plans.robots.items():
        done = [event for _, robot, event in result.events if robot == rid]
        assert done == [e.name for e in plan.mission], rid


def test_cli_simulate(tmp_path, warehouse_2x2):
    _, plans = warehouse_2x2
    plans.save(tmp_path / "plan.json")
    result = runner.invoke(
        app,
        [
            "simulate",
            str(EXAMPLES / "01_warehouse_2x2" / "scenario.yaml"),
            "--plan",
            str(tmp_path / "plan.json"),
            "--summary",
            str(tmp_path / "summary.json"),
        ],
        env={"COLUMNS": "200"},
    )
    assert result.exit_code == 0, result.output
    assert "completed" in result.output
    assert json.loads((tmp_path / "summary.json").read_text())["completed"] is True


def test_cli_simulate_rejects_a_plan_for_another_scenario(tmp_path, warehouse_2x2):
    _, plans = warehouse_2x2
    plans.save(tmp_path / "plan.json")
    result = runner.invoke(
        app,
        [
            "simulate",
            str(EXAMPLES / "02_warehouse_10x10" / "scenario.yaml"),
            "--plan",
            str(tmp_path / "plan.json"),
            "--summary",
            str(tmp_path / "summary.json"),
        ],
    )
    assert result.exit_code == 2
    assert "plan.json" in result.output and "Traceback" not in result.output
    assert len(result.output.strip().splitlines()) == 1
    assert not (tmp_path / "summary.json").exists()


def test_cli_simulate_bad_plan_file(tmp_path):
    bad = tmp_path / "plan.json"
    bad.write_text('{"format": "cosmop.plan/1", "robots": 3}')
    result = runner.invoke(
        app, ["simulate", str(EXAMPLES / "01_warehouse_2x2" / "scenario.yaml"), "--plan", str(bad)]
    )
    assert result.exit_code == 2
    assert result.output.startswith("error: ") and "Traceback" not in result.output


def test_robot_stopped_beside_its_waypoint_creeps_back_onto_the_segment():
    # The plan's second drive runs along the top of a wall block, touching it (allowed).  The
    # robot starts 14 mm below the drive's start, within the tolerance of its first waypoint:
    # the straight way from where it stands runs into the block's corner, so it must first
    # creep back onto the segment -- aiming along the path, it would stand there for ever.
    from cosmop.planning.plan_types import PlanSet
    from cosmop.planning.primitive_effects import plan_from_actions
    from cosmop.scenario import parse_scenario

    box = [[-2000, -1500], [0, -1500], [0, 0], [-2000, 0]]
    room = [[-3000, -2000], [3000, -2000], [3000, 2000], [-3000, 2000]]
    walls = [[a, b] for ring in (box, room) for a, b in zip(ring, ring[1:] + ring[:1], strict=True)]
    scenario = parse_scenario(
        {
            "name": "corner",
            "scene": {
                "obstacles": walls,
                "robots": {"R1": {"size": 400, "pose": [201, 186, 0]}},
                "objects": {"O1": {"size": 100, "position": [2500, 1500]}},
                "workspaces": {"W1": {"x": [1500, 2900], "y": [-1900, -1000]}},
            },
            "mission": {"tasks": {"R1": ["return"]}},
        }
    )
    actions = [
        ("GoTo", (200, 200, 180)),
        ("GoTo", (-1500, 200, 180)),
        ("GoTo", (200, 200, 0)),
        ("GoTo", (201, 186, 0)),
    ]
    plan = plan_from_actions(scenario.scene, "R1", [parse_event("return(R1)")], actions)
    plans = PlanSet("corner", True, {"R1": plan})
    result = simulate(scenario, plans, settings=SimSettings(max_time=120, replan=False))
    assert result.completed
    assert result.contacts_while_moving == 0
    west = result.frames["pose"][:, 0, 0].min()
    assert west <= -1500 + SimSettings().pass_tolerance  # it drove the segment, not around


def test_own_boxes_of_some_robots_are_those_rows_of_all():
    data = {
        "name": "three robots",
        "scene": {
            "obstacles": [[[0, 0], [6000, 0]]],
            "robots": {
                r: {"size": 400, "pose": [1000 + 1500 * k, 2000, 0]} for k, r in enumerate(("A", "B", "C"))
            },
            "objects": {"O1": {"size": 100, "position": [2000, 1000]}},
            "workspaces": {"W1": {"x": [3000, 3900], "y": [3000, 3900]}},
        },
        "mission": {"tasks": {"A": ["pick O1", "drop O1 at W1", "return"]}},
    }
    world = World(parse_scenario(data), PlanSet("three robots", True, {}), 0, SimSettings())
    sensed = world.obstacles()
    every = world.own_boxes(sensed)
    assert every.sum() == 3 and [sensed.names[j] for j in every.argmax(axis=1)] == ["A", "B", "C"]
    np.testing.assert_array_equal(world.own_boxes(sensed, np.array([2, 0])), every[[2, 0]])


def test_a_robot_waiting_for_a_message_holds_no_robot_that_must_send_it():
    # Example 08 with R2 listed first: R2 waits for R1's message, parked within R1's standoff
    # while R1's gripper works.  Were R2 to hold R1 there (it is listed first), R1 could never
    # finish and send what R2 waits for; once the message is out, R2 may leave and holds R1.
    import yaml

    data = yaml.safe_load((EXAMPLES / "08_ordered" / "scenario.yaml").read_text())
    data["scene"]["robots"] = dict(reversed(list(data["scene"]["robots"].items())))
    scenario = parse_scenario(data)
    world = World(scenario, plan_team(scenario).plans, 0, SimSettings())
    r2, r1 = world.agents  # R2 first
    r1.step_index = next(k for k, s in enumerate(r1.steps) if s.primitive == "DropOff")
    r1.dock_stage = "handle"
    r2.step_index = next(k for k, s in enumerate(r2.steps) if s.primitive == "Req")
    r2.waiting = True
    world.pose[r1.index] = [*r1.step.robot[:2], r1.step.robot[2]]
    inside = world.settings.dwa.standoff / 2  # apart by half the standoff: within it
    world.pose[r2.index] = world.pose[r1.index] + [0.0, 400.0 + inside, 0.0]
    world.v[:] = 0.0
    assert world.parked().all() and not world.received(r2, r2.step)
    assert not world.crowded(r1.index)
    world.sent_messages.add(r2.step.message)
    assert world.crowded(r1.index)  # R2 may leave now: R1 keeps its promise


def test_goods_are_put_down_only_where_no_robot_has_come_during_the_handling():
    # The drop's spot is checked before the gripper works and again when it lets go: a robot
    # that drove up during the handling time must not find goods appearing against it.
    from cosmop.sim.execute import decide

    scenario = load_scenario(EXAMPLES / "01_warehouse_2x2" / "scenario.yaml")
    world = World(scenario, plan_team(scenario).plans, 0, SimSettings())
    giver = next(a for a in world.agents if any(s.primitive == "DropOff" for s in a.steps))
    other = next(a for a in world.agents if a is not giver)
    giver.step_index = next(k for k, s in enumerate(giver.steps) if s.primitive == "DropOff")
    step = giver.step
    j = world.object_ids.index(step.object)
    world.carried_by[j] = giver.index
    world.pose[giver.index] = [*step.robot[:2], np.radians(step.robot[2])]
    giver.dock_stage, giver.handling_left = "handle", world.dt  # the gripper's last cycle
    spot = np.array(step.objects[step.object].position, dtype=float)
    away = spot - world.pose[giver.index, :2]  # beyond the spot, seen from the giver
    away /= np.abs(away).max()
    reach = world.robot_half[other.index] + world.object_half[j] + 20.0  # 20 mm from the goods
    world.pose[other.index] = [*(spot + away * reach), 0.0]
    world.v[:] = 0.0
    world.v[other.index] = 300.0  # driving: its stopping distance is far more than 20 mm
    assert not world.crowded(giver.index)  # the giver itself is not crowded: only its spot is
    decide(world, giver)
    assert world.carried_by[j] == giver.index  # held: the goods would appear against a mover
    world.pose[other.index] = [*(spot + away * (reach + 2000.0)), 0.0]  # it has driven on
    decide(world, giver)
    assert world.carried_by[j] == -1 and np.allclose(world.object_xy[j], spot)


def _aisle_world(other: tuple[float, float]) -> World:
    """A 500 mm robot 4 mm right of a good's corner and 19 mm too high to pass below it (the
    stall of a 50-robot run), and a second robot at `other`."""
    data = {
        "name": "tight aisle",
        "scene": {
            "obstacles": [[[0, 0], [6000, 0]]],
            "robots": {
                "R1": {"size": 500, "pose": [1854, 1568.6, 180]},
                "R2": {"size": 500, "pose": [*other, 0]},
            },
            "objects": {"O1": {"size": 200, "position": [1500, 1900]}},
            "workspaces": {"W1": {"x": [5000, 5900], "y": [3000, 3900]}},
        },
        "mission": {"tasks": {"R1": ["pick O1", "drop O1 at W1", "return"]}},
    }
    world = World(parse_scenario(data), PlanSet("tight aisle", True, {}), 0, SimSettings())
    world.agents[0].path = GlobalPath(((1854.0, 1568.6), (1851.0, 1549.0), (400.0, 1449.0)), 0.8)
    return world


def test_a_robot_stuck_in_a_tight_aisle_creeps_along_its_path_and_not_into_a_robot():
    world = _aisle_world((5000, 3000))
    agent = world.agents[0]
    kind, pose = crawl(world, agent)
    # to the path's next vertex (20 mm away, not past it), turned towards it
    assert kind == "dock" and pose[:2] == pytest.approx((1851.0, 1549.0))
    assert pose[2] == pytest.approx(np.degrees(np.arctan2(-19.6, -3.0)))
    # straight on to a pose clear of the good, but cutting its corner on the way: refused
    assert world.static_gaps(np.array([[1000.0, 1500.0]]), 250.0)[0] > 0
    assert not creep_is_safe(world, agent, (1000.0, 1500.0, 180.0))
    assert creep_is_safe(world, agent, pose)
    # a robot 60 mm from the way: it waits for it as before, it does not creep up to it
    near = _aisle_world((1854, 1008.6))
    assert crawl(near, near.agents[0]) is None


def test_a_robot_beside_one_that_waits_for_its_message_creeps_on():
    # the robot 60 mm from the way stands waiting for a message nobody has sent (R1's, say): it
    # cannot move before the message comes, so creeping past it crowds no one that may move
    near = _aisle_world((1854, 1008.6))
    waiter = near.agents[1]
    event = parse_event("msg(R1,R2,clear1)")
    waiter.steps = [Step(Primitive.REQ, None, (1854.0, 1008.6, 0.0), {}, event)]
    waiter.waiting = True
    assert near.held(waiter)
    kind, pose = crawl(near, near.agents[0])
    assert kind == "dock" and pose[:2] == pytest.approx((1851.0, 1549.0))
    near.sent_messages.add(event)  # the message came: it may leave at any moment
    assert not near.held(waiter) and crawl(near, near.agents[0]) is None


def test_a_robot_stopped_at_a_wall_end_beside_one_waiting_for_it_goes_on_without_a_replan():
    # R1 stops touching the end of a wall (the plan passes it 9 mm off) while R4 stands 96 mm
    # from its way waiting for R1's message: R1 creeps along its path instead of standing until
    # it replans a long way round (82.4 s instead of 63.9 s for the plans before)
    scenario = load_scenario(DATA / "wall_end" / "scenario.yaml")
    plans = load_plan(DATA / "wall_end" / "plan.json")
    result = simulate(scenario, plans)
    _assert_done(result, scenario, plans)
    assert result.replans == 0 and result.sim_time_s < 75.0


def _cut_into(plan: RobotPlan, start: Pose, pieces: int) -> RobotPlan:
    """`plan` with every GoTo longer than a metre cut into `pieces` collinear GoTos, as the
    team cuts a drive at the places robots share (:func:`cosmop.planning.messages.cut_drives`)."""
    cuts, here = {}, start
    for k, step in enumerate(plan.steps, 1):
        if step.primitive == Primitive.GOTO and math.dist(here[:2], step.robot[:2]) > 1000.0:
            cuts[k] = [n / pieces for n in range(1, pieces)]
        here = step.robot
    return cut_drives(plan, start, cuts)


def test_a_drive_cut_into_collinear_pieces_is_driven_at_the_pace_of_the_whole():
    # cuts at the places robots share add waypoints on the same straight segment; a robot that
    # passes them (nothing to wait for) aims past each one and keeps its speed
    scenario = load_scenario(EXAMPLES / "02_warehouse_10x10" / "scenario.yaml")
    alone = replace(
        scenario,
        scene=replace(scenario.scene, robots={"R1": scenario.scene.robots["R1"]}),
        mission=Mission(tasks={"R1": scenario.mission.tasks["R1"]}),
    )
    plans = plan_team(alone).plans
    cut = replace(
        plans,
        itinerary=None,
        robots={"R1": _cut_into(plans.robots["R1"], alone.scene.robots["R1"].pose, 6)},
    )
    assert cut.robots["R1"].horizon >= plans.robots["R1"].horizon + 10
    whole, pieces = simulate(alone, plans), simulate(alone, cut)
    _assert_done(pieces, alone, cut)
    assert pieces.sim_time_s <= 1.05 * whole.sim_time_s, (pieces.sim_time_s, whole.sim_time_s)


def test_a_robot_drives_an_aisle_lined_with_goods_at_the_planned_pace():
    # goods on both shelf faces, 50 mm from the robot: braking straight on along the aisle keeps
    # clear, so the robot steers and keeps its speed there (before: 128.3 s, crawling and
    # wobbling, for a plan of 72.2 s)
    scenario = load_scenario(DATA / "goods_aisle" / "scenario.yaml")
    plans = plan_team(scenario, workers=1).plans
    result = simulate(scenario, plans)
    _assert_done(result, scenario, plans)
    assert result.sim_time_s <= 1.05 * plans.itinerary.makespan, (result.sim_time_s, plans.itinerary.makespan)


def test_two_robots_docked_side_by_side_both_put_their_goods_down():
    # Each robot drops goods 30 mm from the other robot, which the plan allows (goods and robot
    # bodies apart).  Goods may not appear within the standoff of a robot that may move, so
    # each waited for the other to park or leave: neither ever dropped.  A robot docked on its
    # pose stays there until its gripper has worked: it is parked, and both drop.
    from cosmop.sim.execute import decide

    hr, ho, gap = 250.0, 100.0, 30.0
    poses = {"A": (0.0, 0.0, 0.0), "B": (2 * hr + 2 * ho + gap, hr + ho + gap, 180.0)}
    spots = {"A": (hr + ho, 0.0), "B": (hr + ho + gap, hr + ho + gap)}
    data = {
        "name": "side-by-side",
        "scene": {
            "robots": {r: {"size": 2 * hr, "pose": list(p)} for r, p in poses.items()},
            "objects": {
                f"O{r}": {"size": 2 * ho, "position": [-3000.0, 3000.0 * k]} for k, r in enumerate(poses)
            },
            "workspaces": {
                f"W{r}": {"x": [x - ho, x + ho], "y": [y - ho, y + ho]} for r, (x, y) in spots.items()
            },
        },
        "mission": {"tasks": {r: [f"pick O{r}", f"drop O{r} at W{r}"] for r in poses}},
    }
    scenario = parse_scenario(data)
    plans = {
        r: RobotPlan.from_steps(
            [parse_event(f"drop({r},O{r},W{r})")],
            [Step("DropOff", f"O{r}", poses[r], {f"O{r}": ObjectState(spots[r], False, False)})],
        )
        for r in poses
    }
    world = World(scenario, PlanSet(scenario.name, True, plans), 0, SimSettings())
    for agent in world.agents:
        world.carried_by[world.object_ids.index(f"O{agent.id}")] = agent.index
    world.v[:] = 0.0
    for _ in range(int(world.settings.handling_time / world.dt) + 5):
        for agent in world.agents:
            kind, command = decide(world, agent)
            assert (kind, command) == ("move", (0.0, 0.0))  # both stand where they docked
    assert all(agent.done for agent in world.agents)
    assert (world.carried_by < 0).all()  # both goods put down
    assert [tuple(world.object_xy[world.object_ids.index(f"O{r}")]) for r in poses] == list(spots.values())
