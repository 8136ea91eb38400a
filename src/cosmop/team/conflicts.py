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
  ``DropOff`` puts it from that step's start until it is picked again (or forever; goods
  shipped on drop, until that ``DropOff`` completes).

Robot regions are grown by half the clearance the simulator keeps between moving robots
(:attr:`ConflictSettings.clearance`), so that two of them closer than that overlap; objects are
not grown.  Two robots whose start poses the scene puts closer than the clearance keep only
that gap while one of them stands at its start and the other stands at its own or drives off
it: the scene put them there, and no plan could otherwise ever let them leave (robots that come
back are held to the clearance, as every other pair).
Two occupancies of different robots (an object counts for the robots that move it)
*conflict* when their regions' interiors overlap, and the conflict is *ordered* when one of
them always ends before the other starts (:meth:`cosmop.team.precedence.Precedence.before_start`).
A plan set is team-safe when every conflict is ordered: then no execution the messages allow
puts two robots, or a robot and another robot's goods, in one place at one time.

The orders themselves are chosen by :mod:`cosmop.team.conflict_order`.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass, field
from functools import lru_cache
from typing import overload

import numpy as np
import shapely
from shapely import STRtree
from shapely.geometry.base import BaseGeometry

from cosmop.control.geometry import rect_gaps
from cosmop.events import Node, Primitive
from cosmop.planning.plan_types import RobotPlan, State
from cosmop.planning.primitive_effects import initial_state
from cosmop.planning.realisation import TOLERANCE, at_pose
from cosmop.scene import Scene
from cosmop.squares import overlap_depths, square, swept_square
from cosmop.team.precedence import Precedence
from cosmop.units import UnitSystem, show_number, show_point

__all__ = [
    "Conflict",
    "ConflictSettings",
    "Futile",
    "Occupancy",
    "conflicts",
    "detours",
    "fixed_places",
    "is_ordered",
    "kept_out",
    "occupancies",
    "ranked_detours",
    "replan_rank",
    "scene_gap",
]


