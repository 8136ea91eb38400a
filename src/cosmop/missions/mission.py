"""The global mission :math:`K_{MI}` and its distribution over the robots.

A global mission is a regular language over every robot's mission events (Section III-B).  It
is held as a :class:`~cosmop.automata.Composition`: the tasks form of the scenario file is the
synchronous product of one sequence automaton per robot (kept as its factors, never built),
the explicit DFA form is a composition of one factor.

**When a mission is complete.**  Planning and execution aim at a *complete* team run, never a
mere prefix.  A DFA that lists ``marked`` states is complete exactly in them (a mission that is
not prefix-closed); a DFA without ``marked`` (prefix-closed: every state marked) is complete in
the states with no outgoing transition; the tasks form is complete when every task list is
done.  :attr:`GlobalMission.complete` is the mission with exactly those states marked, trimmed
to the runs that can still complete; :attr:`GlobalMission.prefixes` is its prefix-closure, the
behaviour the team may show on the way.

Event ownership gives the local alphabets :math:`\\Sigma^i_{MI}`: ``pick``, ``drop`` and
``return`` belong to their robot; a coordination event ``away(O, A, B)`` belongs to both the
requester ``A`` and the responder ``B``, which is what makes it synchronise them.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np

from cosmop.automata import DFA, Composition, prefix_closure, trim, with_marked
from cosmop.events import Event, parse_event
from cosmop.scene import Mission, Scenario


def sequence_automaton(events: Sequence[str], *, closed: bool = True) -> DFA:
    """DFA of one sequence of events :math:`\\sigma_1 \\sigma_2 \\cdots \\sigma_k`.

    With ``closed=True`` (a mission) every state is marked, so the marked language is the
    prefix-closure :math:`\\overline{\\sigma_1 \\cdots \\sigma_k}`; with ``closed=False`` only
    the complete sequence is marked (used to see whether robots can all finish).

    Parameters
    ----------
    events : sequence of str
        The event names, in order.
    closed : bool, default True
        Whether every prefix is marked, or only the whole sequence.
    """
    return DFA.from_word(tuple(events), closed=closed)


def sequence_of(dfa: DFA) -> tuple[str, ...] | None:
    """The events of a linear DFA (one path, no branching, no cycle), or ``None``.

    The inverse of :func:`sequence_automaton`: a local mission that is one sequence of events.

    Parameters
    ----------
    dfa : DFA
        A local mission.
    """
    q, seen = dfa.initial, {dfa.initial}
    seq: list[str] = []
    while True:
        out = [j for j in range(dfa.n_events) if dfa.delta[q, j] >= 0]
        if not out:
            return tuple(seq)
        if len(out) > 1:
            return None
        seq.append(dfa.alphabet[out[0]])
        q = int(dfa.delta[q, out[0]])
        if q in seen:
            return None
        seen.add(q)


def completion(dfa: DFA, *, explicit: bool) -> DFA:
    """The mission automaton marked exactly in its complete states, trimmed.

    Parameters
    ----------
    dfa : DFA
        A mission factor as written.
    explicit : bool
        Whether its marked states were given (then they are the complete states); otherwise
        the complete states are those without an outgoing transition.

    Returns
    -------
    DFA
        Accessible and co-accessible: every run of it can still complete.  Its marked language
        is empty when no complete state can be reached.
    """
    if explicit:
        return trim(dfa)
    sinks = ~(dfa.delta >= 0).any(axis=1)
    return trim(with_marked(dfa, sinks))


def local_alphabets(events: Iterable[Event], robots: Iterable[str]) -> dict[str, tuple[str, ...]]:
    """:math:`\\Sigma^i_{MI}` for every robot: the names of the events it owns, sorted.

    A robot that owns no event gets the empty alphabet (its local mission is
    :math:`\\{\\varepsilon\\}`).

    Parameters
    ----------
    events : iterable of Event
        The mission's events.
    robots : iterable of str
        The team.
    """
    alphabets: dict[str, set[str]] = {robot: set() for robot in robots}
    for event in events:
        for owner in event.owners:
            alphabets.setdefault(owner, set()).add(event.name)
    return {robot: tuple(sorted(names)) for robot, names in alphabets.items()}


@dataclass(frozen=True)
class GlobalMission:
    """A global mission :math:`K_{MI}` with its events and robots.

    Parameters
    ----------
    automaton : Composition
        :math:`K_{MI}` as a synchronous product of factors (one factor for an explicit DFA).
    events : Mapping[str, Event]
        Every event of the alphabet, by canonical name.
    robots : tuple of str
        The team, in scenario order (robots without events included).
    form : str
        ``"tasks"``, ``"dfa"`` or ``"deliveries"``: how the scenario wrote it.
    complete : Composition, optional
        The mission marked exactly where it is complete (see the module docstring); by
        default computed from `automaton` (its marked states when not all are marked, else its
        states without an outgoing transition).
    """

    automaton: Composition
    events: Mapping[str, Event]
    robots: tuple[str, ...]
    form: str
    complete: Composition | None = None

    def __post_init__(self) -> None:
        missing = set(self.automaton.alphabet) - set(self.events)
        if missing:
            raise ValueError(f"events without a definition: {sorted(missing)}")
        object.__setattr__(self, "events", MappingProxyType(dict(self.events)))
        if self.complete is None:
            factors = tuple(
                completion(f, explicit=not bool(np.all(f.marked))) for f in self.automaton.components
            )
            object.__setattr__(self, "complete", Composition(factors))

    @property
    def prefixes(self) -> Composition:
        r""":math:`\overline{K}`: every factor's runs that can still complete, all marked."""
        assert self.complete is not None  # set on construction
        return Composition(tuple(prefix_closure(f) for f in self.complete.components))

    def is_complete_word(self, word: Sequence[str]) -> bool:
        """Whether `word` (event names; messages ignored) is a complete word of the mission.

        Parameters
        ----------
        word : sequence of str
            Event names, in order.
        """
        assert self.complete is not None  # set on construction
        known = set(self.complete.alphabet)
        if any(e not in known and not parse_event(e).is_message for e in word):
            return False
        for factor in self.complete.components:
            alphabet = set(factor.alphabet)
            if not factor.accepts([e for e in word if e in alphabet]):
                return False
        return True

    @property
    def completable(self) -> bool:
        """Whether every factor can reach a complete state (else no team run can complete)."""
        assert self.complete is not None  # set on construction
        return all(bool(f.marked.any()) for f in self.complete.components)

    @property
    def alphabets(self) -> dict[str, tuple[str, ...]]:
        """Local alphabets :math:`\\Sigma^i_{MI}` by robot."""
        return local_alphabets(self.events.values(), self.robots)

    @classmethod
    def from_mission(cls, mission: Mission, robots: Iterable[str]) -> GlobalMission:
        """Build from a validated scenario :class:`~cosmop.scene.Mission`.

        Parameters
        ----------
        mission : Mission
            A validated scenario mission.
        robots : iterable of str
            The team, in scenario order.
        """
        robots = tuple(robots)
        if mission.tasks is not None:
            events = {e.name: e for seq in mission.tasks.values() for e in seq}
            words = [[e.name for e in mission.tasks[r]] for r in mission.tasks]
            factors = tuple(sequence_automaton(w) for w in words)
            ends = tuple(sequence_automaton(w, closed=False) for w in words)
            return cls(Composition(factors), events, robots, "tasks", Composition(ends))
        if mission.deliveries is not None:
            return cls._from_deliveries(mission, robots)
        spec = mission.dfa
        if spec is None:
            raise ValueError("the mission has neither tasks nor a DFA")
        events = {e.name: e for _, e, _ in spec.transitions}
        dfa = DFA.from_transitions(
            spec.initial,
            [(q, e.name, t) for q, e, t in spec.transitions],
            marked=spec.marked,
            states=spec.states or None,
        )
        done = completion(
            DFA.from_transitions(
                spec.initial,
                [(q, e.name, t) for q, e, t in spec.transitions],
                marked=spec.complete_states,
                states=spec.states or None,
            ),
            explicit=True,
        )
        return cls(Composition((dfa,)), events, robots, "dfa", Composition((done,)))

    @classmethod
    def _from_deliveries(cls, mission: Mission, robots: tuple[str, ...]) -> GlobalMission:
        """Deliveries as a product of small factors, never of the robots' alternatives.

        One factor per object: picked by one of its robots, then dropped by the same robot in
        one of its workspaces (complete once dropped).  One factor per robot that may move
        something: it carries one object at a time and, with ``return``, goes home last once it
        has moved something (complete when it moved nothing, or is home; without ``return``,
        whenever it carries nothing).
        """
        assert mission.deliveries is not None  # the caller's test
        events = {e.name: e for e in mission.events}
        prefix, complete = [], []
        for d in mission.deliveries:
            moves = [(f"{d.object}", f"pick({r},{d.object})", f"by_{r}") for r in d.by]
            moves += [(f"by_{r}", f"drop({r},{d.object},{w})", "done") for r in d.by for w in d.to]
            prefix.append(DFA.from_transitions(d.object, moves))
            complete.append(DFA.from_transitions(d.object, moves, marked=["done"]))
        for r in robots:
            mine = [d for d in mission.deliveries if r in d.by]
            if not mine:
                continue
            moves = []
            for d in mine:
                moves += [(q, f"pick({r},{d.object})", f"with_{d.object}") for q in ("fresh", "free")]
                moves += [(f"with_{d.object}", f"drop({r},{d.object},{w})", "free") for w in d.to]
            if mission.returns:
                moves.append(("free", f"return({r})", "home"))
            done = ["fresh", "home"] if mission.returns else ["fresh", "free"]
            prefix.append(DFA.from_transitions("fresh", moves))
            complete.append(DFA.from_transitions("fresh", moves, marked=done))
        return cls(Composition(tuple(prefix)), events, robots, "deliveries", Composition(tuple(complete)))

    @classmethod
    def from_scenario(cls, scenario: Scenario) -> GlobalMission:
        """The mission of a loaded scenario, with the scene's robots as the team.

        Parameters
        ----------
        scenario : Scenario
            A loaded scenario with a mission.

        Raises
        ------
        ValueError
            For a scenario that holds only orders (a lifelong run's, ``cosmop run``).
        """
        if scenario.mission is None:
            raise ValueError(f"{scenario.name} has no mission, only orders: a lifelong run serves them")
        return cls.from_mission(scenario.mission, scenario.scene.robots)

    @classmethod
    def from_dfa(cls, dfa: DFA, robots: Iterable[str] | None = None) -> GlobalMission:
        """Wrap an explicit DFA whose event names parse as mission events.

        Parameters
        ----------
        dfa : DFA
            The mission automaton.
        robots : iterable of str, optional
            The team; by default the events' owners, sorted.
        """
        events = {name: parse_event(name) for name in dfa.alphabet}
        team = (
            tuple(robots)
            if robots is not None
            else tuple(sorted({r for e in events.values() for r in e.owners}))
        )
        return cls(Composition((dfa,)), events, team, "dfa")

    @classmethod
    def from_tasks(
        cls, tasks: Mapping[str, Sequence[str]], robots: Iterable[str] | None = None
    ) -> GlobalMission:
        """The parallel composition of one event sequence per robot (canonical event names).

        Parameters
        ----------
        tasks : mapping of str to sequence of str
            Each robot's events, in order.
        robots : iterable of str, optional
            The team; by default the robots of `tasks`.
        """
        events = {name: parse_event(name) for seq in tasks.values() for name in seq}
        factors = tuple(sequence_automaton(list(seq)) for seq in tasks.values())
        ends = tuple(sequence_automaton(list(seq), closed=False) for seq in tasks.values())
        team = tuple(robots) if robots is not None else tuple(tasks)
        return cls(Composition(factors), events, team, "tasks", Composition(ends))
