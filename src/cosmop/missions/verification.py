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
from typing import TYPE_CHECKING, Any

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

if TYPE_CHECKING:  # pragma: no cover - typing only
    from aalpy.base import SUL, Oracle

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

    def to_dict(self) -> dict[str, Any]:
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

    def to_dict(self) -> dict[str, Any]:
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

        def mover(event: str) -> tuple[int | None, int | None]:
            """(M1 column or None, K column or None) for ``event``."""
            return m1_index.get(event), k_index.get(event)

        self.moves = {e: mover(e) for e in interface}
        self.private = [mover(e) for e in m1.alphabet if e not in set(interface)]
        self.m1_rows, self.k_rows = m1_rows, k_rows
        self.start = self._close({(m1.initial, spec.initial)})

    def _step(self, pairs: set[tuple[int, int]], move: tuple[int | None, int | None]) -> set[tuple[int, int]]:
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


def _to_dfa(hypothesis: Any, interface: Sequence[str]) -> DFA:
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
    from aalpy.learning_algs import run_Lstar

    oracle = _Membership(m1, spec, interface)
    sul = _membership_sul(oracle)
    teacher = _teacher(sul, oracle, m1, environment, spec, interface, log)
    holds: bool | None
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
        holds, word = False, satisfaction_counterexample(parallel(m1, pinned), spec)
    except SystemExit as exc:  # AALpy's reaction to inconsistent answers
        raise RuntimeError(f"L*: inconsistent membership answers ({exc})") from None
    else:  # L* also stops at the round cap without a proof: then the factor is undecided (None)
        holds, word = (True if teacher.proved else None), None
    return holds, teacher.last, word, sul.num_queries + teacher.membership, teacher.equivalence


def _membership_sul(oracle: _Membership) -> SUL:
    """AALpy's view of `oracle` (a system under learning): one step per interface event.

    Its output after a word is :math:`T` of that word; AALpy counts its queries
    (``num_queries``) and caches repeats.
    """
    from aalpy.base import SUL

    class Membership(SUL):  # type: ignore[misc]  # aalpy has no stubs
        """AALpy's view of the membership oracle: one step per interface event."""

        def __init__(self) -> None:
            super().__init__()
            self.pairs = oracle.start

        def pre(self) -> None:
            self.pairs = oracle.start

        def post(self) -> None:
            pass

        def step(self, letter: str | None) -> bool:
            if letter is not None:
                self.pairs = oracle.advance(self.pairs, letter)
            return oracle.holds(self.pairs)

    return Membership()


def _teacher(
    sul: SUL,
    oracle: _Membership,
    m1: DFA,
    environment: DFA,
    spec: DFA,
    interface: tuple[str, ...],
    log: SizeLog,
) -> Oracle:
    """AALpy's equivalence oracle: checks a conjecture against both premises of the rule.

    Its ``find_cex`` returns a counterexample to the conjecture, ``None`` when both premises
    hold (then ``proved`` is set), or raises :class:`_RealViolation` for a word of the
    environment that violates the mission.  ``last`` is the last conjecture (minimal, trim);
    ``membership`` and ``equivalence`` count the teacher's own membership queries and the
    conjectures checked.
    """
    from aalpy.base import Oracle

    class Teacher(Oracle):  # type: ignore[misc]  # aalpy has no stubs
        def __init__(self, alphabet: list[str], sul: SUL) -> None:
            super().__init__(alphabet, sul)
            self.last: DFA | None = None
            self.proved = False
            self.membership = 0
            self.equivalence = 0

        def find_cex(self, hypothesis: Any) -> Word | None:
            self.equivalence += 1
            a = log.observe(_to_dfa(hypothesis, interface))
            self.last = a
            w = satisfaction_counterexample(log.observe(parallel(m1, a)), spec)
            if w is not None:  # premise 1 fails: the conjecture admits a harmful interface word
                return tuple(e for e in w if e in interface)
            c = inclusion_counterexample(environment, a)
            if c is None:  # both premises hold: the rule proves the factor
                self.proved = True
                return None
            self.membership += 1  # the teacher's own query (AALpy counts its own)
            if oracle(c):  # the conjecture is too strong
                return c
            raise _RealViolation(c)

    return Teacher(list(interface), sul)


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
    team = _Team(local, {r: set(d.alphabet) for r, d in local.items()}, SizeLog())
    checks: list[FactorCheck] = []
    reports: list[AssumptionReport] = []
    counterexample: Word | None = None
    for j, factor in enumerate(mission.automaton.components):
        found = _check_factor(j, factor, team, method, max_environment_states, max_rounds)
        checks.append(found.check)
        if found.report is not None:
            reports.append(found.report)
        if found.counterexample is not None:
            counterexample = found.counterexample
        if not found.check.holds:
            break
    return Verification(
        holds=all(c.holds for c in checks),
        counterexample=counterexample,
        checks=tuple(checks),
        assumptions=tuple(reports),
        membership_queries=sum(r.membership_queries for r in reports),
        equivalence_queries=sum(r.equivalence_queries for r in reports),
        largest_automaton=team.log.largest,
        time_s=time.perf_counter() - t0,
    )


@dataclass(frozen=True)
class _Team:
    """The modules verified and what the checks of all factors share.

    Attributes
    ----------
    local : Mapping[str, DFA]
        The modules :math:`M_i` by robot, in team order.
    alphabets : Mapping[str, set of str]
        Each module's events.
    log : SizeLog
        Every automaton built, for ``largest_automaton``.
    """

    local: Mapping[str, DFA]
    alphabets: Mapping[str, set[str]]
    log: SizeLog


