"""The team's words with messages: placing them, modelling them, and proving the team correct.

Every robot ends up performing one word of events (its local mission when that is a sequence,
else the word its plan realises), with message events in it: a robot *sends* a message where
it is the sender and *waits* for it where it is the receiver.  This module

* models each robot's word as an automaton in which its messages are asynchronous
  (:func:`team_modules`): the receiver accepts the message, shared with the sender, at any
  time before the point where it waits, and cannot pass that point before it has come;
* proves the team correct for the global mission (:func:`verify_team`): no deadlock (the
  partial order of :mod:`cosmop.team.precedence` has no cycle and every awaited message is
  sent), every run stays a prefix of the mission, and every complete run is a complete word of
  the mission -- the last two by the compositional assume-guarantee check of
  :mod:`cosmop.missions.verification`, once against the prefix-closure and once against the
  complete words;
* decides the same directly on the partial order (:func:`check_words`), which stays fast when
  many messages link every robot to every other (conflict messages do): the runs of the team,
  seen through one factor :math:`T_j` of the mission, are exactly the linear extensions of the
  order *induced* on the events of :math:`\\Sigma(T_j)` (a linear order of a subset that
  respects the induced order always extends to the whole), so each factor is checked by
  exploring the downsets of that small order alone.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import TypeAlias

import numpy as np

from cosmop.automata import DFA
from cosmop.events import Event, Link, parse_event
from cosmop.missions.mission import GlobalMission
from cosmop.missions.verification import Verification, verify
from cosmop.team.precedence import Precedence

__all__ = [
    "TeamVerdict",
    "blocking_word",
    "check_words",
    "stuck_waits",
    "team_modules",
    "verify_team",
    "word_links",
]


def word_links(words: Mapping[str, Sequence[str]]) -> list[Link]:
    """The messages of the words as links between occurrences (instants 1-based).

    Parameters
    ----------
    words : mapping of str to sequence of str
        Every robot's word (event names), messages included.
    """
    sends: dict[Event, tuple[str, int]] = {}
    waits: dict[Event, tuple[str, int]] = {}
    for robot, word in words.items():
        for k, name in enumerate(word, 1):
            event = parse_event(name)  # the words are the automata's letters: text
            if event.is_message:
                (sends if robot == event.sender else waits).setdefault(event, (robot, k))
    out = []
    for event in sorted(set(sends) | set(waits), key=lambda e: e.name):
        assert event.sender is not None and event.receiver is not None  # a message names both
        send = sends.get(event)
        wait = waits.get(event)
        out.append(
            Link(event, event.sender, send[1] if send else None, event.receiver, wait[1] if wait else None)
        )
    return out


def _module(robot: str, word: Sequence[str], *, closed: bool) -> DFA:
    """`robot`'s word as an automaton with asynchronous receipt of its messages."""
    receives = {name for name in word if parse_event(name).is_message and parse_event(name).receiver == robot}

    def settle(p: int, got: frozenset[str]) -> tuple[int, frozenset[str]]:
        while p < len(word) and word[p] in got:  # a wait whose message has come passes
            got = got - {word[p]}
            p += 1
        return p, got

    alphabet = sorted(set(word))
    col = {e: j for j, e in enumerate(alphabet)}
    start = settle(0, frozenset())
    states, rows, todo = {start: 0}, [], [start]
    while todo:
        p, got = todo.pop(0)
        row = [-1] * len(alphabet)
        moves = []
        if p < len(word) and word[p] not in receives:
            moves.append((word[p], settle(p + 1, got)))
        pending = {n for n in receives if n in word[p:]} - got
        moves += [(n, settle(p, got | {n})) for n in sorted(pending)]
        for name, nxt in moves:
            if nxt not in states:
                states[nxt] = len(states)
                todo.append(nxt)
            row[col[name]] = states[nxt]
        rows.append(row)
    order = sorted(states, key=states.__getitem__)
    marked = np.array([closed or (p == len(word) and not got) for p, got in order], dtype=bool)
    delta = np.array(rows, dtype=np.int32).reshape(len(order), len(alphabet))
    return DFA(tuple(alphabet), delta, 0, marked)


