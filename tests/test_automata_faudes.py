"""Cross-checks of :mod:`cosmop.automata` against libFAUDES (via :mod:`cosmop.automata.reference`).

What is checked
---------------
Our DFAs are converted to ``faudes.Generator`` objects with :func:`reference.to_faudes` and
results come back with :func:`reference.from_faudes`; each comparison is made twice, once
with libFAUDES' ``LanguageEquality`` and once with our :func:`equivalent` on the converted
result, so neither library is the only judge.

* random small DFAs (hypothesis): :func:`parallel` against ``faudes.Parallel`` (language and
  number of accessible states, 2 and 3 factors), :func:`project` against ``faudes.Project``
  (language and minimal size), :func:`project_composition` against ``Project(Parallel(...))``,
  :func:`is_included` against ``faudes.LanguageInclusion`` in both directions, and
  :func:`minimize` against ``faudes.StateMin`` of the trimmed generator;
* the warehouse family (N = 2..5 robots, each the prefix-closed sequence ``pick(Ri,Oi)``,
  ``drop(Ri,Oi,Wi)``, ``return(Ri)``), alone and composed with a mutual-exclusion and a
  pick-order specification: the same four operations, and the known sizes (4^N for the
  mission, 2^N for its projection on the picks).

libFAUDES compares marked languages and ignores alphabets; so do these tests.  The whole
module is skipped when the ``faudes`` binding is not installed.
"""

from __future__ import annotations

import itertools
import os

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

faudes = pytest.importorskip("faudes")

from cosmop.automata import (  # noqa: E402
    DFA,
    canonical,
    equivalent,
    extend_alphabet,
    inverse_project,
    is_empty,
    is_included,
    minimize,
    parallel,
    prefix_closure,
    product,
    project,
    project_composition,
    satisfaction_counterexample,
    trim,
)
from cosmop.automata import reference as ref  # noqa: E402

POOL = ("a", "b", "c", "d")

# COSMOP_EXAMPLES_SCALE=10 multiplies the budget (for a long local hunt; CI keeps 1).
SCALE = float(os.environ.get("COSMOP_EXAMPLES_SCALE", "1"))
CHECKS = settings(max_examples=int(40 * SCALE), deadline=None, suppress_health_check=[HealthCheck.too_slow])


# ---------------------------------------------------------------------------------------------
# conversion
# ---------------------------------------------------------------------------------------------


to_fd = ref.dfa_to_faudes
from_fd = ref.faudes_to_dfa


def assert_same_language(ours: DFA, gen) -> None:
    """Equal marked languages, judged by libFAUDES and by us."""
    assert ref.language_equality(to_fd(ours), gen)
    assert equivalent(ours, from_fd(gen))


def minimal_size(dfa: DFA) -> int:
    """Our minimal state count in libFAUDES' convention (0 for the empty language)."""
    return 0 if is_empty(dfa) else minimize(dfa).n_states


@st.composite
def dfas(draw, max_states: int = 6) -> DFA:
    """Random partial DFA over 0-3 events of POOL (same shape as the property tests)."""
    events = list(draw(st.permutations(POOL))[: draw(st.integers(1, 3))])
    n = draw(st.integers(1, max_states))
    holes = draw(st.integers(1, 3))
    entry = st.integers(-holes, n - 1).map(lambda t: max(t, -1))
    delta = draw(st.lists(entry, min_size=n * len(events), max_size=n * len(events)))
    marked = draw(st.lists(st.booleans(), min_size=n, max_size=n))
    initial = draw(st.integers(0, n - 1))
    table = np.array(delta, dtype=np.int32).reshape(n, len(events))
    return DFA(tuple(events), table, initial, np.array(marked, dtype=bool))


# ---------------------------------------------------------------------------------------------
# random automata
# ---------------------------------------------------------------------------------------------


@CHECKS
@given(a=dfas())
def test_round_trip_through_faudes(a: DFA) -> None:
    back = from_fd(to_fd(a))
    assert set(back.alphabet) == set(a.alphabet)
    assert equivalent(back, a)
    # from_faudes numbers breadth-first over sorted events, as canonical() does
    assert canonical(back).delta.tolist() == canonical(extend_alphabet(a, ())).delta.tolist()


