"""Order between robots by messages, instead of pruning missions that are not separable.

Each robot performs one word of events, :math:`w_i`.  Left alone, the robots interleave their
words in every way; messages cut that down.  A message from robot A, sent right after the
*a*-th event of :math:`w_A`, awaited by robot B right before the *b*-th event of :math:`w_B`, is
an *edge* :math:`(A, a) \\to (B, b)`.  Messages are asynchronous, so the team's runs are exactly
the interleavings that respect program order and the edges (the linear extensions of the
partial order they generate).  The coordination events already in the words (``away``,
``msg``) are such edges too.

The team is correct for the global mission :math:`K` when every complete run projects onto a
complete word of :math:`K` and every run can be completed (no deadlock); then every prefix is
a prefix of :math:`K` too.  :func:`order_words` finds edges that make it so, guided by
counterexamples (after Karimadini and Lin's local coordination by communication, Automatica
2011, for the case where the robots' tasks are fixed):

1. explore the runs (the product of the words' positions and of :math:`K`'s states) and mark
   the *good* states, those from which a complete word of :math:`K` can still be reached;
2. take a shortest run that leaves the good states: a good state :math:`s` and an event
   :math:`x` of robot B enabled there whose successor is not good (it leaves :math:`K`, blocks,
   or can no longer complete);
3. choose an event :math:`y` of another robot A enabled at :math:`s` whose successor is good,
   and add the edge "B waits for A's :math:`y` before :math:`x`".  A good complete run through
   :math:`s y` exists and respects the new edge, so the edges never exclude every good run;
   the run through :math:`s x` is gone, so the loop ends.

The edges are then reduced (an edge implied by the others is dropped), so that a user reads
only the orders the mission needs.  If no complete word of :math:`K` interleaves the words at
all, there is nothing to order: the words themselves must change (``feasible`` false).
"""

from __future__ import annotations

from collections import deque
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TypeAlias

from cosmop.automata import Composition
from cosmop.errors import MissionTooLargeError
from cosmop.events import message, parse_event

__all__ = [
    "Edge",
    "WordOrder",
    "message_edges",
    "message_tag",
    "order_words",
    "reduce_edges",
    "with_messages",
]

Edge = tuple[tuple[str, int], tuple[str, int]]
"""``((A, a), (B, b))``: B's event at index b waits for A's event at index a (0-based)."""

_State: TypeAlias = tuple[tuple[int, ...], tuple[int, ...]]
"""A team state: each robot's position in its word, and each factor's state."""
_Moves: TypeAlias = list[tuple[int, _State | None]]
"""The enabled moves of a state: ``(robot index, next state or None if it leaves the mission)``."""


@dataclass(frozen=True)
class WordOrder:
    """Result of :func:`order_words`.

    Attributes
    ----------
    feasible : bool
        Whether some interleaving of the words is a complete word of the mission.
    edges : tuple of Edge
        The orders added (reduced), each to become a message.
    witness : tuple of str
        A complete word of the mission that the ordered team can run (empty if infeasible).
    states : int
        Product states explored in the last round.
    rounds : int
        Counterexamples used.
    """

    feasible: bool
    edges: tuple[Edge, ...]
    witness: tuple[str, ...]
    states: int
    rounds: int


def message_edges(words: Mapping[str, Sequence[str]]) -> list[Edge]:
    """The edges of the message events already in the words: send occurrence -> receive one.

    Parameters
    ----------
    words : mapping of str to sequence of str
        Each robot's word (event names).
    """
    sends: dict[str, tuple[str, int]] = {}
    waits: dict[str, tuple[str, int]] = {}
    for robot, word in words.items():
        for k, name in enumerate(word):
            event = parse_event(name)
            if event.is_message:
                (sends if robot == event.sender else waits)[name] = (robot, k)
    return [(sends[n], waits[n]) for n in sorted(waits) if n in sends]


