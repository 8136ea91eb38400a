"""The search that orders conflicts between plans and proves its own dead ends.

:class:`Search` chooses one start edge per conflict (:mod:`cosmop.team.conflict_order`) so
that the team's order stays acyclic: unit propagation of the orders that are forced, choices
that follow time (the robot expected first goes first), and conflict-directed backjumping.
Each dead end comes with the set of conflicts it follows from (:func:`_core`); one that follows
from no choice is a *core*, a set of conflicts no order resolves together, found without a
solver.  Of each core one conflict is set aside for re-planning (:class:`CorrectionSetPicker`):
the conflicts set aside hit every core, a *correction set*.  What a dead end takes back is only
what needs what goes (dependency-directed *retraction*, as in Stallman and Sussman's reason
maintenance): the rest of the order stays in place.

A conflict is a *disjunctive edge* of the team's order (as in a disjunctive graph of job-shop
scheduling): one of its two occupancies goes first, and each choice is one of its two
*orientations* (:func:`orientations_of`), a start edge.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Generic, Protocol, TypeVar

import numpy as np
from shapely.geometry.base import BaseGeometry

from cosmop.events import Link, Node
from cosmop.team.conflicts import Conflict, Futile, Occupancy, detours, replan_rank
from cosmop.team.precedence import Precedence, RetractedEdges

__all__ = [
    "CorrectionSetPicker",
    "OrientationTable",
    "Search",
    "backjump",
    "depth_first",
    "orientation_arrays",
    "orientations_of",
    "possible_orientations",
]

Edge = tuple[Node, Node]
"""A start edge ``((A, i), (B, j))``: B starts step *j* once A has completed step *i*."""

_Team = tuple[Mapping[str, int], Sequence[Link], Sequence[Edge], Mapping[str, Sequence[float]]]
"""``(horizons, links, starts, durations)``: the plans' order before any conflict is ordered."""

_Reason = frozenset[int] | bool | None
"""Why an entry of the trail was taken: ``None`` a choice, ``True`` forced by its cycle, or the
set of the dead end that forced it."""

_Taken = tuple[int, Edge, _Reason]
"""A conflict, the start edge that orders it, and why."""


class _Implications(Protocol):
    """Which conflicts dominate which (:class:`cosmop.team.conflict_order._Dominance`)."""

    def among(self, conflicts: Sequence[Conflict]) -> tuple[np.ndarray, np.ndarray]: ...


