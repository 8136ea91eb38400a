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

The same free space bounds how many drives a plan needs (:func:`least_drives`): a mission that
needs more steps than the search allows is refused without the solver.  Most missions are
reached by the free space near the robot and its places (the walls far away are not grown).
The places alone bound how long its route is (:func:`least_route`, in the Manhattan metric the
synthesis measures routes in): a shorter route need not be asked for below it.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import replace

import shapely

from cosmop.docking import docking_pose
from cosmop.events import Event
from cosmop.scene import Scene, Workspace
from cosmop.squares import docking_places
from cosmop.units import show_point

__all__ = ["event_place", "free_component", "least_drives", "least_route", "unreachable"]

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
    places = [
        (i, e, event_place(scene, robot, e)) for i, e in enumerate(events, 1) if e.kind in ("pick", "drop")
    ]
    if not places or _reached_nearby(scene, half, (x0, y0), [where for _, _, where in places]):
        return None
    component = free_component(scene, half, (x0, y0))
    if component is None:
        return None
    for i, event, where in places:
        if not component.intersects(where):
            return (
                f"{robot} cannot reach {event.name} (event {i} of its mission) at any horizon: "
                f"{_separating(scene, half, (x0, y0), where)} its start "
                f"{show_point((x0, y0), scene.units)} from {_place_words(scene, robot, event)}"
            )
    return None


def event_place(
    scene: Scene,
    robot: str,
    event: Event,
    at: tuple[float, float] | None = None,
    centres: Workspace | None = None,
) -> shapely.Geometry | None:
    """Where `event` needs the robot's centre (mm), or ``None`` for an event without a place:
    a pick's poses facing its goods, a drop's every pose that puts its goods in the workspace
    (PickUp's and DropOff's poses, :func:`~cosmop.squares.docking_places`), a return's home.

    Parameters
    ----------
    scene : Scene
    robot : str
        The robot's id.
    event : Event
    at : tuple of float, optional
        Where a pick's goods lie (mm), if not where the scene puts them.
    centres : Workspace, optional
        Where a drop may put its goods' centre, if not anywhere inside its workspace.
    """
    body = scene.robots[robot]
    if event.kind == "return":
        return shapely.Point(body.pose[:2])
    if event.kind not in ("pick", "drop"):
        return None
    assert event.obj is not None  # picks and drops name their object
    obj = scene.objects[event.obj]
    d = (body.size + obj.size) / 2.0
    if event.kind == "pick":
        return shapely.MultiPoint(_pick_poses(scene, robot, event.obj, at))
    assert event.workspace is not None  # a drop names its workspace
    centres = centres or scene.workspaces[event.workspace].centres(obj.size)
    return shapely.union_all(docking_places(*centres.ranges, d, obj.headings))


def _pick_poses(
    scene: Scene, robot: str, obj: str, at: tuple[float, float] | None = None
) -> list[tuple[float, float]]:
    """Where `robot` stands to pick `obj` (lying at `at`, by default where the scene puts it),
    one pose per side it is handled from, in the order of its sides (PickUp's poses)."""
    goods = scene.objects[obj]
    d = (scene.robots[robot].size + goods.size) / 2.0
    return [docking_pose(at or goods.position, d, h) for h in goods.headings]


def _place_words(scene: Scene, robot: str, event: Event) -> str:
    """The places of :func:`event_place` in words, for a pick or a drop."""
    assert event.obj is not None  # picks and drops name their object
    obj = scene.objects[event.obj]
    if event.kind == "pick":
        poses = _pick_poses(scene, robot, event.obj)
        sides = ", ".join(
            f"{side} {show_point(pose, scene.units)}" for side, pose in zip(obj.sides, poses, strict=True)
        )
        return f"its pick poses on the sides tried: {sides}"
    return f"any pose that drops {event.obj} in {event.workspace} (sides tried: {', '.join(obj.sides)})"


def _reached_nearby(
    scene: Scene, half: float, start: tuple[float, float], places: Sequence[shapely.Geometry]
) -> bool:
    """Whether the free space inside a box around `start` and `places` already joins the start
    to every place: then the whole free space does (it holds that part), and the walls far
    away need not be grown and joined (most of a warehouse's, for most missions)."""
    lo_x, lo_y, hi_x, hi_y = shapely.union_all([shapely.Point(start), *places]).bounds
    room = 4 * half + 1000.0
    part = free_component(scene, half, start, within=(lo_x - room, lo_y - room, hi_x + room, hi_y + room))
    return part is not None and all(part.intersects(where) for where in places)


def _separating(scene: Scene, half: float, start: tuple[float, float], where: shapely.Geometry) -> str:
    """What walls the robot off from `where`, with its verb: the walls the planner added and
    labelled (a robot standing, a space kept clear) without which it would reach ("R1, failed
    at 90.1 s, separates"), else "walls separate".  Of more than :data:`_MOST_LABELS_TRIED`
    labels, only those whose walls lie nearest `where` are tried (a label farther away that
    separates is then not named)."""
    labels = sorted({w.label for w in scene.obstacles if w.label is not None})
    if not labels:
        return "walls separate"
    if len(labels) > _MOST_LABELS_TRIED:  # the nearest to `where` are the likeliest to shut it out
        labelled = [(w.label, (w.start, w.end)) for w in scene.obstacles if w.label is not None]
        lines = shapely.linestrings([ends for _, ends in labelled])
        far: dict[str, float] = {}
        for (label, _), d in zip(labelled, shapely.distance(lines, where).tolist(), strict=True):
            far[label] = min(far.get(label, math.inf), d)
        labels = sorted(far, key=lambda label: (far[label], label))[:_MOST_LABELS_TRIED]

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


