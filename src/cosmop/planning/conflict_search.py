"""The search that orders conflicts between plans and proves its own dead ends.

:class:`Search` chooses one start edge per conflict (:mod:`cosmop.planning.conflict_order`) so
that the team's order stays acyclic: unit propagation of the orders that are forced, choices
that follow the robots' priorities, and conflict-directed backjumping.  Each dead end comes
with the set of conflicts it follows from (:func:`_core`); one that follows from no choice is a
*core*, a set of conflicts no order resolves together, found without a solver.  Of each core
one conflict is set aside for re-planning (:class:`Culprits`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from shapely.geometry.base import BaseGeometry

from cosmop.missions.precedence import Node, Precedence
from cosmop.planning.conflicts import Conflict, Occupancy, detours, replan_rank

__all__ = ["Culprits", "Search", "backjump", "both_ways", "depth_first", "way_table", "ways_of"]


class Search:
    """Order conflicts, setting aside what no order resolves, and give conflicts back later.

    A search over the two ways of each conflict with unit propagation and conflict-directed
    backjumping (Prosser's CBJ, here over start edges and cycles), which proves its dead ends:

    * a conflict with a single way left takes it (*forced*); its reason is the cycle its other
      way would close (:func:`_core` follows it when needed);
    * otherwise the open conflict expected to start first is *chosen* a way (:func:`_options`:
      the robot of higher priority first, then the lower makespan);
    * a conflict with no way left gives a dead end and its set of conflicts (:func:`_core`):
      with the choices among them kept, no order of them is acyclic.  The search jumps back to
      the latest of those choices and takes its other way, forced now by that set.  A dead end
      with no choice in it is a *core*: no order resolves it at all.  One of its conflicts is
      set aside (:class:`Culprits`), and what depends on that conflict is taken back.

    Why a set is a core: follow the conflicts in the order they were taken.  A forced one that
    takes its other way closes the cycle of its reason, if everything taken before it on that
    cycle kept its way; a conflict forced by a dead end's set closes a cycle of that set if it
    takes the way that failed; so in an acyclic order every member keeps its way, and then the
    stuck conflict has none.  Both ways of a choice failing makes the union of their two sets
    a set with one choice fewer, so the cores found at the top are cores outright.

    A conflict that another one in `found` implies is left to it while that one is not set
    aside (`implied.among(found)` gives the pairs, stronger and weaker, as indices into `found`:
    :class:`cosmop.planning.conflict_order._Implied`).  The search keeps its state between
    questions: a conflict given back (:meth:`give_back`) is searched on from the order as it is.
    """

    def __init__(self, found: Sequence[Conflict], implied, team, culprits: Culprits) -> None:
        horizons, links, starts, durations = team
        self.found, self.culprits = found, culprits
        self.number = {id(c): i for i, c in enumerate(found)}
        self.precedence = Precedence(horizons, links, starts, durations)
        self.sides = _Sides(found, self.precedence)
        self.graph = _Graph(horizons, links, starts)
        self.stronger, self.weaker = implied.among(found)
        # (conflict, edge, undo log, reason): None for a choice, True when forced by its cycle,
        # or the set of a dead end when forced by it
        self.trail: list[tuple[int, tuple[Node, Node], list, object]] = []
        self.at: dict[int, int] = {}  # conflict -> its place in the trail
        self.aside = np.zeros(len(found), dtype=bool)
        self.hidden = np.zeros(len(found), dtype=bool)
        self.every = self.live = np.arange(len(found))  # the conflicts not known to be ordered yet
        self._hide()
        self.priority = _priorities(horizons, durations)
        self.cores: dict[int, list[Conflict]] = {}  # id of each conflict set aside -> its core

    @property
    def edges(self) -> list[tuple[tuple[Node, Node], Conflict]]:
        """The start edges taken, each with the conflict it orders."""
        return [(edge, self.found[i]) for i, edge, _, _ in self.trail]

    @property
    def set_aside(self) -> list[Conflict]:
        """The conflicts set aside, each with its core in :attr:`cores`."""
        return [self.found[i] for i in np.flatnonzero(self.aside)]

    def is_aside(self, conflict: Conflict) -> bool:
        return bool(self.aside[self.number[id(conflict)]])

    def run(self, budget: int, back: int | None = None) -> bool | None:
        """Order every conflict left: ``True`` when done, ``None`` past `budget` dead ends.

        With `back` (a conflict given back), a core sets aside `back` itself (every core found
        contains it, the others being ordered): then ``False`` once the rest is ordered again.
        """
        dead_ends, kept = 0, True
        while True:
            # a side that holds keeps holding until something is taken back (_pop)
            held = self.sides.holds(self.precedence, self.live)
            live = self.live = self.live[~(held[:, 0] | held[:, 1])]
            open_ = ~self.aside[live] & ~self.hidden[live]
            ways = self.sides.ways(self.precedence, live)
            counts = np.where(open_, ways[:, 0].astype(np.int64) + ways[:, 1], -1)
            stuck = live[counts == 0]
            if len(stuck):
                verdict = self._dead_ends(stuck.tolist(), back)
                if verdict == "choice":
                    dead_ends += 1
                    if dead_ends > budget:
                        return None
                kept &= verdict != "back"
                continue
            at = np.flatnonzero(counts == 1)
            side = dict(zip(live[at].tolist(), ways[at, 1].tolist(), strict=True))  # the way left
            # the hardest to re-plan first: the likely culprits come last, the least to take back
            order = sorted(side, key=lambda i: -self.culprits.rank(self.found[i]))
            self._take_forced([(i, self.sides.edges[i][int(side[i])]) for i in order])
            if len(at):
                continue
            pool = live[open_]
            if not len(pool):
                return kept
            i = int(pool[np.argmin(self.sides.expected_start(self.precedence, pool))])
            self._take(i, _options(self.found[i], self.precedence, self.priority)[0], None)

    def _dead_ends(self, stuck: list[int], back: int | None) -> str:
        """Settle this round's dead ends: ``"choice"`` when the first follows from a choice (the
        search jumps back), ``"back"`` when a core sets aside `back`, else ``"core"``.

        The cores of all conflicts stuck at once are found before anything is taken back, and
        one conflict of each is set aside (a core that holds one set aside already waits for the
        next round); then the order is taken back once, to the earliest place any of them needs.
        """
        places = []
        for s in stuck:
            core = _core(s, self.sides, self.graph, self.trail, self.at)
            if self.aside[list(core)].any():
                continue  # it held a conflict set aside in this round: asked again next round
            choices = [self.at[i] for i in core if i in self.at and self.trail[self.at[i]][3] is None]
            if choices and places:
                break  # the set-asides first; if it is still a dead end, it comes back
            if choices:
                i, edge = self.trail[max(choices)][:2]
                self._back_to(max(choices))
                other = next(e for e in self.sides.edges[i] if e is not None and e != edge)
                self._take(i, other, frozenset(core))
                return "choice"
            if back is not None:
                places.append(self._put_aside(back, core))
                break
            # on a tie, the one taken last (the least to take back): not taken yet, then the latest
            members = sorted(core, key=lambda i: -self.at.get(i, len(self.trail)))
            picked = self.culprits.pick([self.found[i] for i in members])
            places.append(self._put_aside(next(i for i in members if self.found[i] is picked), core))
        if not places:  # every core held a conflict set aside before this round: a stale reason
            raise AssertionError(f"dead ends {stuck} with nothing to set aside or take back")
        self._hide()  # what they implied is no longer ordered by them
        self._back_to(min(places))
        return "core" if back is None else "back"

    def give_back(self, conflict: Conflict, budget: int) -> bool | None:
        """Search on with `conflict` no longer set aside: ``True`` when it is ordered with the
        rest, ``False`` when a core keeps it aside (:attr:`cores` has the new one), ``None``
        past `budget` dead ends."""
        i = self.number[id(conflict)]
        self.aside[i] = False
        self._hide()
        return self.run(budget, back=i)

    def _put_aside(self, i: int, core: set[int]) -> int:
        """Set conflict `i` aside with its `core`; the place in the trail from which to take
        back what it forced, and the ways forced by dead ends it was in."""
        self.aside[i] = True
        self.cores[id(self.found[i])] = [self.found[k] for k in sorted(core)]
        places = [p for p, entry in enumerate(self.trail) if entry[0] == i or _in(i, entry[3])]
        return min(places, default=len(self.trail))

    def _hide(self) -> None:
        self.hidden[:] = False
        self.hidden[self.weaker[~self.aside[self.stronger]]] = True

    def _take(self, i: int, edge, reason, log=None) -> None:
        self.at[i] = len(self.trail)
        self.trail.append((i, edge, self.precedence.add_start(edge) if log is None else log, reason))
        self.graph.push(edge, i)

    def _take_forced(self, forced: list[tuple[int, tuple[Node, Node]]]) -> None:
        """Take the forced ways, in order, each unless the ones before it close its cycle (it
        is then stuck, and seen so next round): in one pass
        (:meth:`~cosmop.missions.precedence.Precedence.add_starts`), taken back as one."""
        if not forced:
            return
        log, refused = self.precedence.add_starts([edge for _, edge in forced])
        stuck = set(refused)
        taken = [way for n, way in enumerate(forced) if n not in stuck]
        batch = _Batch(len(self.trail), len(taken), log)
        for i, edge in taken:
            self._take(i, edge, True, batch)

    def _back_to(self, place: int) -> None:
        """Take back the trail from `place` on.  A batch of forced ways that `place` falls
        inside is taken back whole, and its part before `place` taken again."""
        while len(self.trail) > place:
            self._pop()
        top = self.trail[-1][2] if self.trail else None
        if isinstance(top, _Batch) and top.start + top.size > place:
            kept = [(i, edge) for i, edge, _, _ in self.trail[top.start :]]
            while len(self.trail) > top.start:
                self._pop()
            self._take_forced(kept)

    def _pop(self) -> None:
        i, _, log, _ = self.trail.pop()
        self.live = self.every  # what held may not now
        if not isinstance(log, _Batch):
            self.precedence.undo(log)
        elif log.start == len(self.trail):  # a batch is taken back with its first entry
            self.precedence.undo(log.log)
        self.graph.pop()
        del self.at[i]


@dataclass(frozen=True)
class _Batch:
    """The entries ``start .. start + size - 1`` of the trail, added in one pass with `log`."""

    start: int
    size: int
    log: list


def backjump(found, implied, team, culprits, budget: int):
    """:class:`Search` run once: ``(edges, set aside, cores)``, ``edges`` ``None`` past `budget`."""
    search = Search(found, implied, team, culprits)
    done = search.run(budget)
    return (search.edges if done else None), search.set_aside, search.cores


def _in(i: int, reason) -> bool:
    return isinstance(reason, frozenset) and i in reason


def _core(stuck: int, sides: _Sides, graph: _Graph, trail: list, at: Mapping[int, int]) -> set[int]:
    """`stuck` and every conflict its dead end follows from (:class:`Search`): the conflicts on
    the cycles that close its ways, and, for each of those forced, on the cycle its other way
    closes (or the dead end's set that forced it), back to the choices and the base order."""

    def cycle(edge, before: int) -> list[int]:
        path = graph.path(*edge, before=before)
        if path is None:  # the clocks said the edge closes a cycle
            raise AssertionError(f"no cycle through {edge}: the clocks and the graph disagree")
        return path

    core, traced, todo = {stuck}, {stuck}, []
    for edge in sides.edges[stuck]:
        if edge is not None:
            todo += cycle(edge, len(trail))
    while todo:
        i = todo.pop()
        core.add(i)
        if i in traced or i not in at:  # (a member of a dead end's set need not be taken now)
            continue
        traced.add(i)
        _, chosen, _, reason = trail[at[i]]
        if isinstance(reason, frozenset):
            core |= reason
        elif reason is True:
            for edge in sides.edges[i]:
                if edge is not None and edge != chosen:
                    todo += cycle(edge, at[i])
    return core


class Culprits:
    """Which conflict of a core to set aside (its robot is re-planned around the other side).

    The most re-plannable (:func:`~cosmop.planning.conflicts.replan_rank`); of those, one whose
    robot is already re-planned this round: one more space to keep clear of costs a robot that
    is re-planned anyway little, and a robot not re-planned yet a whole synthesis.  On a tie,
    the first in the core as given.
    """

    def __init__(self, fixed: Mapping[str, Sequence[BaseGeometry]] | None) -> None:
        self.fixed = fixed or {}
        self.movers: set[str] = set()  # the robots of the conflicts set aside so far
        self._rank: dict[int, int] = {}
        self._mover: dict[int, str | None] = {}

    def rank(self, conflict: Conflict) -> int:
        if id(conflict) not in self._rank:
            self._rank[id(conflict)] = replan_rank(conflict, self.fixed)
        return self._rank[id(conflict)]

    def mover(self, conflict: Conflict) -> str | None:
        """The robot re-planned around `conflict` (its best detour), if any."""
        if id(conflict) not in self._mover:
            self._mover[id(conflict)] = next((robot for robot, _ in detours(conflict, self.fixed)), None)
        return self._mover[id(conflict)]

    def pick(self, core: Sequence[Conflict], keep: bool = True) -> Conflict:
        """The culprit of `core`; with `keep`, its robot counts as re-planned from now on."""
        n = {id(c): k for k, c in enumerate(core)}
        worst = min(core, key=lambda c: (self.rank(c), self.mover(c) not in self.movers, n[id(c)]))
        if keep:
            self.movers.add(self.mover(worst))
        return worst


class _Graph:
    """Which step completes before which: program order, messages and given start edges, and
    start edges pushed (and popped) in order, each labelled with what it orders."""

    def __init__(self, horizons, links, starts) -> None:
        self.succ: dict[Node, list[tuple[Node, object, int]]] = {}  # node -> (next, label, place)
        for robot, k in horizons.items():
            for i in range(1, k):
                self._add((robot, i), (robot, i + 1), None, -1)
        for link in links:
            if link.send is not None and link.wait is not None:
                self._add((link.sender, link.send), (link.receiver, link.wait), None, -1)
        for source, target in starts:
            self._add(source, target, None, -1)
        self.pushed: list[tuple[Node, Node, object]] = []

    def _add(self, source: Node, target: Node, label, place: int) -> None:
        self.succ.setdefault(source, []).append((target, label, place))

    def push(self, edge: tuple[Node, Node], label) -> None:
        self.pushed.append((*edge, label))
        self._add(edge[0], edge[1], label, len(self.pushed) - 1)

    def pop(self) -> None:
        source, _, _ = self.pushed.pop()
        self.succ[source].pop()

    def path(self, source: Node, target: Node, before: int | None = None) -> list | None:
        """The labels on a shortest path from `target` to `source` -- the cycle the start edge
        ``source -> target`` would close -- through the edges pushed before place `before`
        (default: all); ``None`` if there is none."""
        before = len(self.pushed) if before is None else before
        parent: dict[Node, tuple[Node, object] | None] = {target: None}
        queue = [target]
        for node in queue:
            if node == source:
                break
            for nxt, label, place in self.succ.get(node, ()):
                if place < before and nxt not in parent:
                    parent[nxt] = (node, label)
                    queue.append(nxt)
        if source not in parent:
            return None
        out, node = [], source
        while parent[node] is not None:
            node, label = parent[node]
            if label is not None:
                out.append(label)
        return out


class _Sides:
    """Both ways of ordering every conflict, as arrays, to ask many questions at once.

    Side 0 puts occupancy ``a`` first, side 1 ``b``: "x before y" is the start edge from
    x's last step to y's first.  A side is *possible* when x ends and y does not start at the
    beginning; it *holds* when the order already implies it; it *closes a cycle* when y's first
    step must already complete before x's last one does.
    """

    def __init__(self, found: Sequence[Conflict], precedence: Precedence) -> None:
        self.edges = [both_ways(c) for c in found]  # each side as a start edge, or None
        offset = np.array([precedence.offsets[r] for r in precedence.robots], dtype=np.int64)
        end = np.array([precedence.horizons[r] + 1 for r in precedence.robots], dtype=np.int64)

        def row(robot: np.ndarray, k: np.ndarray) -> np.ndarray:  # instants clamped to 0..K+1
            return offset[robot] + np.clip(k, 0, end[robot])

        # where each occupancy's expected start is read (0 when it holds from the beginning)
        column = precedence.column
        firsts = [(column[x.first[0]], x.first[1]) if x.first else (0, 0) for c in found for x in (c.a, c.b)]
        first = np.array(firsts, dtype=np.int64).reshape(len(found), 2, 2)
        self.from_start = first[..., 1] < 1
        self.first_row = np.where(self.from_start, 0, row(first[..., 0], first[..., 1]))
        # each side's x last step and y first step: their instants and their rows (also their
        # bits in the order's sets of steps)
        possible, ends = way_table(self.edges, dict(column))
        x_k, y_k = ends[..., 1], ends[..., 3]
        x_row, y_row = row(ends[..., 0], x_k), row(ends[..., 2], y_k)
        same = ends[..., 0] == ends[..., 2]
        # a side within one robot's plan holds or closes a cycle by program order; else as the
        # order's sets say: x's last step completes before y's first starts (it holds), or y's
        # first completes before x's last does (it closes a cycle)
        self.fixed_hold = possible & np.where(same, x_k < y_k, x_k <= 0)
        self.fixed_way = possible & same & (y_k > x_k)
        self.by_order = possible & ~same
        self.hold_at = precedence.places(x_row, y_row)
        self.cycle_at = precedence.places(y_row, x_row)

    def holds(self, precedence: Precedence, rows: np.ndarray | None = None) -> np.ndarray:
        """(n, 2): whether each side (of the conflicts `rows`, default all) is already implied."""
        rows = slice(None) if rows is None else rows
        at, shift = self.hold_at[0][rows], self.hold_at[1][rows]
        implied = precedence.completes_before(at, shift, start=True)
        return self.fixed_hold[rows] | (self.by_order[rows] & implied)

    def expected_start(self, precedence: Precedence, rows: np.ndarray) -> np.ndarray:
        """The expected start of the earlier occupancy of each conflict in `rows`, s."""
        started = np.where(self.from_start[rows], 0.0, precedence.started_flat[self.first_row[rows]])
        return started.min(axis=1)

    def ways(self, precedence: Precedence, rows: np.ndarray | None = None) -> np.ndarray:
        """(n, 2): whether each side (of the conflicts `rows`, default all) can still be added
        without closing a cycle."""
        rows = slice(None) if rows is None else rows
        at, shift = self.cycle_at[0][rows], self.cycle_at[1][rows]
        return self.fixed_way[rows] | (self.by_order[rows] & ~precedence.completes_before(at, shift))


def way_table(ways: Sequence[list], number: dict[str, int]) -> tuple[np.ndarray, np.ndarray]:
    """Every conflict's two ways (:func:`both_ways`) as arrays: whether each exists ``(n, 2)``,
    and each as ``(A, i, B, j)`` ``(n, 2, 4)``, the robots numbered by `number` (robots it
    lacks are added, numbered in the order they come)."""
    table = []
    for pair in ways:
        for way in pair:
            if way is None:
                table.append((0, 0, 0, 0))
            else:
                (a, i), (b, j) = way
                table.append((number.setdefault(a, len(number)), i, number.setdefault(b, len(number)), j))
    ends = np.array(table, dtype=np.int64).reshape(len(ways), 2, 4)
    possible = np.array([way is not None for pair in ways for way in pair], dtype=bool)
    return possible.reshape(len(ways), 2), ends


def both_ways(conflict: Conflict) -> list[tuple[Node, Node] | None]:
    """The conflict's two ways as start edges, ``a`` first then ``b`` first: "x before y" for x
    that ends and y that does not hold its place from the beginning (else ``None``)."""
    return [
        (x.last, y.first) if x.last is not None and y.first is not None and y.first[1] >= 1 else None
        for x, y in ((conflict.a, conflict.b), (conflict.b, conflict.a))
    ]


def ways_of(conflict: Conflict) -> list[tuple[Node, Node]]:
    """The start edges that can order `conflict` (its possible :func:`both_ways`)."""
    return [edge for edge in both_ways(conflict) if edge is not None]


def depth_first(found, horizons, links, starts, durations, max_backtracks, fixed):
    """Depth-first search for edges ordering every conflict; ``(edges, None)`` or ``([], culprit)``.

    At every point the open conflicts are checked forward: one that has no way left to be
    ordered (both ways close a cycle, or the way left never ends) sends the search back to the
    last choice.  A conflict with a single way left is ordered first; otherwise the one expected
    to start first, the way that keeps the team's expected makespan lower.  The culprit is the
    conflict without a way at the deepest dead end.  The order is updated incrementally and
    taken back on backtracking (:meth:`~cosmop.missions.precedence.Precedence.add_start`).
    """
    precedence = Precedence(horizons, links, starts, durations)
    sides = _Sides(found, precedence)
    priority = _priorities(horizons, durations)
    chosen: list[tuple[tuple[Node, Node], Conflict, list]] = []
    stack: list[tuple[int, list[tuple[Node, Node]], Conflict]] = []  # (depth, untried, conflict)
    backtracks, deepest, culprit = 0, -1, None
    while True:
        open_ = ~sides.holds(precedence).any(axis=1)
        if not open_.any():
            return [(edge, conflict) for edge, conflict, _ in chosen], None
        counts = np.where(open_, sides.ways(precedence).sum(axis=1), -1)
        stuck = [found[i] for i in np.flatnonzero(counts == 0)]
        if stuck:
            if len(chosen) > deepest:
                edges = [(e, c) for e, c, _ in chosen]
                worst = min(stuck, key=lambda c: replan_rank(c, fixed))
                deepest, culprit = len(chosen), _culprit(worst, horizons, links, starts, edges, fixed)
            if not stack or backtracks >= max_backtracks:
                return [], culprit
            backtracks += 1
            depth, untried, conflict = stack[-1]
            while len(chosen) > depth:
                precedence.undo(chosen.pop()[2])
            edge = untried.pop(0)
            chosen.append((edge, conflict, precedence.add_start(edge)))
            if not untried:
                stack.pop()
            continue
        pool = np.flatnonzero(counts == 1)
        if not len(pool):
            pool = np.flatnonzero(open_)
        conflict = found[pool[np.argmin(sides.expected_start(precedence, pool))]]
        options = _options(conflict, precedence, priority)
        if len(options) > 1:
            stack.append((len(chosen), options[1:], conflict))
        chosen.append((options[0], conflict, precedence.add_start(options[0])))


def _priorities(horizons, durations) -> dict[str, int]:
    """Each robot's priority (0 first): the robot expected to finish first goes first, so that it
    clears out early; one order for all robots keeps most choices consistent (no cycles)."""
    alone = {r: sum(durations[r]) for r in horizons}
    return {r: n for n, r in enumerate(sorted(horizons, key=lambda r: (alone[r], r)))}


def _options(conflict: Conflict, precedence: Precedence, priority: Mapping[str, int]) -> list:
    """The ways left to order `conflict`, best first: the robot of higher priority first, then
    (between two of the same robot) the lower expected makespan."""
    options = _ways(conflict, precedence)
    if len(options) > 1:
        options = sorted(options, key=lambda e: priority[e[0][0]])
        if len({priority[e[0][0]] for e in options}) < len(options):
            options = sorted(options, key=lambda e: (priority[e[0][0]], _makespan_with(precedence, e)))
    return options


def _start(x: Occupancy, precedence: Precedence) -> float:
    return 0.0 if x.first is None else precedence.start_time(x.first)


def _makespan_with(precedence: Precedence, edge: tuple[Node, Node]) -> float:
    log = precedence.add_start(edge)
    makespan = precedence.makespan
    precedence.undo(log)
    return makespan


def _culprit(stuck: Conflict, horizons, links, starts, chosen, fixed) -> Conflict:
    """The conflict to re-plan around when `stuck` has no way to be ordered.

    If `stuck` itself cannot be re-planned (two robots standing where their goods require), the
    orders that close its cycles came from other conflicts: the most re-plannable of those.
    """
    if replan_rank(stuck, fixed) < 3:
        return stuck
    graph = _Graph(horizons, links, starts)
    for edge, conflict in chosen:
        graph.push(edge, conflict)
    on_cycles: list[Conflict] = []
    for edge in ways_of(stuck):
        on_cycles += graph.path(*edge) or []
    best = min(on_cycles, key=lambda c: replan_rank(c, fixed), default=stuck)
    return best if replan_rank(best, fixed) < 3 else stuck


def _ways(conflict: Conflict, precedence: Precedence) -> list[tuple[Node, Node]]:
    """The start edges that can order `conflict`, the one expected to happen first first."""
    a, b = conflict.a, conflict.b
    options = sorted(((a, b), (b, a)), key=lambda xy: (_start(xy[0], precedence), _start(xy[1], precedence)))
    out = []
    for x, y in options:
        if x.last is None or y.first is None:
            continue  # x never ends, or y holds its place from the beginning
        if precedence.would_cycle(x.last, y.first):
            continue
        out.append((x.last, y.first))
    return out