class Search:
    """Order conflicts, setting aside what no order resolves, and give conflicts back later.

    A search over the two ways of each conflict with unit propagation and conflict-directed
    backjumping (Prosser's CBJ, here over start edges and cycles), which proves its dead ends:

    * a conflict with a single way left takes it (*forced*); its reason is the cycle its other
      way would close (:func:`_core` follows it when needed);
    * otherwise the open conflict expected to start first is *chosen* a way (:func:`_options`:
      the occupancy expected to begin first goes first, so that the order follows the
      itinerary, then the lower makespan);
    * a conflict with no way left gives a dead end and its set of conflicts (:func:`_core`):
      with the choices among them kept, no order of them is acyclic.  The search jumps back to
      the latest of those choices and takes its other way, forced now by that set.  A dead end
      with no choice in it is a *core*: no order resolves it at all.  One of its conflicts is
      set aside (:class:`CorrectionSetPicker`), and what depends on that conflict is taken back.
    * taking back (:meth:`_retract`) keeps every later entry whose reason does not need what
      goes: choices, ways forced by cycles that cannot run through an edge that goes, ways
      forced by sets that lose nothing.  At 50 robots a core took back some 490 entries of
      which nine in ten were taken again the same way, one propagation round at a time.

    Why a set is a core: follow the conflicts in the order they were taken.  A forced one that
    takes its other way closes the cycle of its reason, if everything taken before it on that
    cycle kept its way; a conflict forced by a dead end's set closes a cycle of that set if it
    takes the way that failed; so in an acyclic order every member keeps its way, and then the
    stuck conflict has none.  Both ways of a choice failing makes the union of their two sets
    a set with one choice fewer, so the cores found at the top are cores outright.

    A conflict that another one in `found` implies is left to it while that one is not set
    aside (`implied.among(found)` gives the pairs, stronger and weaker, as indices into `found`:
    :class:`cosmop.team.conflict_order._Dominance`).  The search keeps its state between
    questions: a conflict given back (:meth:`give_back`) is searched on from the order as it is.
    """

    def __init__(
        self,
        found: Sequence[Conflict],
        implied: _Implications,
        team: _Team,
        picker: CorrectionSetPicker,
        table: OrientationTable | None = None,
    ) -> None:
        horizons, links, starts, durations = team
        self.found, self.picker = found, picker
        self.number = {id(c): i for i, c in enumerate(found)}
        self.precedence = Precedence(horizons, links, starts, durations)
        self.orientations = _OrientationTests(found, self.precedence, table)
        self.at: dict[int, int] = {}  # conflict -> its place in the trail
        self.graph: _Graph[int] = _Graph(self.precedence, links, starts, self.at)
        self.stronger, self.weaker = implied.among(found)
        # (conflict, edge, undo log, reason): None for a choice, True when forced by its cycle,
        # or the set of a dead end when forced by it
        self.trail: list[_Entry] = []
        self.aside = np.zeros(len(found), dtype=bool)
        self.hidden = np.zeros(len(found), dtype=bool)
        self.every = self.live = np.arange(len(found))  # the conflicts not known to be ordered yet
        self._hide()
        self.cores: dict[int, list[Conflict]] = {}  # id of each conflict set aside -> its core
        self.stopped = False  # whether :meth:`run` stopped at its limit of conflicts set aside

    @property
    def edges(self) -> list[tuple[Edge, Conflict]]:
        """The start edges taken, each with the conflict it orders."""
        return [(edge, self.found[i]) for i, edge, _, _ in self.trail]

    @property
    def set_aside(self) -> list[Conflict]:
        """The conflicts set aside, each with its core in :attr:`cores`."""
        return [self.found[int(i)] for i in np.flatnonzero(self.aside)]

    def is_aside(self, conflict: Conflict) -> bool:
        """Whether `conflict` is set aside.

        Parameters
        ----------
        conflict : Conflict
            One of the conflicts searched.
        """
        return bool(self.aside[self.number[id(conflict)]])

    def run(self, budget: int, back: int | None = None, limit: int | None = None) -> bool | None:
        """Order every conflict left: ``True`` when done, ``None`` past `budget` dead ends.

        With `back` (a conflict given back), a core sets aside `back` itself (every core found
        contains it, the others being ordered): then ``False`` once the rest is ordered again.
        With `limit`, the search stops (``None``, and :attr:`stopped` set) once more than
        `limit` conflicts are set aside in all.

        Parameters
        ----------
        budget : int
            Dead ends after which the search gives up.
        back : int, optional
            The index of a conflict given back.
        limit : int, optional
            The most conflicts set aside before the search stops (it stops at more than this).
        """
        dead_ends, kept = 0, True
        self.stopped = False
        while True:
            # a side that holds keeps holding until something is taken back (_pop)
            held = self.orientations.holds(self.precedence, self.live)
            live = self.live = self.live[~(held[:, 0] | held[:, 1])]
            open_ = ~self.aside[live] & ~self.hidden[live]
            ways = self.orientations.ways(self.precedence, live)
            counts = np.where(open_, ways[:, 0].astype(np.int64) + ways[:, 1], -1)
            stuck = live[counts == 0]
            if len(stuck):
                verdict = self._dead_ends(stuck.tolist(), back)
                if limit is not None and verdict == "core" and np.count_nonzero(self.aside) > limit:
                    self.stopped = True
                    return None
                if verdict == "choice":
                    dead_ends += 1
                    if dead_ends > budget:
                        return None
                kept &= verdict != "back"
                continue
            at = np.flatnonzero(counts == 1)
            side = dict(zip(live[at].tolist(), ways[at, 1].tolist(), strict=True))  # the way left
            # the hardest to re-plan first: the likely culprits come last, the least to take back
            order = sorted(side, key=lambda i: -self.picker.rank(self.found[i]))
            self._take_forced([(i, self.orientations.way(i, int(side[i]))) for i in order])
            if len(at):
                continue
            pool = live[open_]
            if not len(pool):
                return kept
            i = int(pool[np.argmin(self.orientations.expected_start(self.precedence, pool))])
            self._take(i, _options(self.found[i], self.precedence)[0], None)

    def _dead_ends(self, stuck: list[int], back: int | None) -> str:
        """Settle this round's dead ends: ``"choice"`` when the first follows from a choice (the
        search jumps back), ``"back"`` when a core sets aside `back`, else ``"core"``.

        The cores of all conflicts stuck at once are found before anything is taken back, and
        one conflict of each is set aside (a core that holds one set aside already waits for the
        next round); then the order is taken back once, to the earliest place any of them needs.
        """
        places: list[int] = []
        gone: set[int] = set()
        for s in stuck:
            core, choices = self._dead_end_set(s)
            if self.aside[list(core)].any():
                continue  # it held a conflict set aside in this round: asked again next round
            if choices and places:
                break  # the set-asides first; if it is still a dead end, it comes back
            if choices:
                i, edge = self.trail[max(choices)][:2]
                other = self.orientations.other_way(i, edge)
                self._retract(max(choices), {i}, (i, other, frozenset(core)))
                return "choice"
            if back is not None:
                gone.add(back)
                places.append(self._put_aside(back, core))
                break
            # on a tie, the one taken last (the least to take back): not taken yet, then the latest
            members = sorted(core, key=lambda i: -self.at.get(i, len(self.trail)))
            picked = self.picker.pick([self.found[i] for i in members])
            culprit = next(i for i in members if self.found[i] is picked)
            gone.add(culprit)
            places.append(self._put_aside(culprit, core))
        if not places:  # every core held a conflict set aside before this round: a stale reason
            raise AssertionError(f"dead ends {stuck} with nothing to set aside or take back")
        self._hide()  # what they implied is no longer ordered by them
        self._retract(min(places), gone)
        return "core" if back is None else "back"

    def _dead_end_set(self, stuck: int) -> tuple[set[int], list[int]]:
        """The set of conflicts the dead end of `stuck` follows from (:func:`_core`) and the
        places of the choices in it.  A choice taken again after another one changed its way
        (:meth:`_retract`) may have lost its other way to a cycle since: it counts as forced
        from then on, and the set is traced again."""
        while True:
            core = _core(stuck, self.orientations, self.graph, self.trail, self.at)
            choices = [self.at[i] for i in core if i in self.at and self.trail[self.at[i]][3] is None]
            if not choices:
                return core, choices
            i, edge, log, _ = self.trail[max(choices)]
            other = self.orientations.other_way(i, edge)
            if self.graph.path(*other, before=max(choices)) is None:
                return core, choices
            self.trail[max(choices)] = (i, edge, log, True)

    def give_back(self, conflict: Conflict, budget: int) -> bool | None:
        """Search on with `conflict` no longer set aside: ``True`` when it is ordered with the
        rest, ``False`` when a core keeps it aside (:attr:`cores` has the new one), ``None``
        past `budget` dead ends.

        Parameters
        ----------
        conflict : Conflict
            A conflict set aside.
        budget : int
            Dead ends after which the search gives up.
        """
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

    def _take(self, i: int, edge: Edge, reason: _Reason, log: list[Any] | _Batch | None = None) -> None:
        self.at[i] = len(self.trail)
        self.trail.append((i, edge, self.precedence.add_start(edge) if log is None else log, reason))
        self.graph.push(edge, i)

    def _take_forced(self, forced: list[tuple[int, Edge]]) -> None:
        """Take the forced ways, in order, each unless the ones before it close its cycle (it
        is then stuck, and seen so next round)."""
        self._take_batch([(i, edge, True) for i, edge in forced])

    def _take_batch(self, entries: list[_Taken], prefix: bool = False) -> None:
        """Take ``(conflict, edge, reason)`` entries in order, each unless the ones before it
        close its cycle: in one pass (:meth:`~cosmop.team.precedence.Precedence.add_starts`),
        taken back as one.  With `prefix`, only those before the first that closes a cycle
        (what comes after it may need it)."""
        if not entries:
            return
        log, refused = self.precedence.add_starts([edge for _, edge, _ in entries])
        if prefix and refused:
            self.precedence.undo(log)
            entries = entries[: refused[0]]
            log, refused = (
                self.precedence.add_starts([edge for _, edge, _ in entries]) if entries else ([], [])
            )
        stuck = set(refused)
        taken = [entry for n, entry in enumerate(entries) if n not in stuck]
        if not taken:
            return
        batch = _Batch(len(self.trail), len(taken), log)
        for i, edge, reason in taken:
            self._take(i, edge, reason, batch)

    def _retract(self, place: int, gone: set[int], first: _Taken | None = None) -> None:
        """Take back the trail from `place` on with the conflicts `gone` (set aside, or a choice
        that takes its other way: `first`, the entry that takes it), keeping every entry whose
        reason does not need what goes (:meth:`_needing`).

        The entries kept stay in the trail, in their order, as one batch, and the order drops
        the edges that go (:meth:`~cosmop.team.precedence.Precedence.retract`).  `first`
        comes after them; if they close its cycle, it comes where its choice was, and they are
        taken again after it up to the first that closes a cycle then (what comes after that one
        may need it): the rest is left to the search.
        """
        start, kept, dropped = self._needing(place, gone)
        if kept and self.precedence.complete:
            self._drop(start, kept, dropped)
            if first is None:
                return
            if not self.precedence.would_cycle(*first[1]):
                self._take(*first)
                return
            self._back_to(start)  # the entries before the choice come back with their batch
            self._take_batch(kept[: place - start])
        else:
            self._back_to(place)
        if first is not None:
            self._take(*first)
        self._take_batch(kept[place - start :], prefix=True)

    def _needing(self, place: int, gone: set[int]) -> tuple[int, list[_Taken], set[int]]:
        """Which entries from `place` on need the conflicts `gone`: ``(start, kept, dropped)``,
        the entries from `start` (`place`, or where the batch it falls in starts) that stay as
        ``(conflict, edge, reason)`` and the conflicts of those that go.

        An entry goes when its conflict is gone, when it was forced by a dead end's set that
        holds a conflict that goes, or when it was forced by a cycle that may run through an
        edge that goes (:class:`~cosmop.team.precedence.RetractedEdges`, one-sided).  Choices
        need nothing.  What stays keeps its reason: all it used stays before it.
        """
        log = self.trail[place][2] if place < len(self.trail) else None
        start = log.start if isinstance(log, _Batch) else place  # a batch goes back whole
        through, dropped = RetractedEdges(self.precedence), set(gone)
        kept: list[_Taken] = []
        for n, (i, edge, _, reason) in enumerate(self.trail[start:], start):
            if n < place:
                needs = False
            elif i in gone or reason is None:
                needs = i in gone
            elif isinstance(reason, frozenset):
                needs = not reason.isdisjoint(dropped)
            else:
                needs = any(
                    through.may_pass(*self.orientations.rows[i][n]) for n in self.orientations.others(i, edge)
                )
            if needs:
                through.add(*self.precedence.rows(edge))
                dropped.add(i)
            else:
                kept.append((i, edge, reason))
        return start, kept, dropped

    def _drop(self, start: int, kept: list[_Taken], dropped: set[int]) -> None:
        """Remove the entries of `dropped` from the trail from `start` on; the rest, `kept`,
        stay in place as one batch."""
        tail = self.trail[start:]
        logs = [
            log.log if isinstance(log, _Batch) else log
            for n, (_, _, log, _) in enumerate(tail, start)
            if not isinstance(log, _Batch) or log.start == n
        ]
        away = [edge for i, edge, _, _ in tail if i in dropped]
        batch = _Batch(start, len(kept), self.precedence.retract(logs, away))
        self.graph.remove(start, dropped)
        for i in dropped:
            self.at.pop(i, None)  # (a conflict set aside need not have been taken)
        self.trail[start:] = [(i, edge, batch, reason) for i, edge, reason in kept]
        for n in range(start, len(self.trail)):
            self.at[self.trail[n][0]] = n
        self.live = self.every  # what held may not now

    def _back_to(self, place: int) -> None:
        """Take back the trail from `place` on.  A batch of forced ways that `place` falls
        inside is taken back whole, and its part before `place` taken again."""
        while len(self.trail) > place:
            self._pop()
        top = self.trail[-1][2] if self.trail else None
        if isinstance(top, _Batch) and top.start + top.size > place:
            kept = [(i, edge, reason) for i, edge, _, reason in self.trail[top.start :]]
            while len(self.trail) > top.start:
                self._pop()
            self._take_batch(kept)

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
    log: list[Any]


