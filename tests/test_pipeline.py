"""The top-down ↔ bottom-up loop reproduces the paper's Example 1 and refuses what it cannot do."""

from __future__ import annotations

from pathlib import Path

import yaml

from cosmop.scenario import load_scenario, parse_scenario
from cosmop.team.loop import plan_team

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "01_warehouse_2x2" / "scenario.yaml"


def test_example_1_coordinated():
    result = plan_team(load_scenario(EXAMPLE))
    plans = result.plans
    assert plans.feasible and result.converged and result.iterations == 1
    assert [(c.object, c.requester, c.responder) for c in plans.coordination] == [("O2", "R1", "R2")]
    r1, r2 = plans.robots["R1"], plans.robots["R2"]
    assert result.results["R1"].horizon == 7 and r1.steps[0].label == "Req(O2)"
    assert result.results["R2"].horizon == 7 and "Res(O2)" in [s.label for s in r2.steps]

    def tasks(plan):  # the mission without the messages that keep the robots apart
        return tuple(e.name for e in plan.mission if e.kind != "msg")

    assert tasks(r1) == ("away(O2,R1,R2)", "pick(R1,O1)", "drop(R1,O1,W1)", "return(R1)")
    assert tasks(r2) == ("pick(R2,O2)", "away(O2,R1,R2)", "drop(R2,O2,W2)", "return(R2)")
    assert plans.messages and all(m.kind == "conflict" for m in plans.messages)
    assert result.safety.safe and result.safety.conflicts > 0
    assert result.verification.holds and result.report.ok
    assert set(result.phases) == {
        "decompose",
        "allocate",
        "synthesize",
        "coordinate",
        "conflicts",
        "verify",
        "check",
    }


def test_a_blocking_object_nobody_picks_is_set_aside_by_the_requester():
    data = yaml.safe_load(EXAMPLE.read_text())
    data["mission"]["tasks"] = {"R1": data["mission"]["tasks"]["R1"]}  # nobody moves O2 any more
    for obj in data["scene"]["objects"].values():  # the paper's rule: from the west side only
        obj["sides"] = ["west"]
    result = plan_team(parse_scenario(data))
    assert result.plans.feasible and result.report.ok
    (task,) = result.plans.added
    assert (task.robot, task.object) == ("R1", "O2") and "no mission moves it" in task.why
    # without the request R1 has no plan (the paper's R1 needs O2 gone), so it moves O2 itself
    assert not any("without requesting O2" in r for r in result.replans)
    assert [e.name for e in result.plans.robots["R1"].mission[:2]] == ["pick(R1,O2)", "drop(R1,O2,aside_O2)"]


def test_worker_processes_do_not_change_the_result():
    scenario = load_scenario(EXAMPLE)
    one = plan_team(scenario, workers=1)
    two = plan_team(scenario, workers=2)
    assert one.plans.to_dict() == two.plans.to_dict()


def test_a_mission_with_marked_states_plans_to_a_complete_state():
    # the 2x2 DFA, not prefix-closed: complete only in q15 (both robots home); planning must
    # reach it (and no prefix is taken for the mission)
    path = ROOT / "examples" / "01_warehouse_2x2" / "scenario_dfa.yaml"
    data = yaml.safe_load(path.read_text())
    data["mission"]["dfa"]["marked"] = ["q15"]
    team = plan_team(parse_scenario(data))
    assert team.plans.feasible, team.plans.reason
    done = {e.name for plan in team.plans.robots.values() for e in plan.mission}
    assert {"return(R1)", "return(R2)"} <= done
