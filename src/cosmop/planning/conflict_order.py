"""Ordering conflicts: start edges that keep two plans out of each other's places, without deadlock.

A conflict (:mod:`cosmop.planning.conflicts`) is ordered by a *start edge*: one occupancy ends
before the other starts.  :func:`order_conflicts` chooses one edge per conflict so that the
team's order stays acyclic (no deadlock, :mod:`cosmop.missions.precedence`): the occupancy that
is expected to begin first (:mod:`cosmop.planning.timing`) goes first, unless that closes a
cycle or it never ends (a robot parked for good).  Conflicts no order can resolve together are
returned, irredundant, for re-planning.

Two conflicts between the same robots often say the same thing more strongly or more weakly
(:class:`_Implied`); only the strongest are searched and given to the solver.  The solver's
work grows much faster than the conflicts (a single check of 10,000 conflicts can take a
minute), so cores are first looked for by propagating forced orders, which needs none.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping, Sequence
from decimal import Decimal
from fractions import Fraction

import numpy as np
from shapely.geometry.base import BaseGeometry

from cosmop.missions.precedence import Link, Node, Precedence
from cosmop.planning.conflicts import Conflict, Occupancy, replan_rank

__all__ = ["order_conflicts"]


def order_conflicts(
    found: Sequence[Conflict],
    horizons: Mapping[str, int],
    links: Sequence[Link],
    starts: Sequence[tuple[Node, Node]],
    durations: Mapping[str, Sequence[float]],
    *,
    max_backtracks: int = 200,
    fixed: Mapping[str, Sequence[BaseGeometry]] | None = None,
    rlimit: int = 200_000_000,
) -> tuple[list[tuple[tuple[Node, Node], Conflict]], list[Conflict]]:
    """Start edges that order every conflict in `found`, and the conflicts no order resolves.

    Both the search and the solver see only the conflicts no other one implies
    (:class:`_Implied`): an order of those orders the rest.  Then, in turn, while a step fails:

    1. a depth-first search over the two ways of ordering each conflict (:func:`_search`), fast
       when the conflicts are few or loosely tied;
    2. unit propagation of the orders that are forced (:func:`_propagate`): where forced orders
       alone make a conflict unorderable, they give a *core* -- a set of conflicts no order
       resolves together -- without a solver, and the most re-plannable conflict of each core is
       set aside.  If the search then orders the rest, each conflict set aside is settled
       without a solver where it can be (:func:`_without_solver`), and that is the answer;
    3. the question settled exactly as a scheduling problem (:class:`_Schedule`, Z3 over the
       steps' start and end times): either a schedule orders every conflict left, or an unsat
       core names a set no order resolves together, of which the most re-plannable is set aside
       -- and the others are ordered again without it.  Z3's cores are not minimal, so a
       conflict set aside early may be orderable once later ones are gone: each is then given
       back, the hardest to re-plan first, while a schedule still exists (without a solver call
       when its own core is back in full: the core still proves it).

    The unresolved conflicts returned are therefore irredundant: none of them could be ordered
    together with all the ordered ones.

    Returns the edges added (on top of `starts`), each with the conflict it orders, and the
    unresolved conflicts.
    """
    implied = _Implied(found)
    needed = implied.left(set())
    chosen, culprit = _search(needed, horizons, links, starts, durations, max_backtracks, fixed)
    if culprit is None:
        return chosen, []
    unresolved, cores = _propagate(needed, horizons, links, starts, durations, fixed)
    gone = {id(c) for c in unresolved}
    if unresolved:
        team = (horizons, links, starts, durations)
        settled = _without_solver(found, implied, unresolved, cores, team, fixed, max_backtracks)
        if settled is not None:
            return settled
    schedule = _Schedule(found, horizons, links, starts, durations, rlimit, implied)
    while (core := schedule.solve(implied.left(gone))) is not None:
        if not core:  # undecided within the solver's budget: the search's culprit stays unresolved
            return _give_up(
                found, culprit, horizons, links, starts, durations, max_backtracks, fixed, implied
            )
        unresolved.append(min(core, key=lambda c: replan_rank(c, fixed)))
        gone.add(id(unresolved[-1]))
        cores[id(unresolved[-1])] = core
    # Cores are not minimal, so a conflict set aside early may be orderable once later ones are
    # gone: give each back, the hardest to re-plan first, while a schedule remains.  No solver
    # call when the last schedule already orders it, nor when its own core is all back (the
    # core still proves that no schedule orders it with the others).
    for conflict in sorted(unresolved, key=lambda c: -replan_rank(c, fixed)):
        gone.discard(id(conflict))
        if all(id(c) not in gone for c in cores[id(conflict)]) or (
            schedule.way(conflict) is None and schedule.solve(implied.left(gone)) is not None
        ):
            gone.add(id(conflict))
        else:
            unresolved.remove(conflict)
    # the search's choices keep the makespan low; the schedule stands in where the search fails
    left = implied.left(gone)
    better, culprit = _search(left, horizons, links, starts, durations, max_backtracks, fixed)
    return (schedule.edges(left) if culprit is not None else better), unresolved


def _without_solver(found, implied, unresolved, cores, team, fixed, max_backtracks: int):
    """Settle the conflicts propagation set aside without Z3, if the search orders the rest.

    A conflict whose core's other members are all ordered stays set aside (its core proves it).
    Any other is given back when the search orders it with the rest, or stays set aside when
    propagation then finds a core (which must contain it, the rest being ordered).  ``None``
    when the search fails or a conflict is undecided: then the solver is asked.
    """
    gone = {id(c) for c in unresolved}
    chosen, stuck = _search(implied.left(gone), *team, max_backtracks, fixed)
    if stuck is not None:
        return None
    for conflict in sorted(unresolved, key=lambda c: -replan_rank(c, fixed)):
        if all(id(c) not in gone for c in cores[id(conflict)] if c is not conflict):
            continue
        gone.discard(id(conflict))
        left = implied.left(gone)
        more, stuck = _search(left, *team, max_backtracks, fixed)
        if stuck is None:
            chosen = more  # given back
            continue
        aside, found_cores = _propagate(left, *team, fixed)
        if not aside:
            return None
        gone.add(id(conflict))
        cores[id(conflict)] = found_cores[id(aside[0])]
    return chosen, [c for c in unresolved if id(c) in gone]


def _give_up(found, culprit, horizons, links, starts, durations, max_backtracks, fixed, implied):
    """Order what the search can, leaving each conflict it fails on unresolved (sound, not minimal)."""
    unresolved, gone = [culprit], {id(culprit)}
    while True:
        left = implied.left(gone)
        chosen, culprit = _search(left, horizons, links, starts, durations, max_backtracks, fixed)
        if culprit is None:
            return chosen, unresolved
        unresolved.append(culprit)
        gone.add(id(culprit))


def _propagate(found, horizons, links, starts, durations, fixed) -> tuple[list[Conflict], dict[int, list]]:
    """Set aside conflicts that forced orders alone show cannot all be ordered, with their cores.

    Unit propagation: a conflict with a single way left that does not close a cycle must take
    it.  Its *reason* is the set of conflicts whose edges close the cycle the other way would
    (a path from the other way's target to its source, through program order, messages and
    edges forced before it).  When a conflict has no way left, it and the reasons of the edges
    on its cycles, followed back to the base order, form a *core*: a set of conflicts no order
    resolves together, found without a solver and usually far smaller than the solver's.  Of
    each core the most re-plannable conflict is set aside (what it forced is taken back), and
    propagation goes on.  Conflicts that keep two ways are left to the solver.
    """
    precedence = Precedence(horizons, links, starts, durations)
    sides = _Sides(found, precedence)
    graph = _Graph(horizons, links, starts)
    trail: list[tuple[int, list]] = []  # (conflict, undo log) of each forced edge, in order
    at: dict[int, int] = {}  # conflict -> its place in the trail
    aside = np.zeros(len(found), dtype=bool)
    rank = functools.cache(lambda i: replan_rank(found[i], fixed))
    out: list[Conflict] = []
    cores: dict[int, list] = {}
    while True:
        open_ = ~sides.holds(precedence).any(axis=1) & ~aside
        ways = sides.ways(precedence)
        counts = np.where(open_, ways.sum(axis=1), -1)
        stuck = np.flatnonzero(counts == 0)
        if len(stuck):
            core = _core(int(stuck[0]), sides, graph, at, len(trail))
            # the most re-plannable; of those, the one forced last (least to take back)
            worst = min(core, key=lambda i: (rank(i), -at.get(i, len(trail))))
            while worst in at:  # take back what it forced, and all forced after it
                i, log = trail.pop()
                precedence.undo(log)
                graph.pop()
                del at[i]
            aside[worst] = True
            out.append(found[worst])
            cores[id(found[worst])] = [found[i] for i in sorted(core)]
            continue
        forced = np.flatnonzero(counts == 1)
        if not len(forced):
            return out, cores
        # the hardest to re-plan first: the likely culprits come last, the least to take back
        for i in sorted(forced.tolist(), key=lambda i: -rank(i)):
            edge = sides.edges[i][int(np.argmax(ways[i]))]
            if precedence.would_cycle(*edge):
                continue  # an edge of this batch closed its way: next round
            at[i] = len(trail)
            trail.append((i, precedence.add_start(edge)))
            graph.push(edge, i)


def _core(stuck: int, sides: _Sides, graph: _Graph, at: Mapping[int, int], now: int) -> set[int]:
    """`stuck` and every conflict its dead end follows from (:func:`_propagate`)."""

    def cycle(edge, before: int) -> list[int]:
        path = graph.path(*edge, before=before)
        if path is None:  # the clocks said the edge closes a cycle
            raise AssertionError(f"no cycle through {edge}: the clocks and the graph disagree")
        return path

    core, todo = {stuck}, []
    for edge in sides.edges[stuck]:
        if edge is not None:
            todo += cycle(edge, now)
    while todo:
        i = todo.pop()
        if i in core:
            continue
        core.add(i)
        chosen = graph.pushed[at[i]][:2]
        for edge in sides.edges[i]:
            if edge is not None and edge != chosen:
                todo += cycle(edge, at[i])
    return core


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


class _Schedule:
    """The conflicts as one scheduling problem in Z3, asked again with fewer conflicts each time.

    Each step *k* of robot *r* gets a start :math:`s_{rk}` and an end :math:`e_{rk}` (seconds):
    :math:`s_{rk} \\ge e_{r,k-1}`, :math:`e_{rk} \\ge s_{rk} + \\max(d_{rk}, \\epsilon)`; a message
    is received after it is sent, a start edge starts its step after its source ends; and every
    conflict, under its own assumption literal, has one of its two ways, "x before y":
    :math:`s_{y} \\ge e_{x} + \\epsilon`.  The :math:`\\epsilon` makes every cycle of the order
    infeasible, so a schedule orders the conflicts without deadlock.  Without a schedule, the
    unsat core over the assumed conflicts names a set no order resolves together.  Every
    constraint bounds the difference of two times (a time against 0 for the first step), so
    Z3's difference-logic solver decides it (about 4x faster than its simplex at 2,500
    conflicts).

    A conflict that another asked one implies (:class:`_Implied`) is neither assumed nor, until
    it is needed, written: about two in three of a one-lane warehouse's conflicts, and the
    solver's work grows faster than their number.
    """

    def __init__(self, found, horizons, links, starts, durations, rlimit: int, implied=None) -> None:
        import z3

        self.ctx = ctx = z3.Context()
        self.solver = z3.Solver(ctx=ctx)
        self.solver.set("ctrl_c", False)  # Ctrl-C is Python's (KeyboardInterrupt), not "unknown"
        self.solver.set("smt.arith.solver", 1)  # difference logic (class docstring)
        self.solver.set("rlimit", rlimit)
        # step (r, k) has the times s{i} and e{i}; the problem is written in SMT-LIB and parsed
        # at once: thousands of constraints built through the Python API cost more than solving
        self.index = {
            node: i for i, node in enumerate((r, k) for r, n in horizons.items() for k in range(1, n + 1))
        }
        s = {node: f"s{i}" for node, i in self.index.items()}
        e = {node: f"e{i}" for node, i in self.index.items()}
        text = [f"(declare-fun {s[n]} () Real) (declare-fun {e[n]} () Real)" for n in self.index]
        for r, k in self.index:
            text.append(f"(assert (>= {s[(r, k)]} {e[(r, k - 1)] if k > 1 else 0.0}))")
            text.append(f"(assert {_after(e[(r, k)], s[(r, k)], float(durations[r][k - 1]))})")
        for link in links:
            if link.send is not None and link.wait is not None:
                text.append(f"(assert {_after(e[(link.receiver, link.wait)], e[(link.sender, link.send)])})")
        for source, target in starts:
            if target in s and source in e:
                text.append(f"(assert {_after(s[target], e[source])})")
        self.solver.from_string("\n".join(text))
        self.ways = {id(c): _edges(c) for c in found}
        self.implied = implied if implied is not None else _Implied(found)
        self.number = {id(c): n for n, c in enumerate(found)}
        self.label: dict[int, object] = {}  # conflict -> its literal, once written
        self.by_id: dict[int, Conflict] = {}  # literal -> conflict

    def _write(self, conflicts: Sequence[Conflict]) -> None:
        """Assert "``c{n}`` implies one of the conflict's ways" for those not yet written."""
        import z3

        text = []
        for c in conflicts:
            if id(c) not in self.label:
                self.label[id(c)] = label = z3.Bool(f"c{self.number[id(c)]}", self.ctx)
                self.by_id[label.get_id()] = c
                terms = " ".join(
                    _after(f"s{self.index[b]}", f"e{self.index[a]}") for a, b in self.ways[id(c)]
                )
                n = self.number[id(c)]
                text.append(f"(declare-fun c{n} () Bool) (assert (=> c{n} (or false {terms})))")
        if text:
            self.solver.from_string("\n".join(text))

    def solve(self, conflicts: Sequence[Conflict]) -> list[Conflict] | None:
        """``None`` when a schedule orders `conflicts` (kept for :meth:`edges`); else an unsat
        core of them, or ``[]`` when undecided within the resource limit."""
        import z3

        needed = self.implied.needed(conflicts)
        self._write(needed)
        verdict = _check(self.solver, [self.label[id(c)] for c in needed])
        if verdict == z3.unsat:
            core = [self.by_id[lit.get_id()] for lit in self.solver.unsat_core()]
            return core or list(conflicts)
        if verdict != z3.sat:
            return []  # undecided (resource limit): the caller falls back on the search
        self.time = _Times(self.solver.model())
        return None

    def way(self, conflict: Conflict) -> tuple[Node, Node] | None:
        """The way the last schedule orders `conflict`, if it does (asked or not)."""
        import z3

        for a, b in self.ways[id(conflict)]:
            begins = z3.Real(f"s{self.index[b]}", self.ctx)
            ends = z3.Real(f"e{self.index[a]}", self.ctx)
            if self.time(begins) >= self.time(ends) + Fraction(1, 1000):
                return (a, b)
        return None

    def edges(self, conflicts: Sequence[Conflict]) -> list[tuple[tuple[Node, Node], Conflict]]:
        """The way the last schedule orders each of `conflicts` (those it was asked with)."""
        return [(self.way(c), c) for c in conflicts]


def _both_ways(conflict: Conflict) -> list[tuple[Node, Node] | None]:
    """The conflict's two ways as start edges, ``a`` first then ``b`` first: "x before y" for x
    that ends and y that does not hold its place from the beginning (else ``None``)."""
    return [
        (x.last, y.first) if x.last is not None and y.first is not None and y.first[1] >= 1 else None
        for x, y in ((conflict.a, conflict.b), (conflict.b, conflict.a))
    ]


def _edges(conflict: Conflict) -> list[tuple[Node, Node]]:
    """The start edges that can order `conflict` (its possible :func:`_both_ways`)."""
    return [edge for edge in _both_ways(conflict) if edge is not None]


class _Implied:
    """Which conflicts imply which: of two between the same robots, one may say the other.

    "x before y" is the edge :math:`s_{B,j} \\ge e_{A,i} + \\epsilon`; the edge ``(A, i') ->
    (B, j')`` with :math:`i' \\ge i` and :math:`j' \\le j` implies it, by program order
    (:math:`e_{A,i} \\le e_{A,i'}` and :math:`s_{B,j'} \\le s_{B,j}`).  Conflict *d* implies
    *c* when each of *d*'s ways implies one of *c*'s (so a conflict with no way implies all);
    of two conflicts that imply each other, the earlier in `found` stands for both.
    """

    def __init__(self, found: Sequence[Conflict]) -> None:
        self.index = {id(c): n for n, c in enumerate(found)}
        by_pair: dict[frozenset, list[int]] = {}
        for n, c in enumerate(found):
            by_pair.setdefault(frozenset(c.robots), []).append(n)
        weaker, stronger = [], []
        for group in by_pair.values():
            implies = _implications([found[n] for n in group])
            # strictly: of two that imply each other, the earlier stands for both
            strict = implies & ((np.arange(len(group))[:, None] < np.arange(len(group))) | ~implies.T)
            np.fill_diagonal(strict, False)
            d, c = np.nonzero(strict)
            stronger.append(np.asarray(group)[d])
            weaker.append(np.asarray(group)[c])
        self.found = list(found)
        self.stronger = np.concatenate(stronger) if stronger else np.zeros(0, dtype=np.int64)
        self.weaker = np.concatenate(weaker) if weaker else np.zeros(0, dtype=np.int64)

    def by(self, conflict: Conflict) -> list[Conflict]:
        """The conflicts that imply `conflict`."""
        return [self.found[d] for d in self.stronger[self.weaker == self.index[id(conflict)]]]

    def needed(self, conflicts: Sequence[Conflict]) -> list[Conflict]:
        """`conflicts` without those another of them implies (ordering the rest orders them)."""
        asked = np.zeros(len(self.index), dtype=bool)
        asked[[self.index[id(c)] for c in conflicts]] = True
        implied = np.zeros(len(self.index), dtype=bool)
        implied[self.weaker[asked[self.weaker] & asked[self.stronger]]] = True
        return [c for c in conflicts if not implied[self.index[id(c)]]]

    def left(self, gone: set[int]) -> list[Conflict]:
        """The conflicts not in `gone` (ids), without those the others imply."""
        return self.needed([c for c in self.found if id(c) not in gone])


def _implications(group: Sequence[Conflict]) -> np.ndarray:
    """``[d, c]``: whether each way of conflict *d* implies a way of *c* (see :func:`_implied_by`)."""
    m = len(group)
    robots = {r: n for n, r in enumerate(sorted({r for c in group for r in c.robots}))}
    present = np.zeros((m, 2), dtype=bool)
    ends = np.zeros((m, 2, 4), dtype=np.int64)  # per way: A, i, B, j
    for n, c in enumerate(group):
        for w, ((a, i), (b, j)) in enumerate(_edges(c)):
            present[n, w] = True
            ends[n, w] = (robots[a], i, robots[b], j)
    d, c = ends[:, None, :, None, :], ends[None, :, None, :, :]  # [d, c, d's way, c's way, field]
    match = (
        present[None, :, None, :]
        & (d[..., 0] == c[..., 0])
        & (d[..., 2] == c[..., 2])
        & (d[..., 1] >= c[..., 1])
        & (d[..., 3] <= c[..., 3])
    )
    return (match.any(axis=3) | ~present[:, None, :]).all(axis=2)


def _check(solver, labels):
    """``solver.check(*labels)`` without re-checking the sort of each label (thousands per call)."""
    import z3

    array = (z3.Ast * len(labels))(*(label.as_ast() for label in labels))
    ctx = solver.ctx
    return z3.CheckSatResult(z3.Z3_solver_check_assumptions(ctx.ref(), solver.solver, len(labels), array))


def _after(later: str, earlier: str, gap: float = 0.0) -> str:
    """SMT-LIB for "time `later` is at least `gap` s after time `earlier`", the gap at least
    the schedule's epsilon (1 ms), written exactly as a decimal."""
    return f"(>= {later} (+ {earlier} {Decimal(max(gap, 1e-3))}))"


class _Times:
    """A model's values of time variables, exactly (the eps of the order needs no rounding),
    read when first asked for."""

    def __init__(self, model) -> None:
        self.model = model
        self.seen: dict[int, Fraction] = {}

    def __call__(self, var) -> Fraction:
        key = var.get_id()
        if key not in self.seen:
            value = self.model.eval(var, model_completion=True)
            self.seen[key] = Fraction(value.numerator_as_long(), value.denominator_as_long())
        return self.seen[key]


class _Sides:
    """Both ways of ordering every conflict, as arrays, to ask many questions at once.

    Side 0 puts occupancy ``a`` first, side 1 ``b``: "x before y" is the start edge from
    x's last step to y's first.  A side is *possible* when x ends and y does not start at the
    beginning; it *holds* when the order already implies it; it *closes a cycle* when y's first
    step must already complete before x's last one does.
    """

    def __init__(self, found: Sequence[Conflict], precedence: Precedence) -> None:
        n = len(found)
        self.possible = np.zeros((n, 2), dtype=bool)
        self.x_col = np.zeros((n, 2), dtype=np.int64)
        self.x_k = np.zeros((n, 2), dtype=np.int64)
        self.x_row = np.zeros((n, 2), dtype=np.int64)
        self.y_col = np.zeros((n, 2), dtype=np.int64)
        self.y_k = np.zeros((n, 2), dtype=np.int64)
        self.y_row = np.zeros((n, 2), dtype=np.int64)
        self.same = np.zeros((n, 2), dtype=bool)
        # where each occupancy's expected start is read (0 when it holds from the beginning)
        self.first_row = np.zeros((n, 2), dtype=np.int64)
        self.from_start = np.ones((n, 2), dtype=bool)
        self.edges = [_both_ways(c) for c in found]  # each side as a start edge, or None
        for i, c in enumerate(found):
            for side, x in enumerate((c.a, c.b)):
                if x.first is not None and x.first[1] >= 1:
                    r, k = x.first
                    self.first_row[i, side] = precedence.offsets[r] + min(k, precedence.horizons[r] + 1)
                    self.from_start[i, side] = False
            for side, edge in enumerate(self.edges[i]):
                if edge is None:
                    continue
                (xr, xk), (yr, yk) = edge
                self.possible[i, side] = True
                self.x_col[i, side], self.x_k[i, side] = precedence.column[xr], xk
                self.x_row[i, side] = precedence.offsets[xr] + xk
                self.y_col[i, side], self.y_k[i, side] = precedence.column[yr], yk
                self.y_row[i, side] = precedence.offsets[yr] + min(yk, precedence.horizons[yr] + 1)
                self.same[i, side] = xr == yr

    def holds(self, precedence: Precedence) -> np.ndarray:
        """(n, 2): whether each side is already implied."""
        implied = precedence.begin_flat[self.y_row, self.x_col] >= self.x_k
        return self.possible & np.where(self.same, self.x_k < self.y_k, implied)

    def expected_start(self, precedence: Precedence, rows: np.ndarray) -> np.ndarray:
        """The expected start of the earlier occupancy of each conflict in `rows`, s."""
        started = np.where(self.from_start[rows], 0.0, precedence.started_flat[self.first_row[rows]])
        return started.min(axis=1)

    def ways(self, precedence: Precedence) -> np.ndarray:
        """(n, 2): whether each side can still be added without closing a cycle."""
        cycle = precedence.done_flat[self.x_row, self.y_col] >= self.y_k
        return self.possible & ~np.where(self.same, self.y_k <= self.x_k, cycle)


def _search(found, horizons, links, starts, durations, max_backtracks, fixed):
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
    # priorities: the robot expected to finish first goes first, so that it clears out early;
    # one order for all robots keeps most choices consistent (no cycles among them)
    alone = {r: sum(durations[r]) for r in horizons}
    rank = {r: n for n, r in enumerate(sorted(horizons, key=lambda r: (alone[r], r)))}
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
        options = _ways(conflict, precedence)
        if len(options) > 1:  # the robot of higher priority first, then the lower makespan
            options = sorted(options, key=lambda e: rank[e[0][0]])
            if len({rank[e[0][0]] for e in options}) < len(options):
                options = sorted(options, key=lambda e: (rank[e[0][0]], _makespan_with(precedence, e)))
            stack.append((len(chosen), options[1:], conflict))
        chosen.append((options[0], conflict, precedence.add_start(options[0])))


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
    for edge in _edges(stuck):
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
