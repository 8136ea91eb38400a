"""Robots delayed at random: the messages keep the order between them, and nobody is hit.

The heavy sweep (the 10x10 over 20 seeds) is ``benchmarks/sweep_delays.py``; here one seeded run of
the corridor, where each robot waits for the other to cross, and the bad input of ``--delays``.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from cosmop.cli import app
from cosmop.scenario import load_scenario
from cosmop.sim import Delays, SimSettings, simulate
from cosmop.sim.delays import DelayDraws
from cosmop.sim.world import Agent
from cosmop.team.loop import plan_team
from cosmop.traces import load_trace
from team_checks import assert_complete_word, assert_no_overlap

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
CORRIDOR = EXAMPLES / "07_corridor" / "scenario.yaml"
runner = CliRunner()


@pytest.fixture(scope="module")
def corridor():
    scenario = load_scenario(CORRIDOR)
    return scenario, plan_team(scenario, workers=1).plans


@pytest.fixture(scope="module")
def delayed_run(corridor):
    # 5 % a second, 2 to 10 s: some 20 stops in a run of about two minutes; seed 1 stops robots
    # while they drive, dock and wait for a message
    scenario, plans = corridor
    return simulate(scenario, plans, seed=1, settings=SimSettings(delays=Delays(0.05, 2.0, 10.0)))


def test_a_delayed_team_completes_in_the_order_its_messages_set(corridor, delayed_run):
    scenario, plans = corridor
    result = delayed_run
    assert result.completed and all(result.finished.values())
    assert result.contacts_while_moving == 0
    assert_complete_word(scenario, result)
    assert_no_overlap(scenario, result)
    # every robot realises its plan's events and messages in its plan's order...
    for rid, plan in plans.robots.items():
        assert [e for _, robot, e in result.events if robot == rid] == [e.name for e in plan.mission], rid
    # ...and every Req ends after the Res that sends its message, however late that came
    assert result.messages
    for message in result.messages:
        received = [t for t, robot, e in result.events if robot == message.receiver and e == message.event]
        assert received and received[0] >= message.t, message
    assert all(result.stops[rid] for rid in result.robot_ids)  # the delays struck both robots


def test_a_stopped_robot_brakes_and_stands_for_its_delay(delayed_run):
    result = delayed_run
    t, v, pose, delayed = (result.frames[k] for k in ("t", "v", "pose", "delayed"))
    dt = result.dt
    struck = {"moving": 0, "waiting": 0}
    for rid, stops in result.stops.items():
        i = result.robot_ids.index(rid)
        braking = 500.0  # mm/s^2, the corridor's robots
        for start, seconds in stops:
            k = int(np.argmin(np.abs(t - start)))  # the frame the stop struck in
            struck["moving"] += bool(v[k, i] > 0)
            struck["waiting"] += bool(result.frames["waiting"][k, i])
            stood = (t >= start + v[k, i] / braking + dt - 1e-9) & (t <= start + seconds - 1e-9)
            assert stood.any() and (v[stood, i] == 0).all(), (rid, start)
            assert np.ptp(pose[stood, i, :2], axis=0).max() == 0.0, (rid, start)  # not even a creep
            assert delayed[(t > start + 1e-9) & (t <= start + seconds - 1e-9), i].all(), (rid, start)
    assert struck["moving"] and struck["waiting"], struck  # the sample covers both


def test_the_summary_and_trace_report_the_delays(tmp_path, delayed_run):
    result = delayed_run
    result.save_summary(tmp_path / "s.json")
    result.save_trace(tmp_path / "t.json")
    report = json.loads((tmp_path / "s.json").read_text())["delays"]
    assert (report["p"], report["min_s"], report["max_s"]) == (0.05, 2.0, 10.0)
    for rid, stops in result.stops.items():
        assert report["robots"][rid]["count"] == len(stops)
        assert report["robots"][rid]["seconds"] == pytest.approx(sum(s for _, s in stops), abs=1e-3)
        assert all(2.0 <= s <= 10.0 for _, s in stops)
    assert report["count"] == len(report["log"]) == sum(len(s) for s in result.stops.values())
    assert report["seconds"] == pytest.approx(sum(r["seconds"] for r in report["robots"].values()), abs=1e-2)
    assert [e["t"] for e in report["log"]] == sorted(e["t"] for e in report["log"])
    back = load_trace(tmp_path / "t.json")
    assert back.delayed is not None and np.array_equal(back.delayed, result.frames["delayed"])


def test_delays_are_drawn_from_the_seed_alone():
    delays = Delays(0.3, 1.0, 4.0)
    a, b, c = (DelayDraws(delays, seed, 4).due(50.0) for seed in (7, 7, 8))
    assert a == b and a != c and a  # the same seed: the same stops
    assert all(0 <= i < 4 and 1.0 <= s <= 4.0 for i, s in a)
    assert DelayDraws(Delays(0.0, 1.0, 4.0), 7, 4).due(1000.0) == []
    assert len(DelayDraws(Delays(1.0, 1.0, 1.0), 7, 4).due(9.0)) == 4 * 10  # at 0, 1, ..., 9 s


def test_a_robots_own_stop_is_not_taken_for_a_stall():
    # its clocks of progress and of detours move on by the time it stood: a robot that stood
    # 14 s would otherwise replan (stall_time 12 s) the moment it drove on
    agent = Agent("R1", 0, (), ())
    agent.last_progress_t, agent.detour_until = 8.0, 9.0
    agent.stop_for(10.0, 14.0)
    assert agent.stopped_until == 24.0 and agent.stops == [(10.0, 14.0)]
    agent.resume(24.1)
    assert agent.stopped_until is None
    assert agent.last_progress_t == pytest.approx(22.1) and agent.detour_until == pytest.approx(23.1)


def test_cli_reports_the_delays_and_a_stop_cut_by_the_end(tmp_path, corridor):
    # every second both robots stop for 2 s: stopped 0-2, 2-4 and 4-5 s when the run ends at 5 s
    _, plans = corridor
    plans.save(tmp_path / "plan.json")
    args = ["simulate", str(CORRIDOR), "--plan", str(tmp_path / "plan.json"), "--max-time", "5"]
    result = runner.invoke(
        app, [*args, "--delays", "1:2:2", "--summary", str(tmp_path / "s.json")], env={"COLUMNS": "250"}
    )
    assert result.exit_code == 1, result.output  # not completed
    assert "delays stopped robots 6 times, 10.0 s in all" in result.output
    assert "3 times, 5.0 s" in result.output
    summary = json.loads((tmp_path / "s.json").read_text())
    assert summary["delays"]["robots"] == {rid: {"count": 3, "seconds": 5.0} for rid in ("R1", "R2")}
    assert all(robot["distance_mm"] == 0.0 for robot in summary["robots"].values())
    plain = runner.invoke(app, [*args, "--summary", str(tmp_path / "plain.json")])
    assert plain.exit_code == 1 and "delays" not in plain.output
    assert json.loads((tmp_path / "plain.json").read_text())["delays"] is None


@pytest.mark.parametrize(
    ("given", "said"),
    [
        ("0.01:2", "expected P:MIN:MAX"),
        ("a:2:10", "expected three numbers P:MIN:MAX"),
        ("0.01:2:10:4", "expected P:MIN:MAX"),
        ("1.5:2:10", "the probability P must be in [0, 1], got 1.5"),
        ("-0.1:2:10", "the probability P must be in [0, 1], got -0.1"),
        ("0.01:10:2", "the shortest stop MIN (10 s) must not exceed the longest stop MAX (2 s)"),
        ("0.01:-1:2", "the shortest stop MIN must be 0 s or more, got -1"),
        ("0.01:2:inf", "the longest stop MAX must be a finite number"),
        ("nan:2:10", "the probability P must be a finite number"),
    ],
)
def test_bad_delays_are_one_line_naming_the_option(tmp_path, given, said):
    out = tmp_path / "s.json"
    result = runner.invoke(app, ["simulate", str(CORRIDOR), "--delays", given, "--summary", str(out)])
    assert result.exit_code == 2
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and "--delays" in lines[0] and said in lines[0], result.output
    assert "Traceback" not in result.output and not out.exists()
    with pytest.raises(ValueError, match=re.escape(said)):
        Delays.parse(given)
