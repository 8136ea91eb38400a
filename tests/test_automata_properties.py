"""Property-based tests of :mod:`cosmop.automata` against brute-force word enumeration.

What is checked
---------------
Random small DFAs (1-6 states, partial transition tables, random marking and initial state,
alphabets drawn in random order from a small pool so that two DFAs share some events but
not all) are compared with *oracles written here*, which only read ``delta``/``marked``
(or call :meth:`DFA.accepts`) and enumerate words:

* products: :func:`parallel` (2 and 3 factors) is the synchronous product
  (:math:`w \\in L_m` iff :math:`P_i(w) \\in L_m(G_i)` for every factor), :func:`product`
  the intersection over the union alphabet; both construction paths of ``_pair`` (dense
  table and breadth-first explorer, forced with ``_DENSE_LIMIT = 0``) agree;
* natural projection against a breadth-first search over (state, position in ``u``) pairs,
  inverse projection, complement, alphabet extension and completion by their definitions;
* :func:`trim`, :func:`accessible`, :func:`minimize`, :func:`canonical`,
  :func:`prefix_closure`: language preserved / prefix-closure definition, no blocking or
  inaccessible state, minimum state count against a brute-force Myhill-Nerode count,
  idempotence and canonical tables;
* counterexamples (:func:`inclusion_counterexample`, :func:`equivalence_counterexample`,
  :func:`satisfaction_counterexample`): correct and of minimal length; both inclusion
  paths (``_inclusion_by_partner`` and ``_inclusion_by_pairs``) are exercised and agree;
* :func:`project_composition` equals ``project(parallel(...))`` and is minimal;
  :class:`Composition`; :func:`lift_word` lifts the (first few, short) words of the
  projection and returns ``None`` for words outside it;
* :class:`DFA` construction, validation, ``to_dict``/``from_dict`` and ``to_dot``;
* :class:`cosmop.automata._index.CodeIndex` with huge codes and forced collisions.

Why "up to L" is the right statement
------------------------------------
Language properties are checked on *every* word of length at most ``L`` over the relevant
alphabet, where ``L`` is as large as keeps the enumeration near 2000 words
(:func:`bound`: 5 over four events, 6 over three, 8 over one or two).  That is an
"up to L" statement, not a proof of language equality: two DFAs with ``n1`` and ``n2``
states (``+1`` each for the implicit dead state) can first differ on a word of length
``n1 + n2``, longer than ``L`` for our largest products.  Where an exact statement is cheap,
the tests make it: the Myhill-Nerode count uses suffixes of length ``n - 1``, which
separates any two distinguishable states of an ``n``-state partial DFA (``n + 1`` states
with the dead one, and Moore's bound is ``(n + 1) - 2``); the prefix-closure oracle decides
"can still reach a marked state" by a fixed point on the graph; counterexample minimality is
checked against the brute-force difference, and when that is empty up to ``L`` the returned
word must be longer than ``L``.
"""

from __future__ import annotations

import itertools
import os
from collections import deque
from collections.abc import Iterable, Sequence
from unittest import mock

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cosmop.automata import (
    DFA,
    Composition,
    _index,
    accessible,
    canonical,
    complement,
    complete,
    equivalence_counterexample,
    equivalent,
    extend_alphabet,
    inclusion_counterexample,
    inverse_project,
    is_empty,
    is_included,
    minimize,
    operations,
    parallel,
    prefix_closure,
    product,
    project,
    project_composition,
    satisfaction_counterexample,
    trim,
    words,
)
from cosmop.automata.composition import SizeLog, lift_word, shortest_word

POOL = ("a", "b", "c", "d")
WIDE_POOL = ("a", "b", "c", "d", "e", "f")
WORD_BUDGET = 2000

Word = tuple[str, ...]

# COSMOP_EXAMPLES_SCALE=10 multiplies every budget (for a long local hunt; CI keeps 1).
SCALE = float(os.environ.get("COSMOP_EXAMPLES_SCALE", "1"))
FAST = settings(
    max_examples=int(150 * SCALE),
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)
SLOW = settings(
    max_examples=int(60 * SCALE),
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)


# ---------------------------------------------------------------------------------------------
# strategies
# ---------------------------------------------------------------------------------------------


@st.composite
def dfas(
    draw,
    pool: Sequence[str] = POOL,
    *,
    min_events: int = 1,
    max_events: int = 3,
    max_states: int = 6,
    sorted_alphabet: bool = False,
    names: bool = False,
) -> DFA:
    """Random partial DFA: 1..max_states states, events from ``pool`` (random order)."""
    events = list(draw(st.permutations(pool))[: draw(st.integers(min_events, max_events))])
    if sorted_alphabet:
        events.sort()
    n = draw(st.integers(1, max_states))
    holes = draw(st.integers(1, 3))  # how partial: P(undefined) = holes / (n + holes)
    entry = st.integers(-holes, n - 1).map(lambda t: max(t, -1))
    delta = draw(st.lists(entry, min_size=n * len(events), max_size=n * len(events)))
    marked = draw(st.lists(st.booleans(), min_size=n, max_size=n))
    initial = draw(st.integers(0, n - 1))
    state_names = None
    if names:
        label = st.text(alphabet='ab "\\-_:1', min_size=1, max_size=4)
        state_names = tuple(draw(st.lists(label, min_size=n, max_size=n, unique=True)))
    table = np.array(delta, dtype=np.int32).reshape(n, len(events))
    return DFA(tuple(events), table, initial, np.array(marked, dtype=bool), state_names)


def event_sets(pool: Sequence[str] = (*POOL, "z")) -> st.SearchStrategy[frozenset[str]]:
    """Target alphabets: subsets of ``pool`` (``z`` is an event no generated DFA has)."""
    return st.frozensets(st.sampled_from(pool), max_size=len(pool))


