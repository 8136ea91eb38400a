"""Conflicts between robots' plans: places two plans use, and the orders that keep them apart.

Each robot's plan is checked alone against the scene as it knows it; two plans can still need
the same place.  An *occupancy* is a region held over an interval of the team's execution,
from the start of one step to the completion of another (:class:`Occupancy`):

* a robot at pose :math:`p_k` holds its square from the start of step *k* (time 0 for
  :math:`k = 0`) to the completion of step *k + 1*, and forever after its last step; so a robot
  between two steps, or waiting for a message, holds the place where it stands;
* a robot's ``GoTo`` step *k* holds the area it sweeps (the convex hull of its squares at the
  two ends) during that step;
* an object rests at its scenario position until its first ``PickUp`` completes, and where a
  ``DropOff`` puts it from that step's start until it is picked again (or forever).

Robot regions are grown by half the clearance the simulator keeps between moving robots
(:attr:`ConflictSettings.clearance`), so that two of them closer than that overlap; objects are
not grown.  Two occupancies of different robots (an object counts for the robots that move it)
*conflict* when their regions' interiors overlap, and the conflict is *ordered* when one of
them always ends before the other starts (:meth:`cosmop.missions.precedence.Precedence.before_start`).
A plan set is team-safe when every conflict is ordered: then no execution the messages allow
puts two robots, or a robot and another robot's goods, in one place at one time.

:func:`order_conflicts` orders the open conflicts by adding start edges: the occupancy that
is expected to begin first (:mod:`cosmop.planning.timing`) goes first, unless that closes a
cycle (a deadlock) or it never ends (a robot parked for good); an edge is never added that
would deadlock.  Conflicts that no order can resolve are returned for re-planning.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from decimal import Decimal
from fractions import Fraction

import numpy as np
import shapely
from shapely import STRtree
from shapely.geometry.base import BaseGeometry

from cosmop.events import Primitive
from cosmop.missions.precedence import Link, Node, Precedence
from cosmop.planning.plan import RobotPlan, State, _fmt, _point, initial_state
from cosmop.planning.realisation import at_pose
from cosmop.scene import Scene
from cosmop.squares import square, swept_square

__all__ = [
    "Conflict",
    "ConflictSettings",
    "Occupancy",
    "conflicts",
    "occupancies",
    "order_conflicts",
]


@dataclass(frozen=True)
class ConflictSettings:
    """How conflicts are found.

    Attributes
    ----------
    clearance : float
        Distance (mm) two robots keep when both may move: their regions are grown by half of it
        (the simulator's standoff, 100 mm by default).
    segment : float
        Drives longer than this (mm) are cut into pieces before ordering, so that a robot waits
        only until another has passed the place they share (default 1500).
    rest : float
        How far (mm) a standing robot may be off its planned pose (the simulator stops within
        its goal tolerance, 15 mm): goods another robot moves keep this from where it stands.
    """

    clearance: float = 100.0
    segment: float = math.inf
    rest: float = 20.0


@dataclass(frozen=True)
class Occupancy:
    """A region held from the start of step `first` to the completion of step `last`.

    Attributes
    ----------
    what : str
        The robot or object that holds it.
    parties : frozenset of str
        The robots whose plans decide it: the robot itself, or the robots that move the object.
    region : shapely geometry
        The region (mm).
    first : Node or None
        ``(robot, k)``: held from the start of step *k*; ``None``: from the beginning.
    last : Node or None
        ``(robot, k)``: held until step *k* completes; ``None``: forever.
    label : str
        In words, e.g. ``R1's GoTo at instant 3 from (0, 0) to (500, 0)``.
    movable : bool
        Whether re-planning can move it: a drive can take another route and goods can be put
        down elsewhere, but a robot's start, the pose it picks from and its home cannot move,
        nor where goods start.
    body : shapely geometry, optional
        The region without the clearance robots keep from each other (a robot may pass goods
        as close as its plan allows); by default `region`.
    """

    what: str
    parties: frozenset[str]
    region: BaseGeometry = field(repr=False)
    first: Node | None
    last: Node | None
    label: str
    movable: bool = True
    body: BaseGeometry | None = field(default=None, repr=False)


@dataclass(frozen=True)
class Conflict:
    """Two occupancies of different robots whose regions overlap.

    Attributes
    ----------
    a, b : Occupancy
        The two occupancies; "``a`` before ``b``" is one way of ordering them.
    """

    a: Occupancy
    b: Occupancy

    @property
    def place(self) -> tuple[float, float, float, float]:
        """Bounding box ``(x_min, y_min, x_max, y_max)`` of the shared region (mm)."""
        shared = self.a.region.intersection(self.b.region)
        if shared.is_empty:
            shared = self.a.region
        return tuple(float(v) for v in shared.bounds)

    @property
    def robots(self) -> tuple[str, ...]:
        return tuple(sorted(self.a.parties | self.b.parties))

    def describe(self) -> str:
        """The two occupancies and the space they share, in words."""
        return f"{self.a.label} and {self.b.label} share the space {self.space()}"

    def space(self) -> str:
        """The shared space's bounding box in words: ``x in [.., ..], y in [.., ..]`` (mm)."""
        x0, y0, x1, y1 = (_fmt(round(v, 1)) for v in self.place)
        return f"x in [{x0}, {x1}], y in [{y0}, {y1}]"


def _robot_occupancies(
    robot: str,
    plan: RobotPlan,
    start: State,
    side: float,
    home: Sequence[float],
    grow: float = 0.0,
    rest: float = 0.0,
) -> list[Occupancy]:
    """Where `robot` stands (merged over steps that keep its pose) and what its GoTo steps sweep.

    A standing robot's body, which goods keep clear of, is its square grown by `rest`.
    """
    K = plan.horizon
    poses = [start.robot, *(s.robot for s in plan.steps)]
    party = frozenset((robot,))
    out: list[Occupancy] = []
    k = 0
    while k <= K:
        end = k
        while end < K and plan.steps[end].primitive != Primitive.GOTO:
            end += 1  # steps end+1 keep the pose
        x, y, _ = poses[k]
        first = None if k == 0 else (robot, k)
        last = None if end + 1 > K else (robot, end + 1)
        where = "at its start" if k == 0 else f"from instant {k}"
        fixed = (
            k == 0
            or any(plan.steps[i].primitive == Primitive.PICKUP for i in range(k, end))
            or (end == K and at_pose(poses[k], home))
        )
        out.append(
            Occupancy(
                robot,
                party,
                square(x, y, side),
                first,
                last,
                f"{robot} standing at {_point((x, y))} {where}",
                not fixed,
                square(x, y, side - grow + 2 * rest),
            )
        )
        k = end + 1
    for k, step in enumerate(plan.steps, 1):
        if step.primitive == Primitive.GOTO:
            p, q = poses[k - 1], poses[k]
            out.append(
                Occupancy(
                    robot,
                    party,
                    swept_square(p, q, side),
                    (robot, k),
                    (robot, k),
                    f"{robot}'s GoTo at instant {k} from {_point(p[:2])} to {_point(q[:2])}",
                    True,
                    swept_square(p, q, side - grow),
                )
            )
    return out


def _object_occupancies(
    scene: Scene,
    plans: Mapping[str, RobotPlan],
    precedence: Precedence,
    positions: Mapping[str, tuple[float, float] | None] | None = None,
) -> tuple[list[Occupancy], list[str]]:
    """Where every moved object rests between the steps that handle it; problems found.

    `positions` gives where objects are at the start (``None``: carried); by default the scene's.
    """
    out, problems = [], []
    for oid, spec in scene.objects.items():
        handling = [
            (robot, k, step.primitive)
            for robot, plan in plans.items()
            for k, step in enumerate(plan.steps, 1)
            if step.object == oid and step.primitive in (Primitive.PICKUP, Primitive.DROPOFF)
        ]
        if not handling:
            continue
        handling.sort(key=lambda h: (precedence.start_time((h[0], h[1])), h[0], h[1]))
        for (r1, k1, _), (r2, k2, _) in itertools.pairwise(handling):
            if not precedence.precedes((r1, k1), (r2, k2)):
                problems.append(
                    f"{oid} is handled by {r1} at instant {k1} and by {r2} at instant {k2} with no "
                    "order between them"
                )
        parties = frozenset(h[0] for h in handling)
        position, first = (positions or {}).get(oid, spec.position), None
        for robot, k, primitive in handling:
            if primitive == Primitive.PICKUP:
                if position is not None:
                    where = "at its start" if first is None else f"from {first[0]}'s instant {first[1]}"
                    out.append(
                        Occupancy(
                            oid,
                            parties,
                            square(*position, spec.size),
                            first,
                            (robot, k),
                            f"{oid} resting at {_point(position)} {where}",
                            first is not None,
                        )
                    )
                position = None
            else:
                position, first = plans[robot].steps[k - 1].objects[oid].position, (robot, k)
        if position is not None:
            where = "at its start" if first is None else f"from {first[0]}'s instant {first[1]}"
            out.append(
                Occupancy(
                    oid,
                    parties,
                    square(*position, spec.size),
                    first,
                    None,
                    f"{oid} resting at {_point(position)} {where}",
                    first is not None,
                )
            )
    return out, problems


def occupancies(
    scene: Scene,
    plans: Mapping[str, RobotPlan],
    precedence: Precedence,
    settings: ConflictSettings | None = None,
    starts: Mapping[str, State] | None = None,
    positions: Mapping[str, tuple[float, float] | None] | None = None,
) -> tuple[list[Occupancy], list[str]]:
    """Every occupancy of the robots and the objects they move; problems with object handling.

    `starts` gives the robots' states at the start when it is not the scenario (mid-run), and
    `positions` where the objects are then (``None``: carried).
    """
    settings = settings or ConflictSettings()
    grow = settings.clearance
    out: list[Occupancy] = []
    for robot, plan in plans.items():
        start = (starts or {}).get(robot) or initial_state(scene, robot)
        size, home = scene.robots[robot].size + grow, scene.robots[robot].pose
        out += _robot_occupancies(robot, plan, start, size, home, grow, settings.rest)
    objects, problems = _object_occupancies(scene, plans, precedence, positions)
    return out + objects, problems


def conflicts(items: Sequence[Occupancy]) -> list[Conflict]:
    """Pairs of occupancies of disjoint parties whose regions' interiors overlap."""
    if not items:
        return []
    regions = [item.region for item in items]
    tree = STRtree(regions)
    left, right = tree.query(regions, predicate="intersects")
    keep = left < right
    out = []
    for i, j in zip(left[keep].tolist(), right[keep].tolist(), strict=True):
        a, b = items[i], items[j]
        if a.parties & b.parties:
            continue
        robots = a.what in a.parties and b.what in b.parties
        ra, rb = (a.region, b.region) if robots else (a.body or a.region, b.body or b.region)
        if shapely.intersection(ra, rb).area <= 1e-9:
            continue  # they only touch (a robot keeps its clearance from robots, not from goods)
        out.append(Conflict(a, b))
    return out


def is_ordered(conflict: Conflict, precedence: Precedence) -> bool:
    """Whether one occupancy always ends before the other starts."""
    a, b = conflict.a, conflict.b
    return _before(a, b, precedence) or _before(b, a, precedence)


def _before(x: Occupancy, y: Occupancy, precedence: Precedence) -> bool:
    return x.last is not None and y.first is not None and precedence.before_start(x.last, y.first)


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

    First a depth-first search over the two ways of ordering each conflict (:func:`_search`),
    fast when the conflicts are few or loosely tied.  When it finds no way to order them all,
    the question is settled exactly as a scheduling problem (:class:`_Schedule`, Z3 over the
    steps' start and end times): either a schedule orders every conflict, or an unsat core
    names a set of conflicts no order resolves together, of which the most re-plannable is set
    aside -- and the others are ordered again without it.  Z3's cores are not minimal, so a
    conflict set aside early may be orderable once later ones are gone: each is then given
    back, the hardest to re-plan first, while a schedule still exists.  The unresolved
    conflicts returned are therefore irredundant: none of them could be ordered together with
    all the ordered ones.

    Returns the edges added (on top of `starts`), each with the conflict it orders, and the
    unresolved conflicts.
    """
    chosen, culprit = _search(found, horizons, links, starts, durations, max_backtracks, fixed)
    if culprit is None:
        return chosen, []
    schedule = _Schedule(found, horizons, links, starts, durations, rlimit)
    unresolved: list[Conflict] = []
    gone: set[int] = set()
    while (core := schedule.solve([c for c in found if id(c) not in gone])) is not None:
        if not core:  # undecided within the solver's budget: the search's culprit stays unresolved
            return _give_up(found, culprit, horizons, links, starts, durations, max_backtracks, fixed)
        unresolved.append(min(core, key=lambda c: _replannable(c, fixed)))
        gone.add(id(unresolved[-1]))
    # Cores are not minimal, so a conflict set aside early may be orderable once later ones are
    # gone: give each back, the hardest to re-plan first, while a schedule remains (one the last
    # schedule already orders costs no solver call).
    for conflict in sorted(unresolved, key=lambda c: -_replannable(c, fixed)):
        gone.discard(id(conflict))
        if (
            schedule.way(conflict) is None
            and schedule.solve([c for c in found if id(c) not in gone]) is not None
        ):
            gone.add(id(conflict))
        else:
            unresolved.remove(conflict)
    # the search's choices keep the makespan low; the schedule stands in where the search fails
    left = [c for c in found if id(c) not in gone]
    better, culprit = _search(left, horizons, links, starts, durations, max_backtracks, fixed)
    return (schedule.edges(left) if culprit is not None else better), unresolved


def _give_up(found, culprit, horizons, links, starts, durations, max_backtracks, fixed):
    """Order what the search can, leaving each conflict it fails on unresolved (sound, not minimal)."""
    unresolved, gone = [culprit], {id(culprit)}
    while True:
        left = [c for c in found if id(c) not in gone]
        chosen, culprit = _search(left, horizons, links, starts, durations, max_backtracks, fixed)
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
    """

    def __init__(self, found, horizons, links, starts, durations, rlimit: int) -> None:
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
        text += [f"(declare-fun c{n} () Bool)" for n in range(len(found))]
        for r, k in self.index:
            text.append(f"(assert (>= {s[(r, k)]} {e[(r, k - 1)] if k > 1 else 0.0}))")
            text.append(f"(assert {_after(e[(r, k)], s[(r, k)], float(durations[r][k - 1]))})")
        for link in links:
            if link.send is not None and link.wait is not None:
                text.append(f"(assert {_after(e[(link.receiver, link.wait)], e[(link.sender, link.send)])})")
        for source, target in starts:
            if target in s and source in e:
                text.append(f"(assert {_after(s[target], e[source])})")
        self.ways: dict[int, list] = {}
        for n, c in enumerate(found):
            ways = [
                (x.last, y.first)
                for x, y in ((c.a, c.b), (c.b, c.a))
                if x.last in e and y.first in s  # (None: never ends, or from the beginning)
            ]
            terms = " ".join(_after(s[b], e[a]) for a, b in ways)
            text.append(f"(assert (=> c{n} (or false {terms})))")
            self.ways[id(c)] = ways
        self.solver.from_string("\n".join(text))
        self.label = {id(c): z3.Bool(f"c{n}", ctx) for n, c in enumerate(found)}
        self.by_id = {label.get_id(): c for c, label in zip(found, self.label.values(), strict=True)}

    def solve(self, conflicts: Sequence[Conflict]) -> list[Conflict] | None:
        """``None`` when a schedule orders `conflicts` (kept for :meth:`edges`); else an unsat
        core of them, or ``[]`` when undecided within the resource limit."""
        import z3

        verdict = _check(self.solver, [self.label[id(c)] for c in conflicts])
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
        for i, c in enumerate(found):
            for side, (x, y) in enumerate(((c.a, c.b), (c.b, c.a))):
                if x.last is None or y.first is None or y.first[1] <= 0:
                    continue
                (xr, xk), (yr, yk) = x.last, y.first
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
                worst = min(stuck, key=lambda c: _replannable(c, fixed))
                deepest, culprit = len(chosen), _culprit(worst, horizons, links, edges, fixed)
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
        conflict = min((found[i] for i in pool), key=lambda c: _expected_start(c, precedence))
        options = _ways(conflict, precedence)
        if len(options) > 1:  # the robot of higher priority first, then the lower makespan
            options = sorted(options, key=lambda e: (rank[e[0][0]], _makespan_with(precedence, e)))
            stack.append((len(chosen), options[1:], conflict))
        chosen.append((options[0], conflict, precedence.add_start(options[0])))


def _expected_start(conflict: Conflict, precedence: Precedence) -> float:
    return min(_start(conflict.a, precedence), _start(conflict.b, precedence))


def _start(x: Occupancy, precedence: Precedence) -> float:
    return 0.0 if x.first is None else precedence.start_time(x.first)


def _makespan_with(precedence: Precedence, edge: tuple[Node, Node]) -> float:
    log = precedence.add_start(edge)
    makespan = precedence.makespan
    precedence.undo(log)
    return makespan


def _culprit(stuck: Conflict, horizons, links, chosen, fixed) -> Conflict:
    """The conflict to re-plan around when `stuck` has no way to be ordered.

    If `stuck` itself cannot be re-planned (two robots standing where their goods require), the
    orders that close its cycles came from other conflicts: the most re-plannable of those.
    """
    if _replannable(stuck, fixed) < 3:
        return stuck
    graph: dict[Node, list[tuple[Node, Conflict | None]]] = {}
    for robot, k in horizons.items():
        for i in range(1, k):
            graph.setdefault((robot, i), []).append(((robot, i + 1), None))
    for link in links:
        if link.send is not None and link.wait is not None:
            graph.setdefault((link.sender, link.send), []).append(((link.receiver, link.wait), None))
    for (source, target), conflict in chosen:
        graph.setdefault(source, []).append((target, conflict))
    on_cycles: list[Conflict] = []
    for x, y in ((stuck.a, stuck.b), (stuck.b, stuck.a)):
        if x.last is not None and y.first is not None:
            on_cycles += _path_conflicts(graph, y.first, x.last)
    best = min(on_cycles, key=lambda c: _replannable(c, fixed), default=stuck)
    return best if _replannable(best, fixed) < 3 else stuck


def _path_conflicts(graph, start: Node, goal: Node) -> list[Conflict]:
    """The conflicts whose edges lie on a shortest path from `start` to `goal` (breadth first)."""
    parent: dict[Node, tuple[Node, Conflict | None] | None] = {start: None}
    queue = [start]
    for node in queue:
        if node == goal:
            break
        for nxt, conflict in graph.get(node, ()):
            if nxt not in parent:
                parent[nxt] = (node, conflict)
                queue.append(nxt)
    out, node = [], goal
    while parent.get(node) is not None:
        node, conflict = parent[node]
        if conflict is not None:
            out.append(conflict)
    return out


def detours(conflict: Conflict, fixed: Mapping[str, Sequence[BaseGeometry]]) -> list[tuple[str, Occupancy]]:
    """Who can be re-planned around an unresolved conflict, best first: ``(robot, what to avoid)``.

    The side that moves must be movable (:attr:`Occupancy.movable`): a drive (best: one that
    meets something staying for good) or dropped goods (moved by the robot that drops them).
    Avoiding the other side must leave the mover's fixed places -- its start, the poses it picks
    from, its home, given in `fixed` by robot (regions already grown) -- free.
    """
    return [(robot, keep) for _, robot, keep in ranked_detours(conflict, fixed)]


def ranked_detours(
    conflict: Conflict, fixed: Mapping[str, Sequence[BaseGeometry]]
) -> list[tuple[int, str, Occupancy]]:
    """:func:`detours` with each way's rank: 0 a drive around something staying for good, 1 a
    drive around something passing, 2 goods dropped elsewhere."""
    out = []
    for mover, keep in ((conflict.a, conflict.b), (conflict.b, conflict.a)):
        if not mover.movable or mover.first is None:
            continue
        robot = mover.what if mover.what in mover.parties else mover.first[0]
        if any(shapely.intersection(keep.region, place).area > 1e-9 for place in fixed.get(robot, ())):
            continue
        drive = mover.first == mover.last
        out.append((0 if drive and keep.last is None else 1 if drive else 2, robot, keep))
    return sorted(out, key=lambda o: o[0])


def fixed_places(items: Sequence[Occupancy]) -> dict[str, list[BaseGeometry]]:
    """Every robot's places that re-planning cannot move (start, pick poses, home), by robot."""
    out: dict[str, list[BaseGeometry]] = {}
    for item in items:
        if not item.movable and item.what in item.parties:
            out.setdefault(item.what, []).append(item.region)
    return out


def _replannable(conflict: Conflict, fixed: Mapping[str, Sequence[BaseGeometry]] | None = None) -> int:
    """Rank of a conflict as a culprit to re-plan (lower first): a drive against something that
    stays for good, then any detour, then none (two robots standing where their goods require)."""
    options = detours(conflict, fixed or {})
    if not options:
        return 3
    _, keep = options[0]
    return 0 if keep.last is None else 1


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
