"""Task decomposition by natural projection, separability, counterexample-guided re-synthesis.

Section III of the paper: the local missions are :math:`K^i_{MI} = P_i(K_{MI})`; they jointly
satisfy the global mission iff :math:`\\|_i K^i_{MI} \\subseteq K_{MI}`.  The converse inclusion
always holds (:math:`K \\subseteq P_i^{-1} P_i(K)` for every ``i``), so this is the
*separability* of :math:`K_{MI}` with respect to the local alphabets,
:math:`K_{MI} = \\|_i P_i(K_{MI})` (the paper's Remark).  When it fails because the product
allows an interleaving of different robots' events that :math:`K_{MI}` forbids, the robots are
given an order by messages (:mod:`cosmop.missions.ordering`) instead of losing behaviour: this
keeps every task and only adds waiting.  Only when no placement of messages can work (a local
mission that branches, or words that no complete word of the mission interleaves) does the
paper's pruning run: a counterexample :math:`t \\in \\|_i K^i \\setminus K` shrinks the local
missions, :math:`K^i := K^i - P_i(t)`, until the product is included in :math:`K_{MI}`.

Both checks work on the mission's factors (:class:`~cosmop.automata.Composition`):
:math:`L \\subseteq \\|_j T_j` iff :math:`P_{\\Sigma(T_j)}(L) \\subseteq T_j` for every factor,
and each projection is computed compositionally, so a mission in tasks form is decomposed and
checked without building its :math:`4^N`-state product.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import numpy as np

from cosmop.automata import (
    DFA,
    Composition,
    complement,
    inclusion_counterexample,
    minimize,
    product,
    project_composition,
)
from cosmop.automata.composition import SizeLog, lift_word
from cosmop.missions.mission import GlobalMission, sequence_automaton, sequence_of
from cosmop.missions.ordering import Edge, order_words, with_messages

Word = tuple[str, ...]


def project_locally(
    mission: Composition, alphabets: Mapping[str, tuple[str, ...]], log: SizeLog | None = None
) -> dict[str, DFA]:
    """Local missions :math:`K^i = P_i(K)`, minimal, one per robot.

    Parameters
    ----------
    mission : Composition
        :math:`K` as a product of factors.
    alphabets : Mapping[str, tuple of str]
        :math:`\\Sigma_i` by robot.
    log : SizeLog, optional
        Records the automata built.
    """
    return {
        robot: project_composition(mission.components, sigma, log=log) for robot, sigma in alphabets.items()
    }


def factor_counterexample(modules: list[DFA], factor: DFA, log: SizeLog | None = None) -> Word | None:
    """A word of :math:`\\|_i M_i` whose projection onto :math:`\\Sigma(T)` is not in ``factor``.

    :math:`u \\in P_{\\Sigma(T)}(\\|_i M_i) \\setminus T` is a shortest violation of the factor
    (the projection is computed compositionally), lifted to a word of the product that
    projects onto it; ``None`` when the factor holds.

    Parameters
    ----------
    modules : list of DFA
        The local missions :math:`M_i`.
    factor : DFA
        A factor :math:`T` of the global mission.
    log : SizeLog, optional
        Records every intermediate automaton.
    """
    view = project_composition(modules, factor.alphabet, log=log, minimal=False)  # only searched
    u = inclusion_counterexample(view, factor)
    if u is None:
        return None
    word = lift_word(modules, u, factor.alphabet)
    if word is None:  # cannot happen: u is a word of the projection
        raise AssertionError("counterexample does not lift to the product")
    return word


def separability_counterexample(
    mission: Composition, local: Mapping[str, DFA], log: SizeLog | None = None
) -> Word | None:
    """A word of :math:`\\|_i K^i` outside :math:`K`, or ``None`` when :math:`\\|_i K^i \\subseteq K`.

    Factor by factor (:func:`factor_counterexample`); the first violated factor gives the word.

    Parameters
    ----------
    mission : Composition
        The global mission :math:`K`, as its factors.
    local : mapping of str to DFA
        The local missions :math:`K^i` by robot.
    log : SizeLog, optional
        Records every intermediate automaton.
    """
    modules = list(local.values())
    for factor in mission.components:
        word = factor_counterexample(modules, factor, log)
        if word is not None:
            return word
    return None


def _used_events(dfa: DFA) -> set[str]:
    """Events on at least one transition."""
    return {dfa.alphabet[j] for j in np.flatnonzero((dfa.delta >= 0).any(axis=0))}


def _without_extensions(dfa: DFA, word: Word) -> DFA:
    """:math:`L - w\\Sigma^*`: remove ``word`` and all its extensions (keeps prefix-closure)."""
    n = len(word)
    cone = DFA.from_transitions(
        "c0",
        [
            *((f"c{k}", e, f"c{k + 1}") for k, e in enumerate(word)),
            *((f"c{n}", e, f"c{n}") for e in dfa.alphabet),
        ],
        marked=[f"c{n}"],
        alphabet=dfa.alphabet,
    )
    return minimize(product(dfa, complement(cone, dfa.alphabet)))


@dataclass(frozen=True)
class Resynthesis:
    """Outcome of the counterexample-guided re-synthesis of the paper's Remark.

    Attributes
    ----------
    local_missions : Mapping[str, DFA]
        The shrunk local missions.
    converged : bool
        ``True`` when :math:`\\|_i K^i \\subseteq K` holds for them (they are sound).
    iterations : int
        Counterexamples used.
    counterexamples : tuple of words
        The counterexamples, in order.
    removed : Mapping[str, tuple of words]
        For each robot, the local words cut off (with all their extensions).
    lost_events : Mapping[str, tuple of str]
        For each robot, the events its mission can no longer perform at all.
    """

    local_missions: Mapping[str, DFA]
    converged: bool
    iterations: int
    counterexamples: tuple[Word, ...]
    removed: Mapping[str, tuple[Word, ...]]
    lost_events: Mapping[str, tuple[str, ...]]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form."""
        return {
            "converged": self.converged,
            "iterations": self.iterations,
            "counterexamples": [list(w) for w in self.counterexamples],
            "removed": {r: [list(w) for w in ws] for r, ws in self.removed.items() if ws},
            "lost_events": {r: list(es) for r, es in self.lost_events.items() if es},
            "local_missions": {r: d.to_dict(with_alphabet=True) for r, d in self.local_missions.items()},
        }