def components(max_components: int = 4) -> st.SearchStrategy[list[DFA]]:
    """2..max_components small DFAs over a wider pool, so that clusters often separate."""
    return st.lists(
        dfas(WIDE_POOL, min_events=1, max_events=3, max_states=4), min_size=2, max_size=max_components
    )


# ---------------------------------------------------------------------------------------------
# brute-force oracles (independent of cosmop.automata.operations)
# ---------------------------------------------------------------------------------------------


def bound(n_events: int, budget: int = WORD_BUDGET) -> int:
    """Largest ``L <= 8`` such that there are at most ``budget`` words of length ``<= L``."""
    length, total = 0, 1
    while length < 8 and total + n_events ** (length + 1) <= budget:
        length += 1
        total += n_events**length
    return length


def all_words(alphabet: Iterable[str], length: int) -> list[Word]:
    """Every word over ``alphabet`` of length ``<= length``, shortest first."""
    alphabet = sorted(set(alphabet))
    return [w for k in range(length + 1) for w in itertools.product(alphabet, repeat=k)]


def proj(word: Sequence[str], events: Iterable[str]) -> Word:
    """Natural projection of one word: erase the events outside ``events``."""
    keep = set(events)
    return tuple(e for e in word if e in keep)


def run_from(dfa: DFA, state: int, word: Sequence[str]) -> int:
    """State reached from ``state`` by ``word`` (``-1`` if undefined); reads ``delta`` only."""
    col = {e: j for j, e in enumerate(dfa.alphabet)}
    for e in word:
        if e not in col:
            return -1
        state = int(dfa.delta[state, col[e]])
        if state < 0:
            return -1
    return state


def lang(dfa: DFA, alphabet: Iterable[str], length: int, *, start: int | None = None) -> set[Word]:
    """Marked words over ``alphabet`` of length ``<= length`` (from ``start``, default q0).

    A depth-first walk of the word tree that only follows defined transitions, so it costs
    the number of *generated* words rather than ``|alphabet| ** length``.
    """
    col = {e: j for j, e in enumerate(dfa.alphabet)}
    usable = [(e, col[e]) for e in sorted(set(alphabet)) if e in col]
    delta, marked = dfa.delta.tolist(), dfa.marked.tolist()
    out: set[Word] = set()
    stack: list[tuple[Word, int]] = [((), dfa.initial if start is None else start)]
    while stack:
        w, q = stack.pop()
        if marked[q]:
            out.add(w)
        if len(w) < length:
            for e, j in usable:
                t = delta[q][j]
                if t >= 0:
                    stack.append(((*w, e), t))
    return out


def reachable_states(dfa: DFA) -> set[int]:
    """States reachable from q0 (plain breadth-first search)."""
    seen, queue = {dfa.initial}, deque([dfa.initial])
    while queue:
        q = queue.popleft()
        for t in dfa.delta[q].tolist():
            if t >= 0 and t not in seen:
                seen.add(t)
                queue.append(t)
    return seen


def coreachable_states(dfa: DFA) -> set[int]:
    """States from which some marked state is reachable (fixed point)."""
    good = set(np.flatnonzero(dfa.marked).tolist())
    changed = True
    while changed:
        changed = False
        for q in range(dfa.n_states):
            if q not in good and any(t in good for t in dfa.delta[q].tolist() if t >= 0):
                good.add(q)
                changed = True
    return good


def projects_onto(dfa: DFA, u: Sequence[str], events: Iterable[str]) -> bool:
    """Whether some ``w`` in ``L_m(dfa)`` has ``P_events(w) == u``.

    Breadth-first search over pairs (state, number of letters of ``u`` read): an event
    outside ``events`` moves the state only, the event ``u[i]`` moves both.  The pair space
    is finite, so this is exact for every ``u``.
    """
    keep = set(events)
    col = {e: j for j, e in enumerate(dfa.alphabet)}
    hidden = [j for e, j in col.items() if e not in keep]
    start = (dfa.initial, 0)
    seen, queue = {start}, deque([start])
    while queue:
        q, i = queue.popleft()
        if i == len(u) and dfa.marked[q]:
            return True
        moves = [(int(dfa.delta[q, j]), i) for j in hidden]
        if i < len(u) and u[i] in col:
            moves.append((int(dfa.delta[q, col[u[i]]]), i + 1))
        for t, k in moves:
            if t >= 0 and (t, k) not in seen:
                seen.add((t, k))
                queue.append((t, k))
    return False


def synchronous_words(factors: Sequence[DFA], length: int) -> set[Word]:
    """Words over the union alphabet, ``<= length``, whose projections all are marked."""
    union = sorted({e for f in factors for e in f.alphabet})
    marked = [lang(f, f.alphabet, length) for f in factors]
    return {
        w
        for w in all_words(union, length)
        if all(proj(w, f.alphabet) in m for f, m in zip(factors, marked, strict=True))
    }


def nerode_count(dfa: DFA) -> int:
    """Number of distinct non-empty residuals among the reachable states (brute force).

    Residuals are compared on suffixes of length ``<= n - 1``; with the implicit dead state
    the automaton has ``n + 1`` states, and distinguishable states of such an automaton are
    separated by a word of length at most ``(n + 1) - 2``, so the count is exact.
    """
    depth = max(dfa.n_states - 1, 0)
    residuals = {frozenset(lang(dfa, dfa.alphabet, depth, start=q)) for q in reachable_states(dfa)}
    residuals.discard(frozenset())
    return len(residuals)


def tables(dfa: DFA) -> tuple:
    """Everything that defines a DFA up to names, for exact comparisons."""
    return dfa.alphabet, dfa.initial, dfa.delta.tolist(), dfa.marked.tolist()


def permuted(dfa: DFA, perm: Sequence[int]) -> DFA:
    """The same automaton with state ``q`` renamed ``perm[q]``."""
    perm = np.asarray(perm)
    delta = np.full_like(dfa.delta, -1)
    delta[perm] = np.where(dfa.delta >= 0, perm[np.maximum(dfa.delta, 0)], -1)
    marked = np.zeros(dfa.n_states, dtype=bool)
    marked[perm] = dfa.marked
    return DFA(dfa.alphabet, delta, int(perm[dfa.initial]), marked)