_Entry = tuple[int, Edge, list[Any] | _Batch, _Reason]
"""An entry of the search's trail: a conflict, its edge, the order's undo log (or the batch it
was added in), and why it was taken."""


def backjump(
    found: Sequence[Conflict], implied: _Implications, team: _Team, picker: CorrectionSetPicker, budget: int
) -> tuple[list[tuple[Edge, Conflict]] | None, list[Conflict], dict[int, list[Conflict]]]:
    """:class:`Search` run once: ``(edges, set aside, cores)``, ``edges`` ``None`` past `budget`.

    Parameters
    ----------
    found : sequence of Conflict
        The conflicts to order.
    implied : _Dominance
        Which of them imply which (:class:`cosmop.team.conflict_order._Dominance`).
    team : tuple
        ``(horizons, links, starts, durations)``: the plans' order before any conflict's.
    picker : CorrectionSetPicker
        Which conflict of a core to set aside.
    budget : int
        Dead ends after which the search gives up.
    """
    search = Search(found, implied, team, picker)
    done = search.run(budget)
    return (search.edges if done else None), search.set_aside, search.cores


def _in(i: int, reason: _Reason) -> bool:
    return isinstance(reason, frozenset) and i in reason


def _core(
    stuck: int,
    orientations: _OrientationTests,
    graph: _Graph[int],
    trail: list[_Entry],
    at: Mapping[int, int],
) -> set[int]:
    """`stuck` and every conflict its dead end follows from (:class:`Search`): the conflicts on
    the cycles that close its ways, and, for each of those forced, on the cycle its other way
    closes (or the dead end's set that forced it), back to the choices and the base order."""

    def cycle(edge: Edge, before: int) -> list[int]:
        path = graph.path(*edge, before=before)
        if path is None:  # the clocks said the edge closes a cycle
            raise AssertionError(f"no cycle through {edge}: the clocks and the graph disagree")
        return path

    core, traced = {stuck}, {stuck}
    todo: list[int] = []
    for edge in orientations.edges[stuck]:
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
            for n in orientations.others(i, chosen):
                todo += cycle(orientations.way(i, n), at[i])
    return core


