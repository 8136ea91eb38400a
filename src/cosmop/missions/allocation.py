"""Allocation: commit the team to one way of completing a mission that offers choices.

A global mission :math:`K` may leave choices open: *either* R1 or R2 moves O1, O1 goes to W1
*or* to W2.  Every complete run :math:`s` of the team then realises one *alternative*, the
tuple of the robots' words :math:`(P_1(s), \\dots, P_n(s))` (natural projection onto each
robot's events).  Committing the team to an alternative gives every robot one sequence of
events, which the bottom-up layer plans; the order between robots that :math:`K` requires is
then kept by messages (:func:`cosmop.missions.ordering.order_words`).  The alternative's own
words interleave into the complete word :math:`s`, so that ordering always succeeds, and the
sub-language the team then runs is contained in :math:`K`: the allocation is sound by
construction, and :func:`cosmop.team.mission_proof.check_words` re-proves it on the final plans.

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

A robot's choice that concerns no one else (O2 to W2 *or* W3, the other robots' words the
same either way) needs no word-by-word costing: :func:`own_choices` groups a robot's words by
the others' words, and the bottom-up layer plans each group once over the automaton of its
words (a branching local mission), which yields the group's cheapest word; the others are
dropped.  That keeps the choice exact: for an alternative :math:`(w, s)`, with :math:`s` the
others' words, :math:`(w^*, s)` is an alternative too, the robot's cost for :math:`w^*` is no
larger and the others' are the same (:math:`w^*` picks the same objects, so the others may ask
for the same ones): neither the makespan nor the total grows.  Done robot after robot, each
step keeps an optimal alternative.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType

from cosmop.automata import DFA
from cosmop.missions.mission import GlobalMission

__all__ = [
    "Alternative",
    "Alternatives",
    "Assignment",
    "Choice",
    "alternatives",
    "assign",
    "choose",
    "others",
    "own_choices",
]


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
        """The robot that picks each object up, by object (what ``plan.json`` records).

        Parameters
        ----------
        mission : GlobalMission
            The mission whose events the words name.
        """
        out: dict[str, str] = {}
        for robot, word in self.words.items():
            for name in word:
                event = mission.events[name]
                if event.kind == "pick" and event.robot == robot:
                    assert event.obj is not None  # a pick names its object
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
    assert mission.complete is not None  # set on construction
    factors = mission.complete.components
    robots = mission.robots
    names = sorted(mission.complete.alphabet)
    columns = [f.event_index() for f in factors]
    owners = [tuple(n for n, r in enumerate(robots) if r in mission.events[e].owners) for e in names]
    start = tuple(f.initial for f in factors)
    empty: Words = tuple(() for _ in robots)
    longest = math.prod(f.n_states for f in factors) - 1
    found: dict[Words, None] = {}
    seen = {(start, empty)}
    stack: list[tuple[tuple[int, ...], Words, int, Iterator[int]]] = [
        (start, empty, 0, iter(range(len(names))))
    ]
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


Words = tuple[tuple[str, ...], ...]
"""Several words of one robot, or every other robot's word in team order."""


def own_choices(found: Alternatives, robot: str, mission: GlobalMission) -> dict[Words, Words]:
    """The choices `robot` makes alone: its words that go with the same words of the others.

    The alternatives are grouped by the others' words (:func:`others`); a group in which
    `robot` has several words, each picking the same objects and none holding a message
    (messages are placed on one word, after the choice), is a choice that concerns no one
    else.  Only an `exhaustive` enumeration is split this way.

    Parameters
    ----------
    found : Alternatives
        The alternatives of the mission.
    robot : str
        The robot whose choices are sought.
    mission : GlobalMission
        The mission whose events the words name.

    Returns
    -------
    dict
        The others' words (:func:`others`) to the robot's words among which it may choose.

    Examples
    --------
    >>> from cosmop.automata import DFA
    >>> k = GlobalMission.from_dfa(DFA.from_transitions(
    ...     "a", [("a", "pick(R1,O1)", "b"), ("b", "drop(R1,O1,W1)", "c"), ("b", "drop(R1,O1,W2)", "c")],
    ...     marked=["c"]))
    >>> list(own_choices(alternatives(k), "R1", k).values())
    [(('pick(R1,O1)', 'drop(R1,O1,W1)'), ('pick(R1,O1)', 'drop(R1,O1,W2)'))]
    """
    if not found.exhaustive:
        return {}
    groups: dict[Words, list[tuple[str, ...]]] = {}
    for alt in found.items:
        groups.setdefault(others(alt, robot), []).append(alt.words[robot])
    out: dict[Words, Words] = {}
    for rest, words in groups.items():
        events = [[mission.events[e] for e in w] for w in words]
        picks = {frozenset(e.obj for e in w if e.kind == "pick") for w in events}
        if len(words) > 1 and len(picks) == 1 and not any(e.is_message for w in events for e in w):
            out[rest] = tuple(words)
    return out