def union_alphabet(*dfas_: DFA, extra: Iterable[str] = ()) -> tuple[str, ...]:
    return tuple(sorted({e for d in dfas_ for e in d.alphabet} | set(extra)))


# ---------------------------------------------------------------------------------------------
# the oracle itself
# ---------------------------------------------------------------------------------------------


@FAST
@given(a=dfas())
def test_oracle_lang_matches_accepts(a: DFA) -> None:
    length = bound(len(POOL))
    marked = lang(a, POOL, length)
    for w in all_words(POOL, length):
        assert (w in marked) == a.accepts(w)
        assert a.generates(w) == (run_from(a, a.initial, w) >= 0)


@FAST
@given(a=dfas())
def test_words_enumerates_the_languages_in_length_order(a: DFA) -> None:
    length = bound(len(a.alphabet))
    listed = list(words(a, length))
    assert len(listed) == len(set(listed))
    assert set(listed) == lang(a, a.alphabet, length)
    assert [len(w) for w in listed] == sorted(len(w) for w in listed)
    generated = {w for w in all_words(a.alphabet, length) if a.generates(w)}
    assert set(words(a, length, marked=False)) == generated


# ---------------------------------------------------------------------------------------------
# products (both construction paths)
# ---------------------------------------------------------------------------------------------


@pytest.fixture(params=["dense", "explore"])
def product_path(request):
    """Run the test once with the dense product table and once with the explorer."""
    if request.param == "dense":
        yield request.param
    else:
        with mock.patch.object(operations, "_DENSE_LIMIT", 0):
            yield request.param


@FAST
@given(a=dfas(), b=dfas())
def test_parallel_is_synchronous_product(product_path, a: DFA, b: DFA) -> None:
    p = parallel(a, b)
    union = union_alphabet(a, b)
    assert p.alphabet == union
    length = bound(len(union))
    assert lang(p, union, length) == synchronous_words([a, b], length)
    assert reachable_states(p) == set(range(p.n_states))  # only accessible pairs are built


@SLOW
@given(a=dfas(), b=dfas(), c=dfas())
def test_parallel_of_three(product_path, a: DFA, b: DFA, c: DFA) -> None:
    p = parallel(a, b, c)
    union = union_alphabet(a, b, c)
    assert p.alphabet == union
    length = bound(len(union))
    assert lang(p, union, length) == synchronous_words([a, b, c], length)


@FAST
@given(a=dfas(), b=dfas())
def test_product_is_intersection_over_union_alphabet(product_path, a: DFA, b: DFA) -> None:
    p = product(a, b)
    union = union_alphabet(a, b)
    assert p.alphabet == union
    length = bound(len(union))
    assert lang(p, union, length) == lang(a, union, length) & lang(b, union, length)


@FAST
@given(a=dfas(sorted_alphabet=True), b=dfas(sorted_alphabet=True))
def test_dense_and_explored_products_are_identical(a: DFA, b: DFA) -> None:
    # Both build exactly the accessible pairs, so after canonical renumbering the tables match.
    for synchronous in (True, False):
        dense = operations._pair(a, b, synchronous=synchronous)
        with mock.patch.object(operations, "_DENSE_LIMIT", 0):
            explored = operations._pair(a, b, synchronous=synchronous)
        assert dense.n_states == explored.n_states
        assert tables(canonical(dense)) == tables(canonical(explored))
        assert explored.initial == 0


@FAST
@given(a=dfas(("a", "b")), b=dfas(("c", "d", "e")))
def test_interleaved_products_skip_the_search_only_when_every_pair_is_reached(a: DFA, b: DFA) -> None:
    # no shared event: when both sides are accessible the whole table is the product (no
    # search); otherwise the search runs.  Either way the table is the explorer's.
    dense = operations._pair(a, b, synchronous=True)
    with mock.patch.object(operations, "_DENSE_LIMIT", 0):
        explored = operations._pair(a, b, synchronous=True)
    assert tables(canonical(dense)) == tables(canonical(explored))
    assert reachable_states(dense) == set(range(dense.n_states))
    assert lang(dense, dense.alphabet, 4) == synchronous_words([a, b], 4)


def test_explorer_with_table_growth_matches_dense() -> None:
    # 4**6 = 4096 accessible pairs: the explorer's CodeIndex (1024 slots at first) must grow
    chains = [DFA.from_word((f"p{i}", f"d{i}", f"r{i}")) for i in range(6)]
    order = DFA.from_word(tuple(f"p{i}" for i in range(6)), closed=False)
    for factors in (chains, [*chains, order]):
        dense = parallel(*factors)
        with mock.patch.object(operations, "_DENSE_LIMIT", 0):
            explored = parallel(*factors)
        assert dense.n_states == explored.n_states
        assert tables(canonical(dense)) == tables(canonical(explored))
    assert parallel(*chains).n_states == 4**6


def test_empty_alphabets() -> None:
    eps = DFA((), np.zeros((2, 0)), 1, np.array([False, True]))  # {eps}, one unreachable state
    nothing = DFA.empty()
    a = DFA.from_transitions("0", [("0", "a", "1")], marked=["1"])
    assert equivalent(parallel(eps, a), a) and equivalent(parallel(a, eps), a)
    assert is_empty(parallel(nothing, a)) and is_empty(product(a, nothing))
    assert equivalent(product(eps, a), DFA.empty(["a"]))  # a's only word is not eps
    assert project(a, ()).alphabet == () and project(a, ()).accepts(())
    assert minimize(eps).n_states == 1 and minimize(eps).marked.tolist() == [True]
    assert inclusion_counterexample(eps, nothing) == ()
    assert inclusion_counterexample(nothing, eps) is None
    assert equivalence_counterexample(eps, a) == ()
    assert satisfaction_counterexample(a, eps) is None  # P onto the empty alphabet is always eps
    assert satisfaction_counterexample(eps, a) == ()
    assert {w for w in all_words("a", 2) if complement(eps, ["a"]).accepts(w)} == {("a",), ("a", "a")}
    assert equivalent(project_composition([eps, a], {"a"}), a)
    assert is_empty(project_composition([nothing, a], {"a"}))
    assert lift_word([eps, a], ("a",), {"a"}) == ("a",)
    assert lift_word([nothing, a], ("a",), {"a"}) is None
    assert tables(canonical(eps)) == ((), 0, [[]], [True])