@dataclass(frozen=True)
class ConflictSettings:
    """How conflicts are found.

    Attributes
    ----------
    clearance : float
        Distance (mm) two robots keep when both may move: their regions are grown by half of it
        (100 mm by default; twice the simulator's standoff, so that a robot tracking its plan
        a little off still passes where the plans let it).
    segment : float
        Drives longer than this (mm) are cut into pieces before ordering, so that a robot waits
        only until another has passed the place they share (default ``inf``: not cut; the
        cuts where drives enter and leave shared places, ``cut``, do most of that).
    rest : float
        How far (mm) a standing robot may be off its planned pose (the simulator stops within
        its goal tolerance, 15 mm): goods another robot moves keep this from where it stands.
    cut : bool
        Cut every drive where it enters and leaves a place another robot uses, so that an
        order holds only the piece inside (default true).
    piece : float
        The shortest piece such a cut leaves (mm, default 200).
    passing : float
        How far (mm) before a cut a robot that drives on through it may already count as there
        (the simulator's pass tolerance, 150 mm): the cut where a drive leaves a shared place
        lies this much beyond it, so that the message sent there is never early.
    shipped_on_drop : bool
        Goods leave the world once a plan drops them (a lifelong run ships delivered goods,
        :mod:`cosmop.lifelong`): they hold their drop spot only during the drop (default false:
        goods rest where they are dropped for good).
    """

    clearance: float = 100.0
    segment: float = math.inf
    rest: float = 20.0
    cut: bool = True
    piece: float = 200.0
    passing: float = 150.0
    shipped_on_drop: bool = False


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
    states : tuple of (int, int), optional
        A robot's occupancy: the first and last instants of its plan whose states it spans.
    unseen : tuple of (str, frozenset of int)
        Goods at rest: per robot that moves them, the instants of its plan at which its model
        does not have them lying here although they may be (see :func:`_unseen`).  Only at
        those instants is the robot's plan not already checked against them.
    units : {"mm", "m"}, optional
        The units its words show lengths in: the scenario file's (``Scene.units``).
    start : shapely geometry, optional
        A robot's occupancy where the scene placed it: its square there (no clearance), when
        it stands at its start from instant 0 or is its first drive, off it (the square at its
        start), or when it stands at its home for good at the end of its plan or is the drive
        there (the square at its home); else ``None``.
    """

    what: str
    parties: frozenset[str]
    region: BaseGeometry = field(repr=False)
    first: Node | None
    last: Node | None
    label: str
    movable: bool = True
    body: BaseGeometry | None = field(default=None, repr=False)
    units: UnitSystem = field(default="mm", repr=False, compare=False)
    states: tuple[int, int] | None = None
    unseen: tuple[tuple[str, frozenset[int]], ...] = ()
    start: BaseGeometry | None = field(default=None, repr=False, compare=False)

    @property
    def is_drive(self) -> bool:
        """Whether it is what one GoTo step sweeps (a robot's standing spans more than one
        step; goods shipped on drop hold their spot during one ``DropOff``)."""
        return self.what in self.parties and self.first is not None and self.first == self.last

    def accounts_for(self, other: Occupancy) -> bool:
        """Whether this occupancy and `other` never need an order: they are the same robot's,
        or both goods', or a robot's whose own plan keeps clear of the goods at rest at every
        instant it spans (its model has them lying there, :func:`_unseen`).

        Parameters
        ----------
        other : Occupancy
            Another occupancy of the team.
        """
        if not self.parties & other.parties:
            return False
        goods, robot = (self, other) if other.states is not None else (other, self)
        if robot.states is None or goods.states is not None:
            return True  # two goods, or one robot's two occupancies
        blind = dict(goods.unseen).get(robot.what, frozenset())
        first, last = robot.states
        return not any(first <= k <= last for k in blind)


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
        x_min, y_min, x_max, y_max = (float(v) for v in shared.bounds)
        return x_min, y_min, x_max, y_max

    @property
    def robots(self) -> tuple[str, ...]:
        return tuple(sorted(self.a.parties | self.b.parties))

    def describe(self) -> str:
        """The two occupancies and the space they share, in words."""
        return f"{self.a.label} and {self.b.label} share the space {self.space()}"

    def space(self) -> str:
        """The shared space's bounding box in words: ``x in [.., ..], y in [.., ..]``, to 0.1 mm
        in the scenario file's units."""
        x0, y0, x1, y1 = (show_number(round(v, 1), self.a.units) for v in self.place)
        return f"x in [{x0}, {x1}], y in [{y0}, {y1}]"


def _robot_occupancies(
    robot: str,
    plan: RobotPlan,
    start: State,
    side: float,
    home: Sequence[float],
    grow: float = 0.0,
    rest: float = 0.0,
    units: UnitSystem = "mm",
) -> list[Occupancy]:
    """Where `robot` stands (merged over steps that keep its pose) and what its GoTo steps sweep.

    A standing robot's body, which goods keep clear of, is its square grown by `rest`; the
    words show lengths in `units`.
    """
    motion = (tuple(start.robot), tuple((step.primitive, tuple(step.robot)) for step in plan.steps))
    return list(_motion_occupancies(robot, motion, side, tuple(home), grow, rest, units))


@lru_cache(maxsize=1 << 16)  # a fleet's plans visit the same poses again and again
def _show_xy(x: float, y: float, units: UnitSystem) -> str:
    """:func:`~cosmop.units.show_point` of ``(x, y)``."""
    return show_point((x, y), units)