class _Team:
    """The runs of the words under the edges, tracked in the mission's factors."""

    def __init__(self, mission: Composition, words: Mapping[str, Sequence[str]], edges: Sequence[Edge]):
        self.robots = tuple(words)
        self.words = [tuple(words[r]) for r in self.robots]
        self.factors = mission.components
        self.columns = [f.event_index() for f in self.factors]
        self.waits: dict[tuple[int, int], list[tuple[int, int]]] = {}
        index = {r: n for n, r in enumerate(self.robots)}
        for (a, i), (b, j) in edges:
            self.waits.setdefault((index[b], j), []).append((index[a], i))
        self.tracked = [[self._tracked(name, r) for name in self.words[n]] for n, r in enumerate(self.robots)]

    def _tracked(self, name: str, robot: str) -> bool:
        event = parse_event(name)
        return not event.is_message or event.sender == robot  # a message moves K when sent

    def start(self) -> _State:
        return (tuple(0 for _ in self.robots), tuple(f.initial for f in self.factors))

    def moves(self, state: _State) -> _Moves:
        """Enabled moves ``(robot index, next state or None if it leaves the mission)``."""
        positions, qs = state
        out: _Moves = []
        for n, p in enumerate(positions):
            if p >= len(self.words[n]):
                continue
            if any(positions[a] <= i for a, i in self.waits.get((n, p), ())):
                continue
            name = self.words[n][p]
            nqs = list(qs)
            dead = False
            if self.tracked[n][p]:
                for f, (factor, col) in enumerate(zip(self.factors, self.columns, strict=True)):
                    j = col.get(name)
                    if j is None:
                        continue
                    t = int(factor.delta[qs[f], j])
                    if t < 0:
                        dead = True
                        break
                    nqs[f] = t
            npos = (*positions[:n], p + 1, *positions[n + 1 :])
            out.append((n, None if dead else (npos, tuple(nqs))))
        return out

    def complete(self, state: _State) -> bool:
        positions, qs = state
        return all(p == len(w) for p, w in zip(positions, self.words, strict=True)) and all(
            bool(f.marked[q]) for f, q in zip(self.factors, qs, strict=True)
        )


def _explore(team: _Team, max_states: int) -> tuple[list[_State], dict[_State, _Moves], set[_State]]:
    """Reachable states in breadth-first order, their moves, and the good ones."""
    start = team.start()
    order, seen = [start], {start}
    moves: dict[_State, _Moves] = {}
    queue = deque([start])
    while queue:
        state = queue.popleft()
        moves[state] = team.moves(state)
        for _, nxt in moves[state]:
            if nxt is not None and nxt not in seen:
                if len(seen) >= max_states:
                    raise MissionTooLargeError(
                        f"ordering the robots' events explores more than {max_states} team states; "
                        "split the mission or write it with fewer orders between robots",
                        field="mission",
                    )
                seen.add(nxt)
                order.append(nxt)
                queue.append(nxt)
    good = {s for s in order if team.complete(s)}
    changed = True
    while changed:  # backward closure: states with a move into a good state
        changed = False
        for s in reversed(order):
            if s not in good and any(nxt in good for _, nxt in moves[s] if nxt is not None):
                good.add(s)
                changed = True
    return order, moves, good


def order_words(
    mission: Composition,
    words: Mapping[str, Sequence[str]],
    *,
    max_states: int = 2_000_000,
    max_rounds: int | None = None,
) -> WordOrder:
    """Edges that make every run of the words a complete word of `mission` (module docstring).

    Parameters
    ----------
    mission : Composition
        The global mission marked where it is complete (``GlobalMission.complete``).
    words : Mapping[str, sequence of str]
        Each robot's word (event names), with the messages it already has.
    max_states, max_rounds : int
        Bounds on the explored product and on the counterexamples used (by default four per
        event of the words: each counterexample orders one more pair of events).

    Raises
    ------
    MissionTooLargeError
        When a bound is reached before the order settles.

    Returns
    -------
    WordOrder
    """
    base = message_edges(words)
    added: list[Edge] = []
    rounds = 0
    if max_rounds is None:
        max_rounds = 16 + 4 * sum(len(w) for w in words.values())
    while True:
        team = _Team(mission, words, base + added)
        order, moves, good = _explore(team, max_states)
        if team.start() not in good:
            return WordOrder(False, (), (), len(order), rounds)
        bad = next(
            ((s, n) for s in order if s in good for n, nxt in moves[s] if nxt not in good),
            None,
        )
        if bad is None:
            break
        if rounds >= max_rounds:
            raise MissionTooLargeError(
                f"the order between the robots' events did not settle within {max_rounds} "
                "counterexamples; split the mission or write it with fewer orders between robots",
                field="mission",
            )
        rounds += 1
        state, x = bad
        y = next(n for n, nxt in moves[state] if nxt in good)
        positions = state[0]
        added.append(((team.robots[y], positions[y]), (team.robots[x], positions[x])))
    kept = reduce_edges({r: len(w) for r, w in words.items()}, base, added)
    return WordOrder(True, tuple(kept), _witness(team, order, moves, good), len(order), rounds)


