"""Allocation: the ways a mission with choices can be completed, and the cheapest of them."""

from __future__ import annotations

import itertools
import json
import random
from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner

from cosmop.automata import DFA
from cosmop.cli import app
from cosmop.events import parse_event
from cosmop.missions.allocation import Alternative, Alternatives, alternatives, choose
from cosmop.missions.mission import GlobalMission
from cosmop.planning.synthesis import synthesize
from cosmop.scenario import load_scenario, parse_scenario
from cosmop.sim import simulate
from cosmop.team.loop import plan_team
from team_checks import assert_complete_word, assert_no_overlap

ROOT = Path(__file__).resolve().parents[1]
EITHER = ROOT / "tests" / "data" / "missions" / "either_robot.yaml"
CHOICE = ROOT / "examples" / "06_choice_dfa" / "scenario.yaml"

runner = CliRunner()

EVENTS = ["pick(R1,O1)", "pick(R2,O1)", "drop(R1,O1,W1)", "drop(R2,O1,W1)", "drop(R2,O1,W2)", "return(R1)"]


def _words_by_brute_force(mission: GlobalMission, robots) -> set[tuple]:
    """Every complete word of K of at most |Q| - 1 events (breadth first, no sharing), projected."""
    (k,) = mission.complete.components
    out = set()
    frontier = [(k.initial, ())]
    for _ in range(k.n_states):
        nxt = []
        for q, word in frontier:
            if k.marked[q]:
                owners = [mission.events[e].owners for e in word]
                out.add(tuple(tuple(e for e, o in zip(word, owners, strict=True) if r in o) for r in robots))
            for j, name in enumerate(k.alphabet):
                t = int(k.delta[q, j])
                if t >= 0:
                    nxt.append((t, (*word, name)))
        frontier = nxt
    return out


def _random_mission(rng: random.Random) -> GlobalMission:
    n = rng.randint(2, 6)
    transitions = []
    for q in range(n):
        for name in rng.sample(EVENTS, rng.randint(0, 3)):
            transitions.append((f"s{q}", name, f"s{rng.randrange(n)}"))
    marked = [f"s{q}" for q in range(n) if rng.random() < 0.4] or [f"s{n - 1}"]
    dfa = DFA.from_transitions("s0", transitions, marked=marked, states=[f"s{q}" for q in range(n)])
    return GlobalMission.from_dfa(dfa, robots=("R1", "R2"))


def test_alternatives_match_brute_force_on_random_missions():
    rng = random.Random(5)
    checked = 0
    for _ in range(200):
        mission = _random_mission(rng)
        if not mission.completable:
            continue
        found = alternatives(mission)
        assert found.exhaustive
        got = {tuple(alt.words[r] for r in mission.robots) for alt in found.items}
        assert got == _words_by_brute_force(mission, mission.robots)
        assert len(got) == len(found.items)  # distinct
        checked += 1
    assert checked > 50


def test_choice_is_the_brute_force_optimum():
    rng = random.Random(11)
    for _ in range(100):
        mission = _random_mission(rng)
        if not mission.completable:
            continue
        found = alternatives(mission)
        table = {}
        for alt in found.items:
            for r, w in alt.words.items():
                table.setdefault((r, w), rng.choice([None, 1, 2, 3, 5, 8]) if w else 0)
        choice = choose(found, lambda alt, r, table=table: table[(r, alt.words[r])])
        # brute force: every alternative, every robot plannable, least (max, sum)
        keys = []
        for alt in found.items:
            costs = [table[(r, w)] for r, w in alt.words.items()]
            if None not in costs:
                keys.append((max(costs), sum(costs)))
        if not keys:
            assert choice.alternative is None and choice.unplannable
            continue
        assert (choice.makespan, choice.total) == min(keys)
        chosen = [table[(r, w)] for r, w in choice.alternative.words.items()]
        assert (max(chosen), sum(chosen)) == min(keys)


def test_the_example_offers_four_ways():
    mission = GlobalMission.from_scenario(load_scenario(CHOICE))
    found = alternatives(mission)
    assert found.exhaustive and len(found.items) == 4
    movers = sorted(tuple(sorted(alt.movers(mission).items())) for alt in found.items)
    assert movers == [(("O1", "R1"), ("O2", "R2"))] * 2 + [(("O1", "R2"), ("O2", "R2"))] * 2


def test_the_bound_is_reported():
    mission = GlobalMission.from_scenario(load_scenario(CHOICE))
    cut = alternatives(mission, max_nodes=3)
    assert not cut.exhaustive and cut.explored == 3