def test_parallel_and_product_edge_cases() -> None:
    a = DFA.from_transitions("0", [("0", "a", "1")])
    assert parallel(a) is a
    with pytest.raises(ValueError):
        parallel()
    with pytest.raises(ValueError):
        product()
    # equal alphabets: product == parallel
    b = DFA.from_transitions("0", [("0", "a", "0")], marked=["0"])
    assert equivalent(product(a, b), parallel(a, b))
    # disjoint alphabets: parallel interleaves, product only keeps the common words (epsilon)
    c = DFA.from_transitions("0", [("0", "c", "1")])
    assert parallel(a, c).accepts(("c", "a"))
    assert not product(a, c).accepts(("a",))
    assert product(a, c).accepts(())


# ---------------------------------------------------------------------------------------------
# projection and alphabet operations
# ---------------------------------------------------------------------------------------------


@FAST
@given(a=dfas(), target=event_sets())
def test_project_is_natural_projection(a: DFA, target: frozenset[str]) -> None:
    p = project(a, target)
    assert p.alphabet == tuple(sorted(target))
    length = bound(len(target))
    for u in all_words(target, length):
        assert p.accepts(u) == projects_onto(a, u, target), u
    # the other direction on a's own words: every marked word projects into the result
    for w in lang(a, a.alphabet, bound(len(a.alphabet), 500)):
        assert p.accepts(proj(w, target))


def test_project_examples() -> None:
    # (a | b c) with b hidden: onto {a, c} gives {a, c}; onto {} gives {eps}; unknown z kept
    g = DFA.from_transitions("0", [("0", "a", "1"), ("0", "b", "2"), ("2", "c", "3")], marked=["1", "3"])
    p = project(g, {"a", "c", "z"})
    assert p.alphabet == ("a", "c", "z")
    assert {w for w in all_words(p.alphabet, 3) if p.accepts(w)} == {("a",), ("c",)}
    assert project(g, set()).accepts(())
    unmarked = DFA.from_transitions("0", [("0", "a", "1")], marked=[])
    assert is_empty(project(unmarked, set()))


@FAST
@given(a=dfas(), extra=event_sets())
def test_inverse_project(a: DFA, extra: frozenset[str]) -> None:
    ip = inverse_project(a, extra)
    union = union_alphabet(a, extra=extra)
    assert ip.alphabet == union
    length = bound(len(union))
    marked = lang(a, a.alphabet, length)
    assert lang(ip, union, length) == {w for w in all_words(union, length) if proj(w, a.alphabet) in marked}


@FAST
@given(a=dfas(), extra=event_sets())
def test_complement(a: DFA, extra: frozenset[str]) -> None:
    c = complement(a, extra)
    union = union_alphabet(a, extra=extra)
    assert c.alphabet == union
    length = bound(len(union))
    assert lang(c, union, length) == set(all_words(union, length)) - lang(a, union, length)
    assert equivalent(complement(c), extend_alphabet(a, extra))


@FAST
@given(a=dfas(), extra=event_sets())
def test_extend_alphabet_and_complete(a: DFA, extra: frozenset[str]) -> None:
    union = union_alphabet(a, extra=extra)
    length = bound(len(union))
    expected = lang(a, union, length)
    e = extend_alphabet(a, extra)
    assert e.alphabet == union
    assert e.n_states == a.n_states
    assert lang(e, union, length) == expected
    c = complete(a, extra)
    assert c.alphabet == union
    assert bool((c.delta >= 0).all())
    assert lang(c, union, length) == expected
    assert {w for w in all_words(union, length) if c.generates(w)} == set(all_words(union, length))


# ---------------------------------------------------------------------------------------------
# trim, accessible, prefix closure, minimisation, canonical form
# ---------------------------------------------------------------------------------------------


@FAST
@given(a=dfas())
def test_trim_and_accessible(a: DFA) -> None:
    length = bound(len(a.alphabet))
    expected = lang(a, a.alphabet, length)
    empty = not (reachable_states(a) & set(np.flatnonzero(a.marked).tolist()))
    assert is_empty(a) == empty

    acc = accessible(a)
    assert reachable_states(acc) == set(range(acc.n_states))
    assert lang(acc, a.alphabet, length) == expected
    generated = {w for w in all_words(a.alphabet, length) if a.generates(w)}
    assert {w for w in all_words(a.alphabet, length) if acc.generates(w)} == generated

    t = trim(a)
    # same events; the order is kept, except that the empty language comes back sorted
    assert set(t.alphabet) == set(a.alphabet)
    assert lang(t, a.alphabet, length) == expected
    if empty:
        assert (t.n_states, t.n_transitions, bool(t.marked.any())) == (1, 0, False)
    else:
        everything = set(range(t.n_states))
        assert reachable_states(t) == everything
        assert coreachable_states(t) == everything  # no blocking state
    assert tables(trim(t)) == tables(t)


@FAST
@given(a=dfas())
def test_prefix_closure(a: DFA) -> None:
    length = bound(len(a.alphabet))
    alive = coreachable_states(a)
    expected = set()
    for w in all_words(a.alphabet, length):
        q = run_from(a, a.initial, w)
        if q >= 0 and q in alive:  # w can be extended to a marked word
            expected.add(w)
    pc = prefix_closure(a)
    assert lang(pc, a.alphabet, length) == expected
    if expected:
        assert pc.is_prefix_closed_marking()
    assert is_included(a, pc)