def resynthesize(
    mission: GlobalMission,
    local: Mapping[str, DFA],
    *,
    max_iterations: int = 100,
    log: SizeLog | None = None,
) -> Resynthesis:
    """Shrink local missions with counterexamples until their product is included in :math:`K`.

    Each round takes a counterexample :math:`t = s\\sigma \\in \\|_i K^i \\setminus K` (its last
    event :math:`\\sigma` is the step that leaves :math:`K`) and sets
    :math:`K^i := K^i - P_i(t)\\Sigma_i^*` for the robots ``i`` that own :math:`\\sigma`.
    Removing the extensions keeps every :math:`K^i` prefix-closed.  (The paper writes the
    update for every ``i``; for a robot not owning :math:`\\sigma`, :math:`P_i(t)` may be the
    empty word and removing it would empty the whole local mission.)

    Parameters
    ----------
    mission : GlobalMission
    local : Mapping[str, DFA]
        Starting local missions (normally the projections).
    max_iterations : int
        Cap on the number of counterexamples used; ``converged`` is ``False`` if hit.
    log : SizeLog, optional

    Returns
    -------
    Resynthesis
        Sound (``converged``) local missions, never larger than the given ones.
    """
    current = dict(local)
    alphabets = {r: set(d.alphabet) for r, d in current.items()}
    counterexamples: list[Word] = []
    removed: dict[str, list[Word]] = {r: [] for r in current}
    converged = False
    while True:
        t = separability_counterexample(mission.automaton, current, log=log)
        if t is None:
            converged = True
            break
        if len(counterexamples) >= max_iterations:
            break
        counterexamples.append(t)
        owners = mission.events[t[-1]].owners if t else frozenset(current)
        for robot in sorted(owners & set(current)):
            cut = tuple(e for e in t if e in alphabets[robot])
            current[robot] = _without_extensions(current[robot], cut)
            removed[robot].append(cut)
            if log:
                log.observe(current[robot])
    lost = {r: tuple(sorted(_used_events(local[r]) - _used_events(current[r]))) for r in current}
    return Resynthesis(
        local_missions=MappingProxyType(current),
        converged=converged,
        iterations=len(counterexamples),
        counterexamples=tuple(counterexamples),
        removed=MappingProxyType({r: tuple(ws) for r, ws in removed.items()}),
        lost_events=MappingProxyType(lost),
    )


