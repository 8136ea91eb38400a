"""The top-down layer reproduces the paper (Section III) and scales compositionally.

Checked: the 16-state global mission of Fig. "Global specification" projects onto the two
sequences of Fig. "Robots' specifications" and equals the tasks form; the assumption learned
for R1 is R2's sequence (Fig. A1); verification holds; a mission ordering the two picks is not
separable, with a true counterexample, and its re-synthesised local missions are sound; a
20-robot tasks-form mission is decomposed and verified without building its product.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from cosmop.automata import (
    DFA,
    equivalent,
    inverse_project,
    is_included,
    minimize,
    parallel,
    product,
    project,
    satisfaction_counterexample,
)
from cosmop.missions.decomposition import decompose, resynthesize, separability_counterexample
from cosmop.missions.mission import GlobalMission, local_alphabets, sequence_automaton
from cosmop.missions.verification import verify
from cosmop.scenario import load_scenario
from cosmop.team.mission_proof import check_words, verify_team

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "01_warehouse_2x2"
R1 = ("pick(R1,O1)", "drop(R1,O1,W1)", "return(R1)")
R2 = ("pick(R2,O2)", "drop(R2,O2,W2)", "return(R2)")


def warehouse(n: int) -> GlobalMission:
    """Tasks-form mission of n robots: Ri picks Oi, drops it at Wi, returns."""
    return GlobalMission.from_tasks(
        {f"R{i}": [f"pick(R{i},O{i})", f"drop(R{i},O{i},W{i})", f"return(R{i})"] for i in range(1, n + 1)}
    )


@pytest.fixture(scope="module")
def paper_dfa() -> GlobalMission:
    return GlobalMission.from_scenario(load_scenario(EXAMPLE / "scenario_dfa.yaml"))


@pytest.fixture(scope="module")
def paper_tasks() -> GlobalMission:
    return GlobalMission.from_scenario(load_scenario(EXAMPLE / "scenario.yaml"))


@pytest.fixture(scope="module")
def ordered(paper_dfa: GlobalMission) -> GlobalMission:
    """The paper's mission with R1's pick required before R2's: not separable."""
    k = paper_dfa.automaton.components[0]
    order = DFA.from_transitions("a", [("a", R1[0], "b"), ("b", R2[0], "c")])
    return GlobalMission.from_dfa(minimize(product(k, inverse_project(order, k.alphabet))))


def test_global_specification_has_16_states_and_equals_the_tasks_form(paper_dfa, paper_tasks):
    k = paper_dfa.automaton.components[0]
    assert k.n_states == 16 and k.n_transitions == 24 and k.marked.all()
    assert minimize(k).n_states == 16
    assert equivalent(k, paper_tasks.automaton.build())
    assert paper_tasks.automaton.build().n_states == 16


def test_local_alphabets_follow_event_ownership(paper_dfa):
    assert paper_dfa.alphabets == {"R1": tuple(sorted(R1)), "R2": tuple(sorted(R2))}
    away = GlobalMission.from_tasks({"R1": ["away(O2,R1,R2)"], "R2": []}).events.values()
    assert local_alphabets(away, ["R1", "R2", "R3"]) == {
        "R1": ("away(O2,R1,R2)",),
        "R2": ("away(O2,R1,R2)",),
        "R3": (),
    }


@pytest.mark.parametrize("form", ["dfa", "tasks"])
def test_projection_gives_the_robots_specifications(form, paper_dfa, paper_tasks):
    mission = paper_dfa if form == "dfa" else paper_tasks
    result = decompose(mission)
    assert result.separable and result.counterexample is None and result.resynthesis is None
    for robot, seq in (("R1", R1), ("R2", R2)):
        local = result.local_missions[robot]
        assert local.n_states == 4
        assert equivalent(local, sequence_automaton(seq))
        assert [e for _, e, _ in local.transitions()] == list(seq)


