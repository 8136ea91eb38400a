"""Compositional verification of local missions by assume-guarantee reasoning with L*.

The question (Problem 1): do the local missions :math:`M_i = K^i_{MI}` jointly satisfy the
global mission, :math:`\\|_i M_i \\models K_{MI}`, i.e. :math:`\\|_i L(M_i) \\subseteq K_{MI}`?

The paper's asymmetric rule (Section III), for a guarantor :math:`M_1`, an environment
:math:`M_2` and an assumption :math:`A` over the interface alphabet
:math:`\\Sigma_A = \\Sigma_{M_2} \\cap (\\Sigma_{M_1} \\cup \\Sigma_K)`:

.. math::

   \\frac{\\langle A \\rangle M_1 \\langle K \\rangle \\qquad \\langle true \\rangle M_2 \\langle A \\rangle}
        {\\langle true \\rangle M_1 \\| M_2 \\langle K \\rangle}

:math:`A` is learned with L* (AALpy) and our own teacher: the membership query
:math:`T(t) = \\langle \\mathcal{DFA}(t) \\rangle M_1 \\langle K \\rangle`; a conjecture is checked
against premise 1 (a violation :math:`w` gives the counterexample :math:`P_A(w)`, which the
conjecture wrongly admits) and premise 2 (a word :math:`c` of :math:`M_2` outside the conjecture
is returned when :math:`T(c)` holds; otherwise it is a *real* violation of the global mission).

**Scheme for N robots** (documented in ARCHITECTURE.md).  Three exact reductions keep every
automaton small when the mission has structure:

1. *Property decomposition*: the global mission is a product of factors :math:`\\|_j T_j` (one
   per robot for the tasks form), and :math:`L \\subseteq \\|_j T_j` iff
   :math:`P_{\\Sigma(T_j)}(L) \\subseteq T_j` for every ``j``: one check per factor.
2. *Cone of influence*: for factor ``j`` only the robots that own an event of
   :math:`\\Sigma(T_j)`, and the robots linked to them through shared (coordination) events,
   matter; robots outside that cluster interleave freely and cannot affect the projection.
3. *Asymmetric rule per factor*: the guarantor :math:`M_1` is the robot owning most events of
   :math:`T_j` (the first in team order on ties); the rest of the cluster is the environment
   :math:`M_2`, abstracted exactly by the compositional projection onto :math:`\\Sigma_A`.
   A cluster of one robot is checked directly.

With ``method="auto"`` a factor whose environment abstraction exceeds
``max_environment_states`` is checked directly instead (an explicit global DFA over N robots
has a :math:`4^{N-1}`-state environment; learning it would cost more than the direct check).
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from cosmop.automata import (
    DFA,
    inclusion_counterexample,
    minimize,
    parallel,
    project_composition,
    satisfaction_counterexample,
)
from cosmop.automata.composition import SizeLog, clusters, lift_word
from cosmop.missions.decomposition import factor_counterexample
from cosmop.missions.mission import GlobalMission

Word = tuple[str, ...]


@dataclass(frozen=True)
class AssumptionReport:
    """One application of the asymmetric rule.

    Attributes
    ----------
    factor : int
        Index of the mission factor :math:`T_j` proved.
    guarantor : str
        The robot :math:`M_1`.
    environment : tuple of str
        The robots abstracted by the assumption (:math:`M_2`).
    interface : tuple of str
        :math:`\\Sigma_A`.
    assumption : DFA or None
        The last (on success: the proving) assumption, minimal and trim.
    environment_states : int
        States of the environment's abstraction :math:`P_{\\Sigma_A}(M_2)`.
    membership_queries, equivalence_queries : int
        Membership queries that reached the teacher (AALpy's cache answers repeats) and
        conjectures checked.
    holds : bool
    """

    factor: int
    guarantor: str
    environment: tuple[str, ...]
    interface: tuple[str, ...]
    assumption: DFA | None
    environment_states: int
    membership_queries: int
    equivalence_queries: int
    holds: bool

    def to_dict(self) -> dict:
        """JSON-ready form."""
        a = self.assumption
        return {
            "factor": self.factor,
            "guarantor": self.guarantor,
            "environment": list(self.environment),
            "interface": list(self.interface),
            "assumption": None
            if a is None
            else {
                "initial": a.name_of(a.initial),
                "transitions": [list(t) for t in a.transitions()],
                "states": a.n_states,
            },
            "environment_states": self.environment_states,
            "membership_queries": self.membership_queries,
            "equivalence_queries": self.equivalence_queries,
            "holds": self.holds,
        }


@dataclass(frozen=True)
class FactorCheck:
    """How one factor :math:`T_j` of the mission was checked.

    Attributes
    ----------
    factor : int
    method : str
        ``"direct"`` (compositional projection and inclusion), ``"assume-guarantee"``, or
        ``"direct (L* round cap)"`` when learning stopped at its cap before a proof.
    robots : tuple of str
        The cluster of robots that can influence the factor.
    holds : bool
    """

    factor: int
    method: str
    robots: tuple[str, ...]
    holds: bool


@dataclass(frozen=True)
class Verification:
    """Result of :func:`verify`.

    Attributes
    ----------
    holds : bool
        Whether :math:`\\|_i M_i \\models K_{MI}`.
    counterexample : tuple of str or None
        A word of :math:`\\|_i M_i` (over the robots involved) violating :math:`K_{MI}`.
    checks : tuple of FactorCheck
    assumptions : tuple of AssumptionReport
    membership_queries, equivalence_queries : int
        Totals over all L* runs.
    largest_automaton : int
        Most states of any automaton built during verification.
    time_s : float
    """

    holds: bool
    counterexample: Word | None
    checks: tuple[FactorCheck, ...]
    assumptions: tuple[AssumptionReport, ...]
    membership_queries: int
    equivalence_queries: int
    largest_automaton: int
    time_s: float = field(repr=False)

    @property
    def method(self) -> str:
        """``"assume-guarantee"``, ``"direct"`` or ``"mixed"`` over the factors."""
        methods = {c.method for c in self.checks}
        return methods.pop() if len(methods) == 1 else "mixed"

    def to_dict(self) -> dict:
        """JSON-ready form."""
        return {
            "holds": self.holds,
            "method": self.method,
            "counterexample": None if self.counterexample is None else list(self.counterexample),
            "checks": [c.__dict__ | {"robots": list(c.robots)} for c in self.checks],
            "assumptions": [a.to_dict() for a in self.assumptions],
            "membership_queries": self.membership_queries,
            "equivalence_queries": self.equivalence_queries,
            "assumption_sizes": [a.assumption.n_states if a.assumption else 0 for a in self.assumptions],
            "largest_automaton": self.largest_automaton,
            "time_s": self.time_s,
        }


class _RealViolation(Exception):
    def __init__(self, word: Word) -> None:
        super().__init__(word)
        self.word = word


class _Membership:
    """Incremental answers to :math:`T(t) = \\langle \\mathcal{DFA}(t) \rangle M_1 \\langle K \rangle`.

    :math:`T(t)` holds iff every word :math:`w` of :math:`M_1` with :math:`P_A(w) = t` has
    :math:`P_K(w) \\in L_m(K)` (marked words).  Reading ``t`` one interface event at a time,
    the set of pairs (state of :math:`M_1`, state of :math:`K` or the dead state) reachable by
    such words is updated and closed under :math:`M_1`'s events outside :math:`\\Sigma_A`;
    :math:`T(t)` fails iff the set holds a pair marked in :math:`M_1` and not in :math:`K`.
    This is the product :math:`\\mathcal{DFA}(t) \\| M_1` checked against :math:`K`, explored
    on the fly so that a query costs a few set operations instead of building automata.
    """

    def __init__(self, m1: DFA, spec: DFA, interface: Sequence[str]) -> None:
        self.m1_marked = m1.marked.tolist()
        self.k_marked = [*spec.marked.tolist(), False]  # last entry: the dead state
        dead = spec.n_states
        m1_index, k_index = m1.event_index(), spec.event_index()
        k_rows = [[t if t >= 0 else dead for t in row] for row in spec.delta.tolist()]
        k_rows.append([dead] * spec.n_events)
        m1_rows = m1.delta.tolist()

        def mover(event: str):
            """(M1 column or None, K column or None) for ``event``."""
            return m1_index.get(event), k_index.get(event)

        self.moves = {e: mover(e) for e in interface}
        self.private = [mover(e) for e in m1.alphabet if e not in set(interface)]
        self.m1_rows, self.k_rows = m1_rows, k_rows
        self.start = self._close({(m1.initial, spec.initial)})

    def _step(self, pairs: set[tuple[int, int]], move) -> set[tuple[int, int]]:
        jm, jk = move
        out = set()
        for m, k in pairs:
            m2 = m if jm is None else self.m1_rows[m][jm]
            if m2 < 0:
                continue
            out.add((m2, k if jk is None else self.k_rows[k][jk]))
        return out

    def _close(self, pairs: set[tuple[int, int]]) -> frozenset[tuple[int, int]]:
        todo = list(pairs)
        seen = set(pairs)
        while todo:
            pair = todo.pop()
            for move in self.private:
                for nxt in self._step({pair}, move):
                    if nxt not in seen:
                        seen.add(nxt)
                        todo.append(nxt)
        return frozenset(seen)

    def advance(self, pairs: frozenset[tuple[int, int]], event: str) -> frozenset[tuple[int, int]]:
        """Pairs after one more interface event."""
        return self._close(self._step(set(pairs), self.moves[event]))

    def holds(self, pairs: frozenset[tuple[int, int]]) -> bool:
        """Whether no pair is marked in :math:`M_1` and unmarked (or dead) in :math:`K`."""
        return not any(self.m1_marked[m] and not self.k_marked[k] for m, k in pairs)

    def __call__(self, word: Word) -> bool:
        pairs = self.start
        for event in word:
            pairs = self.advance(pairs, event)
        return self.holds(pairs)


def _to_dfa(hypothesis, interface: Sequence[str]) -> DFA:
    """Convert an AALpy DFA hypothesis (complete, with a rejecting sink) to a minimal DFA."""
    states = list(hypothesis.states)
    ids = {s.state_id: k for k, s in enumerate(states)}
    col = {e: j for j, e in enumerate(interface)}
    delta = np.full((len(states), len(interface)), -1, dtype=np.int32)
    for k, s in enumerate(states):
        for letter, target in s.transitions.items():
            delta[k, col[letter]] = ids[target.state_id]
    marked = np.array([bool(s.is_accepting) for s in states])
    return minimize(DFA(tuple(interface), delta, ids[hypothesis.initial_state.state_id], marked))


def _learn_assumption(
    m1: DFA, environment: DFA, spec: DFA, interface: tuple[str, ...], log: SizeLog, max_rounds: int
) -> tuple[bool | None, DFA | None, Word | None, int, int]:
    """Run L* for an assumption over ``interface``; returns (holds, A, violation, #mq, #eq).

    ``holds`` is ``None`` when L* reached ``max_rounds`` before the premises were proved.
    ``violation`` is a word over :math:`\\Sigma_{M_1} \\cup \\Sigma_A` of :math:`M_1` composed
    with the environment's interface behaviour that violates ``spec``.
    """
    from aalpy.base import SUL, Oracle
    from aalpy.learning_algs import run_Lstar

    counts = {"membership": 0, "equivalence": 0}
    oracle = _Membership(m1, spec, interface)

    def member(word: Word) -> bool:  # the teacher's own queries (AALpy counts its own)
        counts["membership"] += 1
        return oracle(word)

    class Membership(SUL):
        """AALpy's view of the membership oracle: one step per interface event."""

        def __init__(self) -> None:
            super().__init__()
            self.pairs = oracle.start

        def pre(self) -> None:
            self.pairs = oracle.start

        def post(self) -> None:
            pass

        def step(self, letter):
            if letter is not None:
                self.pairs = oracle.advance(self.pairs, letter)
            return oracle.holds(self.pairs)

    class Teacher(Oracle):
        def __init__(self, alphabet: list[str], sul: SUL) -> None:
            super().__init__(alphabet, sul)
            self.last: DFA | None = None
            self.proved = False

        def find_cex(self, hypothesis):
            counts["equivalence"] += 1
            a = log.observe(_to_dfa(hypothesis, interface))
            self.last = a
            w = satisfaction_counterexample(log.observe(parallel(m1, a)), spec)
            if w is not None:  # premise 1 fails: the conjecture admits a harmful interface word
                return tuple(e for e in w if e in interface)
            c = inclusion_counterexample(environment, a)
            if c is None:  # both premises hold: the rule proves the factor
                self.proved = True
                return None
            if member(c):  # the conjecture is too strong
                return c
            raise _RealViolation(c)

    sul = Membership()
    teacher = Teacher(list(interface), sul)
    try:
        run_Lstar(
            list(interface),
            sul,
            teacher,
            automaton_type="dfa",
            print_level=0,
            max_learning_rounds=max_rounds,
        )
    except _RealViolation as violation:
        pinned = DFA.from_word(violation.word, interface, closed=False)
        word = satisfaction_counterexample(parallel(m1, pinned), spec)
        return False, teacher.last, word, sul.num_queries + counts["membership"], counts["equivalence"]
    except SystemExit as exc:  # AALpy's reaction to inconsistent answers
        raise RuntimeError(f"L*: inconsistent membership answers ({exc})") from None
    # L* also stops at the round cap without a proof: then the factor is undecided (None)
    holds = True if teacher.proved else None
    return holds, teacher.last, None, sul.num_queries + counts["membership"], counts["equivalence"]


def _cluster(start: set[str], local: Mapping[str, DFA]) -> list[str]:
    """Robots linked to ``start`` through shared events (directly or not), in team order."""
    robots = list(local)
    members: set[str] = set()
    for group in clusters(list(local.values())):
        names = {robots[i] for i in group}
        if names & start:
            members |= names
    return [r for r in robots if r in members]


def verify(
    mission: GlobalMission,
    local: Mapping[str, DFA],
    *,
    method: str = "auto",
    max_environment_states: int = 256,
    max_rounds: int = 200,
) -> Verification:
    """Decide :math:`\\|_i M_i \\models K_{MI}` compositionally.

    Parameters
    ----------
    mission : GlobalMission
        :math:`K_{MI}` (its factors are the properties checked one by one).
    local : Mapping[str, DFA]
        The modules :math:`M_i` by robot (e.g. the local missions of a decomposition).
    method : {"auto", "assume-guarantee", "direct"}
        ``"assume-guarantee"`` uses the asymmetric rule with L* on every factor whose
        cluster has more than one robot; ``"direct"`` checks each factor by compositional
        projection and inclusion; ``"auto"`` uses assume-guarantee unless the environment
        abstraction has more than ``max_environment_states`` states.
    max_environment_states : int
    max_rounds : int
        Cap on L* learning rounds per factor.

    Returns
    -------
    Verification
    """
    if method not in {"auto", "assume-guarantee", "direct"}:
        raise ValueError(f"method must be auto, assume-guarantee or direct, not {method!r}")
    t0 = time.perf_counter()
    log = SizeLog()
    alphabets = {r: set(d.alphabet) for r, d in local.items()}
    checks: list[FactorCheck] = []
    reports: list[AssumptionReport] = []
    counterexample: Word | None = None
    for j, factor in enumerate(mission.automaton.components):
        sigma = set(factor.alphabet)
        # the guarantor is the robot owning most of the factor's events (team order breaks ties)
        owners = sorted((r for r in local if alphabets[r] & sigma), key=lambda r: -len(alphabets[r] & sigma))
        cluster = _cluster(set(owners), local)
        modules = [local[r] for r in cluster]
        environment_robots = [r for r in cluster if owners and r != owners[0]]
        interface: tuple[str, ...] = ()
        abstraction: DFA | None = None
        use_ag = method != "direct" and len(cluster) > 1
        if use_ag:
            m1_sigma = alphabets[owners[0]]
            env_sigma = set().union(*(alphabets[r] for r in environment_robots))
            interface = tuple(sorted(env_sigma & (m1_sigma | sigma)))
            abstraction = log.observe(
                project_composition([local[r] for r in environment_robots], interface, log=log)
            )
            if method == "auto" and abstraction.n_states > max_environment_states:
                use_ag = False
        holds: bool | None = None
        if use_ag:
            assert abstraction is not None
            holds, assumption, violation, mq, eq = _learn_assumption(
                local[owners[0]], abstraction, factor, interface, log, max_rounds
            )
            reports.append(
                AssumptionReport(
                    factor=j,
                    guarantor=owners[0],
                    environment=tuple(environment_robots),
                    interface=interface,
                    assumption=assumption,
                    environment_states=abstraction.n_states,
                    membership_queries=mq,
                    equivalence_queries=eq,
                    holds=bool(holds),
                )
            )
            if violation is not None:
                counterexample = lift_word(modules, violation, alphabets[owners[0]] | set(interface))
        if holds is None:  # direct check: by method, or because L* stopped at its round cap
            word = factor_counterexample(modules, factor, log)
            holds = word is None
            if word is not None:
                counterexample = word
            method_used = "direct" if not use_ag else "direct (L* round cap)"
        else:
            method_used = "assume-guarantee"
        checks.append(FactorCheck(j, method_used, tuple(cluster), holds))
        if not holds:
            break
    return Verification(
        holds=all(c.holds for c in checks),
        counterexample=counterexample,
        checks=tuple(checks),
        assumptions=tuple(reports),
        membership_queries=sum(r.membership_queries for r in reports),
        equivalence_queries=sum(r.equivalence_queries for r in reports),
        largest_automaton=log.largest,
        time_s=time.perf_counter() - t0,
    )