@FAST
@given(a=dfas())
def test_minimize(a: DFA) -> None:
    length = bound(len(a.alphabet))
    m = minimize(a)
    assert set(m.alphabet) == set(a.alphabet)
    assert lang(m, a.alphabet, length) == lang(a, a.alphabet, length)
    assert m.n_states == max(nerode_count(a), 1)  # the empty language keeps one state
    assert m.n_states <= trim(a).n_states
    if not is_empty(a):
        everything = set(range(m.n_states))
        assert reachable_states(m) == everything
        assert coreachable_states(m) == everything
    assert tables(minimize(m)) == tables(m)  # idempotent
    assert tables(canonical(m)) == tables(m)  # already canonical


@FAST
@given(a=dfas(sorted_alphabet=True), data=st.data())
def test_canonical_minimal_tables_depend_only_on_the_language(a: DFA, data) -> None:
    perm = data.draw(st.permutations(range(a.n_states)))
    shuffled = permuted(a, perm)
    assert tables(canonical(shuffled)) == tables(canonical(a))
    assert equivalent(canonical(a), a)
    m = minimize(a)
    assert tables(minimize(shuffled)) == tables(m)
    assert tables(minimize(parallel(a, a))) == tables(m)
    assert tables(minimize(product(a, prefix_closure(a)))) == tables(m)
    # a redundant copy of every state: same language, twice the states
    n = a.n_states
    twice = DFA(
        a.alphabet,
        np.vstack([np.where(a.delta >= 0, a.delta + n, -1), a.delta]),
        a.initial,
        np.concatenate([a.marked, a.marked]),
    )
    assert tables(minimize(twice)) == tables(m)


def test_canonical_numbers_breadth_first() -> None:
    g = DFA.from_transitions("s", [("s", "b", "x"), ("s", "a", "y"), ("y", "a", "z"), ("x", "a", "s")])
    c = canonical(g)
    # columns a, b: from s, 'a' reaches y (1) before 'b' reaches x (2); then z (3)
    assert c.delta.tolist() == [[1, 2], [3, -1], [0, -1], [-1, -1]]


# ---------------------------------------------------------------------------------------------
# counterexamples
# ---------------------------------------------------------------------------------------------


def check_shortest(word: Word | None, difference: list[Word], length: int) -> None:
    """``word`` is None iff ``difference`` (all words <= length) is empty -- up to length."""
    if word is None:
        assert not difference, f"missed counterexample {min(difference, key=len)}"
    elif difference:
        assert len(word) == min(len(w) for w in difference)
    else:
        assert len(word) > length  # nothing up to ``length``: a shortest one must be longer


@FAST
@given(a=dfas(), b=dfas())
def test_inclusion_counterexample(a: DFA, b: DFA) -> None:
    union = union_alphabet(a, b)
    length = bound(len(union))
    difference = [w for w in lang(a, union, length) if not b.accepts(w)]
    w = inclusion_counterexample(a, b)
    if w is not None:
        assert a.accepts(w)
        assert not b.accepts(w)
    check_shortest(w, difference, length)
    assert is_included(a, b) == (w is None)


@FAST
@given(a=dfas(), b=dfas())
def test_inclusion_finds_the_same_word_with_or_without_trimming(a: DFA, b: DFA) -> None:
    # the search starts on ``a`` untrimmed and trims only when its fast path fails; the
    # word it returns must be the one the trimmed automaton gives
    assert inclusion_counterexample(a, b) == inclusion_counterexample(trim(a), b)


@FAST
@given(a=dfas(), b=dfas())
def test_inclusion_holds_where_it_must(a: DFA, b: DFA) -> None:
    assert inclusion_counterexample(product(a, b), a) is None
    assert inclusion_counterexample(parallel(a, b), inverse_project(a, b.alphabet)) is None
    assert inclusion_counterexample(a, prefix_closure(a)) is None
    assert inclusion_counterexample(trim(a), a) is None
    assert inclusion_counterexample(a, minimize(a)) is None
    assert inclusion_counterexample(DFA.empty(b.alphabet), a) is None
    assert inclusion_counterexample(a, DFA.universal(a.alphabet)) is None


@FAST
@given(a=dfas(), b=dfas())
def test_equivalence_counterexample(a: DFA, b: DFA) -> None:
    union = union_alphabet(a, b)
    length = bound(len(union))
    la, lb = lang(a, union, length), lang(b, union, length)
    w = equivalence_counterexample(a, b)
    if w is not None:
        assert a.accepts(w) != b.accepts(w)
    check_shortest(w, sorted(la ^ lb), length)
    assert equivalent(a, b) == (w is None)
    for same in (minimize(a), trim(a), canonical(a), complement(complement(a)), parallel(a, a)):
        assert equivalence_counterexample(a, same) is None
    assert equivalence_counterexample(parallel(a, b), parallel(b, a)) is None


@FAST
@given(model=dfas(), spec=dfas())
def test_satisfaction_counterexample(model: DFA, spec: DFA) -> None:
    length = bound(len(model.alphabet))
    bad = [w for w in lang(model, model.alphabet, length) if not spec.accepts(proj(w, spec.alphabet))]
    w = satisfaction_counterexample(model, spec)
    if w is not None:
        assert set(w) <= set(model.alphabet)
        assert model.accepts(w)
        assert not spec.accepts(proj(w, spec.alphabet))
    check_shortest(w, bad, length)
    # a model always satisfies its own projection
    assert satisfaction_counterexample(model, project(model, spec.alphabet)) is None


