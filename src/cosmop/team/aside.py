"""Where goods are set down when the robots' plans cannot choose it alone.

Three places are chosen here, before the robots are planned: where to set down goods that
block a robot and that no mission moves (:func:`place_aside`), the spot where one robot hands
goods over to another when neither can choose it first (:func:`handover_spot`), and a slot
for each of the goods that several robots drop into one workspace (:func:`dock_slots`).
The rest of this docstring is about the first.

The paper's feedback from the bottom-up layer re-allocates work: a robot whose shortest plan
asks for goods ``C`` to be moved away, when no mission moves ``C``, gets a helper that picks
``C`` and sets it down elsewhere.  This module chooses *elsewhere*: the free place nearest to
``C`` that blocks no one.  A candidate centre :math:`p` (on a grid of pitch :math:`b`, the
goods' side, around ``C``, nearest first) is taken when

* ``C``'s square at :math:`p`, grown by :data:`ROOM` on every side, overlaps no wall, no
  workspace, no robot's start square, no other goods' square grown by a robot's side (so that
  every side of them stays free to dock at), and no area a robot's current plan sweeps;
* a robot can dock to it: on one of the sides ``C`` allows, the docking pose keeps the robot's
  square clear of the walls and of every other goods' square, and lies in the free space
  connected to the helper's start (:func:`cosmop.planning.reach.free_component`).

The choice is a heuristic for *which* free place; whether the helper can really get there, and
whether the team's plans stay conflict-free with the goods there, is decided afterwards by the
solver, the conflict step and the exact checker, like every other plan.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import shapely

from cosmop.docking import docking_pose
from cosmop.planning.plan_types import RobotPlan
from cosmop.planning.reach import free_component
from cosmop.planning.regions import HalfPlane, wall_regions
from cosmop.scene import Scene
from cosmop.squares import rectangle, square, swept_square

__all__ = ["ROOM", "DockPacking", "dock_slots", "handover_spot", "place_aside"]

ROOM = 40.0
"""mm the set-down goods keep from walls, docks, robots' starts and planned motions: twice the
motion margin of :data:`cosmop.planning.specification.MOTION_MARGIN`, so that no plan has to
slide along them."""

_RINGS = 40  # candidate rings around the goods (pitch: their side)

_WallSides = tuple[tuple[HalfPlane, HalfPlane], ...]
"""A wall's regions, each for a robot's square paired with the same region for a good's."""


def place_aside(
    scene: Scene, obj: str, helper: str, plans: Mapping[str, RobotPlan]
) -> tuple[float, float] | None:
    """The free place nearest to `obj` where `helper` can set it down, or ``None``.

    Parameters
    ----------
    scene : Scene
        Walls, robots, goods and workspaces (mm).
    obj : str
        The goods to move.
    helper : str
        The robot that will move them (its start and size decide where it can dock).
    plans : Mapping[str, RobotPlan]
        The robots' current plans; the place keeps clear of every area they sweep.

    Returns
    -------
    tuple of float or None
        The goods' centre at the place (mm, on the grid of their side around where they are).
    """
    goods = scene.objects[obj]
    side, (ox, oy) = goods.size, goods.position
    body = scene.robots[helper]
    keep_off = _keep_off(scene, obj, plans)
    steps = np.arange(-_RINGS, _RINGS + 1) * side
    dx, dy = np.meshgrid(steps, steps)
    order = np.argsort(np.hypot(dx, dy), axis=None, kind="stable")
    centres = np.column_stack([ox + dx.ravel()[order], oy + dy.ravel()[order]])[1:]  # not where it is
    half = side / 2.0 + ROOM
    boxes = shapely.box(
        centres[:, 0] - half, centres[:, 1] - half, centres[:, 0] + half, centres[:, 1] + half
    )
    free = ~shapely.intersects(keep_off, boxes) if not keep_off.is_empty else np.ones(len(centres), bool)
    reach = free_component(scene, body.size / 2.0, body.pose[:2])
    stand = _standing(scene, obj, body.size)
    gap = (body.size + side) / 2.0
    for x, y in centres[free]:
        for heading in goods.headings:
            pose = shapely.Point(docking_pose((x, y), gap, heading))
            if (reach is None or reach.covers(pose)) and not stand.intersects(pose):
                return float(x), float(y)
    return None