def free_component(
    scene: Scene,
    half: float,
    start: tuple[float, float],
    within: tuple[float, float, float, float] | None = None,
) -> shapely.Polygon | None:
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
    within : (float, float, float, float), optional
        A box ``(xmin, ymin, xmax, ymax)`` (mm): the component of the free space inside it
        only, which is part of the whole one (by default a frame around the whole scene).
    """
    if within is not None:
        blocked = scene.blocked(half, _SLACK, within=within)
        frame = shapely.box(*within)
    else:
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


def least_drives(
    scene: Scene, robot: str, places: Sequence[shapely.Geometry], start: tuple[float, float] | None = None
) -> int:
    """Fewest GoTo steps of any plan that takes `robot` from `start` to each of `places` in turn.

    A lower bound, sound for the same reason as :func:`unreachable`: each GoTo is one straight
    drive whose centre path stays in the free space (walls grown by the robot's square, less
    :data:`_SLACK`; objects ignored, which only enlarges it).  Between two consecutive places
    :math:`P` and :math:`Q` a plan drives at least

    * 0 times if they meet;
    * once if one straight drive may join them: some part of the free space inside the convex
      hull of :math:`P \\cup Q` touches both (a drive from :math:`p \\in P` to :math:`q \\in Q`
      lies in that hull, and is connected);
    * twice otherwise.

    The bound is the sum over the legs: a plan's drives split at the instants it is at each place.

    Parameters
    ----------
    scene : Scene
        The scene whose walls block the robot.
    robot : str
        The robot's id.
    places : sequence of shapely geometries
        Where the robot must be, in order (mm): its pick poses, drop poses, home.
    start : tuple of float, optional
        Where the robot starts (mm), if not its pose in the scene.

    Returns
    -------
    int
    """
    body = scene.robots[robot]
    here = shapely.Point(start if start is not None else body.pose[:2])
    total = 0
    for there in places:
        if here.distance(there) > _TOUCH:
            total += 1 if _one_drive_may_join(scene, body.size / 2.0, here, there) else 2
        here = there
    return total


_TOUCH = 1e-3  # mm within which two places count as meeting: floating point is not exact


def least_route(places: Sequence[shapely.Geometry], start: tuple[float, float]) -> float:
    """A lower bound on the Manhattan length (mm) of any route from `start` through each of
    `places` in turn: :math:`\\min \\sum_i |z_i - z_{i+1}|_1` over :math:`z_0 =` `start` and
    :math:`z_i` in place :math:`i`, walls ignored (which only shortens it).

    Each place is taken as the union of the bounding boxes of its parts (which contain it, so
    the bound stays sound). For one choice of box per place the Manhattan metric splits by axis,
    and on one axis the least total of moves between intervals in turn is found greedily: keep
    the interval of positions reached at the least cost so far; the next interval either meets
    it (no cost, keep the overlap) or lies beside it (pay the gap, keep its near end).  Every
    choice of boxes is tried (a pick has up to four poses, a drop one place per heading); past
    :data:`_CHOICES` of them, each leg is bounded alone (a weaker bound, still sound).

    Parameters
    ----------
    places : sequence of shapely geometries
        Where the route must pass, in order (mm): pick poses, drop places, home.
    start : tuple of float
        Where the route starts (mm).

    Returns
    -------
    float
        mm.

    Examples
    --------
    >>> least_route([shapely.Point(300, 400), shapely.box(1000, 0, 2000, 100)], (0.0, 0.0))
    1700.0
    """
    layers = [[(start[0], start[1], start[0], start[1])]]
    for place in places:
        parts = [part.bounds for part in getattr(place, "geoms", [place]) if not part.is_empty]
        if not parts:
            return 0.0
        layers.append(parts)
    if math.prod(len(layer) for layer in layers) > _CHOICES:
        legs = itertools.pairwise(layers)
        return sum(min(_chase([a, b]) for a in here for b in there) for here, there in legs)
    return min(_chase(list(boxes)) for boxes in itertools.product(*layers))


_CHOICES = 4096
"""Choices of one box per place beyond which :func:`least_route` bounds each leg alone."""


def _chase(boxes: Sequence[tuple[float, float, float, float]]) -> float:
    """The least Manhattan length through `boxes` (``x0, y0, x1, y1``, mm) in turn."""
    total = 0.0
    for axis in (0, 1):
        lo, hi = boxes[0][axis], boxes[0][axis + 2]
        for box in boxes[1:]:
            a, b = box[axis], box[axis + 2]
            if b < lo:  # the next interval lies below: move to its top
                total, lo, hi = total + lo - b, b, b
            elif a > hi:  # above: move to its bottom
                total, lo, hi = total + a - hi, a, a
            else:  # they meet: no move, and only the overlap is reached at this cost
                lo, hi = max(lo, a), min(hi, b)
    return total


def _one_drive_may_join(scene: Scene, half: float, a: shapely.Geometry, b: shapely.Geometry) -> bool:
    """Whether a straight drive of a square of half-side `half` might join `a` to `b`: whether
    one piece of the free space inside their convex hull comes within :data:`_TOUCH` of both."""
    hull = shapely.union(a, b).convex_hull
    blocked = scene.blocked(half, _SLACK, within=hull.bounds) if scene.obstacles else None
    if blocked is None or blocked.is_empty:
        return True
    free = hull.difference(blocked)
    return any(part.dwithin(a, _TOUCH) and part.dwithin(b, _TOUCH) for part in getattr(free, "geoms", [free]))