def inclusion_paths(a: DFA, b: DFA) -> tuple[list[int] | str | None, list[int] | None]:
    """Both inclusion paths on the same input: (partner result or 'not functional', pairs result)."""
    a = trim(a)
    union = union_alphabet(a, b)
    da = operations._columns(a, union, "block")
    db = operations._columns(b, union, "block")
    try:
        fast: list[int] | str | None = operations._inclusion_by_partner(a, b, da, db)
    except operations._NotFunctional:
        fast = "not functional"
    slow = operations._inclusion_by_pairs(a, complete(b, union), da)
    return fast, slow


def check_paths_agree(a: DFA, b: DFA) -> str:
    union = union_alphabet(a, b)
    fast, slow = inclusion_paths(a, b)
    if slow is not None:
        word = tuple(union[j] for j in slow)
        assert a.accepts(word) and not b.accepts(word)
    if fast == "not functional":
        return "pairs"
    if fast is None:
        assert slow is None
    else:
        assert slow is not None and len(fast) == len(slow)
        word = tuple(union[j] for j in fast)
        assert a.accepts(word) and not b.accepts(word)
    return "partner"


@FAST
@given(a=dfas(), b=dfas())
def test_inclusion_paths_agree(a: DFA, b: DFA) -> None:
    check_paths_agree(a, b)
    check_paths_agree(a, parallel(a, b))
    check_paths_agree(parallel(a, b), a)


def test_inclusion_paths_both_exercised() -> None:
    # a state of ``a`` meets two states of ``b``: a's single loop against b's two-cycle
    loop = DFA.from_transitions("0", [("0", "x", "0")])
    cycle = DFA.from_transitions("0", [("0", "x", "1"), ("1", "x", "0")], marked=["0"])
    assert inclusion_paths(loop, cycle)[0] == "not functional"
    assert inclusion_counterexample(loop, cycle) == ("x",)
    assert inclusion_counterexample(cycle, loop) is None
    assert inclusion_paths(cycle, loop)[0] is None
    # and a seeded sweep over random pairs must take both paths, and agree on each
    rng = np.random.default_rng(7)
    seen = {"partner": 0, "pairs": 0}
    for _ in range(300):
        pair = []
        for _ in range(2):
            n = int(rng.integers(1, 6))
            events = tuple(rng.permutation(POOL)[: int(rng.integers(0, 4))])
            delta = rng.integers(-2, n, size=(n, len(events))).clip(-1)
            pair.append(DFA(events, delta, int(rng.integers(n)), rng.random(n) < 0.5))
        seen[check_paths_agree(*pair)] += 1
    assert seen["partner"] >= 20 and seen["pairs"] >= 20, seen


# ---------------------------------------------------------------------------------------------
# compositional projection, Composition, lift_word
# ---------------------------------------------------------------------------------------------


@SLOW
@given(cs=components(), target=event_sets((*WIDE_POOL, "y", "z")))
def test_project_composition_equals_project_of_parallel(cs: list[DFA], target: frozenset[str]) -> None:
    log = SizeLog()
    pc = project_composition(cs, target, log=log)
    whole = project(parallel(*cs), target)
    assert pc.alphabet == tuple(sorted(target))
    assert equivalent(pc, whole), equivalence_counterexample(pc, whole)
    assert pc.n_states == minimize(pc).n_states  # documented as minimal
    length = bound(len(target), 800)
    assert lang(pc, target, length) == lang(whole, target, length)
    composition = Composition(tuple(cs))
    assert composition.alphabet == union_alphabet(*cs)
    assert tables(composition.project(target)) == tables(pc)
    built = composition.build()
    assert tables(canonical(built)) == tables(canonical(parallel(*cs)))


def test_project_composition_separate_clusters() -> None:
    r1 = DFA.from_transitions("0", [("0", "p1", "1"), ("1", "d1", "2")])
    r2 = DFA.from_transitions("0", [("0", "p2", "1"), ("1", "d2", "2")])
    dead = DFA.from_transitions("0", [("0", "x", "1")], marked=[])  # empty marked language
    target = {"p1", "p2", "z"}
    pc = project_composition([r1, r2], target)
    assert pc.alphabet == ("p1", "p2", "z")
    assert equivalent(pc, project(parallel(r1, r2), target))
    assert pc.accepts(("p2", "p1")) and not pc.accepts(("z",))
    # an unrelated cluster with an empty language empties the whole product
    assert is_empty(project_composition([r1, r2, dead], target))
    # no component touches the target: {eps} (or empty)
    assert {w for w in all_words(["y"], 2) if project_composition([r1, r2], {"y"}).accepts(w)} == {()}
    assert Composition((r1, r2)).alphabet == ("d1", "d2", "p1", "p2")
    with pytest.raises(ValueError):
        Composition(())


@SLOW
@given(cs=components(3), target=event_sets((*WIDE_POOL, "z")))
def test_lift_word(cs: list[DFA], target: frozenset[str]) -> None:
    whole = parallel(*cs)
    projected = project(whole, target)
    members = sorted(lang(projected, target, 3), key=lambda w: (len(w), w))[:6]
    others = [u for u in all_words(target, 2) if not projected.accepts(u)][:6]
    for u in members:
        t = lift_word(cs, u, target)
        assert t is not None, u
        assert whole.accepts(t), (u, t)
        assert proj(t, target) == u
    for u in others:
        assert lift_word(cs, u, target) is None, u


def test_lift_word_target_event_unknown_to_components() -> None:
    # BUG reproducer: "b" is in the target alphabet but in no component, so no word of the
    # product projects onto ("b",); lift_word must say None, not return ("b",).
    c = DFA.from_transitions("0", [("0", "a", "1")])
    assert not project(c, {"b"}).accepts(("b",))
    assert lift_word([c], ("b",), {"b"}) is None
    # same with the event next to a known one: the pinned word's private "c" interleaves
    assert not project(c, {"a", "c"}).accepts(("c",))
    assert lift_word([c], ("c",), {"a", "c"}) is None


