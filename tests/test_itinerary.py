"""Timed itineraries: every plan step's expected start and end, in the plan file and beside the
realised times of a simulated run.

The one-lane corridor (example 07) is the case where times matter: R2 waits about half a
minute for R1 to clear the corridor, and that wait must show in the itinerary.
"""

from __future__ import annotations

import copy
import json
from dataclasses import replace
from pathlib import Path

import pytest
from typer.testing import CliRunner

from cosmop.cli import app
from cosmop.errors import CosmopInputError
from cosmop.planning.plan_file import PlanError, load_plan, read_plan
from cosmop.planning.plan_types import Itinerary
from cosmop.planning.realisation import message_links
from cosmop.scenario import load_scenario
from cosmop.sim import simulate
from cosmop.sim.realised_times import StepTimes, carry_instants, step_times
from cosmop.team.loop import plan_team
from cosmop.team.plan_set_checker import check_plan
from cosmop.team.timing import durations, itinerary

CORRIDOR = Path(__file__).resolve().parents[1] / "examples" / "07_corridor" / "scenario.yaml"
runner = CliRunner()


@pytest.fixture(scope="module")
def corridor():
    scenario = load_scenario(CORRIDOR)
    result = plan_team(scenario)
    assert result.plans.feasible and result.plans.itinerary is not None
    return scenario, result


@pytest.fixture(scope="module")
def corridor_run(corridor):
    scenario, result = corridor
    return simulate(scenario, result.plans)


def test_every_step_is_timed_and_waits_show_on_the_req(corridor):
    scenario, result = corridor
    plans = result.plans.robots
    times = result.plans.itinerary.times
    expected = durations(scenario.scene, plans)
    for robot, plan in plans.items():
        slots = times[robot]
        assert len(slots) == plan.horizon and slots[0][0] == 0.0
        for k, ((start, end), step) in enumerate(zip(slots, plan.steps, strict=True)):
            assert start == (slots[k - 1][1] if k else 0.0)  # a step starts when the previous ends
            if step.primitive != "Req":
                assert end - start == pytest.approx(expected[robot][k], abs=2e-3)
    waits = 0
    for link in message_links(plans):  # a wait ends exactly when its message is sent, or at once
        start, end = times[link.receiver][link.wait - 1]
        sent = times[link.sender][link.send - 1][1]
        assert end == pytest.approx(max(start, sent), abs=1e-3)
        waits += end > start + 1.0
    assert waits >= 1  # the corridor: one robot waits for the other to clear it
    assert result.plans.itinerary.makespan == pytest.approx(result.safety.makespan, abs=1e-3)


def test_the_plan_file_carries_the_itinerary_and_old_files_still_load(corridor, tmp_path):
    scenario, result = corridor
    path = tmp_path / "plan.json"
    result.plans.save(path)
    data = json.loads(path.read_text())
    (robot, k) = next(  # the step that waits for a message
        (r, k)
        for r, plan in data["robots"].items()
        for k, s in enumerate(plan["steps"])
        if s["primitive"] == "Req"
    )
    step = data["robots"][robot]["steps"][k]
    assert list(step)[:4] == ["primitive", "object", "message", "start"] and "end" in step
    loaded = load_plan(path)
    assert loaded == result.plans and loaded.itinerary == result.plans.itinerary
    text = loaded.to_text()
    start, end = loaded.itinerary.slot(robot, k + 1)
    assert f"{start:7.1f}-{end:<7.1f}s" in text
    for plan in data["robots"].values():  # a plan file of before: no times at all
        for s in plan["steps"]:
            del s["start"], s["end"]
    old = read_plan(data)
    assert old.itinerary is None and check_plan(scenario, old).ok
    assert old.robots == result.plans.robots


def _drop(key):
    def edit(data):
        del data["robots"]["R1"]["steps"][2][key]

    return edit


def _set(robot, k, key, value):
    def edit(data):
        data["robots"][robot]["steps"][k][key] = value

    return edit


def _untimed(robot):
    def edit(data):
        for s in data["robots"][robot]["steps"]:
            del s["start"], s["end"]

    return edit


@pytest.mark.parametrize(
    ("edit", "field", "words"),
    [
        (_drop("end"), "robots.R1.steps[2].end", "missing required key 'end': expected a time (s)"),
        (_set("R1", 2, "end", 0.5), "robots.R1.steps[2].end", ">= the step's start"),
        (_set("R1", 3, "start", 1.0), "robots.R1.steps[3].start", "when the step before ends"),
        (_set("R1", 0, "start", -1), "robots.R1.steps[0].start", ">= 0"),
        (
            _set("R1", 0, "start", "soon"),
            "robots.R1.steps[0].start",
            "expected a time in seconds (the step's expected start), got 'soon'",
        ),
        (_untimed("R2"), "robots.R2.steps", "as the other robots' steps have them"),
    ],
)
def test_bad_times_name_the_field(corridor, edit, field, words):
    _, result = corridor
    data = copy.deepcopy(result.plans.to_dict())
    edit(data)
    with pytest.raises(PlanError) as err:
        read_plan(data, file="plan.json")
    assert err.value.field == field and words in err.value.expected
    assert isinstance(err.value, CosmopInputError)