def handover_spot(
    scene: Scene,
    obj: str,
    workspace: str,
    robots: tuple[str, ...],
    grid: int = 9,
    avoid: shapely.Geometry | None = None,
) -> tuple[float, float] | None:
    """A spot for `obj` in `workspace` where each of `robots` can dock to it, chosen before either
    is planned (a hand-over whose giver and receiver wait on each other, :mod:`cosmop.team.handover`).

    Of a grid of the centres the workspace allows (its :meth:`~cosmop.scene.Workspace.centres`),
    the spots every robot can dock to are kept (as in :func:`place_aside`, and with no wall
    between the robot and the goods: both in one region of every wall, as the specification's
    gripper asks), and of those the one
    whose square keeps farthest from the walls and the other goods (ties: nearest the middle), so
    that both robots have the most room.  ``None`` when no spot of the grid is dockable by all.

    Parameters
    ----------
    scene : Scene
        Walls, robots, goods and workspaces (mm).
    obj : str
        The goods handed over.
    workspace : str
        The workspace the spot lies in.
    robots : tuple of str
        The robots that must dock to the goods there (giver and receiver).
    grid : int
        Candidate centres per axis of a rectangular workspace.
    avoid : shapely geometry, optional
        Where the goods' square must not lie (mm): places other robots keep for good.

    Returns
    -------
    tuple of float or None
        The goods' centre at the spot (mm).
    """
    size = scene.objects[obj].size
    centres = scene.workspaces[workspace].centres(size)
    if centres.point is not None:
        spots = np.array([centres.point], dtype=float)
    else:
        (x0, x1), (y0, y1) = centres.ranges
        xs, ys = np.meshgrid(np.linspace(x0, x1, grid), np.linspace(y0, y1, grid))
        spots = np.column_stack([xs.ravel(), ys.ravel()])
    dockable = np.ones(len(spots), dtype=bool)
    if avoid is not None:
        dockable &= ~shapely.intersects(shapely.box(*(spots - size / 2).T, *(spots + size / 2).T), avoid)
    for robot in robots:
        body = scene.robots[robot]
        reach = free_component(scene, body.size / 2.0, body.pose[:2])
        stand = _standing(scene, obj, body.size)
        gap = (body.size + size) / 2.0
        regions = _wall_sides(scene, body.size, size)
        for n, (x, y) in enumerate(spots):
            poses = [docking_pose((x, y), gap, h) for h in scene.objects[obj].headings]
            dockable[n] &= any(
                (reach is None or reach.covers(shapely.Point(pose)))
                and not stand.intersects(shapely.Point(pose))
                and _no_wall_between(regions, pose[:2], (x, y))
                for pose in poses
            )
    if not dockable.any():
        return None
    parts = [shapely.LineString([w.start, w.end]) for w in scene.obstacles]
    parts += [square(*o.position, o.size) for oid, o in scene.objects.items() if oid != obj]
    around = shapely.unary_union(parts) if parts else None
    middle = spots.mean(axis=0)
    best = max(
        (n for n in range(len(spots)) if dockable[n]),
        key=lambda n: (
            round(float(square(spots[n][0], spots[n][1], size).distance(around)), 6)
            if around is not None
            else 0.0,
            -float(np.hypot(*(spots[n] - middle))),
        ),
    )
    return float(spots[best][0]), float(spots[best][1])


@dataclass(frozen=True)
class DockPacking:
    """Where goods that several robots drop into one workspace go, each in a slot of its own.

    Attributes
    ----------
    slots : tuple of (str, (float, float))
        The goods placed, in the order they are packed (each one's docking pose stays clear of
        the walls and of the goods before it), with the centre of their slot (mm).
    left_out : tuple of str
        Goods no slot could take: the workspace holds only ``len(slots)`` of them.
    """

    slots: tuple[tuple[str, tuple[float, float]], ...]
    left_out: tuple[str, ...]


