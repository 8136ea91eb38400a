"""Ordering conflicts: start edges that keep two plans out of each other's places, without deadlock.

A conflict (:mod:`cosmop.team.conflicts`) is ordered by a *start edge*: one occupancy ends
before the other starts.  :func:`order_conflicts` chooses one edge per conflict so that the
team's order stays acyclic (no deadlock, :mod:`cosmop.team.precedence`): the occupancy that
is expected to begin first (:mod:`cosmop.team.timing`) goes first, unless that closes a
cycle or it never ends (a robot parked for good).  Conflicts no order can resolve together are
returned, irredundant, for re-planning.

Two conflicts between the same robots often say the same thing more strongly or more weakly:
one *dominates* the other (:class:`_Dominance`); only the undominated are searched and given to
the solver.  The solver's work grows much faster than the conflicts (a single check of 10,000
conflicts can take a minute), so the search proves its own dead ends
(:mod:`cosmop.team.conflict_search`) and the solver is asked only when the search runs out
of its budget.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from decimal import Decimal
from fractions import Fraction
from typing import Any

import numpy as np
from shapely.geometry.base import BaseGeometry

from cosmop.events import Link, Node
from cosmop.team.conflict_search import (
    CorrectionSetPicker,
    Edge,
    OrientationTable,
    Search,
    backjump,
    depth_first,
    possible_orientations,
)
from cosmop.team.conflicts import Conflict, Futile

__all__ = ["order_conflicts"]

_Ordered = tuple[list[tuple[Edge, Conflict]], list[Conflict]]
"""Start edges, each with the conflict it orders, and the conflicts left unresolved."""


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
    max_set_aside: int | None = None,
    futile: Futile = frozenset(),
) -> tuple[list[tuple[tuple[Node, Node], Conflict]], list[Conflict]]:
    """Start edges that order every conflict in `found`, and the conflicts no order resolves.

    Both the search and the solver see only the conflicts no other one implies
    (:class:`_Dominance`): an order of those orders the rest.  Then:

    1. a search over the two ways of ordering each conflict, with unit propagation and
       conflict-directed backjumping (:class:`~cosmop.team.conflict_search.Search`).  Each
       dead end comes with the set of conflicts it follows from; one that follows from no
       choice is a *core* -- a set of conflicts no order resolves together -- and one conflict
       of each core is set aside (the most re-plannable, preferably of a robot already
       re-planned: :class:`~cosmop.team.conflict_search.CorrectionSetPicker`).  The cores are not
       minimal, so each conflict set aside is then given back where the others allow it
       (:func:`_give_back`), and that is the answer;
    2. only if the search passes `max_backtracks` dead ends: the question settled exactly as a
       scheduling problem (:class:`_Schedule`, Z3 over the steps' start and end times), from
       the conflicts set aside so far.  Either a schedule orders every conflict left, or an
       unsat core names a set no order resolves together, of which one is set aside in the same
       way -- and the others are ordered again without it.  Each conflict set aside is then
       given back, the hardest to re-plan first, while a schedule still exists (without a
       solver call when its own core is back in full: the core still proves it).

    The unresolved conflicts returned are therefore irredundant: none of them could be ordered
    together with all the ordered ones.

    With `max_set_aside`, the search stops once it has set aside more conflicts than that, and
    the conflicts set aside so far are returned as unresolved, with the edges taken so far.
    A single core already proves that no order resolves every conflict; what the search would
    do after that only makes the list of unresolved conflicts complete and irredundant, and a
    crowded fleet can set aside hundreds of conflicts before it is (a minute of search).  The
    list returned is then neither: each conflict in it is in a core, and the rest may not all
    be ordered.

    Returns the edges added (on top of `starts`), each with the conflict it orders, and the
    unresolved conflicts.

    Parameters
    ----------
    found : sequence of Conflict
        The conflicts between the plans (:func:`~cosmop.team.conflicts.conflicts`).
    horizons : Mapping[str, int]
        Every robot's number of steps.
    links : sequence of Link
        The messages the plans already have.
    starts : sequence of (Node, Node)
        Start edges the order already has.
    durations : Mapping[str, sequence of float]
        Expected seconds of each robot's steps (:func:`~cosmop.team.timing.durations`).
    max_backtracks : int
        Dead ends after which the search hands over to the solver.
    fixed : Mapping[str, sequence of shapely geometry], optional
        Each robot's places re-planning cannot move
        (:func:`~cosmop.team.conflicts.fixed_places`), to choose which conflict to set aside.
    rlimit : int
        Z3 resource limit of each scheduling call.
    max_set_aside : int, optional
        The most conflicts the search sets aside before it stops (it stops at more than
        this; default: it never stops).
    futile : Futile
        Ways around known not to work: a conflict whose only ways are these is set aside last.
    """
    table = OrientationTable.of(found, list(horizons))
    implied, picker = _Dominance(found, table), CorrectionSetPicker(fixed, futile)
    team = (horizons, links, starts, durations)
    search = Search(found, implied, team, picker, table)
    done = search.run(max_backtracks, limit=max_set_aside)
    if search.stopped:
        return search.edges, search.set_aside
    if done and (settled := _give_back(search, picker, max_backtracks)):
        return settled
    unresolved, cores = search.set_aside, search.cores
    gone = {id(c) for c in unresolved}
    schedule = _Schedule(found, horizons, links, starts, durations, rlimit, implied)
    while (core := schedule.solve(implied.left(gone))) is not None:
        if not core:  # undecided within the solver's budget: what the search fails on stays
            return _give_up(found, horizons, links, starts, durations, max_backtracks, fixed, implied, futile)
        unresolved.append(picker.pick(core))
        gone.add(id(unresolved[-1]))
        cores[id(unresolved[-1])] = core
    # Cores are not minimal, so a conflict set aside early may be orderable once later ones are
    # gone: give each back, the hardest to re-plan first, while a schedule remains.  No solver
    # call when the last schedule already orders it, nor when its own core is all back (the
    # core still proves that no schedule orders it with the others).
    for conflict in sorted(unresolved, key=lambda c: -picker.rank(c)):
        gone.discard(id(conflict))
        if all(id(c) not in gone for c in cores[id(conflict)]) or (
            schedule.way(conflict) is None and schedule.solve(implied.left(gone)) is not None
        ):
            gone.add(id(conflict))
        else:
            unresolved.remove(conflict)
    # the search's choices keep the makespan low; the schedule stands in where the search fails
    rest = [c for c in found if id(c) not in gone]
    better, _, _ = backjump(rest, implied, team, picker, max_backtracks)
    return (better if better is not None else schedule.edges(implied.left(gone))), unresolved


def _give_back(search: Search, picker: CorrectionSetPicker, budget: int) -> _Ordered | None:
    """Give back the conflicts `search` set aside that an order resolves with all the others.

    A conflict whose core's other members are all ordered stays set aside (its core proves it).
    Any other is given back, the hardest to re-plan first, and the search goes on from the order
    as it is: it stays set aside if the search finds a core (which must contain it, the rest
    being ordered).  ``(edges, unresolved)``, or ``None`` when the search runs out of `budget`.
    """
    for conflict in sorted(search.set_aside, key=lambda c: -picker.rank(c)):
        core = search.cores[id(conflict)]
        if not any(search.is_aside(c) for c in core if c is not conflict):
            continue
        if search.give_back(conflict, budget) is None:
            return None
    return search.edges, search.set_aside


def _give_up(
    found: Sequence[Conflict],
    horizons: Mapping[str, int],
    links: Sequence[Link],
    starts: Sequence[Edge],
    durations: Mapping[str, Sequence[float]],
    max_backtracks: int,
    fixed: Mapping[str, Sequence[BaseGeometry]] | None,
    implied: _Dominance,
    futile: Futile = frozenset(),
) -> _Ordered:
    """Order what the search can, leaving each conflict it fails on unresolved (sound, not minimal)."""
    unresolved: list[Conflict] = []
    gone: set[int] = set()
    while True:
        left = implied.left(gone)
        chosen, culprit = depth_first(left, horizons, links, starts, durations, max_backtracks, fixed, futile)
        if culprit is None:
            return chosen, unresolved
        unresolved.append(culprit)
        gone.add(id(culprit))


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

    A conflict that another asked one implies (:class:`_Dominance`) is neither assumed nor, until
    it is needed, written: about two in three of a one-lane warehouse's conflicts, and the
    solver's work grows faster than their number.
    """

    def __init__(
        self,
        found: Sequence[Conflict],
        horizons: Mapping[str, int],
        links: Sequence[Link],
        starts: Sequence[Edge],
        durations: Mapping[str, Sequence[float]],
        rlimit: int,
        implied: _Dominance | None = None,
    ) -> None:
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
        self.ways = {id(c): possible_orientations(c) for c in found}
        self.implied = implied if implied is not None else _Dominance(found)
        self.number = {id(c): n for n, c in enumerate(found)}
        self.label: dict[int, Any] = {}  # conflict -> its literal (a z3 Bool), once written
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

    def edges(self, conflicts: Sequence[Conflict]) -> list[tuple[Edge, Conflict]]:
        """The way the last schedule orders each of `conflicts` (those it was asked with)."""
        out: list[tuple[Edge, Conflict]] = []
        for c in conflicts:
            way = self.way(c)
            assert way is not None  # the last schedule orders every conflict it was asked with
            out.append((way, c))
        return out


class _Dominance:
    """Which conflicts imply which: of two between the same robots, one may say the other.

    The stronger *dominates* the weaker: a *dominated* conflict is ordered by any order of a
    conflict that dominates it, so only the undominated need ordering (as dominance rules prune
    a scheduling search).

    "x before y" is the edge :math:`s_{B,j} \\ge e_{A,i} + \\epsilon`; the edge ``(A, i') ->
    (B, j')`` with :math:`i' \\ge i` and :math:`j' \\le j` implies it, by program order
    (:math:`e_{A,i} \\le e_{A,i'}` and :math:`s_{B,j'} \\le s_{B,j}`).  Conflict *d* implies
    *c* when each of *d*'s ways implies one of *c*'s (so a conflict with no way implies all);
    of two conflicts that imply each other, the earlier in `found` stands for both.
    """

    def __init__(self, found: Sequence[Conflict], table: OrientationTable | None = None) -> None:
        self.index = {id(c): n for n, c in enumerate(found)}
        self.found = list(found)
        # every conflict's ways as (A, i, B, j), robots numbered (OrientationTable); each pair of robots
        # numbered in the order it first appears
        pairs: dict[frozenset[str], int] = {}
        pair = np.array([pairs.setdefault(frozenset(c.robots), len(pairs)) for c in found], dtype=np.int64)
        table = table if table is not None else OrientationTable.of(found, ())
        self.stronger, self.weaker = _implied(pair, table.possible, table.ends)

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

    def among(self, conflicts: Sequence[Conflict]) -> tuple[np.ndarray, np.ndarray]:
        """The pairs (stronger, weaker) of :attr:`found` that both lie in `conflicts`, as
        indices into `conflicts`."""
        place = np.full(len(self.found), -1, dtype=np.int64)
        place[[self.index[id(c)] for c in conflicts]] = np.arange(len(conflicts))
        d, c = place[self.stronger], place[self.weaker]
        both = (d >= 0) & (c >= 0)
        return d[both], c[both]

    def left(self, gone: set[int]) -> list[Conflict]:
        """The conflicts not in `gone` (ids), without those the others imply."""
        return self.needed([c for c in self.found if id(c) not in gone])


def _implied(pair: np.ndarray, present: np.ndarray, ends: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The pairs ``(stronger, weaker)`` of conflicts of which the first implies the second
    (:class:`_Dominance`), sorted by `pair`, then stronger, then weaker; of two that imply each
    other, only the earlier is the stronger.

    `pair` numbers each conflict's two robots, `present` ``(m, 2)`` says which of its ways it
    has and `ends` ``(m, 2, 4)`` gives each as ``(A, i, B, j)``, the robots numbered.  A way
    implies only the way of the other conflict that lets the same robot go first, so the ways
    are first put side by side by direction (the lower-numbered robot first, then the other); a
    missing way is given the latest end and the earliest start, so that it implies every way
    and no way implies it.  Then *d* implies *c* when :math:`i_d \\ge i_c` and
    :math:`j_d \\le j_c` in both directions: a dominance in four numbers, here split by robot
    into two halves, the steps of the lower-numbered robot :math:`(i_0, j_1)` and the other's
    :math:`(i_1, j_0)`.  Each half takes few distinct values (about one per occupancy of that
    robot), so the halves above each half are found by comparing the distinct values
    (:func:`_dominating`), and the conflicts that imply *c* are those with a half above each of
    *c*'s: no two conflicts of a pair are compared (two robots whose plans cross many times can
    have thousands of conflicts, and a few implications each).  The work is, per conflict, the
    halves above its first half times those above its second: small because one robot's
    occupancies rarely hold one another.  Steps are numbered from 0 (the stand-ins for a
    missing way lie beyond every step).
    """
    a = np.where(present[:, 0], ends[:, 0, 0], ends[:, 1, 2])  # each conflict's robots, from a way
    b = np.where(present[:, 0], ends[:, 0, 2], ends[:, 1, 0])
    first = (a > b).astype(np.int64)  # the way that lets the lower-numbered robot go first
    by_direction = np.stack([first, 1 - first], axis=-1)
    has = np.take_along_axis(present, by_direction, axis=-1)
    late = int(ends[:, :, [1, 3]].max(initial=0)) + 1
    i = np.where(has, np.take_along_axis(ends[:, :, 1], by_direction, axis=-1), late)
    j = np.where(has, np.take_along_axis(ends[:, :, 3], by_direction, axis=-1), -late)
    x_values, x = np.unique(np.stack([pair, i[:, 0], j[:, 1]], axis=1), axis=0, return_inverse=True)
    y_values, y = np.unique(np.stack([pair, i[:, 1], j[:, 0]], axis=1), axis=0, return_inverse=True)
    x, y = x.reshape(-1), y.reshape(-1)
    # every conflict c with every half above its first half, then with every half above its second
    c, upper_x = _above(x, *_dominating(x_values))
    at, upper_y = _above(y[c], *_dominating(y_values))
    c, upper_x = c[at], upper_x[at]
    # the conflicts whose halves are those: the stronger ones
    key = x * len(y_values) + y
    by_key = np.argsort(key, kind="stable")
    wanted = upper_x * len(y_values) + upper_y
    low = np.searchsorted(key[by_key], wanted, "left")
    at, d = _spread(low, np.searchsorted(key[by_key], wanted, "right") - low)
    c, d = c[at], by_key[d]
    keep = (d != c) & ((key[d] != key[c]) | (d < c))  # of two alike, the earlier stands for both
    c, d = c[keep], d[keep]
    order = np.lexsort((c, d, pair[c]))
    return d[order], c[order]


def _dominating(values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The pairs ``(above, below)`` of the rows ``(pair, i, j)`` of `values` (sorted by pair)
    with the same pair, :math:`i_{above} \\ge i_{below}` and :math:`j_{above} \\le j_{below}`
    (each row with itself too).  The rows of one pair are compared all at once, the pairs with
    as many rows together."""
    starts = np.flatnonzero(np.diff(values[:, 0], prepend=values[:1, 0] - 1))
    sizes = np.diff(np.append(starts, len(values)))
    above, below = [np.zeros(0, dtype=np.int64)], [np.zeros(0, dtype=np.int64)]
    for size in np.unique(sizes).tolist():
        rows = starts[sizes == size][:, None] + np.arange(size)  # (pairs, size)
        i, j = values[rows, 1], values[rows, 2]
        block, high, low = np.nonzero((i[:, :, None] >= i[:, None, :]) & (j[:, :, None] <= j[:, None, :]))
        above.append(rows[block, high])
        below.append(rows[block, low])
    return np.concatenate(above), np.concatenate(below)


def _above(values: np.ndarray, above: np.ndarray, below: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each conflict (its half's row in `values`), every row that dominates that row (the
    pairs ``(above, below)`` of :func:`_dominating`): the conflict's position repeated once per
    such row, and those rows beside it."""
    by_below = np.argsort(below, kind="stable")
    count = np.bincount(below, minlength=int(values.max(initial=-1)) + 1)
    start = np.cumsum(count) - count
    index, at = _spread(start[values], count[values])
    return index, above[by_below[at]]


def _spread(start: np.ndarray, count: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each position ``n`` repeated ``count[n]`` times, beside ``start[n], start[n] + 1, ...``."""
    index = np.repeat(np.arange(len(start)), count)
    return index, start[index] + np.arange(len(index)) - (np.cumsum(count) - count)[index]


def _check(solver: Any, labels: Sequence[Any]) -> Any:
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

    def __init__(self, model: Any) -> None:
        self.model = model
        self.seen: dict[int, Fraction] = {}

    def __call__(self, var: Any) -> Fraction:
        key = var.get_id()
        if key not in self.seen:
            value = self.model.eval(var, model_completion=True)
            self.seen[key] = Fraction(value.numerator_as_long(), value.denominator_as_long())
        return self.seen[key]