def test_learned_assumption_for_r1_is_r2_sequence(paper_dfa):
    result = decompose(paper_dfa)
    v = verify(paper_dfa, result.local_missions, method="assume-guarantee")
    assert v.holds and v.counterexample is None and v.method == "assume-guarantee"
    (report,) = v.assumptions
    assert report.guarantor == "R1" and report.environment == ("R2",)
    assert report.interface == tuple(sorted(R2))
    assert equivalent(report.assumption, sequence_automaton(R2))  # Fig. A1
    assert report.assumption.n_states == 4
    assert report.membership_queries > 0 and report.equivalence_queries >= 1
    # premise 2 of the rule: <true> K2 <A>
    assert is_included(result.local_missions["R2"], report.assumption)


def test_direct_and_assume_guarantee_agree(paper_dfa, ordered):
    for mission in (paper_dfa, ordered):
        local = decompose(mission).local_missions
        ag = verify(mission, local, method="assume-guarantee")
        direct = verify(mission, local, method="direct")
        assert ag.holds == direct.holds
        assert direct.method == "direct" and not direct.assumptions


def test_ordered_picks_are_not_separable_with_a_true_counterexample(ordered):
    result = decompose(ordered)
    assert not result.separable
    t = result.counterexample
    k = ordered.automaton.components[0]
    product_of_locals = parallel(*result.local_missions.values())
    assert product_of_locals.accepts(t) and not k.accepts(t)  # t is in ||K_i but not in K
    assert t == (R2[0],)  # the shortest: R2 picks first
    v = verify(ordered, result.local_missions)
    assert not v.holds
    assert product_of_locals.accepts(v.counterexample) and not k.accepts(v.counterexample)


def test_ordered_picks_are_kept_by_a_message_not_pruned(ordered):
    result = decompose(ordered)
    assert not result.separable and result.resynthesis is None
    messaging = result.messaging
    assert messaging is not None
    ((name, ((a, i), (b, j))),) = messaging.messages
    assert (a, i, b, j) == ("R1", 0, "R2", 0)  # R2 waits before its pick for R1's pick
    assert messaging.words["R1"] == (R1[0], name, *R1[1:])
    assert messaging.words["R2"] == (name, *R2)
    verdict = verify_team(ordered, messaging.words)
    assert verdict.holds and verdict.blocking is None
    assert check_words(ordered, messaging.words).holds
    assert not check_words(ordered, {"R1": R1, "R2": R2}).holds  # without the message: R2 may pick first
    assert result.sound_local_missions is messaging.local_missions


def test_resynthesised_local_missions_are_sound(ordered):
    result = decompose(ordered)
    rs = resynthesize(ordered, result.local_missions)
    assert rs is not None and rs.converged and rs.iterations >= 1
    k = ordered.automaton.components[0]
    for robot, local in rs.local_missions.items():
        assert is_included(local, result.local_missions[robot])  # only ever shrinks
        assert local.marked.all()  # still prefix-closed
    assert is_included(parallel(*rs.local_missions.values()), k)
    assert verify(ordered, rs.local_missions, method="assume-guarantee").holds
    assert rs.lost_events["R2"] == tuple(sorted(R2))  # without messages R2 cannot know R1 picked
    assert rs.lost_events["R1"] == ()


def test_resynthesis_cap_is_reported(ordered):
    local = decompose(ordered).local_missions
    capped = resynthesize(ordered, local, max_iterations=0)
    assert not capped.converged and capped.iterations == 0
    assert all(equivalent(capped.local_missions[r], local[r]) for r in local)


def test_separability_of_the_tasks_form_is_checked_factor_by_factor():
    mission = warehouse(3)
    local = decompose(mission).local_missions
    assert separability_counterexample(mission.automaton, local) is None
    # a local mission that lets R1 return before dropping breaks factor R1 only
    bad = dict(local)
    bad["R1"] = DFA.from_transitions("a", [("a", "pick(R1,O1)", "b"), ("b", "return(R1)", "c")])
    t = separability_counterexample(mission.automaton, bad)
    assert t == ("pick(R1,O1)", "return(R1)")
    v = verify(mission, bad)
    assert not v.holds and v.counterexample == t


