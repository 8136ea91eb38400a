"""Team-safe plans: every place two robots' plans share is ordered by a message.

:func:`make_team_safe` takes plans that are each sound alone (and the messages they already
have), finds their conflicts (:mod:`cosmop.team.conflicts`), orders each one by a start
edge (:mod:`cosmop.team.conflict_order`) -- the occupancy expected first goes first, never
closing a cycle -- drops the edges the others imply, and turns the rest into messages
(:mod:`cosmop.planning.messages`): the robot that must wait gets a ``Req`` right before the
step that enters the shared place, the other a ``Res`` right after the step that leaves it.
Conflicts no order can resolve (a robot parked for good where another must pass, or two
orders that would wait on each other) are returned, for the caller to re-plan one robot around
the other's space.

Drives are cut where they enter and leave the places other robots use, so that a robot waits
only for the shared piece (:func:`_cut_where_shared`).  A cut is also a place to stand, and a
robot waiting there may be in the way of another and close a cycle of waits.  When a robot
stands at a cut in every conflict left unresolved, only those drives are made whole again;
otherwise (or when that leaves no fewer unresolved) every drive of the robots in them, then of
every robot.

Expected times come from :mod:`cosmop.team.timing`, so the orders follow what is likely to
happen first and the team's makespan stays low.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Collection, Mapping, Sequence
from dataclasses import dataclass, field, replace

import numpy as np
import shapely
from shapely.geometry.base import BaseGeometry

from cosmop.events import Event, Link, Node, Primitive
from cosmop.io import collector_paused
from cosmop.planning.messages import CUT_GRAIN, cut_drives, merge_drives, place_edges, split_drives
from cosmop.planning.plan_types import PlanMessage, RobotPlan, State
from cosmop.planning.realisation import message_links
from cosmop.scene import Scene
from cosmop.squares import swept_square
from cosmop.team.conflict_order import order_conflicts
from cosmop.team.conflicts import (
    Conflict,
    ConflictSettings,
    Futile,
    Occupancy,
    conflicts,
    fixed_places,
    is_ordered,
    occupancies,
    ranked_detours,
)
from cosmop.team.precedence import Precedence
from cosmop.team.timing import durations, start_pose

__all__ = ["TeamSafety", "Wait", "make_team_safe"]

_Drive = tuple[tuple[float, float], tuple[float, float]]
"""The centres (mm) at the two ends of a drive."""

_Order = tuple[tuple[Node, Node], Conflict]
"""A start edge chosen for a conflict, with the conflict."""

_Placed = tuple[Event, tuple[Node, Node], tuple[Node, Node]]
"""A message placed for a start edge: its event, the edge, and the edge in the new instants."""

_Context = tuple[
    Scene,
    ConflictSettings,
    Mapping[str, State] | None,
    Mapping[str, tuple[float, float] | None] | None,
    str | None,
    set[Event] | None,
    frozenset[tuple[str, ...]],
    int | None,
    Futile,
]
"""What every ordering attempt shares: ``(scene, settings, starts, positions, about, used, also,
max_set_aside, futile)``."""


@dataclass(frozen=True)
class Wait:
    """How long one conflict's order keeps a robot waiting, by the itinerary.

    Attributes
    ----------
    seconds : float
        Expected seconds the robot waits at the message's ``Req`` (0 when the other has left
        the shared place before it gets there).
    robot, other : str
        The robot that waits and the robot it waits for.
    message : Event
        The message's event.
    conflict : Conflict
        The conflict the message orders.
    first, then : Occupancy
        The occupancy that goes first (`other`'s side) and the one that waits for it.
    drives : tuple or None
        When both sides are drives: ``((p, q), (p', q'))``, the centres (mm) at the two ends of
        the first's drive and of the waiting one's.
    critical : bool
        Whether the wait lies on the path of waits and steps that ends the team's itinerary
        last: only such a wait, made shorter, can end the team sooner.
    """

    seconds: float
    robot: str
    other: str
    message: Event
    conflict: Conflict = field(repr=False)
    first: Occupancy = field(repr=False)
    then: Occupancy = field(repr=False)
    drives: tuple[tuple[tuple[float, float], tuple[float, float]], ...] | None = None
    critical: bool = False


@dataclass(frozen=True)
class TeamSafety:
    """Result of :func:`make_team_safe`.

    Attributes
    ----------
    plans : Mapping[str, RobotPlan]
        The plans with the conflict messages in place.
    messages : tuple of PlanMessage
        The messages added, each with what it protects and where.
    conflicts : int
        Conflicts found between the plans.
    ordered_before : int
        Of those, how many the plans' own messages already ordered.
    unresolved : tuple of Conflict
        Conflicts no order can resolve (then ``plans`` are not team-safe); of an attempt
        stopped at its limit (`max_set_aside`), those set aside when it stopped.
    makespan_alone, makespan : float
        Expected seconds until the whole team is done: each robot on its own (no waiting), and
        with every message.
    time_s : float
        Seconds this took.
    fixed : Mapping[str, list of shapely geometry]
        Every robot's places that re-planning cannot move (to choose detours).
    chosen : int
        Orders the search chose (one per conflict it ordered, before the implied ones are
        dropped).
    flipped : int
        Of those, the orders that let go first the robot the itineraries expect there later:
        where a cycle made the search depart from time (:mod:`cosmop.team.conflict_search`).
    waits : tuple of Wait
        Every conflict message's expected wait, the longest first.
    futile : Futile
        Ways around known not to work when it was made (:meth:`detours` leaves them out).
    """

    plans: Mapping[str, RobotPlan]
    messages: tuple[PlanMessage, ...]
    conflicts: int
    ordered_before: int
    unresolved: tuple[Conflict, ...]
    makespan_alone: float
    makespan: float
    time_s: float
    fixed: Mapping[str, list[BaseGeometry]] = field(default_factory=dict, repr=False)
    chosen: int = 0
    flipped: int = 0
    waits: tuple[Wait, ...] = ()
    futile: Futile = frozenset()

    @property
    def safe(self) -> bool:
        return not self.unresolved

    def detours(self, conflict: Conflict) -> list[tuple[int, str, Occupancy]]:
        """Who can be re-planned around `conflict`, best first, each with its rank
        (:func:`~cosmop.team.conflicts.ranked_detours`): ``(rank, robot, what to avoid)``.

        Parameters
        ----------
        conflict : Conflict
            A conflict between the plans (one of :attr:`unresolved`).
        """
        return ranked_detours(conflict, self.fixed, self.futile)


def _reduce(horizons: Mapping[str, int], links: Sequence[Link], chosen: Sequence[_Order]) -> list[_Order]:
    """Drop every edge that the program order, the messages and the other kept edges imply.

    The edge ``(A, i) -> start of (B, j)`` is implied when, without it, a path leads from A's
    step *i* to a step of B before *j* or to another edge into the start of B's step *j*.
    Such a path leaves A's step *i* by one of its other edges: its next step, a message it
    sends, or another kept edge from it.  So the edge is implied iff one of those successors
    completes before B's step *j* starts, which the vector clocks of the order with every
    chosen edge decide (:meth:`~cosmop.team.precedence.Precedence.before_start`).  That
    order has the same paths as the kept edges at every point, because an edge is dropped only
    when the others imply it; and no path from a successor of A's step *i* runs through the
    edge itself, since the order has no cycle (the chosen orders are deadlock-free).  The edges
    are looked at from the last chosen to the first, and of two equal edges the first stays.
    """
    order = Precedence(horizons, links, [edge for edge, _ in chosen])
    if not order.complete:
        raise ValueError("the chosen orders deadlock")
    links_out: dict[Node, list[Node]] = {}
    for link in links:
        if link.send is not None and link.wait is not None:
            links_out.setdefault((link.sender, link.send), []).append((link.receiver, link.wait))
    starts: dict[Node, list[Node]] = {}
    by_pair: dict[tuple[str, str], list[int]] = {}  # the edges robot to robot
    for n, ((source, target), _) in enumerate(chosen):
        starts.setdefault(source, []).append(target)
        by_pair.setdefault((source[0], target[0]), []).append(n)
    pairs = {key: np.array(members) for key, members in by_pair.items()}
    ends = np.array([(source[1], target[1]) for (source, target), _ in chosen], dtype=np.int64).reshape(-1, 2)
    kept = np.ones(len(chosen), dtype=bool)
    for n in reversed(range(len(chosen))):
        source, target = chosen[n][0]
        starts[source].remove(target)
        # another kept edge from later in A's plan to earlier in B's implies it at once
        pair = pairs[(source[0], target[0])]
        later = kept[pair] & (ends[pair, 0] >= source[1]) & (ends[pair, 1] <= target[1]) & (pair != n)
        if later.any() or _implied(order, horizons, links_out, starts, source, target):
            kept[n] = False
        else:
            starts[source].append(target)
    return [item for n, item in enumerate(chosen) if kept[n]]


def _implied(
    order: Precedence,
    horizons: Mapping[str, int],
    links_out: Mapping[Node, list[Node]],
    starts: Mapping[Node, list[Node]],
    source: Node,
    target: Node,
) -> bool:
    """Whether `source` completes before `target` starts by a way that leaves it through its
    next step, a message it sends or a kept edge in `starts` (:func:`_reduce`)."""
    (r, k), (robot, j) = source, target
    if r == robot and k < j:
        return True
    onward = starts.get(source, [])
    if target in onward:  # an equal edge, kept
        return True
    nxt = [(r, k + 1)] if k < horizons[r] else []
    return any(order.before_start(node, target) for node in (*nxt, *links_out.get(source, ()), *onward))


@collector_paused()
def make_team_safe(
    scene: Scene,
    plans: Mapping[str, RobotPlan],
    *,
    settings: ConflictSettings | None = None,
    used: set[Event] | None = None,
    starts: Mapping[str, State] | None = None,
    positions: Mapping[str, tuple[float, float] | None] | None = None,
    about: str | None = None,
    also: Collection[tuple[str, ...]] = (),
    max_set_aside: int | None = None,
    futile: Futile = frozenset(),
) -> TeamSafety:
    """Order every conflict between `plans` by messages (see the module docstring).

    Parameters
    ----------
    scene : Scene
        The scenario's scene (walls, robots, objects).
    plans : Mapping[str, RobotPlan]
        Every robot's plan, sound alone, with the messages it already has (no deadlock).
    settings : ConflictSettings, optional
        How conflicts are found (default :class:`~cosmop.team.conflicts.ConflictSettings`).
    used : set of Event, optional
        Messages already taken (new ones avoid them; the set is updated).
    starts : Mapping[str, State], optional
        The robots' states at instant 0 when it is not the scenario (re-coordination mid-run).
    positions : Mapping[str, tuple or None], optional
        Where the objects are at instant 0 (``None``: carried), when it is not the scenario.
    about : str, optional
        Order only the conflicts of this robot's plan (the others' plans are already ordered
        among themselves: a robot that replanned mid-run).
    also : collection of tuple of str
        With `about`: the parties (as :attr:`Conflict.robots` names them) whose conflicts are
        ordered too where the plans no longer order them (the robot's old messages ordered
        them, passing through it: :func:`cosmop.sim.recoordinate.recoordinate`).
    max_set_aside : int, optional
        An ordering attempt stops once its search has set aside more conflicts than this (it
        cannot be safe then; :func:`~cosmop.team.conflict_order.order_conflicts`); its
        unresolved conflicts are those set aside so far (other conflicts may be left unordered
        too), and the next attempt starts from them, so the attempts that follow, and which
        one is kept, may differ from a search without a limit.  Default: every attempt orders
        all it can.
    futile : Futile
        Ways around known not to work: the search sets aside a conflict whose only ways are
        these last (:class:`~cosmop.team.conflict_search.CorrectionSetPicker`).

    Returns
    -------
    TeamSafety
    """
    t0 = time.perf_counter()
    settings = settings or ConflictSettings()
    waypoints = {r: set(_points(p)) for r, p in plans.items()}
    walls = shapely.MultiLineString([[w.start, w.end] for w in scene.obstacles]) if scene.obstacles else None
    plans = {
        r: split_drives(
            p, start_pose(scene, r, starts), settings.segment, _roomy(walls, scene, r, settings.clearance)
        )
        for r, p in plans.items()
    }
    context: _Context = (
        scene,
        settings,
        starts,
        positions,
        about,
        used,
        frozenset(also),
        max_set_aside,
        futile,
    )
    uncut = frozenset() if settings.cut else frozenset(plans)
    # each robot's cuts depend on the others' whole drives only: made once, undone robot by robot
    cut = (
        _cut_where_shared(scene, plans, settings, starts, positions, walls, about) if settings.cut else plans
    )
    best, joined, before = None, dict[str, set[tuple[float, float]]](), math.inf
    while True:
        tried = {r: p if r in uncut else _joined(cut[r], joined.get(r, set())) for r, p in plans.items()}
        attempt = _order(context, tried, waypoints)
        if best is None or len(attempt.unresolved) < len(best.unresolved):
            best = attempt
        if attempt.safe or uncut == frozenset(plans):
            break
        # standing at a cut may close a cycle (module docstring): the drives robots stand in
        # are made whole while that helps, then the robots' plans, then everyone's
        stands = _stands_at_cuts(attempt.unresolved, tried, waypoints)
        if stands is not None and len(attempt.unresolved) < before and _adds(stands, joined):
            before = len(attempt.unresolved)
            for r, points in stands.items():
                joined.setdefault(r, set()).update(points)
            continue
        involved = {r for c in attempt.unresolved for r in c.robots} - uncut
        uncut = uncut | involved if involved else frozenset(plans)
    if used is not None:  # each attempt named its messages in a copy; the kept one's are taken
        used |= {m.event for m in best.messages}
    return replace(best, time_s=time.perf_counter() - t0)


def _stands_at_cuts(
    unresolved: Sequence[Conflict],
    plans: Mapping[str, RobotPlan],
    waypoints: Mapping[str, set[tuple[float, float]]],
) -> dict[str, set[tuple[float, float]]] | None:
    """The cuts of the drives at whose cuts a robot stands in the `unresolved` conflicts
    (cuts: the points of `plans` not among the robots' own `waypoints`), ``robot -> {(x, y)}``;
    ``None`` when some conflict has no robot standing at a cut."""
    out: dict[str, set[tuple[float, float]]] = {}
    for conflict in unresolved:
        found = False
        for side in (conflict.a, conflict.b):
            robot = side.what
            if robot not in plans or robot not in side.parties or side.is_drive or not side.states:
                continue  # goods, a drive, or not a robot of these plans
            cuts = _drive_cuts(plans[robot], side.states[0], waypoints[robot])
            out.setdefault(robot, set()).update(cuts)
            found = found or bool(cuts)
        if not found:
            return None
    return out


def _adds(
    points: Mapping[str, set[tuple[float, float]]], joined: Mapping[str, set[tuple[float, float]]]
) -> bool:
    """Whether `points` holds a cut not yet in `joined`."""
    return any(p - joined.get(r, set()) for r, p in points.items())


def _drive_cuts(plan: RobotPlan, k: int, waypoints: set[tuple[float, float]]) -> set[tuple[float, float]]:
    """The cuts of the drive a robot stands in at instant `k` of `plan`: where the pieces of
    that drive meet (points not among the robot's own `waypoints`); empty when the robot stands
    at one of its waypoints (or its start) at instant `k`."""
    points = _points(plan)
    if not 1 <= k < len(points) or points[k - 1] in waypoints:
        return set()
    first, last = k, k
    while first > 1 and points[first - 2] not in waypoints:
        first -= 1
    while last < len(points) - 1 and points[last] not in waypoints:
        last += 1
    return set(points[first - 1 : last])


def _joined(plan: RobotPlan, points: set[tuple[float, float]]) -> RobotPlan:
    """`plan` with its drives joined again at the cuts `points` (:func:`merge_drives`)."""
    if not points:
        return plan
    return merge_drives(plan, set(_points(plan)) - points)


def _points(plan: RobotPlan) -> list[tuple[float, float]]:
    """Where each step of `plan` leaves the robot's centre, ``(x, y)`` mm, step by step."""
    return [(s.robot[0], s.robot[1]) for s in plan.steps]


def _order(
    context: _Context, plans: Mapping[str, RobotPlan], waypoints: Mapping[str, set[tuple[float, float]]]
) -> TeamSafety:
    """One ordering of every conflict between `plans` (already cut; `waypoints` are the
    robots' own, where pieces are joined again after), its time not yet set."""
    scene, settings, starts, positions, about, used, also, max_set_aside, futile = context
    horizons = {r: p.horizon for r, p in plans.items()}
    links = message_links(plans)
    times = durations(scene, plans, starts=starts)
    precedence = Precedence(horizons, links, (), times)
    if not precedence.complete:
        raise ValueError("the plans' own messages deadlock; order them before the conflicts")
    alone = max((sum(d) for d in times.values()), default=0.0)
    items, _ = occupancies(scene, plans, precedence, settings, starts, positions)
    found = [
        c
        for c in conflicts(items, settings.clearance, about=about, also=also)
        # with `about`, the rest are the pairs of `also`: ordered again only where no order holds
        if about is None or about in c.robots or not is_ordered(c, precedence)
    ]
    ordered = sum(1 for c in found if is_ordered(c, precedence))
    fixed = fixed_places(items)
    chosen, unresolved = order_conflicts(
        found, horizons, links, [], times, fixed=fixed, max_set_aside=max_set_aside, futile=futile
    )
    kept = _reduce(horizons, links, chosen)
    taken = set(used or ())
    new_plans, placed = place_edges(scene, plans, [edge for edge, _ in kept], "clear", taken, starts)
    new_plans = {r: merge_drives(p, waypoints[r]) for r, p in new_plans.items()}
    messages = tuple(
        PlanMessage(event, "conflict", _protects(new_plans, event, conflict), conflict.place)
        for (event, _, _), (_, conflict) in zip(placed, kept, strict=True)
    )
    final = Precedence(
        {r: p.horizon for r, p in new_plans.items()},
        message_links(new_plans),
        (),
        durations(scene, new_plans, starts=starts),
    )
    return TeamSafety(
        new_plans,
        messages,
        len(found),
        ordered,
        tuple(unresolved),
        alone,
        final.makespan,
        0.0,
        fixed,
        len(chosen),
        _flipped(chosen, precedence),
        _waits(new_plans, final, placed, kept, _drive_ends(scene, plans, starts)),
        futile,
    )


def _drive_ends(
    scene: Scene, plans: Mapping[str, RobotPlan], starts: Mapping[str, State] | None
) -> dict[Node, _Drive]:
    """The centres at the two ends of every GoTo step of `plans`: ``(robot, k) -> (p, q)``."""
    out: dict[Node, _Drive] = {}
    for robot, plan in plans.items():
        pose = start_pose(scene, robot, starts)
        for k, step in enumerate(plan.steps, 1):
            if step.primitive == Primitive.GOTO:
                out[(robot, k)] = ((pose[0], pose[1]), (step.robot[0], step.robot[1]))
            pose = step.robot
    return out


def _waits(
    plans: Mapping[str, RobotPlan],
    order: Precedence,
    placed: Sequence[_Placed],
    kept: Sequence[_Order],
    ends: Mapping[Node, _Drive],
) -> tuple[Wait, ...]:
    """Each conflict message's wait in `order` (the final plans' itinerary), longest first.

    `placed` and `kept` pair each message with its conflict (`plans` wait for it at their
    ``Req`` of it); `ends` gives the drives of the plans the conflicts were found on
    (:func:`_drive_ends`).
    """
    critical = _critical_waits(plans, order)
    out = []
    for (event, _, _), ((first_step, _), conflict) in zip(placed, kept, strict=True):
        robot, other = event.receiver, event.sender
        assert robot is not None and other is not None  # a message has both
        k = next(k for k, s in enumerate(plans[robot].steps, 1) if s.message == event)
        first, then = (conflict.a, conflict.b) if conflict.a.last == first_step else (conflict.b, conflict.a)
        seconds = float(order.finish[robot][k] - order.finish[robot][k - 1])
        drives: tuple[_Drive, ...] | None = None
        if first.is_drive and then.is_drive:
            assert first.first is not None and then.first is not None  # (a drive has its step)
            drives = (ends[first.first], ends[then.first])
        out.append(Wait(seconds, robot, other, event, conflict, first, then, drives, (robot, k) in critical))
    return tuple(sorted(out, key=lambda w: (-w.seconds, w.message.name)))


def _critical_waits(plans: Mapping[str, RobotPlan], order: Precedence) -> set[Node]:
    """The ``Req`` steps on the path that ends the itinerary last: from the robot done last
    back through its steps, and at a ``Req`` that waited, on to the step that sent its message."""
    if not plans:
        return set()
    senders = {(link.receiver, link.wait): (link.sender, link.send) for link in message_links(plans)}
    robot = max(plans, key=lambda r: (order.finish[r][plans[r].horizon], r))
    k, out = plans[robot].horizon, set[Node]()
    while k >= 1:
        source = senders.get((robot, k))
        waited = order.finish[robot][k] > order.finish[robot][k - 1] + 1e-9
        if source is not None and source[1] is not None and waited:
            out.add((robot, k))
            robot, k = source[0], source[1]
            continue
        k -= 1
    return out


def _flipped(chosen: Sequence[_Order], alone: Precedence) -> int:
    """How many of the `chosen` orders let go first the occupancy the robots' own itineraries
    (`alone`: no conflict ordered) expect to begin later: where the search departed from time."""
    out = 0
    for (first, _), conflict in chosen:
        x, y = (conflict.a, conflict.b) if conflict.a.last == first else (conflict.b, conflict.a)
        begins = [0.0 if o.first is None else alone.start_time(o.first) for o in (x, y)]
        out += begins[0] > begins[1] + 1e-6
    return out


def _cut_where_shared(
    scene: Scene,
    plans: Mapping[str, RobotPlan],
    settings: ConflictSettings,
    starts: Mapping[str, State] | None,
    positions: Mapping[str, tuple[float, float] | None] | None,
    walls: BaseGeometry | None,
    about: str | None = None,
) -> dict[str, RobotPlan]:
    """Every drive cut where it enters and where it leaves a place another robot uses.

    A conflict then holds only the piece of the drive inside the shared place, so the robot
    waits just before it enters, not before its whole drive, and the other is told as soon as
    it leaves (the temporal plan graph's grain: an order between the pieces of two drives that
    share a region).  The plans stay sound: a piece sweeps part of what the drive swept.
    With `about`, only the conflicts of that robot are ordered, so only the places it shares
    with the others cut drives: its own against everyone's, the others' against its.
    """
    precedence = Precedence({r: p.horizon for r, p in plans.items()}, message_links(plans))
    items, _ = occupancies(scene, plans, precedence, settings, starts, positions)
    every = list(range(len(items)))
    tree = shapely.STRtree([item.region for item in items])
    # with `about`, the others' drives are cut only where they meet its places: a tree of those
    theirs = every if about is None else [n for n in every if about in items[n].parties]
    their_tree = tree if about is None else shapely.STRtree([items[n].region for n in theirs])
    out: dict[str, RobotPlan] = {}
    for robot, plan in plans.items():
        index, near = (every, tree) if about in (None, robot) else (theirs, their_tree)
        grown = scene.robots[robot].size + settings.clearance
        poses = [start_pose(scene, robot, starts), *(step.robot for step in plan.steps)]
        cuts: dict[int, list[float]] = {}
        for k, step in enumerate(plan.steps, 1):
            p, q = poses[k - 1], poses[k]
            if step.primitive != Primitive.GOTO or math.dist(p[:2], q[:2]) < 2 * settings.piece:
                continue
            for n in near.query(swept_square(p, q, grown), predicate="intersects"):
                if robot not in items[index[n]].parties:
                    region = items[index[n]].region
                    cuts.setdefault(k, []).extend(_entry_exit(p, q, grown / 2.0, region, settings.passing))
            cuts[k] = _spaced(cuts.get(k, []), settings.piece / math.dist(p[:2], q[:2]))
        roomy = _roomy(walls, scene, robot, settings.clearance)
        out[robot] = cut_drives(plan, poses[0], cuts, roomy) if cuts else plan
    return out


def _entry_exit(
    p: Sequence[float], q: Sequence[float], half: float, region: BaseGeometry, passing: float
) -> tuple[float, ...]:
    """Where a square of half side `half` moving from `p` to `q` starts and stops overlapping the
    convex `region`: fractions of the way in (0, 1), rounded outwards to the cut grain; the
    exit lies `passing` mm beyond (:attr:`~cosmop.team.conflicts.ConflictSettings.passing`)."""
    # the region's corners moved by the square's, in the order (-h, -h), (-h, h), (h, -h), (h, h)
    coords = shapely.get_coordinates(region.exterior)
    shifts = np.array([(-half, -half), (-half, half), (half, -half), (half, half)])
    corners = (coords[:, None, :] + shifts[None, :, :]).reshape(-1, 2)
    reach = shapely.convex_hull(shapely.multipoints(corners))  # the Minkowski sum: centres that overlap it
    inside = shapely.LineString([p[:2], q[:2]]).intersection(reach)
    if inside.is_empty:
        return ()
    dx, dy = q[0] - p[0], q[1] - p[1]
    ts = [
        ((x - p[0]) * dx + (y - p[1]) * dy) / (dx * dx + dy * dy) for x, y in shapely.get_coordinates(inside)
    ]
    beyond = passing / math.hypot(dx, dy)
    low, high = (
        math.floor(min(ts) * CUT_GRAIN) / CUT_GRAIN,
        math.ceil((max(ts) + beyond) * CUT_GRAIN) / CUT_GRAIN,
    )
    return tuple(t for t in (low, high) if 0.0 < t < 1.0)


def _spaced(cuts: list[float], gap: float) -> list[float]:
    """`cuts` sorted, without those closer than `gap` to the one kept before them."""
    out: list[float] = []
    for t in sorted(set(cuts)):
        if gap <= t <= 1.0 - gap and (not out or t - out[-1] >= gap):
            out.append(t)
    return out


def _roomy(
    walls: BaseGeometry | None, scene: Scene, robot: str, room: float
) -> Callable[[float, float], bool]:
    """Whether the robot's square at ``(x, y)`` keeps `room` (mm) from every wall (`walls`, the
    scene's obstacles as one geometry, or ``None``)."""
    half = scene.robots[robot].size / 2.0 + room

    def roomy(x: float, y: float) -> bool:
        return walls is None or not walls.intersects(shapely.box(x - half, y - half, x + half, y + half))

    return roomy


def _protects(plans: Mapping[str, RobotPlan], event: Event, conflict: Conflict) -> str:
    a, b = event.sender, event.receiver
    assert a is not None and b is not None  # a message has both
    send = next(k for k, s in enumerate(plans[a].steps, 1) if s.message == event)
    wait = next(k for k, s in enumerate(plans[b].steps, 1) if s.message == event)
    cleared = plans[a].steps[send - 2].label if send >= 2 else "its start"
    entered = plans[b].steps[wait].label if wait < plans[b].horizon else "the end of its plan"
    return (
        f"{b} waits before its {entered} at instant {wait + 1} until {a} has done its {cleared} "
        f"at instant {send - 1}: they share the space {conflict.space()}"
    )
