"""Where to set down goods that block a robot and that no mission moves.

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
from collections.abc import Mapping

import numpy as np
import shapely

from cosmop.docking import docking_pose
from cosmop.planning.plan import RobotPlan
from cosmop.planning.reach import free_component
from cosmop.scene import Scene
from cosmop.squares import rectangle, square, swept_square

__all__ = ["ROOM", "place_aside"]

ROOM = 40.0
"""mm the set-down goods keep from walls, docks, robots' starts and planned motions: twice the
motion margin of :data:`cosmop.planning.specification.MOTION_MARGIN`, so that no plan has to
slide along them."""

_RINGS = 40  # candidate rings around the goods (pitch: their side)


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


def _keep_off(scene: Scene, obj: str, plans: Mapping[str, RobotPlan]):
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


def _standing(scene: Scene, obj: str, size: float):
    """Robot centres whose square overlaps a wall or other goods (touching allowed)."""
    half = size / 2.0
    parts = [scene.blocked(half)]
    for oid, other in scene.objects.items():
        if oid != obj:
            grown = (size + other.size) / 2.0 - 0.5
            parts.append(square(*other.position, 2 * grown))
    return shapely.unary_union(parts)