@lru_cache(maxsize=4096)  # a running fleet asks again for every robot's rest at every hand-over
def _motion_occupancies(
    robot: str,
    motion: tuple[tuple[float, ...], tuple[tuple[Primitive, tuple[float, ...]], ...]],
    side: float,
    home: tuple[float, ...],
    grow: float,
    rest: float,
    units: UnitSystem,
) -> tuple[Occupancy, ...]:
    """:func:`_robot_occupancies` of the `motion` ``(start pose, ((primitive, pose), ...))``:
    all they depend on of a plan."""
    start, moves = motion
    primitives = [primitive for primitive, _ in moves]
    K = len(moves)
    poses = [start, *(pose for _, pose in moves)]
    party = frozenset((robot,))
    bare = square(poses[0][0], poses[0][1], side - grow)  # its body at its start
    first_drive = next((k for k, primitive in enumerate(primitives, 1) if primitive == Primitive.GOTO), 0)
    # home again at the end: the gap the scene gave it there holds again (see `conflicts`)
    homing = _homing_drive(primitives, poses, home)
    at_home = square(home[0], home[1], side - grow)
    out: list[Occupancy] = []
    k = 0
    while k <= K:
        end = k
        while end < K and primitives[end] != Primitive.GOTO:
            end += 1  # steps end+1 keep the pose
        x, y, _ = poses[k]
        first = None if k == 0 else (robot, k)
        last = None if end + 1 > K else (robot, end + 1)
        where = "at its start" if k == 0 else f"from instant {k}"
        fixed = (
            k == 0
            or any(primitives[i] == Primitive.PICKUP for i in range(k, end))
            or (end == K and at_pose(poses[k], home))
        )
        out.append(
            Occupancy(
                robot,
                party,
                square(x, y, side),
                first,
                last,
                f"{robot} standing at {_show_xy(x, y, units)} {where}",
                not fixed,
                square(x, y, side - grow + 2 * rest),
                units,
                (k, end),
                start=bare if k == 0 else at_home if k == homing else None,
            )
        )
        k = end + 1
    for k, primitive in enumerate(primitives, 1):
        if primitive == Primitive.GOTO:
            p, q = poses[k - 1], poses[k]
            out.append(
                Occupancy(
                    robot,
                    party,
                    swept_square(p, q, side),
                    (robot, k),
                    (robot, k),
                    f"{robot}'s GoTo at instant {k} from {_show_xy(p[0], p[1], units)} to "
                    f"{_show_xy(q[0], q[1], units)}",
                    True,
                    swept_square(p, q, side - grow),
                    units,
                    (k - 1, k),
                    start=bare if k == first_drive else at_home if k == homing else None,
                )
            )
    return tuple(out)


def _homing_drive(
    primitives: Sequence[Primitive], poses: Sequence[Sequence[float]], home: Sequence[float]
) -> int | None:
    """The instant `k` of the GoTo that brings the robot home for good (its plan, the
    `primitives` of its steps, keeps that pose from instant `k` to the end), or ``None`` when
    the plan does not end at `home` after a drive."""
    K = len(primitives)
    if K == 0 or not at_pose(poses[K], home):
        return None
    k = K
    while k > 0 and primitives[k - 1] != Primitive.GOTO:
        k -= 1
    return k or None


class _States(Sequence[State]):
    """A robot's states, instant 0 first, each made when it is read: the goods' occupancies read
    only the states of the robots that move them, and a running fleet has many robots with long
    plans."""

    def __init__(self, start: State, plan: RobotPlan) -> None:
        self._start, self._steps = start, plan.steps

    def __len__(self) -> int:
        return len(self._steps) + 1

    @overload
    def __getitem__(self, k: int) -> State: ...

    @overload
    def __getitem__(self, k: slice) -> Sequence[State]: ...

    def __getitem__(self, k: int | slice) -> State | Sequence[State]:
        if isinstance(k, slice):
            return [self[i] for i in range(*k.indices(len(self)))]
        if not -len(self) <= k < len(self):
            raise IndexError(k)
        k %= len(self)
        return self._start if k == 0 else self._steps[k - 1].state