class CorrectionSetPicker:
    """Which conflict of a core to set aside (its robot is re-planned around the other side).

    The conflicts set aside, one of each core, form a *correction set* (the term of unsat-core
    and MaxSAT work: a set whose removal leaves the rest satisfiable, a hitting set of the
    cores); this class picks its members, one core at a time.

    The most re-plannable (:func:`~cosmop.team.conflicts.replan_rank`); of those, one whose
    robot is already re-planned this round: one more space to keep clear of costs a robot that
    is re-planned anyway little, and a robot not re-planned yet a whole synthesis.  On a tie,
    the first in the core as given.
    """

    def __init__(
        self, fixed: Mapping[str, Sequence[BaseGeometry]] | None, futile: Futile = frozenset()
    ) -> None:
        self.fixed, self.futile = fixed or {}, futile
        self.movers: set[str | None] = set()  # the robots of the conflicts set aside so far
        self._rank: dict[int, int] = {}
        self._mover: dict[int, str | None] = {}

    def rank(self, conflict: Conflict) -> int:
        """The conflict's :func:`~cosmop.team.conflicts.replan_rank` (lower: re-planned first).

        Parameters
        ----------
        conflict : Conflict
            A conflict between the plans.
        """
        if id(conflict) not in self._rank:
            self._rank[id(conflict)] = replan_rank(conflict, self.fixed, self.futile)
        return self._rank[id(conflict)]

    def mover(self, conflict: Conflict) -> str | None:
        """The robot re-planned around `conflict` (its best detour), if any.

        Parameters
        ----------
        conflict : Conflict
            A conflict between the plans.
        """
        if id(conflict) not in self._mover:
            self._mover[id(conflict)] = next(
                (robot for robot, _ in detours(conflict, self.fixed, self.futile)), None
            )
        return self._mover[id(conflict)]

    def pick(self, core: Sequence[Conflict], keep: bool = True) -> Conflict:
        """The culprit of `core`; with `keep`, its robot counts as re-planned from now on.

        Parameters
        ----------
        core : sequence of Conflict
            Conflicts no order resolves together (not empty).
        keep : bool
            Count the culprit's robot as re-planned.
        """
        n = {id(c): k for k, c in enumerate(core)}
        worst = min(core, key=lambda c: (self.rank(c), self.mover(c) not in self.movers, n[id(c)]))
        if keep:
            self.movers.add(self.mover(worst))
        return worst


