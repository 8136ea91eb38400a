"""Allocation: commit the team to one way of completing a mission that offers choices.

A global mission :math:`K` may leave choices open: *either* R1 or R2 moves O1, O1 goes to W1
*or* to W2.  Every complete run :math:`s` of the team then realises one *alternative*, the
tuple of the robots' words :math:`(P_1(s), \\dots, P_n(s))` (natural projection onto each
robot's events).  Committing the team to an alternative gives every robot one sequence of
events, which the bottom-up layer plans; the order between robots that :math:`K` requires is
then kept by messages (:func:`cosmop.missions.ordering.order_words`).  The alternative's own
words interleave into the complete word :math:`s`, so that ordering always succeeds, and the
sub-language the team then runs is contained in :math:`K`: the allocation is sound by
construction, and :func:`cosmop.missions.team.check_words` re-proves it on the final plans.

:func:`alternatives` enumerates the distinct alternatives, from the complete words of
:math:`K` no longer than :math:`|Q| - 1` events (:math:`Q` the states of :math:`K`): every
complete word that visits no state twice is among them, and a longer one repeats a state, a loop
whose cut leaves a complete word that asks no robot for more.  It walks :math:`K`'s factors in
step (the product is never built), remembering each (state, words so far) once -- what can
follow depends on nothing else -- so interleavings that give the same words are explored
once.  :func:`choose` then picks, from the bottom-up costs (each robot's shortest plan for its
word, in primitive steps), the alternative of least *makespan* (the longest plan), then least
total; this is exact over every alternative enumerated.  When the enumeration is cut short by
its bound, the result says so (``exhaustive`` false) and the choice is the best among the
alternatives found first (depth-first, events in name order).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

from cosmop.missions.mission import GlobalMission

__all__ = ["Alternative", "Alternatives", "Choice", "alternatives", "choose"]


@dataclass(frozen=True)
class Alternative:
    """One way the team can complete the mission: a word of events per robot.

    Attributes
    ----------
    words : Mapping[str, tuple of str]
        Each robot's word (event names), every robot of the team present (maybe empty).
    """

    words: Mapping[str, tuple[str, ...]]

    def __post_init__(self) -> None:
        object.__setattr__(self, "words", MappingProxyType({r: tuple(w) for r, w in self.words.items()}))

    def movers(self, mission: GlobalMission) -> dict[str, str]:
        """The robot that picks each object up, by object (what ``plan.json`` records)."""
        out = {}
        for robot, word in self.words.items():
            for name in word:
                event = mission.events[name]
                if event.kind == "pick" and event.robot == robot:
                    out[event.obj] = robot
        return dict(sorted(out.items()))

    def label(self) -> str:
        """``R1: a b; R2: c`` for messages and tables."""
        return "; ".join(f"{r}: {' '.join(w) or '(nothing)'}" for r, w in self.words.items())


@dataclass(frozen=True)
class Alternatives:
    """Result of :func:`alternatives`.

    Attributes
    ----------
    items : tuple of Alternative
        The distinct alternatives, in the order found.
    exhaustive : bool
        False when the bound stopped the enumeration (then more alternatives may exist).
    explored : int
        Search nodes visited.
    """

    items: tuple[Alternative, ...]
    exhaustive: bool
    explored: int

    def pairs(self) -> list[tuple[str, tuple[str, ...]]]:
        """The distinct ``(robot, word)`` pairs with a non-empty word: what must be costed."""
        seen: dict[tuple[str, tuple[str, ...]], None] = {}
        for alt in self.items:
            for robot, word in alt.words.items():
                if word:
                    seen.setdefault((robot, word))
        return list(seen)


def alternatives(mission: GlobalMission, *, max_nodes: int = 200_000) -> Alternatives:
    """The distinct tuples of robots' words by which the team can complete `mission`.

    Parameters
    ----------
    mission : GlobalMission
        :math:`K`; its :attr:`~GlobalMission.complete` factors are walked.
    max_nodes : int
        Bound on the search nodes (``exhaustive`` false when reached).

    Returns
    -------
    Alternatives

    Examples
    --------
    >>> from cosmop.automata import DFA
    >>> k = DFA.from_transitions("a", [("a", "pick(R1,O1)", "b"), ("a", "pick(R2,O1)", "b")],
    ...                          marked=["b"])
    >>> [alt.label() for alt in alternatives(GlobalMission.from_dfa(k)).items]
    ['R1: pick(R1,O1); R2: (nothing)', 'R1: (nothing); R2: pick(R2,O1)']
    """
    factors = mission.complete.components
    robots = mission.robots
    names = sorted(mission.complete.alphabet)
    columns = [f.event_index() for f in factors]
    owners = [tuple(n for n, r in enumerate(robots) if r in mission.events[e].owners) for e in names]
    start = tuple(f.initial for f in factors)
    empty = tuple(() for _ in robots)
    longest = math.prod(f.n_states for f in factors) - 1
    found: dict[tuple, None] = {}
    seen = {(start, empty)}
    stack = [(start, empty, 0, iter(range(len(names))))]
    nodes = 1
    if all(f.marked[q] for f, q in zip(factors, start, strict=True)):
        found[empty] = None
    while stack:
        state, words, length, todo = stack[-1]
        nxt = next(todo, None) if length < longest else None
        if nxt is None:
            stack.pop()
            continue
        target = _step(factors, columns, state, names[nxt])
        if target is None:
            continue
        grown = tuple((*w, names[nxt]) if n in owners[nxt] else w for n, w in enumerate(words))
        if (target, grown) in seen:
            continue
        if nodes >= max_nodes:
            return Alternatives(_items(found, robots), False, nodes)
        nodes += 1
        seen.add((target, grown))
        if all(f.marked[q] for f, q in zip(factors, target, strict=True)):
            found.setdefault(grown)
        stack.append((target, grown, length + 1, iter(range(len(names)))))
    return Alternatives(_items(found, robots), True, nodes)


def _step(factors, columns, state: tuple, name: str) -> tuple | None:
    """The factors' states after `name`, or ``None`` where a factor forbids it."""
    out = list(state)
    for i, (factor, column) in enumerate(zip(factors, columns, strict=True)):
        j = column.get(name)
        if j is None:
            continue
        t = int(factor.delta[state[i], j])
        if t < 0:
            return None
        out[i] = t
    return tuple(out)