def dock_slots(
    scene: Scene, workspace: str, goods: Mapping[str, str], step: float = 50.0, rest: float = 20.0
) -> DockPacking:
    """Pack `goods` (object -> the robot that drops it) into `workspace`, each docked to its slot.

    Candidate slots are a grid (pitch `step`, mm) of the centres the workspace allows each
    good.  A slot is *dockable* when, on a side the good allows, the robot's docking pose lies
    in its free space, its square clears the walls, and no wall comes between robot and good
    (the specification's gripper: both squares in one region of every wall); and, against
    the goods packed before, the good's square overlaps none of them (touching allowed) and
    the robot keeps `rest` (mm) from them, the room the conflict step gives a standing robot
    (:class:`~cosmop.team.conflicts.ConflictSettings`).  Goods are packed one at a time
    into the dockable slot that leaves the most dockable slots to the goods still to come
    (ties: the slot farthest from the middle, packing from the edges in), trying every order
    of up to four goods and keeping the order that packs the most.  A heuristic: the solver,
    the conflict step and the exact checker decide the plans, as for every place this module
    chooses.

    Parameters
    ----------
    scene : Scene
        Walls, robots, goods and workspaces (mm).
    workspace : str
        The workspace the goods are dropped into.
    goods : Mapping[str, str]
        The robot that drops each good, by object id.
    step : float
        The pitch of the candidate slots (mm).
    rest : float
        The room a docked robot keeps from the goods packed before (mm).
    """
    names = list(goods)
    candidates = {o: _dockable_slots(scene, workspace, o, goods[o], step, rest) for o in names}
    orders = itertools.permutations(names) if len(names) <= 4 else [tuple(names)]
    best: tuple[tuple[str, tuple[float, float]], ...] = ()
    for order in orders:
        packed = _pack(scene, order, candidates)
        if len(packed) > len(best):
            best = packed
        if len(best) == len(names):
            break
    placed = {o for o, _ in best}
    return DockPacking(best, tuple(o for o in names if o not in placed))


def _dockable_slots(
    scene: Scene, workspace: str, obj: str, robot: str, step: float, rest: float
) -> np.ndarray:
    """Rows ``(x, y, robot x, robot y, reach)``: slots of `obj` in `workspace` and a docking pose
    of `robot` each, clear of the walls (a row per dockable side); `reach` is the robot's half
    side and the `rest` it keeps from other goods."""
    size, body = scene.objects[obj].size, scene.robots[robot]
    centres = scene.workspaces[workspace].centres(size)
    (x0, x1), (y0, y1) = centres.ranges
    xs = np.linspace(x0, x1, max(1, round((x1 - x0) / step) + 1))
    ys = np.linspace(y0, y1, max(1, round((y1 - y0) / step) + 1))
    reach = free_component(scene, body.size / 2.0, body.pose[:2])
    walls = shapely.MultiLineString([[w.start, w.end] for w in scene.obstacles]) if scene.obstacles else None
    regions = _wall_sides(scene, body.size, size, near=shapely.box(x0, y0, x1, y1).buffer(body.size + size))
    gap = (body.size + size) / 2.0
    rows = []
    for x, y in itertools.product(xs, ys):
        for heading in scene.objects[obj].headings:
            px, py = docking_pose((x, y), gap, heading)
            if reach is not None and not reach.covers(shapely.Point(px, py)):
                continue
            if walls is not None and square(px, py, body.size).buffer(-1e-6).intersects(walls):
                continue
            if _no_wall_between(regions, (px, py), (x, y)):
                rows.append((x, y, px, py, body.size / 2.0 + rest))
    return np.array(rows, dtype=float).reshape(-1, 5)


def _wall_sides(
    scene: Scene, robot: float, good: float, near: shapely.Geometry | None = None
) -> list[_WallSides]:
    """Per wall (those meeting the geometry `near`, when given), its regions for a robot's square
    of side `robot` paired with the same regions for a good's of side `good` (mm)
    (:func:`~cosmop.planning.regions.wall_regions`)."""
    return [
        tuple(zip(wall_regions(w.start, w.end, robot), wall_regions(w.start, w.end, good), strict=True))
        for w in scene.obstacles
        if near is None or near.intersects(shapely.LineString([w.start, w.end]))
    ]