def test_twenty_robots_in_tasks_form_never_build_the_product():
    mission = warehouse(20)
    result = decompose(mission)
    assert result.separable
    assert result.stats.largest_automaton <= 4  # 4^20 states are never built
    for i in range(1, 21):
        seq = (f"pick(R{i},O{i})", f"drop(R{i},O{i},W{i})", f"return(R{i})")
        assert equivalent(result.local_missions[f"R{i}"], sequence_automaton(seq))
    v = verify(mission, result.local_missions)
    assert v.holds and v.largest_automaton <= 4 and len(v.checks) == 20


def test_coordinated_mission_verified_with_small_assumptions():
    mission = GlobalMission.from_scenario(load_scenario(ROOT / "tests" / "data" / "coordinated_2x2.yaml"))
    result = decompose(mission)
    assert result.separable
    v = verify(mission, result.local_missions, method="assume-guarantee")
    assert v.holds and {c.method for c in v.checks} == {"assume-guarantee"}
    assert {a.guarantor for a in v.assumptions} == {"R1", "R2"}
    for report in v.assumptions:
        assert report.interface == ("away(O2,R1,R2)",)
        assert report.assumption.n_states == 1
    # R2 answering before it has picked O2 would let R1 go too early: the answer is in R2's factor
    early = dict(result.local_missions)
    early["R2"] = sequence_automaton(["away(O2,R1,R2)", "pick(R2,O2)", "drop(R2,O2,W2)", "return(R2)"])
    bad = verify(mission, early, method="assume-guarantee")
    assert not bad.holds
    k2 = mission.automaton.components[1]
    assert satisfaction_counterexample(parallel(*early.values()), k2) is not None
    assert parallel(*early.values()).accepts(bad.counterexample)


def test_auto_falls_back_to_direct_for_large_monolithic_environments():
    k = warehouse(4).automaton.build()  # explicit DFA of 256 states
    mission = GlobalMission.from_dfa(k)
    local = decompose(mission).local_missions
    auto = verify(mission, local, max_environment_states=16)
    assert auto.holds and auto.method == "direct"
    ag = verify(mission, local, method="assume-guarantee")
    assert ag.holds and ag.assumptions[0].assumption.n_states == 64  # the other three robots


def test_results_serialise(paper_dfa):
    result = decompose(paper_dfa)
    data = result.to_dict()
    assert set(data) >= {"separable", "counterexample", "local_missions", "stats"}
    assert data["local_missions"]["R1"]["alphabet"] == sorted(R1)
    assert DFA.from_dict(data["local_missions"]["R1"]).n_states == 4
    vdata = verify(paper_dfa, result.local_missions).to_dict()
    assert vdata["holds"] is True and vdata["assumption_sizes"] == [4]
    assert vdata["membership_queries"] > 0


def test_projection_of_the_explicit_dfa_matches_plain_projection(paper_dfa):
    k = paper_dfa.automaton.components[0]
    result = decompose(paper_dfa)
    assert equivalent(result.local_missions["R1"], project(k, R1))


def test_lstar_round_cap_never_claims_a_proof(paper_dfa, ordered):
    # one L* round is not enough to learn R2's sequence: no proof, so the factor is decided directly
    local = decompose(paper_dfa).local_missions
    capped = verify(paper_dfa, local, method="assume-guarantee", max_rounds=1)
    assert capped.holds and capped.checks[0].method == "direct (L* round cap)"
    assert not capped.assumptions[0].holds
    bad = verify(ordered, decompose(ordered).local_missions, method="assume-guarantee", max_rounds=1)
    assert not bad.holds and bad.counterexample == ("pick(R2,O2)",)