@FAST
@given(a=dfas())
def test_shortest_word(a: DFA) -> None:
    w = shortest_word(a)
    marked = lang(a, a.alphabet, bound(len(a.alphabet)))
    if w is None:
        assert is_empty(a)
    else:
        assert a.accepts(w)
        assert not marked or len(w) == min(len(x) for x in marked)


# ---------------------------------------------------------------------------------------------
# the DFA type: construction, validation, serialisation
# ---------------------------------------------------------------------------------------------


def named_structure(d: DFA) -> tuple:
    """A DFA up to state order: names of everything."""
    return (
        d.name_of(d.initial),
        frozenset(d.name_of(q) for q in range(d.n_states)),
        frozenset(d.transitions()),
        frozenset(d.name_of(int(q)) for q in np.flatnonzero(d.marked)),
    )


@FAST
@given(a=dfas(names=True))
def test_dict_round_trip(a: DFA) -> None:
    data = a.to_dict()
    back = DFA.from_dict(data)
    assert named_structure(back) == named_structure(a)
    assert set(back.alphabet) <= set(a.alphabet)
    assert {e for _, e, _ in a.transitions()} <= set(back.alphabet)
    assert back.alphabet == tuple(sorted(back.alphabet))
    assert equivalent(back, a)
    assert named_structure(DFA.from_dict(back.to_dict())) == named_structure(a)
    full = DFA.from_dict(a.to_dict(with_alphabet=True))
    assert full.alphabet == tuple(sorted(a.alphabet))
    assert named_structure(full) == named_structure(a)


@FAST
@given(a=dfas(names=True))
def test_from_transitions_rebuilds_the_table(a: DFA) -> None:
    names = [a.name_of(q) for q in range(a.n_states)]
    marked = [names[q] for q in np.flatnonzero(a.marked)]
    b = DFA.from_transitions(
        names[a.initial], a.transitions(), marked=marked, states=names, alphabet=a.alphabet
    )
    assert b.alphabet == tuple(sorted(a.alphabet))
    assert b.state_names == tuple(names)
    assert b.initial == a.initial
    assert b.marked.tolist() == a.marked.tolist()
    assert tables(b) == tables(extend_alphabet(a, ()))  # same table, columns sorted


@FAST
@given(a=dfas(names=True))
def test_to_dot_mentions_every_state_and_event(a: DFA) -> None:
    dot = a.to_dot("G")

    def quote(text: str) -> str:
        return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'

    assert dot.startswith('digraph "G" {') and dot.rstrip().endswith("}")
    for q in range(a.n_states):
        shape = "doublecircle" if a.marked[q] else "circle"
        assert f"  {quote(a.name_of(q))} [shape={shape}];" in dot
    assert f"__start -> {quote(a.name_of(a.initial))};" in dot
    for event in {e for _, e, _ in a.transitions()}:
        assert quote(event)[1:-1] in dot
    pairs = {(s, t) for s, _, t in a.transitions()}
    assert dot.count(" -> ") == len(pairs) + 1


def test_to_dot_escapes_names() -> None:
    g = DFA.from_transitions('say "hi"', [('say "hi"', 'ev "x"', "back\\slash")], marked=["back\\slash"])
    dot = g.to_dot('my "graph"')
    assert dot.startswith('digraph "my \\"graph\\"" {')
    assert '"say \\"hi\\"" -> "back\\\\slash" [label="ev \\"x\\""];' in dot
    assert '"back\\\\slash" [shape=doublecircle];' in dot


def test_from_transitions_examples() -> None:
    g = DFA.from_transitions("s", [("s", "b", "t"), ("t", "a", "s"), ("s", "b", "t")], alphabet=["z"])
    assert g.alphabet == ("a", "b", "z")
    assert g.state_names == ("s", "t")
    assert g.marked.all()
    assert g.accepts(("b", "a", "b"))
    g = DFA.from_transitions("s", [("s", "a", "t")], marked=["t"], states=["t", "u", "s"])
    assert g.state_names == ("t", "u", "s") and g.initial == 2 and g.marked.tolist() == [True, False, False]
    with pytest.raises(ValueError, match="nondeterministic"):
        DFA.from_transitions("s", [("s", "a", "t"), ("s", "a", "s")])
    with pytest.raises(ValueError):
        DFA.from_transitions("s", [("s", "a", "t")], marked=["nowhere"])


def test_word_universal_empty() -> None:
    w = DFA.from_word(("a", "b"), {"c"})
    assert w.alphabet == ("a", "b", "c")
    assert {x for x in all_words("abc", 3) if w.accepts(x)} == {(), ("a",), ("a", "b")}
    w = DFA.from_word(("a", "b"), closed=False)
    assert {x for x in all_words("ab", 3) if w.accepts(x)} == {("a", "b")}
    assert all(DFA.universal("ab").accepts(x) for x in all_words("ab", 3))
    assert is_empty(DFA.empty("ab"))
    assert DFA.empty().n_states == 1


def _dfa_kwargs(**changes) -> dict:
    base = {
        "alphabet": ("a", "b"),
        "delta": np.array([[1, -1], [0, 1]]),
        "initial": 0,
        "marked": np.array([True, False]),
    }
    base.update(changes)
    return base


@pytest.mark.parametrize(
    "changes",
    [
        {"delta": np.array([1, 0])},  # not 2-D
        {"delta": np.array([[1], [0]])},  # wrong number of columns
        {"delta": np.zeros((0, 2)), "marked": np.zeros(0, dtype=bool)},  # no state
        {"alphabet": ("a", "a")},  # repeated event
        {"marked": np.array([True])},  # marked of the wrong shape
        {"initial": 2},
        {"initial": -1},
        {"delta": np.array([[2, -1], [0, 1]])},  # target out of range
        {"delta": np.array([[-2, -1], [0, 1]])},  # below -1
        {"state_names": ("only one",)},
    ],
)
def test_constructor_rejects_malformed_input(changes: dict) -> None:
    DFA(**_dfa_kwargs())  # the base is fine
    with pytest.raises(ValueError):
        DFA(**_dfa_kwargs(**changes))