@dataclass(frozen=True)
class Messaging:
    """Messages that order the robots' events so that the local missions add up to :math:`K`.

    Attributes
    ----------
    messages : tuple of (str, Edge)
        Each ``msg(S,R,tag)`` with its edge ``((S, a), (R, b))``: S sends it right after its
        event *a*, R waits for it right before its event *b* (indices into the words without
        the new messages).
    words : Mapping[str, tuple of str]
        Every robot's local mission with the messages in place.
    local_missions : Mapping[str, DFA]
        The same, as sequence automata.
    rounds : int
        Counterexamples used.
    unordered : Mapping[str, tuple of str]
        The local missions before the messages (what the edges index).
    """

    messages: tuple[tuple[str, Edge], ...]
    words: Mapping[str, tuple[str, ...]]
    local_missions: Mapping[str, DFA]
    rounds: int
    unordered: Mapping[str, tuple[str, ...]]

    def to_dict(self) -> list[dict[str, Any]]:
        """JSON-ready list: ``{"event", "sender", "receiver", "after", "before"}`` per message."""
        out, words = [], self.unordered
        for name, ((a, i), (b, j)) in self.messages:
            out.append(
                {"event": name, "sender": a, "receiver": b, "after": words[a][i], "before": words[b][j]}
            )
        return out


def order_by_messages(mission: GlobalMission, local: Mapping[str, DFA]) -> Messaging | None:
    """Order the robots by messages when every local mission is one sequence of events.

    ``None`` when a local mission branches or no complete word of the mission interleaves the
    sequences (then only pruning or other words can help).

    Parameters
    ----------
    mission : GlobalMission
        The global mission, with its complete words.
    local : mapping of str to DFA
        The local missions by robot.
    """
    words = {}
    for robot, dfa in local.items():
        seq = sequence_of(dfa)
        if seq is None:
            return None
        words[robot] = seq
    assert mission.complete is not None  # set on construction
    result = order_words(mission.complete, words)
    if not result.feasible:
        return None
    placed, messages = with_messages(words, result.edges)
    dfas = {r: sequence_automaton(list(w)) for r, w in placed.items()}
    frozen = MappingProxyType
    return Messaging(tuple(messages), frozen(placed), frozen(dfas), result.rounds, frozen(words))