_Label = TypeVar("_Label")


class _Graph(Generic[_Label]):
    """Which step completes before which: program order, messages and given start edges, and
    start edges pushed (and popped, or removed) in order, each labelled with what it orders.

    Steps are the rows of `precedence`, whose clocks prune the search for a path: only a step
    that completes before the path's end can be on it.  With `at` (label -> place, kept by the
    caller), :meth:`path` can stop at a place; the clocks must then be those of an order that
    holds every edge pushed."""

    def __init__(
        self,
        precedence: Precedence,
        links: Sequence[Link],
        starts: Sequence[Edge],
        at: Mapping[_Label, int] | None = None,
    ) -> None:
        self.precedence, self.at = precedence, at
        self.succ: dict[int, list[tuple[int, _Label | None]]] = {}  # row -> (next row, label)
        for robot, k in precedence.horizons.items():
            o = precedence.offsets[robot]
            for i in range(1, k):
                self.succ[o + i] = [(o + i + 1, None)]
        for link in links:
            if link.send is not None and link.wait is not None:
                self._add(((link.sender, link.send), (link.receiver, link.wait)), None)
        for edge in starts:
            self._add(edge, None)
        self.pushed: list[tuple[int, int, _Label | None]] = []  # (source, target, label) pushed

    def _add(self, edge: Edge, label: _Label | None) -> tuple[int, int, _Label | None]:
        source, target = self.precedence.rows(edge)
        self.succ.setdefault(source, []).append((target, label))
        return source, target, label

    def push(self, edge: Edge, label: _Label) -> None:
        self.pushed.append(self._add(edge, label))

    def pop(self) -> None:
        self.succ[self.pushed.pop()[0]].pop()

    def remove(self, start: int, labels: set[_Label]) -> None:
        """Take out the edges pushed from place `start` on whose labels are in `labels` (a
        label names one edge pushed)."""
        tail = self.pushed[start:]
        for source in {source for source, _, label in tail if label in labels}:
            self.succ[source] = [edge for edge in self.succ[source] if edge[1] not in labels]
        self.pushed[start:] = [edge for edge in tail if edge[2] not in labels]

    def path(self, source: Node, target: Node, before: int | None = None) -> list[_Label] | None:
        """The labels on a shortest path from `target` to `source` -- the cycle the start edge
        ``source -> target`` would close -- through the edges pushed before place `before`
        (default: all); ``None`` if there is none."""
        end, start = self.precedence.rows((source, target))
        on_way = self.precedence.done_before(end)  # only these can be on the path
        if not on_way >> start & 1:
            return None
        at = self.at if before is not None else None
        parent: dict[int, tuple[int, _Label | None] | None] = {start: None}
        queue = [start]
        for row in queue:
            if row == end:
                break
            for nxt, label in self.succ.get(row, ()):
                if not on_way >> nxt & 1 or nxt in parent:
                    continue
                if label is None or at is None or before is None or at[label] < before:
                    parent[nxt] = (row, label)
                    queue.append(nxt)
        if end not in parent:
            return None
        out: list[_Label] = []
        row = end
        while (step := parent[row]) is not None:
            row, label = step
            if label is not None:
                out.append(label)
        return out