def _no_wall_between(
    regions: list[_WallSides], robot: tuple[float, float], good: tuple[float, float]
) -> bool:
    """Whether no wall comes between a robot centred at `robot` and a good at `good`: for every
    wall of :func:`_wall_sides`, both squares lie in one of its regions (the specification's
    gripper)."""
    return all(any(a.contains(*robot) and b.contains(*good) for a, b in pairs) for pairs in regions)


def _pack(
    scene: Scene, order: tuple[str, ...], candidates: Mapping[str, np.ndarray]
) -> tuple[tuple[str, tuple[float, float]], ...]:
    """Goods of `order` packed one at a time (see :func:`dock_slots`); stops at the first that
    finds no slot."""
    placed: list[tuple[float, float, float]] = []  # (x, y, half side) of the goods packed
    out = []
    for n, obj in enumerate(order):
        rows = _clear(candidates[obj], scene.objects[obj].size / 2.0, placed)
        if not len(rows):
            break
        best = max(rows, key=lambda row: _leaves(scene, row, obj, order[n + 1 :], candidates, placed))
        placed.append((float(best[0]), float(best[1]), scene.objects[obj].size / 2.0))
        out.append((obj, (float(best[0]), float(best[1]))))
    return tuple(out)


def _leaves(
    scene: Scene,
    row: np.ndarray,
    obj: str,
    rest: Sequence[str],
    candidates: Mapping[str, np.ndarray],
    placed: list[tuple[float, float, float]],
) -> tuple[int, float, float, float]:
    """How good a slot is: the dockable slots it leaves the goods still to pack, then how far
    it lies from the middle of the workspace (packing from the edges in)."""
    after = [*placed, (float(row[0]), float(row[1]), scene.objects[obj].size / 2.0)]
    room = sum(len(_clear(candidates[o], scene.objects[o].size / 2.0, after)) for o in rest)
    middle = candidates[obj][:, :2].mean(axis=0)
    return room, round(float(np.hypot(*(row[:2] - middle))), 6), -float(row[0]), -float(row[1])


def _clear(rows: np.ndarray, half: float, placed: list[tuple[float, float, float]]) -> np.ndarray:
    """The `rows` (slots of goods of half side `half`) whose good overlaps none of the `placed`
    goods and whose docking robot keeps its rest from them."""
    if not placed or not len(rows):
        return rows
    ok = np.ones(len(rows), dtype=bool)
    for x, y, h in placed:
        good = (np.abs(rows[:, 0] - x) < half + h - 1e-6) & (np.abs(rows[:, 1] - y) < half + h - 1e-6)
        reach = rows[:, 4] + h
        body = (np.abs(rows[:, 2] - x) < reach) & (np.abs(rows[:, 3] - y) < reach)
        ok &= ~good & ~body
    return rows[ok]


def _keep_off(scene: Scene, obj: str, plans: Mapping[str, RobotPlan]) -> shapely.Geometry:
    """Everything the set-down goods' grown square must not overlap (one shapely geometry)."""
    parts = [shapely.LineString([w.start, w.end]) for w in scene.obstacles]
    parts += [rectangle(*ws.ranges) for ws in scene.workspaces.values()]
    reach = max((r.size for r in scene.robots.values()), default=0.0)
    for oid, other in scene.objects.items():
        if oid != obj:  # every side of the others stays free to dock at
            parts.append(square(*other.position, other.size + 2 * reach))
    parts += [square(*robot.pose[:2], robot.size) for robot in scene.robots.values()]
    for rid, plan in plans.items():
        size = scene.robots[rid].size
        poses = [scene.robots[rid].pose, *(step.robot for step in plan.steps)]
        parts += [swept_square(a, b, size) for a, b in itertools.pairwise(poses)]
    return shapely.unary_union(parts)


def _standing(scene: Scene, obj: str, size: float) -> shapely.Geometry:
    """Robot centres whose square overlaps a wall or other goods (touching allowed)."""
    half = size / 2.0
    parts = [scene.blocked(half)]
    for oid, other in scene.objects.items():
        if oid != obj:
            grown = (size + other.size) / 2.0 - 0.5
            parts.append(square(*other.position, 2 * grown))
    return shapely.unary_union(parts)
