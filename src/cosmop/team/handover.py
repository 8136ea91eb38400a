"""Goods handed over between robots: which robot picks what another robot has put down.

In a relay, robot G carries goods O to a hand-over area and drops them there, and robot R
picks them up later and carries them on.  The mission orders the two events (``drop(G,O,H)``
before ``pick(R,O)``), and the robots' words keep that order with a message.  Each robot is
planned alone, against the scene as it knows it, so R must know that O lies where G drops it,
not where the scene put it: R's synthesis starts with O at G's drop spot, and G's drop is held
to that spot whenever G is planned again (:attr:`cosmop.planning.specification.RobotProblem.spots`).

A *hand-over* is a pair of events of two robots' words: a ``drop`` of O by G and a ``pick`` of
O by R such that, in the team's order (program order and messages,
:class:`~cosmop.team.precedence.Precedence` over the words' events), the drop comes before
the pick and is the last drop of O by another robot before it.  Only a robot's first pick of an
object can be a hand-over: its model of the object starts at the hand-over spot.  A robot that
meets the same goods again after another robot has moved them would need its model changed in
the middle of its plan; such missions are refused with a reason (:attr:`Handovers.refused`).

The giver must be planned before the receiver (:meth:`Handovers.turns`).  When givers and
receivers form a cycle (R1 hands O1 to R2, which hands O2 to R1), one hand-over of the cycle
gets a spot chosen for both before either is planned
(:func:`cosmop.team.aside.handover_spot`).
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from cosmop.events import Event, Link
from cosmop.team.precedence import Precedence

__all__ = ["Handover", "Handovers", "handovers"]


@dataclass(frozen=True)
class Handover:
    """Goods `obj` dropped by `giver` (its `nth` drop of them, from 0, the event `drop`) and
    then picked by `receiver` (the event `pick`, its first of them)."""

    obj: str
    giver: str
    drop: Event
    nth: int
    receiver: str
    pick: Event

    def describe(self) -> str:
        """In words: ``R1 hands O1 over to R2 in H``."""
        return f"{self.giver} hands {self.obj} over to {self.receiver} in {self.drop.workspace}"


@dataclass(frozen=True)
class Handovers:
    """The hand-overs of a team's words, and why some of the words cannot be planned.

    Attributes
    ----------
    items : tuple of Handover
    refused : tuple of str
        Reasons, in words, for goods a robot meets again after another robot moved them.
    unordered : tuple of (str, (str, int), (str, int))
        Goods handled by two robots with no order between the two events: ``(object, (robot,
        index in its word), (other robot, index))``, indices from 0.
    """

    items: tuple[Handover, ...] = ()
    refused: tuple[str, ...] = ()
    unordered: tuple[tuple[str, tuple[str, int], tuple[str, int]], ...] = ()

    def to(self, robot: str) -> tuple[Handover, ...]:
        """The hand-overs `robot` receives.

        Parameters
        ----------
        robot : str
            The receiver.
        """
        return tuple(h for h in self.items if h.receiver == robot)

    def turns(self, robots: Sequence[str]) -> tuple[tuple[tuple[str, ...], tuple[Handover, ...]], ...]:
        """The order to plan `robots` in: ``(robots planned together, hand-overs whose spot is
        chosen before them)`` per turn.

        A robot is planned once every robot that hands it goods is (Kahn's algorithm); when the
        rest wait on each other in a cycle, the first hand-over among them (in `robots`' order)
        gets its spot chosen for both, and the wait is broken.

        Parameters
        ----------
        robots : sequence of str
            The robots to plan, in order.
        """
        waiting = {r: {h for h in self.to(r) if h.giver != r} for r in robots}
        todo, out = list(robots), []
        while todo:
            ready = tuple(r for r in todo if not any(h.giver in todo for h in waiting[r]))
            chosen: tuple[Handover, ...] = ()
            if not ready:  # a cycle of givers and receivers: break it at its first hand-over
                receiver = todo[0]
                first = min(
                    (h for h in waiting[receiver] if h.giver in todo), key=lambda h: todo.index(h.giver)
                )
                waiting[receiver].discard(first)
                chosen = (first,)
                ready = tuple(r for r in todo if not any(h.giver in todo for h in waiting[r]))
            out.append((ready, chosen))
            todo = [r for r in todo if r not in ready]
        return tuple(out)


def handovers(words: Mapping[str, Sequence[Event]]) -> Handovers:
    """The hand-overs in the robots' `words` (see the module docstring).

    Parameters
    ----------
    words : Mapping[str, sequence of Event]
        Each robot's word, with the messages that order it against the others (``msg`` and
        ``away`` events; a message orders the receiver's event after the sender's).

    Returns
    -------
    Handovers

    Examples
    --------
    >>> from cosmop.events import parse_event as e
    >>> words = {
    ...     "R1": [e("pick(R1,O1)"), e("drop(R1,O1,H)"), e("msg(R1,R2,t)")],
    ...     "R2": [e("msg(R1,R2,t)"), e("pick(R2,O1)"), e("drop(R2,O1,W)")],
    ... }
    >>> [h.describe() for h in handovers(words).items]
    ['R1 hands O1 over to R2 in H']
    """
    order = _order(words)
    handling: dict[str, list[tuple[str, int, Event]]] = {}
    for robot, word in words.items():
        for i, event in enumerate(word, 1):
            if event.kind in ("pick", "drop") and event.robot == robot:
                assert event.obj is not None  # a pick or a drop names its object
                handling.setdefault(event.obj, []).append((robot, i, event))
    items, refused, unordered = [], [], []
    for obj, events in handling.items():
        for (r1, i1, _), (r2, i2, _) in itertools.combinations(events, 2):
            if r1 != r2 and not order.precedes((r1, i1), (r2, i2)) and not order.precedes((r2, i2), (r1, i1)):
                unordered.append((obj, (r1, i1 - 1), (r2, i2 - 1)))
        for robot, i, event in events:
            if event.kind != "pick":
                continue
            before = [
                (r, j, e) for r, j, e in events if (r, j) != (robot, i) and order.precedes((r, j), (robot, i))
            ]
            # the last handling before the pick: the one no other handling before it follows
            latest = [h for h in before if not any(g != h and order.precedes(h[:2], g[:2]) for g in before)]
            if len(latest) != 1 or latest[0][0] == robot or latest[0][2].kind != "drop":
                continue  # its own goods, or handlings left unordered (the checker says so)
            last = latest[0]
            if any(r == robot for r, _, _ in before):
                refused.append(
                    f"{robot} picks {obj} again after {last[0]} has moved it ({last[2].name}); a robot "
                    "meets the same goods again only where it left them"
                )
                continue
            nth = sum(1 for r, j, e in events if r == last[0] and e.kind == "drop" and j < last[1])
            items.append(Handover(obj, last[0], last[2], nth, robot, event))
    return Handovers(tuple(items), tuple(refused), tuple(unordered))


def _order(words: Mapping[str, Sequence[Event]]) -> Precedence:
    """The team's order on the words' events: program order and messages (event *i* of a
    word is step *i*; a message's receiver performs it after its sender)."""
    sends: dict[Event, tuple[str, int]] = {}
    waits: dict[Event, tuple[str, int]] = {}
    for robot, word in words.items():
        for i, event in enumerate(word, 1):
            if event.is_message:
                (sends if event.sender == robot else waits).setdefault(event, (robot, i))
    links = [
        Link(event, sends[event][0], sends[event][1], waits[event][0], waits[event][1])
        for event in sorted(set(sends) & set(waits), key=lambda e: e.name)
    ]
    return Precedence({r: len(w) for r, w in words.items()}, links)