class _OrientationTests:
    """Both orientations of every conflict (its two ways of ordering, its *sides*), as arrays,
    tested against the order many at once.

    Side 0 puts occupancy ``a`` first, side 1 ``b``: "x before y" is the start edge from
    x's last step to y's first.  A side is *possible* when x ends and y does not start at the
    beginning; it *holds* when the order already implies it; it *closes a cycle* when y's first
    step must already complete before x's last one does.
    """

    def __init__(
        self, found: Sequence[Conflict], precedence: Precedence, table: OrientationTable | None = None
    ) -> None:
        table = table if table is not None else OrientationTable.of(found, precedence.robots)
        self.edges = table.edges  # each side as a start edge, or None
        offset = np.array([precedence.offsets[r] for r in precedence.robots], dtype=np.int64)
        end = np.array([precedence.horizons[r] + 1 for r in precedence.robots], dtype=np.int64)

        def row(robot: np.ndarray, k: np.ndarray) -> np.ndarray:  # instants clamped to 0..K+1
            rows: np.ndarray = offset[robot] + np.clip(k, 0, end[robot])
            return rows

        # where each occupancy's expected start is read (0 when it holds from the beginning)
        column = precedence.column
        firsts = [(column[x.first[0]], x.first[1]) if x.first else (0, 0) for c in found for x in (c.a, c.b)]
        first = np.array(firsts, dtype=np.int64).reshape(len(found), 2, 2)
        self.from_start = first[..., 1] < 1
        self.first_row = np.where(self.from_start, 0, row(first[..., 0], first[..., 1]))
        # each side's x last step and y first step: their instants and their rows (also their
        # bits in the order's sets of steps)
        possible, ends = table.possible, table.ends
        x_k, y_k = ends[..., 1], ends[..., 3]
        x_row, y_row = row(ends[..., 0], x_k), row(ends[..., 2], y_k)
        same = ends[..., 0] == ends[..., 2]
        # a side within one robot's plan holds or closes a cycle by program order; else as the
        # order's sets say: x's last step completes before y's first starts (it holds), or y's
        # first completes before x's last does (it closes a cycle)
        # (where they read, with the places that always or never hold standing for the rest)
        fixed_hold = possible & np.where(same, x_k < y_k, x_k <= 0)
        fixed_way = possible & same & (y_k > x_k)
        by_order = possible & ~same
        never, always = precedence.never, precedence.always
        hold = precedence.places(x_row, y_row)
        self.hold_at = np.where(fixed_hold, always, np.where(by_order, hold, never))
        cycle = precedence.places(y_row, x_row)
        self.cycle_at = np.where(fixed_way, never, np.where(by_order, cycle, always))
        # each side's edge as rows (Precedence.rows: -1 for a step past the plan), as lists
        x_source = np.where(x_k > end[ends[..., 0]] - 1, -1, x_row)
        self.rows = np.stack([x_source, y_row], axis=-1).tolist()
        # the order keeps up to date only the copies read here (about a third of its steps)
        starts = np.unique(np.concatenate([y_row[by_order], self.first_row[~self.from_start]]))
        precedence.watch(np.unique(x_row[by_order]).tolist(), starts.tolist())

    def way(self, i: int, n: int) -> Edge:
        """Side `n` of conflict `i`, one that exists."""
        edge = self.edges[i][n]
        assert edge is not None  # (asked only of a possible side)
        return edge

    def others(self, i: int, taken: Edge) -> list[int]:
        """The sides of conflict `i` that exist other than the way `taken`."""
        return [n for n, edge in enumerate(self.edges[i]) if edge is not None and edge != taken]

    def other_way(self, i: int, taken: Edge) -> Edge:
        """The start edge of conflict `i`'s way other than `taken` (it has two)."""
        return self.way(i, self.others(i, taken)[0])

    def holds(self, precedence: Precedence, rows: np.ndarray | None = None) -> np.ndarray:
        """(n, 2): whether each side (of the conflicts `rows`, default all) is already implied."""
        which = slice(None) if rows is None else rows
        held: np.ndarray = precedence.completes_before(self.hold_at[which], start=True)
        return held

    def expected_start(self, precedence: Precedence, rows: np.ndarray) -> np.ndarray:
        """The expected start of the earlier occupancy of each conflict in `rows`, s."""
        started = np.where(self.from_start[rows], 0.0, precedence.start_times(self.first_row[rows]))
        earliest: np.ndarray = started.min(axis=1)
        return earliest

    def ways(self, precedence: Precedence, rows: np.ndarray | None = None) -> np.ndarray:
        """(n, 2): whether each side (of the conflicts `rows`, default all) can still be added
        without closing a cycle."""
        which = slice(None) if rows is None else rows
        free: np.ndarray = ~precedence.completes_before(self.cycle_at[which])
        return free