@dataclass(frozen=True)
class DecompositionStats:
    """Where the time and memory of a decomposition went.

    Attributes
    ----------
    project_s, separability_s, resynthesis_s, total_s : float
        Wall-clock seconds per phase.
    largest_automaton : int
        Most states of any automaton built (factors of the mission included).
    automata_built : int
    mission_factors : int
        Factors of :math:`K` (1 for an explicit DFA, the number of robots for tasks).
    mission_factor_states : tuple of int
        States of each factor.
    """

    project_s: float
    separability_s: float
    resynthesis_s: float
    total_s: float
    largest_automaton: int
    automata_built: int
    mission_factors: int
    mission_factor_states: tuple[int, ...]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form."""
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in self.__dict__.items()}


@dataclass(frozen=True)
class Decomposition:
    """Result of :func:`decompose`.

    Attributes
    ----------
    alphabets : Mapping[str, tuple of str]
        :math:`\\Sigma^i_{MI}` by robot.
    local_missions : Mapping[str, DFA]
        :math:`K^i_{MI} = P_i(K_{MI})`, minimal.
    separable : bool
        Whether :math:`K_{MI} = \\|_i P_i(K_{MI})`.
    counterexample : tuple of str or None
        When not separable, a word of :math:`\\|_i P_i(K_{MI})` outside :math:`K_{MI}`.
    resynthesis : Resynthesis or None
        When not separable and messages cannot order the robots, the pruned (sound) local
        missions.
    stats : DecompositionStats
    messaging : Messaging or None
        When not separable: the messages that order the robots (then no pruning is done).
    """

    alphabets: Mapping[str, tuple[str, ...]]
    local_missions: Mapping[str, DFA]
    separable: bool
    counterexample: Word | None
    resynthesis: Resynthesis | None
    stats: DecompositionStats = field(repr=False)
    messaging: Messaging | None = None

    @property
    def sound_local_missions(self) -> Mapping[str, DFA]:
        """Local missions that together do what :math:`K_{MI}` asks, when known.

        The projections if separable, else the projections with their ordering messages, else
        the re-synthesised (pruned) ones if they converged.
        """
        if self.separable:
            return self.local_missions
        if self.messaging is not None:
            return self.messaging.local_missions
        if self.resynthesis is not None and self.resynthesis.converged:
            return self.resynthesis.local_missions
        raise ValueError("no sound local missions: re-synthesis did not converge")

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form (``separable``, ``counterexample``, ``local_missions``, ...)."""
        return {
            "separable": self.separable,
            "counterexample": list(self.counterexample) if self.counterexample is not None else None,
            "local_missions": {r: d.to_dict(with_alphabet=True) for r, d in self.local_missions.items()},
            "resynthesis": self.resynthesis.to_dict() if self.resynthesis is not None else None,
            "messages": [] if self.messaging is None else self.messaging.to_dict(),
            "coordinated_missions": None
            if self.messaging is None
            else {r: list(w) for r, w in self.messaging.words.items()},
            "stats": self.stats.to_dict(),
        }


def decompose(mission: GlobalMission, *, max_iterations: int = 100) -> Decomposition:
    """Decompose a global mission into local missions and decide separability.

    Parameters
    ----------
    mission : GlobalMission
        :math:`K_{MI}` with its events and team.
    max_iterations : int
        Cap for the re-synthesis when the mission is not separable.

    Returns
    -------
    Decomposition
    """
    log = SizeLog()
    for factor in mission.automaton.components:
        log.observe(factor)
    t0 = time.perf_counter()
    alphabets = mission.alphabets
    local = project_locally(mission.automaton, alphabets, log)
    t1 = time.perf_counter()
    cex = separability_counterexample(mission.automaton, local, log)
    t2 = time.perf_counter()
    messaging = None if cex is None else order_by_messages(mission, local)
    resynthesis = (
        None
        if cex is None or messaging is not None
        else resynthesize(mission, local, max_iterations=max_iterations, log=log)
    )
    t3 = time.perf_counter()
    stats = DecompositionStats(
        project_s=t1 - t0,
        separability_s=t2 - t1,
        resynthesis_s=t3 - t2,
        total_s=t3 - t0,
        largest_automaton=log.largest,
        automata_built=log.built,
        mission_factors=len(mission.automaton.components),
        mission_factor_states=tuple(f.n_states for f in mission.automaton.components),
    )
    return Decomposition(
        alphabets=MappingProxyType(alphabets),
        local_missions=MappingProxyType(local),
        separable=cex is None,
        counterexample=cex,
        resynthesis=resynthesis,
        stats=stats,
        messaging=messaging,
    )
