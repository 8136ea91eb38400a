"""Requests become per-requester request/response pairs, placed so that the team cannot deadlock.

Reproduced: the 2x2 example gets the pair (O2, R1, R2); the 10x10 example gets exactly the
coordination structure of the paper's example (R1 <- O2, O3; R2 <- O3; R4 <- O5, O6; R5 <- O6;
R7 <- O8; R9 <- O10), deadlock-free, and every robot re-planned with its
coordinated mission passes the exact checker; the coordinated local missions satisfy the
global mission (verified by assume-guarantee).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from cosmop.events import parse_event
from cosmop.missions.mission import GlobalMission, sequence_automaton
from cosmop.missions.verification import verify
from cosmop.planning.checker import check_robot_plan
from cosmop.planning.realisation import request_phases
from cosmop.planning.synthesis import synthesize
from cosmop.scenario import load_scenario
from cosmop.team.coordination_events import Pair, blocking_word, coordinate
from paper_rules import west_only

ROOT = Path(__file__).resolve().parents[1]


def seq(*names: str):
    return tuple(parse_event(n) for n in names)


def plan_requests(sc):
    sequences = {r: tuple(sc.mission.tasks[r]) for r in sc.scene.robots}
    requests = {}
    for robot, events in sequences.items():
        res = synthesize(sc.scene, robot, events, max_horizon=12)
        requests[robot] = request_phases(res.plan, robot, sc.scene, events)
    return sequences, requests


def test_requests_are_attached_to_the_event_they_prepare():
    sc = load_scenario(ROOT / "examples" / "01_warehouse_2x2" / "scenario.yaml")
    events = tuple(sc.mission.tasks["R1"])
    plan = synthesize(sc.scene, "R1", events, max_horizon=12).plan
    req = next(k for k, s in enumerate(plan.steps) if s.primitive == "Req")
    pick = next(k for k, s in enumerate(plan.steps) if s.primitive == "PickUp")
    assert req < pick  # R1 asks for O2 to be moved before it picks O1
    assert request_phases(plan, "R1", sc.scene, events) == [("O2", 0)]


def test_two_by_two_gets_one_pair():
    sc = load_scenario(ROOT / "examples" / "01_warehouse_2x2" / "scenario.yaml")
    sequences, requests = plan_requests(sc)
    result = coordinate(sequences, requests)
    assert result.pairs == (Pair("O2", "R1", "R2"),) and result.deadlock_free and not result.unanswered
    assert result.sequences["R1"][0].name == "away(O2,R1,R2)"
    assert [e.name for e in result.sequences["R2"]][:2] == ["pick(R2,O2)", "away(O2,R1,R2)"]
    mission = GlobalMission.from_scenario(sc)
    local = {r: sequence_automaton([e.name for e in s]) for r, s in result.sequences.items()}
    proof = verify(mission, local, method="assume-guarantee")
    assert proof.holds


@pytest.fixture(scope="module")
def ten():
    sc = west_only(load_scenario(ROOT / "examples" / "02_warehouse_10x10" / "scenario.yaml"))
    sequences, requests = plan_requests(sc)
    return sc, sequences, coordinate(sequences, requests)


def test_ten_by_ten_coordination_structure_is_the_papers(ten):
    _, _, result = ten
    expected = {
        ("O2", "R1", "R2"),
        ("O3", "R1", "R3"),
        ("O3", "R2", "R3"),
        ("O5", "R4", "R5"),
        ("O6", "R4", "R6"),
        ("O6", "R5", "R6"),
        ("O8", "R7", "R8"),
        ("O10", "R9", "R10"),
    }
    assert {(p.obj, p.requester, p.responder) for p in result.pairs} == expected
    assert result.deadlock_free and blocking_word(result.sequences) is None
    # R3 answers both of its requesters, each with its own event, right after picking O3
    r3 = [e.name for e in result.sequences["R3"]]
    assert r3[0] == "pick(R3,O3)" and set(r3[1:3]) == {"away(O3,R1,R3)", "away(O3,R2,R3)"}
    # a responder that others wait on is answered first: when R1 waits for R2 (O2) before R3,
    # R3 must answer R2 before R1 (the order of the paper's figures)
    r1 = [e.name for e in result.sequences["R1"]]
    if r1.index("away(O2,R1,R2)") < r1.index("away(O3,R1,R3)"):
        assert r3[1:3] == ["away(O3,R2,R3)", "away(O3,R1,R3)"]


def test_ten_by_ten_coordinated_plans_are_checked_and_verified(ten):
    sc, sequences, result = ten
    for robot, events in result.sequences.items():
        if events == sequences[robot]:
            continue
        res = synthesize(sc.scene, robot, events, max_horizon=14)
        assert res.feasible and check_robot_plan(sc.scene, robot, res.plan) == []
        answers = sum(1 for e in events if e.kind == "away" and e.responder == robot)
        assert sum(1 for s in res.plan.steps if s.primitive == "Res") == answers
    mission = GlobalMission.from_scenario(sc)
    local = {r: sequence_automaton([e.name for e in s]) for r, s in result.sequences.items()}
    proof = verify(mission, local)
    assert proof.holds and proof.largest_automaton < 1000  # clusters of at most three robots


def test_a_circular_wait_is_found():
    # R1 waits for R2's answer before its pick, and R2 for R1's before its own: nobody can move
    sequences = {
        "R1": seq("away(O2,R1,R2)", "pick(R1,O1)", "away(O1,R2,R1)"),
        "R2": seq("away(O1,R2,R1)", "pick(R2,O2)", "away(O2,R1,R2)"),
    }
    word = blocking_word(sequences)
    assert word is not None and word[-2:] == (
        "[R1 waits for away(O2,R1,R2)]",
        "[R2 waits for away(O1,R2,R1)]",
    )


def test_answers_are_asynchronous_so_answer_order_cannot_block():
    # R3 answers R1 before R2 while R1 first waits for R2: the answers are sent and R3 goes on
    sequences = {
        "R1": seq("away(O2,R1,R2)", "away(O3,R1,R3)", "pick(R1,O1)"),
        "R2": seq("away(O3,R2,R3)", "pick(R2,O2)", "away(O2,R1,R2)"),
        "R3": seq("pick(R3,O3)", "away(O3,R1,R3)", "away(O3,R2,R3)"),
    }
    assert blocking_word(sequences) is None
    requests = {"R1": [("O2", 0), ("O3", 0)], "R2": [("O3", 0)]}
    plain = {"R1": seq("pick(R1,O1)"), "R2": seq("pick(R2,O2)"), "R3": seq("pick(R3,O3)")}
    result = coordinate(plain, requests)
    assert result.deadlock_free
    # those who wait least are answered first: R2 before R1
    assert [e.name for e in result.sequences["R3"]] == ["pick(R3,O3)", "away(O3,R2,R3)", "away(O3,R1,R3)"]


def test_a_request_nobody_answers_is_reported():
    result = coordinate({"R1": seq("pick(R1,O1)")}, {"R1": [("O9", 0)]})
    assert result.unanswered == (("O9", "R1"),) and result.pairs == ()