def test_repeated_state_names_are_rejected() -> None:
    # x(0) --a--> x(1), only the first marked: L_m = {eps}; merged by name it becomes a*
    with pytest.raises(ValueError):
        DFA(("a",), np.array([[1], [-1]]), 0, np.array([True, False]), ("x", "x"))


def test_dfa_is_immutable() -> None:
    d = DFA(**_dfa_kwargs())
    with pytest.raises(ValueError):
        d.delta[0, 0] = 0
    with pytest.raises(ValueError):
        d.marked[0] = False
    assert d.run(("a", "z")) == -1 and not d.generates(("z",))


# ---------------------------------------------------------------------------------------------
# the code index and the explorer
# ---------------------------------------------------------------------------------------------

_MASK64 = (1 << 64) - 1
_GOLDEN = int(_index._GOLDEN)
_GOLDEN_INV = pow(_GOLDEN, -1, 1 << 64)


def colliding_codes(bits: int, slot: int, count: int) -> list[int]:
    """Distinct non-negative int64 codes that all hash to ``slot`` in a table of ``2**bits``."""
    out: list[int] = []
    low = 0
    while len(out) < count:
        product_ = (slot << (64 - bits)) | low  # any value with these top bits
        code = (product_ * _GOLDEN_INV) & _MASK64
        if code < (1 << 63):
            out.append(code)
        low += 1
    return out


int64_codes = st.integers(0, (1 << 63) - 1)


@FAST
@given(
    batches=st.lists(st.lists(int64_codes, max_size=200), min_size=1, max_size=6),
    absent=st.lists(int64_codes, max_size=50),
    hint=st.integers(1, 64),
)
def test_code_index_add_and_lookup(batches: list[list[int]], absent: list[int], hint: int) -> None:
    index = _index.CodeIndex(hint)
    ids: dict[int, int] = {}
    for batch in batches:
        fresh = list(dict.fromkeys(c for c in batch if c not in ids))
        got = index.add(np.array(fresh, dtype=np.int64))
        assert got.tolist() == list(range(len(ids), len(ids) + len(fresh)))
        ids.update(zip(fresh, got.tolist(), strict=True))
        assert index.size == len(ids)
        known = np.array(list(ids), dtype=np.int64)
        assert index.lookup(known).tolist() == list(ids.values())
    missing = [c for c in absent if c not in ids]
    assert index.lookup(np.array(missing, dtype=np.int64)).tolist() == [-1] * len(missing)


def test_code_index_collisions_growth_and_extremes() -> None:
    index = _index.CodeIndex(1)
    bits = index._bits
    # every code of the batch lands on the last slot: probing must wrap around the table
    same_slot = colliding_codes(bits, (1 << bits) - 1, 100)
    assert len({int(s) for s in index._slots(np.array(same_slot, dtype=np.int64))}) == 1
    extremes = [0, 1, (1 << 63) - 1, (1 << 62), 12345678901234567]
    ids = index.add(np.array(same_slot + extremes, dtype=np.int64))
    assert ids.tolist() == list(range(105))
    # a second batch that forces growth (the table doubles, everything is rehashed)
    many = colliding_codes(bits, 3, 2000)
    more = index.add(np.array(many, dtype=np.int64))
    assert index._bits > bits
    assert more.tolist() == list(range(105, 2105))
    everything = np.array(same_slot + extremes + many, dtype=np.int64)
    assert index.lookup(everything).tolist() == list(range(2105))
    # lookups keep the shape and give -1 for absent codes, colliding or not
    grid = everything[:6].reshape(2, 3)
    assert index.lookup(grid).tolist() == [[0, 1, 2], [3, 4, 5]]
    absent = np.array([*colliding_codes(index._bits, 0, 5), 2, 3], dtype=np.int64)
    absent = absent[~np.isin(absent, everything)]
    assert (index.lookup(absent) == -1).all()


def test_explore_matches_breadth_first_search() -> None:
    # x -> 2x+1 and x -> 2x+2 below 200: a binary tree, shortest words are binary expansions
    def successors(codes: np.ndarray) -> np.ndarray:
        out = np.stack([2 * codes + 1, 2 * codes + 2], axis=1)
        return np.where(out < 200, out, -1)

    ex = _index.explore(0, successors, 2)
    assert sorted(ex.codes.tolist()) == list(range(200))
    assert ex.stopped_at == -1
    for i, code in enumerate(ex.codes.tolist()):
        x = 0
        for j in ex.word_to(i):
            x = 2 * x + 1 + j
        assert x == code
    stopped = _index.explore(0, successors, 2, stop=lambda c: c == 150)
    assert stopped.codes[stopped.stopped_at] == 150
    assert len(stopped.word_to(stopped.stopped_at)) == 7  # depth of 150 in the tree


@pytest.mark.parametrize("n", [1000, 1 << 16, (1 << 16) + 3])
def test_coreachable_is_the_same_on_both_sides_of_16_bit_state_numbers(n: int) -> None:
    # up to 2**16 states the targets are sorted as 16-bit keys (radix), above as they are
    from cosmop.automata._index import coreachable

    rng = np.random.default_rng(n)
    delta = rng.integers(-1, n, (n, 3)).astype(np.int32)
    delta[rng.random((n, 3)) < 0.6] = -1  # sparse: many states reach no target
    targets = rng.choice(n, 5, replace=False)
    seen = np.zeros(n, dtype=bool)  # the same question by a plain backward search
    todo = list(targets)
    seen[targets] = True
    sources = [[] for _ in range(n)]
    for s, t in zip(*np.nonzero(delta >= 0), strict=True):
        sources[delta[s, t]].append(s)
    while todo:
        for s in sources[todo.pop()]:
            if not seen[s]:
                seen[s] = True
                todo.append(s)
    got = coreachable(delta, targets)
    np.testing.assert_array_equal(got, seen)
    assert 0 < got.sum() < n