def _object_occupancies(
    scene: Scene,
    plans: Mapping[str, RobotPlan],
    precedence: Precedence,
    models: Mapping[str, Sequence[State]],
    positions: Mapping[str, tuple[float, float] | None] | None = None,
    shipped_on_drop: bool = False,
) -> tuple[list[Occupancy], list[str]]:
    """Where every moved object rests between the steps that handle it; problems found.

    `models` gives each robot's states, instant 0 first (what its plan knows of the objects);
    `positions` where objects are at the start (``None``: carried), by default the scene's;
    goods `shipped_on_drop` leave the world at their last drop instead of resting there.
    The handlings of an object must be ordered, and each pick must find the object where the
    team's order leaves it: where the last drop before it put it (or where it starts).
    """
    out, problems = [], []
    handlings: dict[str, list[tuple[str, int, Primitive]]] = {}  # by object: few of the scene's
    for robot, plan in plans.items():
        for k, step in enumerate(plan.steps, 1):
            if step.object is not None and step.primitive in (Primitive.PICKUP, Primitive.DROPOFF):
                handlings.setdefault(step.object, []).append((robot, k, step.primitive))
    for oid, spec in scene.objects.items():
        handling = handlings.get(oid)
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
                    out.append(
                        _resting(oid, spec.size, parties, position, first, (robot, k), models, scene.units)
                    )
                    problems += _misplaced(models[robot], robot, k, oid, position, first, scene.units)
                position = None
            else:
                position, first = plans[robot].steps[k - 1].objects[oid].position, (robot, k)
        if position is not None:
            # shipped goods still appear on the drop spot while the gripper lets go: that spot
            # must be free then, or the drop waits for whoever stands there
            last = first if shipped_on_drop and first is not None else None
            out.append(_resting(oid, spec.size, parties, position, first, last, models, scene.units))
    return out, problems


def _resting(
    oid: str,
    size: float,
    parties: frozenset[str],
    position: Sequence[float],
    first: Node | None,
    last: Node | None,
    models: Mapping[str, Sequence[State]],
    units: UnitSystem = "mm",
) -> Occupancy:
    """Goods `oid` at rest at `position` from the start of step `first` (``None``: from the
    beginning) to the completion of step `last` (``None``: for good), moved by `parties`."""
    where = "at its start" if first is None else f"from {first[0]}'s instant {first[1]}"
    unseen = ((r, _unseen(models[r], oid, position, first, last, r)) for r in sorted(parties))
    return Occupancy(
        oid,
        parties,
        square(position[0], position[1], size),
        first,
        last,
        f"{oid} resting at {show_point(position, units)} {where}",
        first is not None,
        units=units,
        unseen=tuple((r, k) for r, k in unseen if k),
    )


def _lying(state: State, oid: str, position: Sequence[float]) -> bool:
    """Whether `state` has `oid` at rest at `position` (within the checker's tolerance)."""
    known = state.objects.get(oid)
    return (
        known is not None
        and not known.carried
        and not known.away
        and all(abs(a - b) <= TOLERANCE for a, b in zip(known.position, position, strict=True))
    )


def _unseen(
    model: Sequence[State],
    oid: str,
    position: Sequence[float],
    first: Node | None,
    last: Node | None,
    robot: str,
) -> frozenset[int]:
    """The instants of `robot`'s plan (states `model`) at which the goods may lie at `position`
    (from the start of step `first` to the completion of step `last`) but its model does not
    have them there: its plan was not checked against them then.

    The robot's own drop that puts them there and its own pick that takes them bound the
    instants that matter.  At instant 0 the model is the robot's belief, checked against
    nothing: goods put there by another robot are unseen then.
    """
    lo = first[1] if first is not None and first[0] == robot else 0
    hi = last[1] - 1 if last is not None and last[0] == robot else len(model) - 1
    out = {k for k in range(lo, hi + 1) if not _lying(model[k], oid, position)}
    if lo == 0 and first is not None:
        out.add(0)
    return frozenset(out)


def _misplaced(
    model: Sequence[State],
    robot: str,
    k: int,
    oid: str,
    position: Sequence[float],
    first: Node | None,
    units: UnitSystem = "mm",
) -> list[str]:
    """Why `robot`'s pick of `oid` at instant `k` is not where the goods lie (``[]``: it is)."""
    if _lying(model[k - 1], oid, position):
        return []
    where = "where they start" if first is None else f"where {first[0]} dropped them at instant {first[1]}"
    planned = model[k - 1].objects.get(oid)
    at = f" at {show_point(planned.position, units)}" if planned is not None else ""
    lies = show_point(position, units)
    return [f"{robot} picks {oid}{at} at instant {k}, but {oid} lies at {lies} then ({where})"]


