"""A fast, sound test that a robot can never perform an event: its free space does not reach.

Proving with the solver that no plan of at most K steps exists takes every horizon up to K
(seconds each on a warehouse); a robot walled off from an object needs no solver at all.  The
robot's *free space* here is the set of centres where its square overlaps no wall (touching
allowed), objects ignored; its *component* is the part connected to where the robot starts.  A
plan moves the robot only inside that component (a straight GoTo never crosses a wall), so:

* ``pick(R,O)`` needs one of the four pick poses :math:`o - d\\,(\\cos h, \\sin h)`,
  :math:`h \\in \\{0, 90, 180, 270\\}`, in it (:math:`d` the centre distance at which robot and
  object touch, PickUp's pose);
* ``drop(R,O,W)`` needs a pose :math:`w - d\\,(\\cos h, \\sin h)` in it, :math:`w` a centre that
  puts O wholly inside W.

If not, the event is unreachable at any horizon.  Ignoring objects only enlarges the free
space, and the walls are grown by the exact Minkowski sum with the square, less half a
millimetre (a passage exactly one robot wide stays open), so the test never refuses a
feasible mission; it proves only what no plan can do.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import shapely

from cosmop.docking import docking_pose
from cosmop.events import Event
from cosmop.scene import Scene
from cosmop.squares import docking_places
from cosmop.units import show_point

__all__ = ["free_component", "unreachable"]

_SLACK = 0.5  # mm the grown walls are shrunk by: touching and one-robot-wide passages stay free


def unreachable(
    scene: Scene, robot: str, events: Sequence[Event], start: tuple[float, float] | None = None
) -> str | None:
    """Why `robot` can never perform one of `events`, or ``None`` when the test cannot tell.

    Parameters
    ----------
    scene : Scene
        The scene: walls, objects and workspaces.
    robot : str
        The robot's id.
    events : sequence of Event
        Its mission (messages and requests are ignored).
    start : tuple of float, optional
        Where the robot starts (mm), if not its pose in the scene.

    Returns
    -------
    str or None
        The first event it cannot reach, in words.
    """
    if not scene.obstacles:
        return None
    body = scene.robots[robot]
    half = body.size / 2.0
    x0, y0 = start if start is not None else body.pose[:2]
    component = free_component(scene, half, (x0, y0))
    if component is None:
        return None
    for i, event in enumerate(events, 1):
        if event.kind not in ("pick", "drop"):
            continue
        assert event.obj is not None  # picks and drops name their object
        d = (body.size + scene.objects[event.obj].size) / 2.0
        if event.kind == "pick":
            obj = scene.objects[event.obj]
            poses = [docking_pose(obj.position, d, h) for h in obj.headings]
            where = shapely.MultiPoint(poses)
            sides = ", ".join(
                f"{side} {show_point(pose, scene.units)}" for side, pose in zip(obj.sides, poses, strict=True)
            )
            what = f"its pick poses on the sides tried: {sides}"
        else:
            assert event.workspace is not None  # a drop names its workspace
            obj = scene.objects[event.obj]
            centres = scene.workspaces[event.workspace].centres(obj.size)
            where = shapely.union_all(docking_places(*centres.ranges, d, obj.headings))
            what = f"any pose that drops {event.obj} in {event.workspace}"
            what += f" (sides tried: {', '.join(obj.sides)})"
        if not component.intersects(where):
            return (
                f"{robot} cannot reach {event.name} (event {i} of its mission) at any horizon: "
                f"{_separating(scene, half, (x0, y0), where)} its start "
                f"{show_point((x0, y0), scene.units)} from {what}"
            )
    return None


def _separating(scene: Scene, half: float, start: tuple[float, float], where: shapely.Geometry) -> str:
    """What walls the robot off from `where`, with its verb: the walls the planner added and
    labelled (a robot standing, a space kept clear) without which it would reach ("R1, failed
    at 90.1 s, separates"), else "walls separate"."""
    labels = sorted({w.label for w in scene.obstacles if w.label is not None})
    if not labels or len(labels) > _MOST_LABELS_TRIED:
        return "walls separate"

    def reaches_without(dropped: set[str]) -> bool:
        kept = tuple(w for w in scene.obstacles if w.label not in dropped)
        component = free_component(replace(scene, obstacles=kept), half, start) if kept else None
        return component is None or component.intersects(where)

    alone = [label for label in labels if reaches_without({label})]
    if len(alone) == 1:
        return f"{alone[0]}, separates"
    if alone:
        return f"each of what the planner added ({'; '.join(alone)}) separates"
    if reaches_without(set(labels)):
        return f"walls and what the planner added ({'; '.join(labels)}) separate"
    return "walls separate"


_MOST_LABELS_TRIED = 8  # each label tried costs a free-space component of the scene


def free_component(scene: Scene, half: float, start: tuple[float, float]) -> shapely.Polygon | None:
    """The centres of a square of half-side `half` (mm) that overlaps no wall, connected to `start`.

    A shapely polygon (objects ignored; touching allowed), or ``None`` when `start` itself is
    inside a wall.

    Parameters
    ----------
    scene : Scene
        The scene whose walls block the square.
    half : float
        The square's half-side (mm).
    start : (float, float)
        A centre in the component wanted (mm).
    """
    blocked = scene.blocked(half, _SLACK)
    # a frame around everything: walls, objects, workspaces and the start
    points = [start, *(o.position for o in scene.objects.values())]
    for ws in scene.workspaces.values():
        if ws.point is not None:
            points += [ws.point]
        else:
            assert ws.x is not None and ws.y is not None  # a rectangle
            points += [(ws.x[0], ws.y[0]), (ws.x[1], ws.y[1])]
    lo_x, lo_y, hi_x, hi_y = shapely.MultiPoint(points).union(blocked).bounds
    margin = 4 * half + 1000.0
    frame = shapely.box(lo_x - margin, lo_y - margin, hi_x + margin, hi_y + margin)
    free = frame.difference(blocked)
    point = shapely.Point(start)
    for part in getattr(free, "geoms", [free]):
        if part.intersects(point.buffer(_SLACK)):
            return part
    return None  # the start itself is inside a wall: leave the verdict to the solver