@dataclass(frozen=True)
class _Roles:
    """Who takes which part in the check of one factor.

    Attributes
    ----------
    cluster : tuple of str
        The robots that can influence the factor (its cone of influence), in team order.
    guarantor : str or None
        :math:`M_1`, the robot owning most of the factor's events; ``None`` when no robot
        owns one.
    environment : tuple of str
        The rest of the cluster (:math:`M_2`).
    """

    cluster: tuple[str, ...]
    guarantor: str | None
    environment: tuple[str, ...]


def _roles(sigma: set[str], team: _Team) -> _Roles:
    """The cluster, guarantor and environment for a factor over the events `sigma`."""
    local, alphabets = team.local, team.alphabets
    # the guarantor is the robot owning most of the factor's events (team order breaks ties)
    owners = sorted((r for r in local if alphabets[r] & sigma), key=lambda r: -len(alphabets[r] & sigma))
    cluster = _cluster(set(owners), local)
    environment = [r for r in cluster if owners and r != owners[0]]
    return _Roles(tuple(cluster), owners[0] if owners else None, tuple(environment))


@dataclass(frozen=True)
class _FactorResult:
    """The outcome of checking one factor.

    Attributes
    ----------
    check : FactorCheck
    report : AssumptionReport or None
        When the asymmetric rule was applied.
    counterexample : tuple of str or None
        A word of the cluster violating the factor.
    """

    check: FactorCheck
    report: AssumptionReport | None
    counterexample: Word | None


def _check_factor(
    j: int,
    factor: DFA,
    team: _Team,
    method: str,
    max_environment_states: int,
    max_rounds: int,
) -> _FactorResult:
    """Check factor `j` by the asymmetric rule or directly, as `method` asks (see :func:`verify`).

    The rule applies to a cluster of more than one robot, unless ``method="auto"`` finds the
    environment's abstraction larger than `max_environment_states`; a factor the rule leaves
    undecided (L* at its round cap) is checked directly.
    """
    sigma = set(factor.alphabet)
    roles = _roles(sigma, team)
    interface: tuple[str, ...] = ()
    abstraction: DFA | None = None
    use_ag = method != "direct" and len(roles.cluster) > 1
    if use_ag:
        interface, abstraction = _environment(roles, sigma, team)
        if method == "auto" and abstraction.n_states > max_environment_states:
            use_ag = False
    holds: bool | None = None
    report, word = None, None
    if use_ag:
        assert abstraction is not None
        holds, report, word = _assume_guarantee(j, factor, roles, interface, abstraction, team, max_rounds)
    if holds is None:  # direct check: by method, or because L* stopped at its round cap
        word = factor_counterexample([team.local[r] for r in roles.cluster], factor, team.log)
        holds = word is None
        method_used = "direct" if not use_ag else "direct (L* round cap)"
    else:
        method_used = "assume-guarantee"
    return _FactorResult(FactorCheck(j, method_used, roles.cluster, holds), report, word)


def _environment(roles: _Roles, sigma: set[str], team: _Team) -> tuple[tuple[str, ...], DFA]:
    """The interface :math:`\\Sigma_A` and the environment's abstraction :math:`P_{\\Sigma_A}(M_2)`.

    :math:`\\Sigma_A = \\Sigma_{M_2} \\cap (\\Sigma_{M_1} \\cup \\Sigma_K)`, sorted; the abstraction is
    the compositional projection of the environment's modules (the product is never built).
    """
    assert roles.guarantor is not None  # a cluster of two robots or more has one
    m1_sigma = team.alphabets[roles.guarantor]
    env_sigma = set().union(*(team.alphabets[r] for r in roles.environment))
    interface = tuple(sorted(env_sigma & (m1_sigma | sigma)))
    modules = [team.local[r] for r in roles.environment]
    abstraction = team.log.observe(project_composition(modules, interface, log=team.log))
    return interface, abstraction


def _assume_guarantee(
    j: int,
    factor: DFA,
    roles: _Roles,
    interface: tuple[str, ...],
    abstraction: DFA,
    team: _Team,
    max_rounds: int,
) -> tuple[bool | None, AssumptionReport, Word | None]:
    """Apply the asymmetric rule to factor `j`: learn an assumption for the guarantor.

    Returns
    -------
    holds : bool or None
        ``None`` when L* stopped at its round cap before a proof.
    report : AssumptionReport
    counterexample : tuple of str or None
        A violation lifted to a word of the cluster.
    """
    guarantor = roles.guarantor
    assert guarantor is not None  # a cluster of two robots or more has one
    holds, assumption, violation, mq, eq = _learn_assumption(
        team.local[guarantor], abstraction, factor, interface, team.log, max_rounds
    )
    report = AssumptionReport(
        factor=j,
        guarantor=guarantor,
        environment=roles.environment,
        interface=interface,
        assumption=assumption,
        environment_states=abstraction.n_states,
        membership_queries=mq,
        equivalence_queries=eq,
        holds=bool(holds),
    )
    word = None
    if violation is not None:
        modules = [team.local[r] for r in roles.cluster]
        word = lift_word(modules, violation, team.alphabets[guarantor] | set(interface))
    return holds, report, word