@dataclass(frozen=True)
class OrientationTable:
    """Every conflict's two ways, the orientations of its disjunctive edge (:func:`orientations_of`),
    and the same as arrays (:func:`orientation_arrays`): computed once for the search and
    :class:`~cosmop.team.conflict_order._Dominance`.

    Attributes
    ----------
    edges : list of list of (Edge or None)
        Per conflict, its two ways as start edges (``None`` where a way is not possible).
    possible : numpy.ndarray
        ``(n, 2)`` bool: which ways exist.
    ends : numpy.ndarray
        ``(n, 2, 4)`` int: each way as ``(A, i, B, j)``, the robots numbered.
    """

    edges: list[list[Edge | None]]
    possible: np.ndarray
    ends: np.ndarray

    @classmethod
    def of(cls, found: Sequence[Conflict], robots: Sequence[str]) -> OrientationTable:
        """The table of `found`, the robots numbered in the order of `robots` (then as met).

        Parameters
        ----------
        found : sequence of Conflict
            The conflicts.
        robots : sequence of str
            Robot ids, numbered in this order.
        """
        edges = [orientations_of(c) for c in found]
        return cls(edges, *orientation_arrays(edges, {r: n for n, r in enumerate(robots)}))


def orientation_arrays(
    ways: Sequence[Sequence[Edge | None]], number: dict[str, int]
) -> tuple[np.ndarray, np.ndarray]:
    """Every conflict's two ways (:func:`orientations_of`) as arrays: whether each exists ``(n, 2)``,
    and each as ``(A, i, B, j)`` ``(n, 2, 4)``, the robots numbered by `number` (robots it
    lacks are added, numbered in the order they come).

    Parameters
    ----------
    ways : sequence of sequence of (Edge or None)
        Each conflict's two ways.
    number : dict of str to int
        The robots' numbers (updated).
    """
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


def orientations_of(conflict: Conflict) -> list[Edge | None]:
    """The conflict's two ways as start edges, ``a`` first then ``b`` first: "x before y" for x
    that ends and y that does not hold its place from the beginning (else ``None``).  They are
    the two *orientations* of the conflict's disjunctive edge (a disjunctive graph's term).

    Parameters
    ----------
    conflict : Conflict
        A conflict between the plans.
    """
    return [
        (x.last, y.first) if x.last is not None and y.first is not None and y.first[1] >= 1 else None
        for x, y in ((conflict.a, conflict.b), (conflict.b, conflict.a))
    ]


def possible_orientations(conflict: Conflict) -> list[Edge]:
    """The start edges that can order `conflict` (its possible :func:`orientations_of`).

    Parameters
    ----------
    conflict : Conflict
        A conflict between the plans.
    """
    return [edge for edge in orientations_of(conflict) if edge is not None]


