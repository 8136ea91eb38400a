"""Branching local missions in CLTLB(D): the mission automaton's state per instant.

A robot given a DFA over its events gets the shortest plan over *every* marked word (checked
here against planning each word alone, brute force), the fewest requests among those, a plan
that passes the exact checker for the word it performs, and that word is in the language.  A
sequence written as a chain automaton gives the same K and requests as the until chain.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from cosmop.automata import DFA
from cosmop.planning.checker import check_robot_plan
from cosmop.planning.synthesis import synthesize
from cosmop.scenario import load_scenario, parse_scenario
from rooms import branching_words, room

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("seed", [2, 5])
def test_the_branching_plan_is_as_short_as_the_best_word(seed):
    scene = parse_scenario(room(seed)).scene
    words = branching_words()
    alone = {w: synthesize(scene, "R1", w, max_horizon=20) for w in words}
    best = min(r.horizon for r in alone.values() if r.feasible)
    res = synthesize(scene, "R1", DFA.from_words(words), max_horizon=20)
    assert res.feasible and res.horizon == best
    word = tuple(e.name for e in res.plan.mission)
    assert word in words
    assert alone[word].horizon == best
    # the fewest requests among the shortest words
    assert len(res.requests) == min(len(r.requests) for r in alone.values() if r.horizon == best)
    assert check_robot_plan(scene, "R1", res.plan) == []


def test_a_loop_in_the_mission_changes_nothing():
    # after delivering O1 the automaton may go round "pick O1, drop O1 at W1" again: an
    # infinite language whose shortest plan is the loop-free one
    scene = parse_scenario(room(3)).scene
    word = ("pick(R1,O1)", "drop(R1,O1,W1)", "return(R1)")
    loop = DFA.from_transitions(
        "s",
        [
            ("s", word[0], "a"),
            ("a", word[1], "b"),
            ("b", word[0], "a"),
            ("b", word[2], "done"),
        ],
        marked=["done"],
    )
    res = synthesize(scene, "R1", loop)
    straight = synthesize(scene, "R1", word)
    assert (
        res.feasible and res.horizon == straight.horizon and tuple(e.name for e in res.plan.mission) == word
    )
    assert check_robot_plan(scene, "R1", res.plan) == []


@pytest.mark.parametrize("robot", ["R1", "R2"])
def test_a_chain_automaton_is_the_until_chain(robot):
    example = load_scenario(ROOT / "examples" / "01_warehouse_2x2" / "scenario.yaml")
    word = tuple(e.name for e in example.mission.tasks[robot])
    seq = synthesize(example.scene, robot, word)
    chain = synthesize(example.scene, robot, DFA.from_word(word, closed=False))
    assert (chain.horizon, sorted(chain.requests)) == (seq.horizon, sorted(seq.requests))
    assert tuple(e.name for e in chain.plan.mission) == word
    assert check_robot_plan(example.scene, robot, chain.plan) == []


def test_a_walled_off_dock_is_ruled_out_without_the_solver():
    data = room(3)
    x, y = data["scene"]["workspaces"]["W2"]["x"], data["scene"]["workspaces"]["W2"]["y"]
    # W2 inside a closed box: only W1 remains
    data["scene"]["obstacles"] += [
        [[x[0] - 300, y[0] - 300], [x[1] + 300, y[0] - 300]],
        [[x[1] + 300, y[0] - 300], [x[1] + 300, y[1] + 300]],
        [[x[1] + 300, y[1] + 300], [x[0] - 300, y[1] + 300]],
        [[x[0] - 300, y[1] + 300], [x[0] - 300, y[0] - 300]],
    ]
    scene = parse_scenario(data).scene
    either = DFA.from_words([("pick(R1,O1)", f"drop(R1,O1,{w})") for w in ("W1", "W2")])
    res = synthesize(scene, "R1", either)
    assert res.feasible and [e.name for e in res.plan.mission] == ["pick(R1,O1)", "drop(R1,O1,W1)"]
    only_w2 = synthesize(scene, "R1", DFA.from_words([("pick(R1,O1)", "drop(R1,O1,W2)")]))
    assert not only_w2.feasible and only_w2.checks == 0
    assert "can complete no word" in only_w2.reason and "drop(R1,O1,W2)" in only_w2.reason