@CHECKS
@given(a=dfas(), b=dfas(), c=dfas())
def test_parallel_matches_faudes(a: DFA, b: DFA, c: DFA) -> None:
    ours = parallel(a, b)
    theirs = ref.parallel(to_fd(a), to_fd(b))
    assert_same_language(ours, theirs)
    assert ours.n_states == theirs.Size()  # both build exactly the accessible pairs
    three = parallel(a, b, c)
    assert_same_language(three, ref.parallel(theirs, to_fd(c)))


@CHECKS
@given(a=dfas(), target=st.frozensets(st.sampled_from((*POOL, "z"))))
def test_project_matches_faudes(a: DFA, target: frozenset[str]) -> None:
    ours = project(a, target)
    theirs = ref.project(to_fd(a), target)
    assert_same_language(ours, theirs)
    assert minimal_size(ours) == ref.minimal_states(theirs)


@CHECKS
@given(cs=st.lists(dfas(max_states=4), min_size=2, max_size=3), target=st.frozensets(st.sampled_from(POOL)))
def test_project_composition_matches_faudes(cs: list[DFA], target: frozenset[str]) -> None:
    whole = to_fd(cs[0])
    for c in cs[1:]:
        whole = ref.parallel(whole, to_fd(c))
    theirs = ref.project(whole, target)
    ours = project_composition(cs, target)
    assert_same_language(ours, theirs)
    assert minimal_size(ours) == ref.minimal_states(theirs)


@CHECKS
@given(a=dfas(), b=dfas())
def test_inclusion_matches_faudes(a: DFA, b: DFA) -> None:
    cases = [
        (a, b),
        (b, a),
        (product(a, b), a),  # included
        (parallel(a, b), inverse_project(a, b.alphabet)),  # included
        (prefix_closure(a), a),
        (trim(a), b),
    ]
    for x, y in cases:
        fx, fy = to_fd(x), to_fd(y)
        assert is_included(x, y) == ref.language_inclusion(fx, fy)
        assert is_included(y, x) == ref.language_inclusion(fy, fx)


@CHECKS
@given(a=dfas(), b=dfas())
def test_minimal_states_match_faudes(a: DFA, b: DFA) -> None:
    for x in (a, parallel(a, b), product(a, b), prefix_closure(a)):
        assert minimal_size(x) == ref.minimal_states(to_fd(x))
        if is_empty(x):
            assert minimize(x).n_states == 1  # ours keeps one unmarked state


# ---------------------------------------------------------------------------------------------
# the warehouse family
# ---------------------------------------------------------------------------------------------


def pick(i: int) -> str:
    return f"pick(R{i},O{i})"


def drop(i: int) -> str:
    return f"drop(R{i},O{i},W{i})"


def back(i: int) -> str:
    return f"return(R{i})"


def robot(i: int) -> DFA:
    """Prefix-closed task sequence of robot ``i``."""
    return DFA.from_word((pick(i), drop(i), back(i)))


def mutex(n: int) -> DFA:
    """At most one robot carries an object: between pick(Ri) and drop(Ri) no other pick."""
    transitions = [("idle", pick(i), f"busy{i}") for i in range(1, n + 1)]
    transitions += [(f"busy{i}", drop(i), "idle") for i in range(1, n + 1)]
    return DFA.from_transitions("idle", transitions)


def pick_order(n: int) -> DFA:
    """Robots pick in index order (prefix-closed)."""
    return DFA.from_word(tuple(pick(i) for i in range(1, n + 1)))


def fold_faudes(dfas_: list[DFA]):
    gen = to_fd(dfas_[0])
    for d in dfas_[1:]:
        gen = ref.parallel(gen, to_fd(d))
    return gen