def occupancies(
    scene: Scene,
    plans: Mapping[str, RobotPlan],
    precedence: Precedence,
    settings: ConflictSettings | None = None,
    starts: Mapping[str, State] | None = None,
    positions: Mapping[str, tuple[float, float] | None] | None = None,
    robots: Collection[str] | None = None,
) -> tuple[list[Occupancy], list[str]]:
    """Every occupancy of the robots and the objects they move; problems with object handling.

    `starts` gives the robots' states at the start when it is not the scenario (mid-run), and
    `positions` where the objects are then (``None``: carried).

    Parameters
    ----------
    scene : Scene
        The scenario: robots' sizes and start poses, objects.
    plans : Mapping[str, RobotPlan]
        Every robot's plan, by id.
    precedence : Precedence
        The order the plans' messages impose on their steps.
    settings : ConflictSettings, optional
        How far robots keep apart (default :class:`ConflictSettings`).
    starts : Mapping[str, State], optional
        The robots' states at the start, by id, when it is not the scenario.
    positions : Mapping[str, (float, float) or None], optional
        Where objects are at the start (mm; ``None``: carried), by default the scene's.
    robots : collection of str, optional
        Only these robots' own occupancies (the objects' are all made: where goods rest
        depends on every plan that moves them); by default every robot's.

    Returns
    -------
    tuple of (list of Occupancy, list of str)
        The occupancies, and problems with how the objects are handled, in words.
    """
    settings = settings or ConflictSettings()
    grow = settings.clearance
    out: list[Occupancy] = []
    models: dict[str, Sequence[State]] = {}
    moved = {
        s.object
        for plan in plans.values()
        for s in plan.steps
        if s.primitive == Primitive.PICKUP and s.object is not None  # (a PickUp always has one)
    }
    for robot, plan in plans.items():
        start = (starts or {}).get(robot) or initial_state(scene, robot, plan, moved)
        models[robot] = _States(start, plan)
        if robots is None or robot in robots:
            size, home = scene.robots[robot].size + grow, scene.robots[robot].pose
            out += _robot_occupancies(robot, plan, start, size, home, grow, settings.rest, scene.units)
    objects, problems = _object_occupancies(
        scene, plans, precedence, models, positions, settings.shipped_on_drop
    )
    return out + objects, problems


def conflicts(
    items: Sequence[Occupancy],
    clearance: float | None = None,
    *,
    about: str | None = None,
    also: Collection[tuple[str, ...]] = (),
) -> list[Conflict]:
    """Pairs of occupancies of disjoint parties whose regions' interiors overlap.

    `clearance` (mm; default :attr:`ConflictSettings.clearance`) is the one the robots'
    regions were grown by: two robots that start closer than that keep only their start gap
    where one stands at its start and the other stands at or drives off its own, and likewise
    where one stands at its home at the end and the other stands at or drives into its own
    (:func:`_given_gap`): a scene that parks two robots touching gets them back parked so.

    Parameters
    ----------
    items : sequence of Occupancy
        The team's occupancies (:func:`occupancies`).
    clearance : float, optional
        The clearance the robots' regions were grown by (mm).
    about : str, optional
        Only the pairs one of whose parties is this robot, and those of the parties in `also`
        (as :attr:`Conflict.robots` names them): a robot ordered again among plans already
        ordered needs no other pair's overlap measured.
    also : collection of tuple of str
        With `about`, the further parties whose pairs are wanted.
    """
    if not items:
        return []
    regions = [item.region for item in items]
    # shape n is item n's region, shape N + n its body (a robot keeps its clearance from
    # robots, not from goods)
    shapes = _geometries(regions + [item.body or item.region for item in items])
    left, right = _touching(shapes[: len(items)], None if about is None else _named(items, about, also))
    keep = left < right
    pairs, first, second = [], [], []
    for i, j in zip(left[keep].tolist(), right[keep].tolist(), strict=True):
        a, b = items[i], items[j]
        if a.accounts_for(b):
            continue
        if about is not None:
            parties = a.parties | b.parties
            if about not in parties and tuple(sorted(parties)) not in also:
                continue
        robots = a.what in a.parties and b.what in b.parties
        pairs.append((a, b))
        first.append(i if robots else len(items) + i)
        second.append(j if robots else len(items) + j)
    overlap = _overlap(shapes, first, second)
    clearance = ConflictSettings().clearance if clearance is None else clearance
    return [
        Conflict(a, b)
        for (a, b), real in zip(pairs, overlap, strict=True)
        if real and not _given_gap(a, b, clearance) and not _placed_so(a, b)
    ]