def test_either_robot_moves_o1_exactly_once_and_the_run_completes_k(tmp_path):
    # "either R1 or R2 moves O1 to W1; R2 may also take it to W2": one robot is chosen
    out = tmp_path / "plan.json"
    result = runner.invoke(app, ["plan", str(EITHER), "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "allocation: O1 by" in result.stdout
    data = json.loads(out.read_text())
    picks = [e for p in data["robots"].values() for e in p["mission"] if e.startswith("pick(")]
    assert len(picks) == 1
    mover = data["allocation"]["O1"]
    assert picks == [f"pick({mover},O1)"]
    scenario = load_scenario(EITHER)
    team = plan_team(scenario)
    assert dict(team.plans.allocation) == data["allocation"]
    run = simulate(scenario, team.plans)
    assert run.completed and run.contacts_while_moving == 0
    assert_complete_word(scenario, run)
    assert_no_overlap(scenario, run)


def test_a_choice_of_dock_is_planned():
    # one robot, O1 to W1 or W2: formerly "R1's local mission has branches"
    data = yaml.safe_load(EITHER.read_text())
    data["mission"]["dfa"]["transitions"] = [
        ["s", "pick(R1,O1)", "a"],
        ["a", "drop(R1,O1,W1)", "b"],
        ["a", "drop(R1,O1,W2)", "b"],
        ["b", "return(R1)", "done"],
    ]
    scenario = parse_scenario(data)
    team = plan_team(scenario)
    assert team.plans.feasible, team.plans.reason
    # a choice no other robot takes part in: planned once, as R1's branching mission
    assert team.allocation.considered == 1
    assert "R1's own choices planned as one branching mission" in team.allocation.method
    # the dock chosen is a cheapest one, as costing each word alone shows (no one else moves
    # anything, so R1 may request nothing)
    word = ("pick(R1,O1)", "drop(R1,O1,{})", "return(R1)")
    nobody = frozenset(scenario.scene.objects)
    alone = {
        w: synthesize(scenario.scene, "R1", [e.format(w) for e in word], unrequestable=nobody).horizon
        for w in ("W1", "W2")
    }
    (chosen,) = [w for w in alone if parse_event(f"drop(R1,O1,{w})") in team.plans.robots["R1"].mission]
    assert team.allocation.makespan == alone[chosen] == min(alone.values())


def test_no_plannable_way_exits_1_naming_the_robots_words(tmp_path):
    data = yaml.safe_load(EITHER.read_text())
    # a wall seals R1 into its corner: it can do nothing but stay home
    data["scene"]["obstacles"] += [
        [[-2400, -2500], [-2400, -1000]],
        [[-2400, -1000], [-1600, -1000]],
        [[-1600, -1000], [-1600, -2500]],
    ]
    data["mission"]["dfa"]["transitions"] = [
        ["s", "pick(R1,O1)", "a"],
        ["a", "drop(R1,O1,W1)", "b"],
        ["a", "drop(R1,O1,W2)", "b"],
        ["b", "return(R1)", "done"],
    ]
    path = tmp_path / "sealed.yaml"
    path.write_text(yaml.safe_dump(data))
    out = tmp_path / "plan.json"
    result = runner.invoke(app, ["plan", str(path), "-o", str(out)])
    assert result.exit_code == 1, result.output
    plan = json.loads(out.read_text())
    assert not plan["feasible"]
    assert "none of the 2 ways" in plan["reason"] and "R1 cannot do pick(R1,O1)" in plan["reason"]


@pytest.mark.parametrize("words", [{"R1": ("pick(R1,O1)",)}, {"R1": ()}])
def test_alternative_words_are_read_only(words):
    alt = Alternative(words)
    with pytest.raises(TypeError):
        alt.words["R1"] = ()  # type: ignore[index]
    assert Alternatives((alt,), True, 1).pairs() == [(r, w) for r, w in words.items() if w]


def test_makespan_first_then_total_then_the_first_found():
    k = DFA.from_transitions(
        "a", [("a", "pick(R1,O1)", "b"), ("a", "pick(R2,O1)", "b"), ("b", "return(R1)", "c")], marked=["c"]
    )
    found = alternatives(GlobalMission.from_dfa(k, robots=("R1", "R2")))
    assert [alt.movers(GlobalMission.from_dfa(k)) for alt in found.items] == [{"O1": "R1"}, {"O1": "R2"}]
    for c1, c2 in itertools.product([1, 2, 3], repeat=2):
        # R1 moving O1 and coming back costs c1; R2 moving it costs c2 (and R1 returns, 1)
        def cost(alt, robot, c1=c1, c2=c2):
            return c1 if alt.words[robot] == ("pick(R1,O1)", "return(R1)") else (1 if robot == "R1" else c2)

        choice = choose(found, cost)
        keys = [(c1, c1), (max(1, c2), 1 + c2)]
        assert (choice.makespan, choice.total) == min(keys)
        assert choice.alternative is found.items[keys.index(min(keys))]  # ties: the first found


def test_alternatives_that_cannot_win_are_never_planned():
    # the mission may be left as it is (its first state is complete), or R1 or R2 moves O1:
    # doing nothing costs nothing, so no word of the others is planned (branch and bound)
    data = yaml.safe_load(EITHER.read_text())
    data["mission"]["dfa"] = {
        "initial": "s",
        "marked": ["s", "done"],
        "transitions": [
            ["s", "pick(R1,O1)", "a"],
            ["s", "pick(R2,O1)", "b"],
            ["a", "drop(R1,O1,W1)", "done"],
            ["b", "drop(R2,O1,W1)", "done"],
        ],
    }
    team = plan_team(parse_scenario(data), workers=1)
    assert team.plans.feasible and team.allocation.makespan == 0
    assert team.allocation.considered == 1  # the others were never planned