@pytest.fixture(scope="module", params=[2, 3, 4, 5], ids=lambda n: f"N={n}")
def warehouse(request) -> dict:
    n = request.param
    robots = [robot(i) for i in range(1, n + 1)]
    mission = parallel(*robots)
    safe = parallel(mission, mutex(n))
    ordered = parallel(mission, pick_order(n))
    both = parallel(safe, pick_order(n))
    gens = {
        "mission": fold_faudes(robots),
        "safe": fold_faudes([*robots, mutex(n)]),
        "ordered": fold_faudes([*robots, pick_order(n)]),
        "both": fold_faudes([*robots, mutex(n), pick_order(n)]),
    }
    ours = {"mission": mission, "safe": safe, "ordered": ordered, "both": both}
    return {"n": n, "robots": robots, "ours": ours, "gens": gens}


def test_warehouse_parallel(warehouse: dict) -> None:
    n = warehouse["n"]
    for key, ours in warehouse["ours"].items():
        gen = warehouse["gens"][key]
        assert_same_language(ours, gen)
        assert ours.n_states == gen.Size(), key
    mission = warehouse["ours"]["mission"]
    assert mission.n_states == 4**n
    assert minimal_size(mission) == ref.minimal_states(warehouse["gens"]["mission"]) == 4**n


def test_warehouse_project(warehouse: dict) -> None:
    n = warehouse["n"]
    picks = {pick(i) for i in range(1, n + 1)}
    robot1 = {pick(1), drop(1), back(1)}
    targets = [picks, robot1, picks | {drop(1)}, {drop(i) for i in range(1, n + 1)} | {"z"}]
    for key, ours in warehouse["ours"].items():
        gen = warehouse["gens"][key]
        for target in targets:
            projected = project(ours, target)
            theirs = ref.project(gen, target)
            assert_same_language(projected, theirs)
            assert minimal_size(projected) == ref.minimal_states(theirs), (key, sorted(target))
    # projecting the shuffle on the picks leaves the shuffle of n one-letter words
    assert minimal_size(project(warehouse["ours"]["mission"], picks)) == 2**n
    compositional = project_composition(warehouse["robots"], picks)
    assert_same_language(compositional, ref.project(warehouse["gens"]["mission"], picks))
    assert compositional.n_states == 2**n
    guarded = project_composition([*warehouse["robots"], mutex(n)], picks | {drop(1)})
    assert_same_language(guarded, ref.project(warehouse["gens"]["safe"], picks | {drop(1)}))


def test_warehouse_inclusion(warehouse: dict) -> None:
    for (k1, x), (k2, y) in itertools.product(warehouse["ours"].items(), repeat=2):
        expected = ref.language_inclusion(warehouse["gens"][k1], warehouse["gens"][k2])
        assert is_included(x, y) == expected, (k1, k2)
    ours = warehouse["ours"]
    assert is_included(ours["both"], ours["safe"]) and is_included(ours["safe"], ours["mission"])
    assert not is_included(ours["mission"], ours["safe"])


def test_warehouse_satisfaction(warehouse: dict) -> None:
    n = warehouse["n"]
    ours = warehouse["ours"]
    spec = mutex(n)
    assert satisfaction_counterexample(ours["safe"], spec) is None
    word = satisfaction_counterexample(ours["mission"], spec)
    assert word is not None and len(word) == 2  # two picks in a row, shortest
    assert ours["mission"].accepts(word) and not spec.accepts(word)
    # libFAUDES agrees that the mission does not satisfy the specification
    spec_everywhere = inverse_project(spec, ours["mission"].alphabet)
    assert not ref.language_inclusion(warehouse["gens"]["mission"], to_fd(spec_everywhere))
    assert ref.language_inclusion(warehouse["gens"]["safe"], to_fd(spec_everywhere))


# ---------------------------------------------------------------------------------------------
# the adapter's calling convention
# ---------------------------------------------------------------------------------------------


def test_to_faudes_accepts_numpy_integers() -> None:
    a = DFA.from_transitions("0", [("0", "a", "1")], marked=["1"])
    rows, cols = np.nonzero(a.delta >= 0)
    transitions = [(q, a.alphabet[j], a.delta[q, j]) for q, j in zip(rows, cols, strict=True)]
    gen = ref.to_faudes(a.alphabet, a.n_states, a.initial, np.flatnonzero(a.marked), transitions)
    assert ref.language_equality(gen, to_fd(a))