def depth_first(
    found: Sequence[Conflict],
    horizons: Mapping[str, int],
    links: Sequence[Link],
    starts: Sequence[Edge],
    durations: Mapping[str, Sequence[float]],
    max_backtracks: int,
    fixed: Mapping[str, Sequence[BaseGeometry]] | None,
    futile: Futile = frozenset(),
) -> tuple[list[tuple[Edge, Conflict]], Conflict | None]:
    """Depth-first search for edges ordering every conflict; ``(edges, None)`` or ``([], culprit)``.

    At every point the open conflicts are checked forward: one that has no way left to be
    ordered (both ways close a cycle, or the way left never ends) sends the search back to the
    last choice.  A conflict with a single way left is ordered first; otherwise the one expected
    to start first, the way that keeps the team's expected makespan lower.  The culprit is the
    conflict without a way at the deepest dead end.  The order is updated incrementally and
    taken back on backtracking (:meth:`~cosmop.team.precedence.Precedence.add_start`).

    Parameters
    ----------
    found : sequence of Conflict
        The conflicts to order.
    horizons : Mapping[str, int]
        Every robot's number of steps.
    links : sequence of Link
        The messages the plans already have.
    starts : sequence of (Node, Node)
        Start edges the order already has.
    durations : Mapping[str, sequence of float]
        Expected seconds of each robot's steps.
    max_backtracks : int
        Dead ends after which the search gives up.
    fixed : Mapping[str, sequence of shapely geometry] or None
        Each robot's places re-planning cannot move
        (:func:`~cosmop.team.conflicts.fixed_places`).
    futile : Futile
        Ways around known not to work (:func:`~cosmop.team.conflicts.replan_rank`).
    """
    precedence = Precedence(horizons, links, starts, durations)
    orientations = _OrientationTests(found, precedence)
    chosen: list[tuple[Edge, Conflict, list[Any]]] = []
    stack: list[tuple[int, list[Edge], Conflict]] = []  # (depth, untried, conflict)
    backtracks, deepest = 0, -1
    culprit: Conflict | None = None
    while True:
        open_ = ~orientations.holds(precedence).any(axis=1)
        if not open_.any():
            return [(edge, conflict) for edge, conflict, _ in chosen], None
        counts = np.where(open_, orientations.ways(precedence).sum(axis=1), -1)
        stuck = [found[int(i)] for i in np.flatnonzero(counts == 0)]
        if stuck:
            if len(chosen) > deepest:
                edges = [(e, c) for e, c, _ in chosen]
                worst = min(stuck, key=lambda c: replan_rank(c, fixed, futile))
                deepest, culprit = (
                    len(chosen),
                    _culprit(worst, precedence, links, starts, edges, fixed, futile),
                )
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
        conflict = found[pool[np.argmin(orientations.expected_start(precedence, pool))]]
        options = _options(conflict, precedence)
        if len(options) > 1:
            stack.append((len(chosen), options[1:], conflict))
        chosen.append((options[0], conflict, precedence.add_start(options[0])))


def _options(conflict: Conflict, precedence: Precedence) -> list[Edge]:
    """The ways left to order `conflict`, best first: the occupancy expected to begin first goes
    first (the robot that gets there first), and of two expected at once the way that keeps the
    team's expected makespan lower."""
    options = _ways(conflict, precedence)
    if len(options) > 1:
        starts = [_start(x, precedence) for x in _first_of(conflict, options)]
        if abs(starts[0] - starts[1]) <= _AT_ONCE:
            options = sorted(options, key=lambda e: _makespan_with(precedence, e))
    return options


_AT_ONCE = 1e-6
"""Seconds within which two occupancies count as expected to begin at once."""


def _first_of(conflict: Conflict, options: list[Edge]) -> list[Occupancy]:
    """The occupancy that goes first in each of `options` (start edges of `conflict`)."""
    a, b = conflict.a, conflict.b
    return [a if (a.last, b.first) == edge else b for edge in options]


def _start(x: Occupancy, precedence: Precedence) -> float:
    return 0.0 if x.first is None else precedence.start_time(x.first)


def _makespan_with(precedence: Precedence, edge: Edge) -> float:
    log = precedence.add_start(edge)
    makespan = precedence.makespan
    precedence.undo(log)
    return makespan


def _culprit(
    stuck: Conflict,
    precedence: Precedence,
    links: Sequence[Link],
    starts: Sequence[Edge],
    chosen: Sequence[tuple[Edge, Conflict]],
    fixed: Mapping[str, Sequence[BaseGeometry]] | None,
    futile: Futile = frozenset(),
) -> Conflict:
    """The conflict to re-plan around when `stuck` has no way to be ordered.

    If `stuck` itself cannot be re-planned (two robots standing where their goods require), the
    orders that close its cycles came from other conflicts: the most re-plannable of those.
    """
    if replan_rank(stuck, fixed, futile) < 3:
        return stuck
    graph: _Graph[Conflict] = _Graph(precedence, links, starts)
    for edge, conflict in chosen:
        graph.push(edge, conflict)
    on_cycles: list[Conflict] = []
    for edge in possible_orientations(stuck):
        on_cycles += graph.path(*edge) or []
    best = min(on_cycles, key=lambda c: replan_rank(c, fixed, futile), default=stuck)
    return best if replan_rank(best, fixed, futile) < 3 else stuck


def _ways(conflict: Conflict, precedence: Precedence) -> list[Edge]:
    """The start edges that can order `conflict`, the one expected to happen first first."""
    a, b = conflict.a, conflict.b
    options = sorted(((a, b), (b, a)), key=lambda xy: (_start(xy[0], precedence), _start(xy[1], precedence)))
    out: list[Edge] = []
    for x, y in options:
        if x.last is None or y.first is None:
            continue  # x never ends, or y holds its place from the beginning
        if precedence.would_cycle(x.last, y.first):
            continue
        out.append((x.last, y.first))
    return out