def _items(found: Mapping[tuple, None], robots: tuple[str, ...]) -> tuple[Alternative, ...]:
    return tuple(Alternative(dict(zip(robots, words, strict=True))) for words in found)


@dataclass(frozen=True)
class Choice:
    """Result of :func:`choose`.

    Attributes
    ----------
    alternative : Alternative or None
        The chosen one (``None`` when no alternative can be planned).
    makespan, total : int or None
        Its longest plan and the sum of its plans, in primitive steps.
    considered : int
        Alternatives compared.
    unplannable : Mapping[tuple, str]
        ``(robot, word)`` pairs without a plan, each with why.
    """

    alternative: Alternative | None
    makespan: int | None
    total: int | None
    considered: int
    unplannable: Mapping[tuple[str, tuple[str, ...]], str] = field(default_factory=dict)


def choose(
    found: Alternatives,
    cost: Callable[[Alternative, str], int | None],
    why: Callable[[Alternative, str], str] | None = None,
) -> Choice:
    """The alternative of least makespan, then least total plan length (exact over `found`).

    Parameters
    ----------
    found : Alternatives
    cost : callable
        ``cost(alternative, robot)``: the robot's shortest plan for its word in that alternative
        (in primitive steps), or ``None`` when it has none.  An empty word costs 0 and is never
        asked.  (The alternative matters beyond the word: which objects the others move.)
    why : callable, optional
        ``why(alternative, robot)``: why a word without a plan has none (kept in
        ``unplannable``).

    Returns
    -------
    Choice
        Ties go to the alternative found first.
    """
    best, key, unplannable = None, None, {}
    for alt in found.items:
        costs = []
        for robot, word in alt.words.items():
            c = cost(alt, robot) if word else 0
            if c is None:
                unplannable[(robot, word)] = why(alt, robot) if why is not None else "no plan"
                break
            costs.append(c)
        else:
            k = (max(costs, default=0), sum(costs))
            if key is None or k < key:
                best, key = alt, k
    return Choice(
        best,
        key[0] if key else None,
        key[1] if key else None,
        len(found.items),
        MappingProxyType(unplannable),
    )
