"""Which part of the map a plan picture shows: where the team works, not every wall of the map.

A team busy in one corner of a big map would be a few pixels in a sea of walls. The picture
therefore shows the *activity* (:func:`activity_box`): the robots at their starts, the poses
their plans go through, the objects the plans handle (where they lie and where they are
dropped) and the workspaces they are dropped in; :func:`crop` widens it by a margin and keeps it
within the map's own extent. Lengths are mm.
"""

from __future__ import annotations

import re
from collections.abc import Iterable

from cosmop.events import ID_PATTERN, Primitive
from cosmop.planning.plan_types import PlanSet
from cosmop.scene import Scene
from cosmop.viz.scene_drawing import DEFAULT_ROBOT_SIZE

__all__ = ["Box", "activity_box", "crop"]

Box = tuple[float, float, float, float]
"""A box ``(x_min, y_min, x_max, y_max)``, mm."""

_ID = re.compile(ID_PATTERN)

MARGIN_SHARE = 0.1
"""The margin around the activity, as a share of its longer side."""
MARGIN_ROBOTS = 1.5
"""The least margin around the activity, in robot sizes (the largest robot's side)."""


def _square(x: float, y: float, side: float) -> Box:
    return (x - side / 2, y - side / 2, x + side / 2, y + side / 2)


def _union(boxes: Iterable[Box]) -> Box | None:
    boxes = list(boxes)
    if not boxes:
        return None
    return (
        min(b[0] for b in boxes),
        min(b[1] for b in boxes),
        max(b[2] for b in boxes),
        max(b[3] for b in boxes),
    )


def _used(scene: Scene, plans: PlanSet) -> tuple[list[Box], set[str], set[str]]:
    """What the plans use: the robots' footprints at every step, and the ids of the objects
    they handle and of the workspaces they drop in; dropped goods' places among the boxes."""
    boxes: list[Box] = []
    objects: set[str] = set()
    workspaces: set[str] = set()
    for rid, plan in plans.robots.items():
        robot = scene.robots.get(rid)
        side = robot.size if robot is not None else DEFAULT_ROBOT_SIZE
        for step in plan.steps:
            boxes.append(_square(*step.robot[:2], side))
            if step.object is None:
                continue
            objects.add(step.object)
            if step.primitive == Primitive.DROPOFF and step.object in step.objects:
                size = scene.objects[step.object].size if step.object in scene.objects else 0.0
                boxes.append(_square(*step.objects[step.object].position, size))
        workspaces |= {e.workspace for e in plan.mission if e.kind == "drop" and e.workspace}
    if not plans.feasible and plans.reason:  # show what the reason talks about, too
        named = set(_ID.findall(plans.reason))
        objects |= named & set(scene.objects)
        workspaces |= named & set(scene.workspaces)
    return boxes, objects, workspaces


def activity_box(scene: Scene, plans: PlanSet | None) -> Box | None:
    """The box (mm) around what a plan picture must show.

    With plans: every robot at its start (its whole square), every pose of every plan, the
    objects the plans pick up, drop off or ask about (at their places in the scene and where
    they are dropped), the workspaces they are dropped in (the plan file's own drop points
    too) and, for an infeasible plan set, the objects and workspaces its reason names. Without
    any robot's plan: the robots, objects and workspaces of the scene.

    Parameters
    ----------
    scene : Scene
    plans : PlanSet or None

    Returns
    -------
    Box or None
        ``(x_min, y_min, x_max, y_max)`` in mm; None for a scene with nothing to show.
    """
    boxes = [_square(*r.pose[:2], r.size) for r in scene.robots.values()]
    if plans is None or not plans.robots:
        objects, workspaces = set(scene.objects), set(scene.workspaces)
    else:
        used, objects, workspaces = _used(scene, plans)
        boxes += used
    boxes += [_square(*o.position, o.size) for oid, o in scene.objects.items() if oid in objects]
    for wid, ws in scene.workspaces.items():
        if wid in workspaces:
            x, y = ws.ranges
            boxes.append(_square(*ws.point, 0.0) if ws.point is not None else (x[0], y[0], x[1], y[1]))
    added = plans.added if plans is not None else ()
    boxes += [_square(*task.point, 0.0) for task in added if task.workspace in workspaces]
    return _union(boxes)


def crop(activity: Box, extent: Box, robot_size: float = DEFAULT_ROBOT_SIZE) -> Box:
    """The view of a plan picture: `activity` with a margin, within the map's `extent`.

    Parameters
    ----------
    activity : Box
        What must be seen (:func:`activity_box`), mm.
    extent : Box
        The whole map as drawn (all its walls), mm; the view never goes beyond it.
    robot_size : float
        The side of the largest robot, mm.

    Returns
    -------
    Box
        The activity widened on every side by :data:`MARGIN_SHARE` of its longer side, at
        least :data:`MARGIN_ROBOTS` robot sizes, then cut to `extent` (mm).
    """
    x0, y0, x1, y1 = activity
    margin = max(MARGIN_SHARE * max(x1 - x0, y1 - y0), MARGIN_ROBOTS * robot_size)
    view = (
        max(x0 - margin, extent[0]),
        max(y0 - margin, extent[1]),
        min(x1 + margin, extent[2]),
        min(y1 + margin, extent[3]),
    )
    if view[0] >= view[2] or view[1] >= view[3]:  # activity off the drawn map: show the map
        return extent
    return view
