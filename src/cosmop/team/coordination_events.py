"""Coordination events: turn the motion layer's requests into request/response pairs.

When robot A's plan asks for object O to be moved away (a Req step), the robot B whose mission
picks O must answer after it has picked O.  Every such need becomes one *coordination event*
``away(O, A, B)``, shared by A (the request ``?O Away``) and B (the response ``!O Away``).  The
pair is keyed by (object, requester, responder): one event per requester, never one event
shared by three robots (one event shared by two requesters and a responder would make the
synchronous product wait for all three at once, and the team deadlock; the paper's figures draw
R3's two answers as two events).

* In A's sequence ``away(O, A, B)`` goes just before the mission event during whose approach
  the Req was taken.
* In B's sequence it goes right after ``pick(B, O)``.  When several robots wait on B, B answers
  first those whose own wait is shortest: the requester with fewer coordination events before
  this one in its sequence.  A responder that others wait on is thereby answered first (in the
  10×10 example R3 answers R2 before R1).  If that order still blocks, the other orders of B's
  answers are tried.
* The result is proved deadlock-free: with asynchronous messages (the responder sends and
  goes on, the requester waits until it has been sent) the robots can block only if their
  waits form a cycle, which :func:`blocking_word` rules out.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from types import MappingProxyType

from cosmop.events import Event
from cosmop.team.mission_proof import blocking_word as team_blocking_word


@dataclass(frozen=True)
class Pair:
    """One request/response pair: ``responder`` tells ``requester`` that ``obj`` is away."""

    obj: str
    requester: str
    responder: str

    @property
    def event(self) -> Event:
        return Event("away", self.requester, obj=self.obj, responder=self.responder)


@dataclass(frozen=True)
class Coordinated:
    """Result of :func:`coordinate`.

    Attributes
    ----------
    sequences : Mapping[str, tuple of Event]
        Every robot's local mission with its coordination events in place.
    pairs : tuple of Pair
    unanswered : tuple of (str, str)
        ``(object, requester)`` for requests no robot's mission can answer (no mission picks the
        object): these need re-allocation or make the scenario infeasible.
    deadlock_free : bool
        Whether the coordinated sequences can always all complete (checked per cluster).
    blocking : tuple of str or None
        When not deadlock-free: a shortest sequence of events into a state from which the
        cluster cannot complete.
    """

    sequences: Mapping[str, tuple[Event, ...]]
    pairs: tuple[Pair, ...]
    unanswered: tuple[tuple[str, str], ...]
    deadlock_free: bool
    blocking: tuple[str, ...] | None = None


def blocking_word(sequences: Mapping[str, Sequence[Event]]) -> tuple[str, ...] | None:
    """A shortest word into a deadlock, or ``None`` when the robots can always all complete.

    Messages are asynchronous (a responder sends and goes on; a requester waits until the
    answer has been sent), as the robots execute them: see
    :func:`cosmop.team.mission_proof.blocking_word`.

    Parameters
    ----------
    sequences : mapping of str to sequence of Event
        Each robot's events, in order.
    """
    return team_blocking_word({r: [e.name for e in seq] for r, seq in sequences.items()})


def coordinate(
    sequences: Mapping[str, Sequence[Event]], requests: Mapping[str, Sequence[tuple[str, int]]]
) -> Coordinated:
    """Add request/response pairs for the requests and order them without deadlock.

    Parameters
    ----------
    sequences : Mapping[str, sequence of Event]
        Every robot's local mission (without coordination events for these requests).
    requests : Mapping[str, sequence of (str, int)]
        Per requester, ``(object, index of the mission event the request prepares)``, as from
        :func:`cosmop.planning.realisation.request_phases`.

    Returns
    -------
    Coordinated
    """
    pickers = {e.obj: r for r, seq in sequences.items() for e in seq if e.kind == "pick"}
    pairs: list[Pair] = []
    unanswered: list[tuple[str, str]] = []
    new = {r: list(seq) for r, seq in sequences.items()}
    # requester side: insert before the prepared event, from the back so indices stay valid
    for requester, reqs in requests.items():
        answered = []
        for obj, before in reqs:
            responder = pickers.get(obj)
            if responder is None or responder == requester:
                unanswered.append((obj, requester))
                continue
            pair = Pair(obj, requester, responder)
            if pair not in pairs:
                pairs.append(pair)
                answered.append((before, pair))
        # back to front (later requests first at equal positions), so the plan's order is kept
        for k in sorted(range(len(answered)), key=lambda k: (answered[k][0], k), reverse=True):
            before, pair = answered[k]
            new[requester].insert(before, pair.event)

    # responder side: right after the pick, those who wait least first
    def rank(pair: Pair) -> tuple[int, int]:
        seq = new[pair.requester]
        position = seq.index(pair.event)
        waits = sum(1 for e in seq[:position] if e.kind == "away")
        return (waits, list(sequences).index(pair.requester))

    by_responder: dict[str, list[Pair]] = {}
    for pair in pairs:
        by_responder.setdefault(pair.responder, []).append(pair)
    base = {r: list(seq) for r, seq in new.items()}

    def place(orders: Mapping[str, Sequence[Pair]]) -> dict[str, tuple[Event, ...]]:
        out = {r: list(seq) for r, seq in base.items()}
        for responder, answers in orders.items():
            seq = out[responder]
            for k, pair in enumerate(answers):
                at = next(i for i, e in enumerate(seq) if e.kind == "pick" and e.obj == pair.obj) + 1 + k
                seq.insert(at, pair.event)
        return {r: tuple(seq) for r, seq in out.items()}

    preferred = {b: sorted(ps, key=rank) for b, ps in by_responder.items()}
    candidates: list[Mapping[str, Sequence[Pair]]] = [preferred]
    alternatives = [list(itertools.permutations(ps)) for ps in preferred.values()]
    if alternatives and all(len(a) <= 24 for a in alternatives):
        for combo in itertools.islice(itertools.product(*alternatives), 1, 200):
            candidates.append(dict(zip(preferred, combo, strict=True)))
    first_block: tuple[dict[str, tuple[Event, ...]], tuple[str, ...]] | None = None
    for orders in candidates:
        placed = place(orders)
        word = blocking_word(placed)
        if word is None:
            return Coordinated(MappingProxyType(placed), tuple(pairs), tuple(unanswered), True)
        first_block = first_block or (placed, word)
    assert first_block is not None  # the candidates hold at least the preferred order
    placed, word = first_block
    return Coordinated(MappingProxyType(placed), tuple(pairs), tuple(unanswered), False, word)