def team_modules(words: Mapping[str, Sequence[str]], *, closed: bool = True) -> dict[str, DFA]:
    """Each robot's word as a module: own events and sends in order, receipts asynchronous.

    With ``closed=True`` every state is marked (the words' prefixes), else only the end of the
    word (complete runs).

    Parameters
    ----------
    words : mapping of str to sequence of str
        Every robot's word (event names), messages included.
    closed : bool, default True
        Whether every state is marked, or only the end of the word.
    """
    return {robot: _module(robot, word, closed=closed) for robot, word in words.items()}


@dataclass(frozen=True)
class TeamVerdict:
    """Whether the robots' words with their messages do exactly what the mission asks.

    Attributes
    ----------
    holds : bool
        No deadlock, every run a prefix of the mission, every complete run a complete word.
    blocking : tuple of str or None
        When the team can deadlock: the events done before it blocks (a shortest blocking
        word) and, last, what each blocked robot waits for.
    safety, completion : Verification or None
        The assume-guarantee checks against the prefixes and the complete words.
    counterexample : tuple of str or None
        A run that violates the mission.
    """

    holds: bool
    blocking: tuple[str, ...] | None
    safety: Verification | None
    completion: Verification | None
    counterexample: tuple[str, ...] | None

    @property
    def method(self) -> str:
        """How it was decided: the assume-guarantee method(s), or ``"partial order"``."""
        methods = {v.method for v in (self.safety, self.completion) if v is not None}
        if not methods:
            return "partial order"
        return methods.pop() if len(methods) == 1 else "mixed"

    def reason(self) -> str | None:
        """What is wrong, in words, or ``None`` when it holds."""
        if self.blocking is not None:
            return "the robots' messages can deadlock: " + " ".join(self.blocking)
        if self.counterexample is not None:
            word = " ".join(self.counterexample) or "(no event at all)"
            return f"the robots' missions can violate the global mission: {word}"
        return None


def _word_order(words: Mapping[str, Sequence[str]]) -> Precedence:
    """The partial order the words' messages put on their events (one step per event)."""
    return Precedence({r: len(w) for r, w in words.items()}, word_links(words))


def blocking_word(words: Mapping[str, Sequence[str]]) -> tuple[str, ...] | None:
    """A shortest word into the team's deadlock (then the waits), or ``None`` if it cannot block.

    Parameters
    ----------
    words : mapping of str to sequence of str
        Every robot's word (event names), messages included.
    """
    return _blocking(_word_order(words), words)


def _blocking(precedence: Precedence, words: Mapping[str, Sequence[str]]) -> tuple[str, ...] | None:
    """:func:`blocking_word` read off the words' order `precedence`."""
    if precedence.complete:
        return None
    done = [words[r][k - 1] for r, k in precedence.order]
    waiting = [f"[{r} waits for {words[r][k - 1]}]" for r, k in precedence.stuck.items()]
    return tuple(done + waiting)


def stuck_waits(words: Mapping[str, Sequence[str]]) -> dict[str, int]:
    """Where the robots stuck in the team's deadlock wait: ``{robot: instant}`` (1-based, the
    waits :func:`blocking_word` ends with, in its order); empty if the words cannot block.

    Parameters
    ----------
    words : mapping of str to sequence of str
        Every robot's word (event names), messages included.
    """
    return dict(_word_order(words).stuck)


def verify_team(
    mission: GlobalMission, words: Mapping[str, Sequence[str]], *, method: str = "auto"
) -> TeamVerdict:
    """Prove that the words, with their asynchronous messages, do exactly what `mission` asks.

    Parameters
    ----------
    mission : GlobalMission
    words : Mapping[str, sequence of str]
        Every robot's word (event names), messages included.
    method : str
        Passed to :func:`cosmop.missions.verification.verify`.

    Returns
    -------
    TeamVerdict
    """
    words = {r: tuple(words.get(r, ())) for r in mission.robots} | dict(words)
    blocked = blocking_word(words)
    if blocked is not None:
        return TeamVerdict(False, blocked, None, None, None)
    safety = verify(replace(mission, automaton=mission.prefixes), team_modules(words), method=method)
    if not safety.holds:
        return TeamVerdict(False, None, safety, None, safety.counterexample)
    assert mission.complete is not None  # set on construction
    completion = verify(
        replace(mission, automaton=mission.complete), team_modules(words, closed=False), method=method
    )
    return TeamVerdict(completion.holds, None, safety, completion, completion.counterexample)