def _witness(
    team: _Team, order: list[_State], moves: Mapping[_State, _Moves], good: set[_State]
) -> tuple[str, ...]:
    """A complete run: from the start, always a move into a good state."""
    state, word = team.start(), []
    while not team.complete(state):
        n, state = next((n, nxt) for n, nxt in moves[state] if nxt is not None and nxt in good)
        word.append(team.words[n][state[0][n] - 1])
    return tuple(word)


def reduce_edges(lengths: Mapping[str, int], fixed: Sequence[Edge], edges: Sequence[Edge]) -> list[Edge]:
    """`edges` without those implied by program order, `fixed` and the other kept edges.

    Parameters
    ----------
    lengths : mapping of str to int
        Each robot's word length.
    fixed : sequence of Edge
        Edges that stay (the messages').
    edges : sequence of Edge
        The edges to reduce, in order.
    """
    kept = list(edges)
    for edge in list(edges):
        rest = [e for e in kept if e != edge]
        if _implied(lengths, list(fixed) + rest, edge):
            kept = rest
    return kept


def _implied(lengths: Mapping[str, int], edges: Sequence[Edge], edge: Edge) -> bool:
    """Whether the occurrence ``edge[0]`` precedes ``edge[1]`` through program order and `edges`."""
    (a, i), target = edge
    out: dict[tuple[str, int], list[tuple[str, int]]] = {}
    for src, dst in edges:
        out.setdefault(src, []).append(dst)
    seen, todo = set(), [(a, i)]
    while todo:
        node = todo.pop()
        if node == target:
            return True
        if node in seen:
            continue
        seen.add(node)
        robot, k = node
        if robot == target[0] and k < target[1]:
            return True  # program order reaches the target
        if k + 1 < lengths[robot]:
            todo.append((robot, k + 1))
        todo.extend(out.get(node, ()))
    return False


def message_tag(name: str) -> str:
    """A message tag that says after which event it is sent: ``drop(R1,O1,W1)`` -> ``after_drop_O1_W1``.

    Parameters
    ----------
    name : str
        The event's canonical name.
    """
    event = parse_event(name)
    parts = [event.kind] + [p for p in (event.obj, event.workspace, event.tag) if p]
    return "after_" + "_".join(parts)


def with_messages(
    words: Mapping[str, Sequence[str]], edges: Sequence[Edge]
) -> tuple[dict[str, tuple[str, ...]], list[tuple[str, Edge]]]:
    """The words with one ``msg`` per edge, and the messages with their edges.

    For an edge ``((A, a), (B, b))`` the message ``msg(A,B,tag)`` goes right after A's event
    *a* and right before B's event *b* (indices into the given words); at one place a robot's
    sends come before its waits, so that it never waits with news it could already give.

    Parameters
    ----------
    words : mapping of str to sequence of str
        Each robot's word (event names).
    edges : sequence of Edge
        The edges to turn into messages.
    """
    inserts: dict[str, list[tuple[int, int, str]]] = {r: [] for r in words}
    used: set[str] = set()
    out_messages = []
    for edge in edges:
        (a, i), (b, j) = edge
        tag = message_tag(words[a][i])
        name, n = message(a, b, tag).name, 1
        while name in used:
            n += 1
            name = message(a, b, f"{tag}_{n}").name
        used.add(name)
        inserts[a].append((i + 1, 0, name))
        inserts[b].append((j, 1, name))
        out_messages.append((name, edge))
    out = {}
    for robot, word in words.items():
        at: dict[int, list[tuple[int, str]]] = {}
        for pos, rank, name in inserts[robot]:
            at.setdefault(pos, []).append((rank, name))
        new: list[str] = []
        for pos in range(len(word) + 1):
            new += [name for _, name in sorted(at.get(pos, ()))]
            if pos < len(word):
                new.append(word[pos])
        out[robot] = tuple(new)
    return out, out_messages