def test_the_checker_refuses_times_that_break_the_message_order(corridor):
    scenario, result = corridor
    plans = result.plans

    def waited(x) -> float:
        start, end = plans.itinerary.slot(x.receiver, x.wait)
        return end - start

    link = next(x for x in message_links(plans.robots) if waited(x) > 1.0)  # a wait that lasts
    times = {r: list(slots) for r, slots in plans.itinerary.times.items()}
    # the receiver stops waiting at once, and the rest of its plan moves up accordingly
    start = times[link.receiver][link.wait - 1][0]
    shift = times[link.receiver][link.wait - 1][1] - start
    times[link.receiver] = [
        (a, b) if k < link.wait - 1 else (max(start, a - shift), max(start, b - shift))
        for k, (a, b) in enumerate(times[link.receiver])
    ]
    bad = replace(plans, itinerary=Itinerary(times))
    report = check_plan(scenario, bad)
    assert not report.ok and {v.rule for v in report.violations} == {"itinerary"}
    assert link.event.name in report.violations[0].message
    assert check_plan(scenario, plans).ok


def test_itinerary_values_are_checked():
    with pytest.raises(ValueError, match="previous step ends"):
        Itinerary({"R1": [(0.0, 2.0), (1.0, 3.0)]})
    with pytest.raises(ValueError, match=">= 0"):
        Itinerary({"R1": [(-1.0, 2.0)]})
    with pytest.raises(ValueError, match="previous step ends"):
        Itinerary({"R1": [(0.0, 2.0), (3.0, 2.5)]})
    it = Itinerary({"R1": [(0.0, 2.0)], "R2": []})
    assert it.makespan == 2.0 and it.end("R2") == 0.0
    with pytest.raises(IndexError):
        it.slot("R1", 2)


def test_the_itinerary_must_time_exactly_the_plans(corridor):
    _, result = corridor
    with pytest.raises(ValueError, match="every step of every plan"):
        replace(result.plans, itinerary=Itinerary({"R1": [(0.0, 1.0)]}))


def test_a_deadlocking_plan_set_has_no_itinerary(corridor):
    scenario, result = corridor
    plans = dict(result.plans.robots)
    sender = next(r for r, plan in plans.items() if any(s.primitive == "Res" for s in plan.steps))
    plan = plans[sender]  # without its answers, a robot waits for ever
    plans[sender] = replace(
        plan,
        steps=tuple(s for s in plan.steps if s.primitive != "Res"),
        horizon=plan.horizon - sum(s.primitive == "Res" for s in plan.steps),
    )
    with pytest.raises(ValueError, match="deadlock"):
        itinerary(scenario.scene, plans)


def test_the_run_reports_realised_times_beside_planned_ones(corridor, corridor_run):
    _, result = corridor
    run = corridor_run
    assert run.completed and run.replans == 0
    it = result.plans.itinerary
    summary = run.summary()
    assert summary["makespan"]["planned"] == pytest.approx(it.makespan)
    assert summary["makespan"]["realised"] == pytest.approx(run.sim_time_s, abs=0.15)
    realised_end = {}
    for robot, plan in result.plans.robots.items():
        rows = summary["itinerary"][robot]
        assert [r["instant"] for r in rows] == list(range(1, plan.horizon + 1))
        assert [r["step"] for r in rows] == [s.label for s in plan.steps]
        assert [tuple(r["planned"]) for r in rows] == [tuple(round(v, 3) for v in s) for s in it.times[robot]]
        previous = 0.0
        for r in rows:
            start, end = r["realised"]
            assert start == pytest.approx(previous) and end >= start
            previous = end
        realised_end[robot] = [r["realised"][1] for r in rows]
    for link in message_links(result.plans.robots):  # nobody went on before its message was sent
        assert realised_end[link.receiver][link.wait - 1] >= realised_end[link.sender][link.send - 1]
    assert all(isinstance(row, StepTimes) for rows in run.steps.values() for row in rows)


def test_a_plan_file_without_times_is_compared_with_the_expected_ones(corridor, corridor_run):
    scenario, result = corridor
    untimed = replace(result.plans, itinerary=None)
    run = simulate(scenario, untimed, settings=None)
    assert [r.planned for r in run.steps["R1"]] == [r.planned for r in corridor_run.steps["R1"]]


def test_replanned_steps_have_no_instant_and_dropped_ones_no_realised_time():
    assert carry_instants("abc", [1, 2, 3], "axbc") == [1, None, 2, 3]
    assert carry_instants("abc", [4, 5, 6], "xyz") == [None, None, None]
    assert carry_instants("abc", [1, None, 3], "ac") == [1, 3]
    plan = Itinerary({"R1": [(0.0, 1.0), (1.0, 3.0), (3.0, 4.0)]})
    done = {"R1": [(1, "GoTo", 0.0, 1.5), (None, "GoTo", 1.5, 6.0)]}
    rows = step_times({"R1": ["GoTo", "PickUp(O1)", "GoTo"]}, plan, done)["R1"]
    assert [(r.instant, r.planned, r.realised) for r in rows] == [
        (1, (0.0, 1.0), (0.0, 1.5)),
        (None, None, (1.5, 6.0)),
        (2, (1.0, 3.0), None),
        (3, (3.0, 4.0), None),
    ]
    assert rows[0].delay == pytest.approx(0.5) and rows[1].delay is None
    assert rows[1].to_dict() == {"step": "GoTo", "instant": None, "planned": None, "realised": [1.5, 6.0]}


def test_the_cli_says_planned_beside_realised(corridor, tmp_path):
    _, result = corridor
    result.plans.save(tmp_path / "plan.json")
    args = [
        "simulate",
        str(CORRIDOR),
        "--plan",
        str(tmp_path / "plan.json"),
        "--summary",
        str(tmp_path / "s.json"),
    ]
    out = runner.invoke(app, args, env={"COLUMNS": "200"})
    assert out.exit_code == 0, out.output
    planned = result.plans.itinerary.makespan
    assert f"planned {planned:.1f} s" in out.output and "done at (planned)" in out.output
    assert json.loads((tmp_path / "s.json").read_text())["makespan"]["planned"] == pytest.approx(planned)