_State: TypeAlias = tuple[tuple[int, ...], int]
"""A state of the search of :func:`_factor_counterexample`: each robot's occurrences done, and
the factor's state."""


def _factor_counterexample(
    factor: DFA, words: Mapping[str, Sequence[str]], precedence: Precedence
) -> tuple[str, ...] | None:
    """A run of the team whose events of the factor are not a complete word of it, or ``None``."""
    sigma = set(factor.alphabet)
    occurrences: dict[str, list[tuple[int, str]]] = {}
    for robot, word in words.items():
        occ = [
            (k, name)
            for k, name in enumerate(word, 1)
            if name in sigma and (not parse_event(name).is_message or parse_event(name).sender == robot)
        ]
        if occ:
            occurrences[robot] = occ
    robots = list(occurrences)
    column = factor.event_index()
    needs = {  # occurrence -> per robot, how many of its occurrences must be done before
        (r, p): [
            sum(1 for k, _ in occurrences[o] if k <= precedence.completed((r, kk), o)) if o != r else p
            for o in robots
        ]
        for r in robots
        for p, (kk, _) in enumerate(occurrences[r])
    }
    start: _State = (tuple(0 for _ in robots), factor.initial)
    parent: dict[_State, tuple[_State, str] | None] = {start: None}
    queue = [start]
    for state in queue:
        positions, q = state
        if all(p == len(occurrences[r]) for p, r in zip(positions, robots, strict=True)):
            if not factor.marked[q]:
                return _trail(parent, state, robots, occurrences)
            continue
        for n, r in enumerate(robots):
            p = positions[n]
            if p == len(occurrences[r]) or any(positions[m] < need for m, need in enumerate(needs[(r, p)])):
                continue
            name = occurrences[r][p][1]
            t = int(factor.delta[q, column[name]])
            nxt = ((*positions[:n], p + 1, *positions[n + 1 :]), t)
            if t < 0:
                parent[nxt] = (state, name)
                return _trail(parent, nxt, robots, occurrences)
            if nxt not in parent:
                parent[nxt] = (state, name)
                queue.append(nxt)
    return None


def _trail(
    parent: Mapping[_State, tuple[_State, str] | None],
    state: _State,
    robots: Sequence[str],
    occurrences: Mapping[str, Sequence[tuple[int, str]]],
) -> tuple[str, ...]:
    out = []
    while (step := parent.get(state)) is not None:
        state, name = step
        out.append(name)
    return tuple(reversed(out))


def check_words(mission: GlobalMission, words: Mapping[str, Sequence[str]]) -> TeamVerdict:
    """Decide on the partial order whether the words, with their asynchronous messages, can
    deadlock or produce a run that is not a complete word of `mission` (module docstring).

    Exact, like :func:`verify_team`; it explores, per factor of the mission, only the order
    induced on that factor's events.

    Parameters
    ----------
    mission : GlobalMission
        The global mission, with its complete words.
    words : mapping of str to sequence of str
        Every robot's word (event names), messages included.
    """
    words = {r: tuple(words.get(r, ())) for r in mission.robots} | {r: tuple(w) for r, w in words.items()}
    precedence = _word_order(words)
    if not precedence.complete:
        return TeamVerdict(False, _blocking(precedence, words), None, None, None)
    assert mission.complete is not None  # set on construction
    for factor in mission.complete.components:
        word = _factor_counterexample(factor, words, precedence)
        if word is not None:
            return TeamVerdict(False, None, None, None, word)
    return TeamVerdict(True, None, None, None, None)