def _named(items: Sequence[Occupancy], about: str, also: Collection[tuple[str, ...]]) -> np.ndarray:
    """Which `items` have `about` or a robot of `also` (pairs of robots' names) among their
    parties: every pair :func:`conflicts` keeps with `about` has one of them."""
    named = {about, *(robot for parties in also for robot in parties)}
    return np.array([bool(item.parties & named) for item in items], dtype=bool)


def _touching(regions: np.ndarray, wanted: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """The pairs of intersecting `regions` (an array of shapes, :func:`_geometries`) as an
    R-tree query of all of them finds them (``left`` by index, each one's partners in the
    tree's order), or only the pairs with a region `wanted` in them, in the same order.

    Asking the tree about every region costs as many pairs as the team has; with `wanted`
    (a re-planned robot's few regions) only those regions are asked about, and then the
    regions that meet them at a lower index (a pair is kept where its lower index asks), so
    the conflicts come in the same order and the ordering makes the same choices.
    """
    tree = STRtree(regions)
    if wanted is None:
        left, right = tree.query(regions, predicate="intersects")
        return left, right
    mine = np.flatnonzero(wanted)
    left, right = tree.query(regions[mine], predicate="intersects")
    left = mine[left]
    lower = np.unique(right[(right < left) & ~wanted[right]])  # they meet a wanted region above them
    more_left, more_right = tree.query(regions[lower], predicate="intersects")
    more_left, with_wanted = lower[more_left], wanted[more_right]
    left = np.concatenate([left, more_left[with_wanted]])
    right = np.concatenate([right, more_right[with_wanted]])
    by_left = np.argsort(left, kind="stable")  # each region's partners were found in one query
    return left[by_left], right[by_left]


def _placed_so(a: Occupancy, b: Occupancy) -> bool:
    """Whether `a` and `b` are a robot standing where it starts and goods resting where they
    start, apart: the overlap is only the room (:attr:`ConflictSettings.rest`) a robot that has
    stopped may be off its pose, and a robot that has not moved yet is exactly where it stands.
    The scene, or the running world when a lifelong run re-plans (a robot that failed beside
    the goods it was about to pick), put them so; no order of the plans could change it."""
    robot, goods = (a, b) if a.states is not None else (b, a)
    if robot.states is None or goods.states is not None:
        return False  # not a robot and goods
    if robot.first is not None or robot.is_drive or goods.first is not None or robot.start is None:
        return False  # one of them is not where the scene (or the world) put it
    return not _overlap(_geometries([robot.start, goods.region]), [0], [1])[0]


def _given_gap(a: Occupancy, b: Occupancy, clearance: float) -> bool:
    """Whether the overlap of `a` and `b` (robots' occupancies where the scene placed them, one
    standing: :attr:`Occupancy.start`) is only the clearance the scene's poses already break:
    their bare shapes, grown by half the gap between those two places (L-infinity, mm), do
    not overlap."""
    gap = scene_gap(a, b, clearance)
    if gap is None:
        return False
    shapes = []
    for o in (a, b):
        shape = o.body if o.is_drive else o.start
        assert shape is not None  # a drive has its body, and both have their start
        shapes.append(shape.buffer(max(gap, 0.0) / 2, join_style="mitre"))
    return not _overlap(_geometries(shapes), [0], [1])[0]


def scene_gap(a: Occupancy, b: Occupancy, clearance: float) -> float | None:
    """The gap (L-infinity, mm) the scene gave two robots where `a` and `b` have them, when it
    is below `clearance` and one of them stands (:attr:`Occupancy.start`); else ``None``.

    Parameters
    ----------
    a, b : Occupancy
        Two robots' occupancies.
    clearance : float
        The clearance robots keep otherwise, mm.
    """
    if a.start is None or b.start is None or (a.is_drive and b.is_drive):
        return None
    (ax0, ay0, ax1, ay1), (bx0, by0, bx1, by1) = a.start.bounds, b.start.bounds
    gap = max(bx0 - ax1, ax0 - bx1, by0 - ay1, ay0 - by1)
    return gap if gap < clearance else None


def _overlap(shapes: np.ndarray, first: list[int], second: list[int]) -> list[bool]:
    """Whether the interiors of each pair of `shapes` overlap: the area of their intersection
    is above 1e-9 mm² (they may only touch).  Convex polygons (all the occupancies' regions)
    are decided by their overlap depth (:func:`~cosmop.squares.overlap_depths`) unless it is
    within 1e-6 mm of 0, where they may only touch; those and any other shape by the area."""
    first_, second_ = np.asarray(first, dtype=np.int64), np.asarray(second, dtype=np.int64)
    depth = overlap_depths(shapes, first_, second_)
    overlap = depth > 1e-6
    unsure = ~(np.abs(depth) > 1e-6)  # NaN too
    if unsure.any():
        a, b = shapes[first_[unsure]], shapes[second_[unsure]]
        overlap[unsure] = shapely.area(shapely.intersection(a, b)) > 1e-9
    result: list[bool] = overlap.tolist()
    return result


def _geometries(shapes: list[BaseGeometry]) -> np.ndarray:
    """`shapes` as a 1-D array, for shapely's vectorised functions."""
    out = np.empty(len(shapes), dtype=object)
    out[:] = shapes
    return out


def is_ordered(conflict: Conflict, precedence: Precedence) -> bool:
    """Whether one occupancy always ends before the other starts.

    Parameters
    ----------
    conflict : Conflict
        The two occupancies.
    precedence : Precedence
        The order the plans' messages impose on their steps.
    """
    a, b = conflict.a, conflict.b
    return _before(a, b, precedence) or _before(b, a, precedence)


def _before(x: Occupancy, y: Occupancy, precedence: Precedence) -> bool:
    return x.last is not None and y.first is not None and precedence.before_start(x.last, y.first)


Futile = frozenset[tuple[str, str]]
"""Ways around known not to work: ``(robot, label of the occupancy it would keep out of)``
(its re-plan around that space failed, or gave the same plan)."""


def detours(
    conflict: Conflict, fixed: Mapping[str, Sequence[BaseGeometry]], futile: Futile = frozenset()
) -> list[tuple[str, Occupancy]]:
    """Who can be re-planned around an unresolved conflict, best first: ``(robot, what to avoid)``.

    The side that moves must be movable (:attr:`Occupancy.movable`): a drive (best: one that
    meets something staying for good) or dropped goods (moved by the robot that drops them).
    Avoiding the other side must leave the mover's fixed places -- its start, the poses it picks
    from, its home, given in `fixed` by robot (regions already grown) -- free.

    Parameters
    ----------
    conflict : Conflict
        The unresolved conflict.
    fixed : Mapping[str, sequence of shapely geometry]
        Each robot's places re-planning cannot move (its start, pick poses, home), regions
        already grown (:func:`fixed_places`).
    futile : Futile
        Ways around known not to work, left out.
    """
    return [(robot, keep) for _, robot, keep in ranked_detours(conflict, fixed, futile)]


def ranked_detours(
    conflict: Conflict, fixed: Mapping[str, Sequence[BaseGeometry]], futile: Futile = frozenset()
) -> list[tuple[int, str, Occupancy]]:
    """:func:`detours` with each way's rank: 0 a drive around something staying for good, 1 a
    drive around something passing, 2 goods dropped elsewhere, 3 a drive kept out only by the
    gap the scene gave (:func:`kept_out`) that the conflict rule holds to the clearance.

    Parameters
    ----------
    conflict : Conflict
        The unresolved conflict.
    fixed : Mapping[str, sequence of shapely geometry]
        Each robot's places re-planning cannot move (its start, pick poses, home), regions
        already grown (:func:`fixed_places`).
    futile : Futile
        Ways around known not to work, left out.
    """
    out: list[tuple[int, str, Occupancy]] = []
    clearance = ConflictSettings().clearance
    for mover, keep in ((conflict.a, conflict.b), (conflict.b, conflict.a)):
        if not mover.movable or mover.first is None:
            continue
        robot = mover.what if mover.what in mover.parties else mover.first[0]
        if (robot, keep.label) in futile:
            continue
        places = _geometries(list(fixed.get(robot, ())))
        avoid = kept_out(robot, keep, fixed, clearance)
        if avoid is not None:  # kept out by the gap the scene gave, bodies against bodies
            places = shapely.buffer(places, -clearance / 2, join_style="mitre")
        if (shapely.area(shapely.intersection(keep.region if avoid is None else avoid, places)) > 1e-9).any():
            continue
        drive = mover.is_drive
        if avoid is not None and drive and mover.start is None:
            # walls at the scene's gap let this drive pass closer than the clearance, which the
            # rule allows only drives off or into a place the scene gave (`conflicts`): the
            # conflict is likely to come back, so other conflicts are re-planned first
            out.append((3, robot, keep))
            continue
        out.append((0 if drive and keep.last is None else 1 if drive else 2, robot, keep))
    return sorted(out, key=lambda o: o[0])


def kept_out(
    robot: str, keep: Occupancy, fixed: Mapping[str, Sequence[BaseGeometry]], clearance: float
) -> BaseGeometry | None:
    """The region `robot`'s body must stay out of to keep clear of `keep` when the scene allows
    less than the clearance; ``None`` when the clearance holds (a re-plan then keeps out of
    `keep`'s region grown by the other half of it).

    A robot the scene placed (`keep` stands at its start or home, or drives off or into it:
    :attr:`Occupancy.start`) closer than `clearance` to one of `robot`'s fixed places (its
    start, home or the poses it picks from, `fixed`, grown by the clearance) is kept out of
    only by the least such gap (L-infinity, mm): the bare square of `keep` grown by it.  A
    robot parked touching another may then drive past it, as it may leave it.

    Parameters
    ----------
    robot : str
        The robot that is re-planned.
    keep : Occupancy
        What it keeps clear of.
    fixed : Mapping[str, sequence of shapely geometry]
        Each robot's fixed places, grown by the clearance (:func:`fixed_places`).
    clearance : float
        The clearance robots keep from each other, mm.
    """
    if keep.start is None or not fixed.get(robot):
        return None
    x0, y0, x1, y1 = keep.start.bounds
    bare = shapely.bounds(shapely.buffer(_geometries(list(fixed[robot])), -clearance / 2, join_style="mitre"))
    gap = float(rect_gaps(np.array([x0, y0]), np.array([x1, y1]), bare[:, :2], bare[:, 2:]).min())
    if gap >= clearance:
        return None
    return keep.start.buffer(gap, join_style="mitre")


def fixed_places(items: Sequence[Occupancy]) -> dict[str, list[BaseGeometry]]:
    """Every robot's places that re-planning cannot move (start, pick poses, home), by robot.

    Parameters
    ----------
    items : sequence of Occupancy
        The team's occupancies (:func:`occupancies`).
    """
    out: dict[str, list[BaseGeometry]] = {}
    for item in items:
        if not item.movable and item.what in item.parties:
            out.setdefault(item.what, []).append(item.region)
    return out


def replan_rank(
    conflict: Conflict,
    fixed: Mapping[str, Sequence[BaseGeometry]] | None = None,
    futile: Futile = frozenset(),
) -> int:
    """Rank of a conflict as a culprit to re-plan (lower first): a drive against something that
    stays for good, then any detour, then a detour likely to leave the conflict as it is
    (:func:`ranked_detours`, rank 3), then none (two robots standing where their goods
    require, or only ways known not to work).

    Parameters
    ----------
    conflict : Conflict
        The conflict.
    fixed : Mapping[str, sequence of shapely geometry], optional
        Each robot's places re-planning cannot move (:func:`fixed_places`); none by default.
    futile : Futile
        Ways around known not to work.
    """
    options = ranked_detours(conflict, fixed or {}, futile)
    if not options:
        return 3
    rank, _, keep = options[0]
    return 2 if rank == 3 else 0 if keep.last is None else 1