def others(alt: Alternative, robot: str) -> Words:
    """The words of every robot but `robot` in `alt`, in team order.

    Parameters
    ----------
    alt : Alternative
        An alternative of the team.
    robot : str
        The robot left out.
    """
    return tuple(w for r, w in alt.words.items() if r != robot)


def _step(
    factors: Sequence[DFA], columns: Sequence[Mapping[str, int]], state: tuple[int, ...], name: str
) -> tuple[int, ...] | None:
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


def _items(found: Mapping[Words, None], robots: tuple[str, ...]) -> tuple[Alternative, ...]:
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
        Alternatives compared (search nodes, for deliveries).
    unplannable : Mapping[tuple, str]
        ``(robot, word)`` pairs without a plan, each with why.
    exhaustive : bool
        Whether the choice is proved the best (else: the best found within a bound).
    method : str
        How the choice was made, in words.
    costs : Mapping[tuple, int or None]
        The costs the choice was made from: by ``(robot, object, workspace)`` for deliveries,
        by ``(robot, word)`` otherwise (``None``: no plan).
    """

    alternative: Alternative | None
    makespan: int | None
    total: int | None
    considered: int
    unplannable: Mapping[tuple[str, tuple[str, ...]], str] = field(default_factory=dict)
    exhaustive: bool = True
    method: str = "every alternative costed by the robots' shortest plans"
    costs: Mapping[tuple[str, str, str], int | None] | Mapping[tuple[str, tuple[str, ...]], int | None] = (
        field(default_factory=dict)
    )


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
    best: Alternative | None = None
    key: tuple[int, int] | None = None
    unplannable: dict[tuple[str, tuple[str, ...]], str] = {}
    table: dict[tuple[str, tuple[str, ...]], int | None] = {}
    for alt in found.items:
        costs = []
        for robot, word in alt.words.items():
            c = cost(alt, robot) if word else 0
            table.setdefault((robot, word), c)
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
        found.exhaustive,
        costs=MappingProxyType(table),
    )


# ----------------------------------------------------------------------------------------------
# Deliveries: which robot moves each object, and to which of its workspaces
# ----------------------------------------------------------------------------------------------

Option = tuple[str, str]
"""``(robot, workspace)``: one way to deliver an object."""


@dataclass(frozen=True)
class Assignment:
    """Result of :func:`assign`.

    Attributes
    ----------
    tasks : Mapping[str, Option]
        The chosen ``(robot, workspace)`` by object (empty when some object has no option).
    makespan, total : int or None
        The largest robot load and the sum of the loads (load: the sum of the robot's costs).
    exhaustive : bool
        Whether the search proved the choice optimal (else: best found within the bound).
    nodes : int
        Search nodes visited.
    stuck : tuple of str
        Objects without any option that has a cost (then nothing is chosen).
    """

    tasks: Mapping[str, Option]
    makespan: int | None
    total: int | None
    exhaustive: bool
    nodes: int
    stuck: tuple[str, ...] = ()

    def loads(self, costs: Mapping[tuple[str, str, str], int | None]) -> dict[str, int]:
        """Each robot's load under `costs` (robots with nothing to do left out).

        Parameters
        ----------
        costs : mapping of (str, str, str) to int or None
            :math:`c(r, o, w)` by ``(robot, object, workspace)``, as given to :func:`assign`.
        """
        out: dict[str, int] = {}
        for obj, (robot, ws) in self.tasks.items():
            cost = costs[(robot, obj, ws)]
            assert cost is not None  # a chosen option has a cost
            out[robot] = out.get(robot, 0) + cost
        return out


def assign(
    options: Mapping[str, Sequence[Option]],
    costs: Mapping[tuple[str, str, str], int | None],
    *,
    seconds: Mapping[tuple[str, str, str], float] | None = None,
    max_nodes: int = 200_000,
) -> Assignment:
    """Give each object one robot and workspace, least makespan first, then least total.

    A robot's load is the sum of :math:`c(r, o, w)` over the objects it delivers, where
    :math:`c` is the cost of delivering that object alone (the robot's shortest plan from home
    for it, in primitive steps; ``None``: it cannot).  The makespan is the largest load.

    Depth-first branch and bound over the objects, the most expensive first, each object's
    options cheapest first, starting from the greedy assignment (each object, in that order,
    where it raises (makespan, total) least) and pruning every branch that cannot beat the best
    found (bounds: the loads so far, each object left at its cheapest, shared at best evenly).
    Exact when it ends within `max_nodes` (``exhaustive``); otherwise the best found.

    Parameters
    ----------
    options : Mapping[str, sequence of Option]
        The allowed ``(robot, workspace)`` by object.
    costs : Mapping[tuple, int or None]
        :math:`c(r, o, w)` by ``(robot, object, workspace)``.
    seconds : Mapping[tuple, float], optional
        The expected duration of each delivery alone: among options of equal cost the faster
        is tried first, so that of assignments equally good the first found moves less.
    max_nodes : int

    Examples
    --------
    >>> c = {("R1", "O1", "W"): 4, ("R2", "O1", "W"): 5, ("R1", "O2", "W"): 4, ("R2", "O2", "W"): 6}
    >>> a = assign({"O1": [("R1", "W"), ("R2", "W")], "O2": [("R1", "W"), ("R2", "W")]}, c)
    >>> dict(a.tasks), a.makespan, a.total
    ({'O1': ('R2', 'W'), 'O2': ('R1', 'W')}, 5, 9)
    """
    seconds = seconds or {}
    usable = {o: _ranked(o, opts, costs, seconds) for o, opts in options.items()}
    stuck = tuple(o for o, opts in usable.items() if not opts)
    if stuck:
        return Assignment(MappingProxyType({}), None, None, True, 0, stuck)
    order = sorted(usable, key=lambda o: (-usable[o][0][0], o))
    found = _branch_and_bound(order, usable, max_nodes)
    (span, total), picks = found.best
    tasks = MappingProxyType(dict(sorted(zip(order, picks, strict=True))))
    return Assignment(tasks, span, total, found.exhaustive, found.nodes)


def _ranked(
    obj: str,
    opts: Sequence[Option],
    costs: Mapping[tuple[str, str, str], int | None],
    seconds: Mapping[tuple[str, str, str], float],
) -> list[tuple[int, str, str]]:
    """`obj`'s options that have a cost, as ``(cost, robot, workspace)``, cheapest then fastest first."""
    keyed = [
        (c, seconds.get((r, obj, w), 0.0), r, w) for r, w in opts if (c := costs.get((r, obj, w))) is not None
    ]
    return [(c, r, w) for c, _, r, w in sorted(keyed)]


@dataclass(frozen=True)
class _Search:
    """Result of :func:`_branch_and_bound`.

    Attributes
    ----------
    best : tuple
        ``((makespan, total), picks)``: the best assignment found, one ``(robot, workspace)``
        per object in search order.
    nodes : int
        Search nodes visited.
    exhaustive : bool
        Whether the search ended within its node bound (then ``best`` is optimal).
    """

    best: tuple[tuple[int, int], list[Option]]
    nodes: int
    exhaustive: bool


def _branch_and_bound(
    order: Sequence[str], usable: Mapping[str, list[tuple[int, str, str]]], max_nodes: int
) -> _Search:
    """Depth-first branch and bound over the objects in `order`, from the greedy assignment.

    Each object's options are tried in their rank order (`usable`); a branch is cut when its
    bound (the loads so far, each object left at its cheapest, shared at best evenly) cannot
    beat the best found.  Of equally good assignments the first found is kept.
    """
    floor = [0] * (len(order) + 1)  # the least total the objects from i on still add
    for i in range(len(order) - 1, -1, -1):
        floor[i] = floor[i + 1] + usable[order[i]][0][0]
    best = _greedy(order, usable)
    team = len({r for opts in usable.values() for _, r, _ in opts})
    loads: dict[str, int] = {}
    chosen: list[Option] = []
    nodes, exhaustive = 0, True

    def visit(i: int, total: int) -> None:
        nonlocal best, nodes, exhaustive
        if i == len(order):
            key = (max(loads.values(), default=0), total)
            if key < best[0]:  # strictly better: of equals, the first found stays
                best = (key, list(chosen))
            return
        span_so_far = max(loads.values(), default=0)
        for c, r, w in usable[order[i]]:
            if nodes >= max_nodes:
                exhaustive = False
                return
            nodes += 1
            load = loads.get(r, 0) + c
            # (span, total) only grow from here, and the busiest robot carries at least an even
            # share of the least total: a branch that cannot beat the best is cut
            least = total + c + floor[i + 1]
            if (max(span_so_far, load, -(-least // team)), least) >= best[0]:
                continue
            loads[r] = load
            chosen.append((r, w))
            visit(i + 1, total + c)
            chosen.pop()
            loads[r] = load - c

    visit(0, 0)
    return _Search(best, nodes, exhaustive)


def _greedy(
    order: Sequence[str], usable: Mapping[str, list[tuple[int, str, str]]]
) -> tuple[tuple[int, int], list[Option]]:
    """Each object in turn where it raises the makespan least: the first bound.

    The options are ranked (cost, seconds), so of options that raise it equally the cheapest
    and then the fastest is taken.
    """
    loads: dict[str, int] = {}
    picks, total = [], 0
    for o in order:
        span = max(loads.values(), default=0)
        rank = min(
            range(len(usable[o])),
            key=lambda n: (max(span, loads.get(usable[o][n][1], 0) + usable[o][n][0]), n),
        )
        c, r, w = usable[o][rank]
        loads[r] = loads.get(r, 0) + c
        total += c
        picks.append((r, w))
    return (max(loads.values(), default=0), total), picks
