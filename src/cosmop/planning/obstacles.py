"""Which obstacle constraints the solver holds: all of them (eager), or lazily, those a plan needs.

A robot's specification (:func:`cosmop.planning.specification.specification`) is a list of
named parts; some keep the robot or its goods off one wall or one resting object (the GoTo
clearance, the gripper, the drop place, the room kept while handling).  On a large map almost
all of them are about walls the robot never comes near, yet each is unrolled at every instant.

Lazy geometry holds back the obstacles far from the robot's route and adds an obstacle's parts
only when a plan breaks one of them.  Write :math:`\\Phi = C \\wedge \\bigwedge_{o \\in O} G_o`
for the specification: :math:`C` the parts about no single obstacle, :math:`G_o` the
conjunction of obstacle :math:`o`'s parts.  The solver holds :math:`\\Phi_S = C \\wedge
\\bigwedge_{o \\in S} G_o` for a set :math:`S \\subseteq O` that only grows.

**Claim.** The search of :mod:`cosmop.planning.synthesis` (horizons :math:`K` in increasing
order; at each, models of :math:`\\Phi_S` are checked against every :math:`G_o`,
:math:`o \\notin S`, exactly, by :func:`cosmop.logic.failing`, and the broken obstacles join
:math:`S` before solving again; then the bound on requests is tightened the same way) returns
the same shortest :math:`K` and the same least number of requests as the eager encoding
:math:`S = O`.

*Proof.* Every model of :math:`\\Phi` is a model of :math:`\\Phi_S` (fewer conjuncts).  (1) An
unsatisfiable :math:`\\Phi_S` at horizon :math:`K`, or with at most :math:`r` requests, makes
:math:`\\Phi` unsatisfiable there too.  (2) A model of :math:`\\Phi_S` that satisfies every
:math:`G_o` with :math:`o \\notin S` is a model of :math:`\\Phi`, and it is the only kind of
model the search accepts.  (3) Each rejected model adds at least one obstacle to the finite
:math:`S`, so every check ends, at the latest with :math:`S = O`, either in an accepted model
or in unsatisfiability.  By (1) every horizon below the one returned has no plan of
:math:`\\Phi`; by (2) the one returned has one, so it is :math:`\\Phi`'s shortest.  At that
horizon, by (2) the plan with :math:`r` requests is a plan of :math:`\\Phi`, and by (1) no plan
of :math:`\\Phi` has fewer.  :math:`\\square`

Which obstacles start in :math:`S` changes only the number of rounds, never the answer: those
within reach of the box around the robot's start, home, its goods and its drop places.

A wall or object to drives is also a second obstacle of :math:`O`,
:func:`~cosmop.planning.specification.corner_clearance_key`: its GoTo part with departures from past
its ends made to pass them clear.  It implies the first; the claim holds with both in
:math:`O`.  It is never in :math:`S` at the start: the solver pays for it only where a plan
passes an end too close, which a numeric pre-test (:func:`_passes_ends`) rules out for most
obstacles and models before the exact one.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from fractions import Fraction
from typing import Any

import numpy as np
import shapely
from numpy.typing import NDArray

from cosmop.events import Event, Primitive
from cosmop.logic import Formula, conj, failing, to_fraction
from cosmop.planning.regions import square_sides, wall_regions
from cosmop.planning.specification import (
    HANDLING_CLEARANCE,
    PASSING,
    PAST_AN_END,
    ObstacleKey,
    ObstaclePart,
    PartName,
    RobotProblem,
    corner_clearance_key,
    object_key,
    specification,
    wall_key,
)


def obstacle_of(name: PartName) -> ObstacleKey | None:
    """The obstacle a part of the specification keeps clear of, or ``None``.

    A wall is two obstacles: ``wall 3`` to drives and ``wall 3 while handling`` to picks and
    drops (they concern different instants and places); an object is one, ``object O2``.

    Parameters
    ----------
    name : str or ObstaclePart
        The name of a part of a robot's specification (only an obstacle part's names one).
    """
    return name.obstacle if isinstance(name, ObstaclePart) else None


class Geometry:
    """The obstacle parts of one robot's specification, and which of them the solver holds.

    Parameters
    ----------
    p : RobotProblem
        The robot's planning problem.
    events : sequence of Event, optional
        The events planned (default the problem's mission), as for
        :func:`~cosmop.planning.specification.specification`.
    lazy : bool
        Hold back the obstacles out of reach of the robot's route until a plan breaks them
        (see the module docstring); else hold every part from the start.
    lines : bool
        With `lazy`, hold from the start only the obstacles near the straight lines between the
        mission's places, within their box (:func:`_corridor`), instead of the whole box: the
        same shortest horizon, found sooner on a large map, but the solver's first plan may be
        another (off by default, as :func:`~cosmop.planning.synthesis.synthesize`'s ``copies``).

    Attributes
    ----------
    held : Formula
        What the solver holds, :math:`\\Phi_S`.
    admitted : int
        Obstacles added after a plan broke them.

    Notes
    -----
    The parts of an obstacle not held are written only when a plan comes near enough to it to
    need testing.  Every part is about one motion or one instant, and is a disjunction over the
    obstacle's sides: a plan whose every motion keeps the robot on one side of the obstacle
    (both ends in the side's half-plane grown by the motion margin, as in
    :func:`~cosmop.planning.specification.specification`; the motion's swept hull is then in it
    too, since a half-plane is convex), and whose robot and goods lie together on one and the
    same side at all the instants of its picks and drops and the next, satisfies all its parts,
    so only the others are written and evaluated exactly.  The sides may differ from motion to
    motion: a robot that drives round a shelf never comes near most of the goods inside the
    corner it turns.  The one-side test is numeric with a safety gap (:data:`_GAP`): it may send
    an obstacle to the exact test needlessly, never skip one.
    """

    def __init__(
        self, p: RobotProblem, events: Sequence[Event] | None, lazy: bool, *, lines: bool = False
    ) -> None:
        walls = range(len(p.scene.obstacles))
        keys = [wall_key(i, handling) for handling in (False, True) for i in walls]
        keys += [object_key(o) for o in p.scene.objects]
        keys += [corner_clearance_key(k) for k in [*map(wall_key, walls), *map(object_key, p.scene.objects)]]
        held = set(keys) if not lazy else _near_route(p, lines) | {object_key(o) for o in p.own_objects}
        self._p, self._events = p, events
        self.held = conj(f for _, f in specification(p.with_obstacles(frozenset(held)), events))
        self._waiting = [k for k in keys if k not in held]
        self._written: dict[ObstacleKey, Formula] = {}
        self._half_planes = _SeparatingHalfPlanes(p) if self._waiting else None
        self.admitted = 0

    def broken(self, trace: Sequence[Mapping[str, Any]]) -> list[ObstacleKey]:
        """The obstacles not yet held whose parts the plan `trace` breaks (exact evaluation).

        Parameters
        ----------
        trace : sequence of Mapping[str, Any]
            The plan: the value of each variable of the specification at instants 0..K.
        """
        if self._half_planes is None:
            return []
        near = self._half_planes.unsure(self._waiting, trace)
        self._write([k for k in near if k not in self._written])
        broken = [near[i] for i in failing([self._written[k] for k in near], trace)]
        # an obstacle driven through needs its own part first; its stronger one may follow
        return [k for k in broken if k.base == k or k.base not in broken]

    def admit(self, keys: Sequence[ObstacleKey]) -> Formula:
        """Move the obstacles `keys` into the solver's share: their parts, to assert.

        Parameters
        ----------
        keys : sequence of ObstacleKey
            Obstacles not yet held.
        """
        self._write([k for k in keys if k not in self._written])
        added = conj(self._written.pop(k) for k in keys)
        admitted = set(keys)
        self._waiting = [k for k in self._waiting if k not in admitted]
        self.admitted += len(keys)
        self.held = conj([self.held, added])
        return added

    def _write(self, keys: Sequence[ObstacleKey]) -> None:
        if not keys:
            return
        groups: dict[ObstacleKey, list[Formula]] = {k: [] for k in keys}
        for name, formula in specification(self._p.with_obstacles(frozenset(keys)), self._events):
            key = obstacle_of(name)
            if key is not None and key in groups:
                groups[key].append(formula)
        self._written.update({k: conj(fs) for k, fs in groups.items()})


_GAP = 1e-3
"""mm by which the numeric one-side test must clear a half-plane (floating point is not exact)."""


class _SeparatingHalfPlanes:
    """Each obstacle's half-planes that keep the robot, and its goods, clear of it (floats):
    *separating* half-planes: a body whose centre lies inside one of them is apart from it.

    For a wall: its four regions (:func:`~cosmop.planning.regions.wall_regions`) for the
    robot's square grown by the margin, and for each good's square; for a resting object: its
    four sides (:func:`~cosmop.planning.regions.square_sides`) at the robot's centre distance
    plus the larger of the margin and the handling clearance, and at each good's.  Each row is
    :math:`(a, b, c)` scaled so that :math:`|a| + |b| = 1`.
    """

    def __init__(self, p: RobotProblem) -> None:
        self._p = p
        side, margin = p.side, p.margin
        goods = {o: to_fraction(p.scene.objects[o].size) for o in p.own_objects}
        planes: dict[ObstacleKey, list[list[tuple[Fraction, Fraction, Any]]]] = {}
        self._roles: dict[ObstacleKey, int] = {}  # 0: a wall to drives, 1: to picks and drops, 2: an object
        self._handling = {a.code for a in p.actions if a.primitive in (Primitive.PICKUP, Primitive.DROPOFF)}
        for i, w in enumerate(p.scene.obstacles):
            regions = [wall_regions(w.start, w.end, g) for g in (side + 2 * margin, *goods.values())]
            planes[wall_key(i)] = [[(h.a, h.b, h.c) for h in body] for body in regions]
            self._roles[wall_key(i)], self._roles[wall_key(i, handling=True)] = 0, 1
        robot_gap = max(margin, HANDLING_CLEARANCE)
        others = [o for o in p.scene.objects if o not in goods]  # own goods move: always held
        for o in others:
            self._roles[object_key(o)] = 2
        self._keys = list(planes) + [object_key(o) for o in others]
        self._row = {k: n for n, k in enumerate(self._keys)}
        for i in range(len(p.scene.obstacles)):  # a wall's handling parts: robot and goods
            self._row[wall_key(i, handling=True)] = self._row[wall_key(i)]
        for key in list(self._keys):  # the stronger GoTo part: kept clear by the same sides
            self._row[corner_clearance_key(key)], self._roles[corner_clearance_key(key)] = self._row[key], 0
        walls = np.array([planes[k] for k in planes], dtype=float)  # (obstacles, bodies, 4 sides, abc)
        # no wall or no other object: keep the shape
        walls = walls.reshape(len(planes), 1 + len(goods), 4, 3)
        reach = [float(side / 2 + robot_gap), *(float(g / 2) for g in goods.values())]
        table = np.concatenate([walls, _object_sides(p, others, reach)])
        table /= np.abs(table[..., :2]).sum(axis=-1, keepdims=True)
        self._table = table
        grown = np.array([float(margin if self._roles[k] == 0 else robot_gap) for k in self._keys])
        self._touching = table[:, 0].copy()  # the robot's sides above, moved back to touching
        self._touching[..., 2] -= grown[:, None]
        self._margin = float(margin)
        self._goods = list(goods)

    def unsure(self, keys: Sequence[ObstacleKey], trace: Sequence[Mapping[str, Any]]) -> list[ObstacleKey]:
        """The obstacles among `keys` that the plan does not keep to one side of, in order.

        A wall's drive parts look at each motion of the robot (from one instant to the next);
        its parts for picks and drops at the robot and the goods together at the instants of a
        PickUp or DropOff and the next; an object's parts at the robot's motions and at the
        goods at those instants.
        """
        if not keys:
            return []
        fixed = [k for k in keys if k in self._row]  # not the robot's own goods: they move
        own = [k for k in keys if k not in self._row]  # their stronger parts
        ok = {k: self._own_ends(k.obj, trace) for k in own if k.obj is not None}
        ok.update(zip(fixed, self._one_side(fixed, trace), strict=True))
        return [k for k in keys if not ok[k]]

    def _own_ends(self, obj: str, trace: Sequence[Mapping[str, Any]]) -> bool:
        """Whether the motions that start where the robot's own good `obj` rests surely pass its
        ends clear (:func:`_passes_ends`, with the good where it lies then)."""
        p = self._p
        v, d = p.obj(obj), float((to_fraction(p.scene.objects[obj].size) + p.side) / 2)
        for k in range(len(trace) - 1):
            x, y, carried, away = v.read(trace[k])
            if carried or away:
                continue
            sides = np.array([square_sides(float(x), float(y), d)], dtype=float)  # |a| + |b| = 1
            motion = [(float(s["x"]), float(s["y"])) for s in trace[k : k + 2]]
            if not _passes_ends(sides, motion, self._margin)[0]:
                return False
        return True

    def _one_side(self, keys: Sequence[ObstacleKey], trace: Sequence[Mapping[str, Any]]) -> np.ndarray:
        """Per obstacle of `keys` (all with sides), whether the plan `trace` surely keeps its parts."""
        if not keys:
            return np.zeros(0, dtype=bool)
        p = self._p
        handled = [k for k in range(len(trace) - 1) if trace[k + 1]["pi"] in self._handling]
        at = sorted({j for k in handled for j in (k, k + 1)})
        robot = [(float(s["x"]), float(s["y"])) for s in trace]
        rows = self._table[[self._row[k] for k in keys]]
        role = np.array([self._roles[k] for k in keys])
        on = _on_sides(rows[:, 0], robot)  # (obstacles, 4 sides, instants)
        # each motion on one side (its sides may differ from the next one's); a plan of no step
        # has no motion, and no part to break (each looks at the next instant)
        motions: NDArray[np.bool_] = on[..., :-1] & on[..., 1:]
        drives = np.all(np.any(motions, axis=1), axis=1)
        # the gripper pairs the robot at one instant with the goods at the next: robot and goods
        # together on one and the same side at all the instants of the picks and drops and the next
        together = np.all(on[..., at], axis=-1)
        goods = np.ones((len(keys), len(at)), dtype=bool)  # each good on some side, each instant
        for b, o in enumerate(self._goods, start=1):
            sides = _on_sides(rows[:, b], [tuple(float(v) for v in p.obj(o).read(trace[j])[:2]) for j in at])
            together &= np.all(sides, axis=-1)
            goods &= np.any(sides, axis=1)
        # a wall's drive parts look at the robot's motions, its parts for picks and drops at the
        # robot and goods together; an object's at the robot's motions (drives, and the room kept
        # while handling at their ends) and, apart, at the goods dropped clear of it
        handling = np.any(together, axis=1)
        ok: NDArray[np.bool_] = np.where(
            role == 0, drives, np.where(role == 1, handling, drives & np.all(goods, axis=1))
        )
        ends = np.array([k.past_ends for k in keys])
        if ends.any():  # the stronger part differs only for starts past an end, near a side
            stronger_rows = [self._row[k] for k, stronger in zip(keys, ends, strict=True) if stronger]
            ok[ends] |= _passes_ends(self._touching[stronger_rows], robot, self._margin)
        return ok


def _object_sides(p: RobotProblem, objects: Sequence[str], reach: Sequence[float]) -> NDArray[np.float64]:
    """The sides of resting `objects` (:func:`~cosmop.planning.regions.square_sides`, in floats)
    for bodies whose centres stay ``reach[b]`` (mm) plus an object's half side away from it:
    ``(objects, bodies, 4 sides, abc)``, the rows of :class:`_SeparatingHalfPlanes`."""
    table = np.zeros((len(objects), len(reach), 4, 3))
    if not objects:
        return table
    at = np.array([p.at_start(o)[0] for o in objects], dtype=float)
    half = np.array([p.scene.objects[o].size / 2.0 for o in objects], dtype=float)
    d = half[:, None] + np.asarray(reach, dtype=float)[None, :]  # (objects, bodies)
    ox, oy = at[:, 0, None], at[:, 1, None]
    one, zero = np.ones_like(d), np.zeros_like(d)
    table[:, :, 0] = np.stack([-one, zero, d - ox], axis=-1)  # left
    table[:, :, 1] = np.stack([one, zero, ox + d], axis=-1)  # right
    table[:, :, 2] = np.stack([zero, -one, d - oy], axis=-1)  # below
    table[:, :, 3] = np.stack([zero, one, oy + d], axis=-1)  # above
    return table


_SIDE_AND_END = np.array([(0, 2), (0, 3), (1, 2), (1, 3), (2, 0), (2, 1), (3, 0), (3, 1)])
"""Each side of an obstacle with each of its neighbours (sides 0, 1 and 2, 3 are opposite)."""


def _passes_ends(
    sides: NDArray[np.float64], robot: Sequence[tuple[float, float]], margin: float
) -> NDArray[np.bool_]:
    """Per obstacle (`sides`: obstacles x 4 x abc, touching, scaled as in :class:`_SeparatingHalfPlanes`),
    whether every motion of `robot` surely meets what
    :func:`~cosmop.planning.specification.corner_clearance_key` adds to the obstacle's own part.

    That is asked only of a motion that leaves a side for the margin from nearer (and may be
    a departure), from past one of the side's ends; it holds when the start is
    :data:`PASSING` margins off both, or the motion is one of :data:`PAST_AN_END`'s.  The
    test is numeric with the safety gap :data:`_GAP`: it may send an obstacle to the exact
    test needlessly, never skip one.
    """
    if len(robot) < 2:
        return np.ones(len(sides), dtype=bool)
    xy = np.asarray(robot)
    value = sides[..., 0, None] * xy[:, 0] + sides[..., 1, None] * xy[:, 1] - sides[..., 2, None]
    start, end = value[..., :-1], value[..., 1:]  # (obstacles, 4 sides, motions)
    side, past = _SIDE_AND_END[:, 0], _SIDE_AND_END[:, 1]
    v, g = start[:, side], start[:, past]
    gain, towards = end[:, side] - v, g - end[:, past]
    leaves = (v > -_GAP) & (v < margin + _GAP) & (end[:, side] > margin - _GAP) & (g > -_GAP)
    passing = float(PASSING) * margin + _GAP
    fine = (v >= passing) & (g >= passing)
    for rate, margins in PAST_AN_END:
        fine |= (towards <= rate * gain - (rate + 1) * _GAP) & (g >= margins * margin + _GAP)
    passes: NDArray[np.bool_] = ~(leaves & ~fine).any(axis=(1, 2))
    return passes


def _on_sides(planes: NDArray[np.float64], points: Sequence[tuple[float, ...]]) -> NDArray[np.bool_]:
    """Per obstacle, side (`planes`: obstacles x 4 x abc) and point, whether the point lies on
    the side (by :data:`_GAP` at least): ``(obstacles, 4, points)``."""
    xy = np.asarray(points, dtype=float).reshape(-1, 2)
    value = planes[..., 0, None] * xy[:, 0] + planes[..., 1, None] * xy[:, 1]
    on_it: NDArray[np.bool_] = value >= planes[..., 2, None] + _GAP
    return on_it


def _near_route(p: RobotProblem, lines: bool = False) -> set[ObstacleKey]:
    """The obstacles within reach of where the robot must be.

    To drives: the walls and objects in the box around the robot's start and home, its goods
    where they start and the places it may drop them; with `lines` (and a sequence of events),
    only those of the box near the straight lines between those places in the mission's order
    or near the places themselves (:func:`_corridor`).  To picks and drops: the walls near
    those goods and places.  Boxes are grown by the robot's side, the motion margin and the
    largest good, so that every obstacle a straight drive inside them could touch is in.
    """
    scene = p.scene
    grow = float(p.side + p.margin) + max((ob.size for ob in scene.objects.values()), default=0.0)
    robot = [p.scene.robots[p.robot].pose[:2]] + ([p.start.robot[:2]] if p.start is not None else [])
    places = []  # ((x0, y0), (x1, y1)) of each place the robot picks or drops a good at
    for o in p.own_objects:
        places.append((p.at_start(o)[0],) * 2)
        for e in p.mission:
            if e.kind == "drop" and e.obj == o:
                places.append(_drop_box(p, e))
    corners = robot + [q for place in places for q in place]
    xs, ys = [q[0] for q in corners], [q[1] for q in corners]
    boxes = [shapely.box(a[0] - grow, a[1] - grow, b[0] + grow, b[1] + grow) for a, b in places]
    route = shapely.box(min(xs) - grow, min(ys) - grow, max(xs) + grow, max(ys) + grow)
    if lines and p.automaton is None:  # a sequence: its places in order
        route = route.intersection(shapely.union_all([_corridor(p, grow), *boxes]))
    handling = shapely.union_all(boxes)
    walls = shapely.linestrings([[w.start, w.end] for w in scene.obstacles]) if scene.obstacles else []
    near = (
        {wall_key(int(i)) for i in np.flatnonzero(shapely.intersects(route, walls))} if len(walls) else set()
    )
    if len(walls) and not handling.is_empty:
        near |= {wall_key(int(i), handling=True) for i in np.flatnonzero(shapely.intersects(handling, walls))}
    if scene.objects:  # each object's square grown by its side meets the route (or touches it)
        ids = list(scene.objects)
        at = np.array([p.at_start(o)[0] for o in ids], dtype=float)
        size = np.array([scene.objects[o].size for o in ids], dtype=float)
        squares = shapely.box(at[:, 0] - size, at[:, 1] - size, at[:, 0] + size, at[:, 1] + size)
        near |= {object_key(o) for o, yes in zip(ids, shapely.intersects(route, squares), strict=True) if yes}
    return near


_CORRIDOR_SIDES = 2
"""How many robot sides, beyond the reach of a drive, the first obstacles lie within of the
straight lines between a mission's places (:func:`_corridor`)."""


def _drop_box(p: RobotProblem, e: Event) -> tuple[tuple[float, float], tuple[float, float]]:
    """The box ``(x0, y0), (x1, y1)`` of the centres where the drop `e` may put its good (mm)."""
    assert e.workspace is not None and e.obj is not None  # a drop names its goods and workspace
    (x0, x1), (y0, y1) = p.scene.workspaces[e.workspace].centres(p.scene.objects[e.obj].size).ranges
    return (x0, y0), (x1, y1)


def _corridor(p: RobotProblem, grow: float) -> shapely.Geometry:
    """Where the robot's centre is within `grow` and :data:`_CORRIDOR_SIDES` sides (mm) of the
    broken line from its start through the places of its events in order (a good where it lies
    then, the middle of a drop's box, home for a ``return``) to its home.

    Only which obstacles the solver holds from the start depends on it (the module docstring's
    claim holds for any set): on a large map the box around far-apart places holds thousands
    of walls and goods the robot never comes near, while a route keeps mostly near these lines
    (measured on MovingAI hand-overs, ``benchmarks/BENCHMARKS.md``, 2026-12-07, sixth).
    """
    home = tuple(p.scene.robots[p.robot].pose[:2])
    line = [tuple(p.start.robot[:2]) if p.start is not None else home]
    put: dict[str, tuple[float, float]] = {}  # where the mission last put each good
    for e in p.mission:
        if e.kind == "pick" and e.obj is not None:
            line.append(put.get(e.obj, p.at_start(e.obj)[0]))
        elif e.kind == "drop" and e.obj is not None:
            (x0, y0), (x1, y1) = _drop_box(p, e)
            put[e.obj] = ((x0 + x1) / 2, (y0 + y1) / 2)
            line.append(put[e.obj])
        elif e.kind == "return":
            line.append(home)
    line.append(home)
    width = grow + _CORRIDOR_SIDES * float(p.side)
    return shapely.LineString(line).buffer(width, cap_style="square", join_style="mitre")


__all__ = ["Geometry", "obstacle_of"]
