"""The global mission :math:`K_{MI}` and its distribution over the robots.

A global mission is a prefix-closed regular language over every robot's mission events
(Section III-B).  It is held as a :class:`~cosmop.automata.Composition`: the tasks form of the
scenario file is the synchronous product of one sequence automaton per robot (kept as its
factors, never built), the explicit DFA form is a composition of one factor.

Event ownership gives the local alphabets :math:`\\Sigma^i_{MI}`: ``pick``, ``drop`` and
``return`` belong to their robot; a coordination event ``away(O, A, B)`` belongs to both the
requester ``A`` and the responder ``B``, which is what makes it synchronise them.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from types import MappingProxyType

from cosmop.automata import DFA, Composition
from cosmop.missions.events import Event, parse_event
from cosmop.scenario import Mission, Scenario


def sequence_automaton(events: Sequence[str], *, closed: bool = True) -> DFA:
    """DFA of one sequence of events :math:`\\sigma_1 \\sigma_2 \\cdots \\sigma_k`.

    With ``closed=True`` (a mission) every state is marked, so the marked language is the
    prefix-closure :math:`\\overline{\\sigma_1 \\cdots \\sigma_k}`; with ``closed=False`` only
    the complete sequence is marked (used to see whether robots can all finish).
    """
    return DFA.from_word(tuple(events), closed=closed)


def sequence_of(dfa: DFA) -> tuple[str, ...] | None:
    """The events of a linear DFA (one path, no branching, no cycle), or ``None``.

    The inverse of :func:`sequence_automaton`: a local mission that is one sequence of events.
    """
    q, seq, seen = dfa.initial, [], {dfa.initial}
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


def local_alphabets(events: Iterable[Event], robots: Iterable[str]) -> dict[str, tuple[str, ...]]:
    """:math:`\\Sigma^i_{MI}` for every robot: the names of the events it owns, sorted.

    A robot that owns no event gets the empty alphabet (its local mission is
    :math:`\\{\\varepsilon\\}`).
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
        ``"tasks"`` or ``"dfa"``: how the scenario wrote it.
    """

    automaton: Composition
    events: Mapping[str, Event]
    robots: tuple[str, ...]
    form: str

    def __post_init__(self) -> None:
        missing = set(self.automaton.alphabet) - set(self.events)
        if missing:
            raise ValueError(f"events without a definition: {sorted(missing)}")
        object.__setattr__(self, "events", MappingProxyType(dict(self.events)))

    @property
    def alphabets(self) -> dict[str, tuple[str, ...]]:
        """Local alphabets :math:`\\Sigma^i_{MI}` by robot."""
        return local_alphabets(self.events.values(), self.robots)

    @classmethod
    def from_mission(cls, mission: Mission, robots: Iterable[str]) -> GlobalMission:
        """Build from a validated scenario :class:`~cosmop.scenario.Mission`."""
        robots = tuple(robots)
        if mission.tasks is not None:
            events = {e.name: e for seq in mission.tasks.values() for e in seq}
            factors = tuple(sequence_automaton([e.name for e in mission.tasks[r]]) for r in mission.tasks)
            return cls(Composition(factors), events, robots, "tasks")
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
        return cls(Composition((dfa,)), events, robots, "dfa")

    @classmethod
    def from_scenario(cls, scenario: Scenario) -> GlobalMission:
        """The mission of a loaded scenario, with the scene's robots as the team."""
        return cls.from_mission(scenario.mission, scenario.scene.robots)

    @classmethod
    def from_dfa(cls, dfa: DFA, robots: Iterable[str] | None = None) -> GlobalMission:
        """Wrap an explicit DFA whose event names parse as mission events."""
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
        """The parallel composition of one event sequence per robot (canonical event names)."""
        events = {name: parse_event(name) for seq in tasks.values() for name in seq}
        factors = tuple(sequence_automaton(list(seq)) for seq in tasks.values())
        return cls(
            Composition(factors), events, tuple(robots) if robots is not None else tuple(tasks), "tasks"
        )
