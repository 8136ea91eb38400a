"""Lanes: where two robots drive head-on through a place wide enough for both, one keeps to each side.

Each robot is planned alone, and the shortest plans of two robots that cross a wide aisle in
opposite directions often use the same line down it; the conflict step then orders them, and
one robot waits until the other has left.  When the place is wide enough for the two robots
side by side with the clearance between them, they can pass each other instead:
:func:`lanes` gives each of them the other's side of the place as space to keep out of, so that
re-planned with it as walls they drive in two lanes.

The lanes run along the wall that bounds the place (the nearest one across the drives, when it
runs roughly their way), else along the drives themselves; the free width is measured across
them, and it is split between the two robots in proportion to their extents, with the
clearance between the halves.  The robot already more to one side keeps that side (if neither
is, each keeps right).  Nothing here decides safety: the re-planned robots' conflicts are
found and ordered again like any others.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np
import shapely
from numpy.typing import ArrayLike
from shapely import Polygon
from shapely.geometry.base import BaseGeometry

from cosmop.planning.specification import MOTION_MARGIN
from cosmop.scene import Scene

__all__ = ["HEAD_ON", "lanes"]

HEAD_ON = math.cos(math.radians(135.0))
"""Two drives are head-on when the cosine of the angle between their directions is below this
(they run within 45 degrees of opposite ways)."""

Segment = tuple[tuple[float, float], tuple[float, float]]

_Wall = tuple[np.ndarray, np.ndarray]
"""A wall's end points as arrays (mm)."""


def lanes(
    scene: Scene,
    drives: Mapping[str, Segment],
    shared: BaseGeometry,
    clearance: float,
    fixed: Mapping[str, Sequence[BaseGeometry]] | None = None,
) -> dict[str, Polygon] | None:
    """The space each of two robots keeps out of so that they pass side by side, or ``None``.

    Parameters
    ----------
    scene : Scene
        The walls that bound the place, and the robots' sizes (mm).
    drives : Mapping[str, Segment]
        The two robots' drives through the place: ``robot -> ((x, y), (x', y'))``, centres in mm.
    shared : shapely geometry
        The place the two drives share (their occupancies' overlap, grown by half the clearance).
    clearance : float
        The distance (mm) the two robots keep: the halves of the place lie this far apart once
        each is grown by half of it (as the pipeline grows the walls around a space).
    fixed : Mapping[str, sequence of geometry], optional
        Each robot's places re-planning cannot move (grown by half the clearance): a lane that
        would shut one in is no lane.

    Returns
    -------
    dict or None
        ``robot -> region`` (the other's half of the place, to be kept out of), or ``None`` when
        the drives are not head-on, the place is too narrow for both, or a half covers a fixed
        place of the robot that must keep out of it.

    Examples
    --------
    >>> from cosmop.scene import Robot, Scene, Wall
    >>> scene = Scene(
    ...     obstacles=(Wall((0, 500), (6000, 500)), Wall((0, -500), (6000, -500))),
    ...     robots={"A": Robot("A", 400, (0, 0, 0)), "B": Robot("B", 400, (6000, 0, 180))},
    ... )
    >>> drives = {"A": ((500, 0), (5500, 0)), "B": ((5500, 0), (500, 0))}
    >>> keep = lanes(scene, drives, shapely.box(500, -250, 5500, 250), 100)
    >>> [tuple(round(v) for v in keep[r].bounds) for r in ("A", "B")]  # A, eastbound, keeps right
    [(300, 0, 5700, 501), (300, -501, 5700, 0)]
    """
    (a, (pa, qa)), (b, (pb, qb)) = drives.items()
    da, db = _unit(pa, qa), _unit(pb, qb)
    if da is None or db is None or float(da @ db) > HEAD_ON:
        return None
    u = _unit((0.0, 0.0), da - db)
    assert u is not None  # head-on drives point different ways
    centre = np.asarray(shared.centroid.coords[0])
    reach = 2.0 * (scene.robots[a].size + scene.robots[b].size) + clearance
    walls = [(np.asarray(w.start, float), np.asarray(w.end, float)) for w in scene.obstacles]
    u = _along_wall(walls, centre, u, reach)
    n = np.array([-u[1], u[0]])
    ends = [pa, qa, pb, qb, *shapely.get_coordinates(shared.exterior)]
    along = [float((np.asarray(p) - centre) @ u) for p in ends]
    side = max(scene.robots[a].size, scene.robots[b].size) * (abs(u[0]) + abs(u[1]))
    start, stop = min(along) - side / 2.0, max(along) + side / 2.0
    low, high = _free_width(walls, centre, u, n, (start, stop), reach)
    extent = {r: scene.robots[r].size * (abs(n[0]) + abs(n[1])) for r in (a, b)}
    slack = high - low - extent[a] - extent[b] - clearance - 4 * float(MOTION_MARGIN)
    if slack < 0:
        return None
    upper = _upper(a, b, drives, centre, n, da)
    lower = b if upper == a else a
    middle = low + extent[lower] + 2 * float(MOTION_MARGIN) + slack / 2.0 + clearance / 2.0
    keep = {
        upper: _rectangle(centre, u, n, (start, stop), (low - 1.0, middle)),
        lower: _rectangle(centre, u, n, (start, stop), (middle, high + 1.0)),
    }
    for robot, region in keep.items():
        grown = region.buffer(clearance / 2.0, join_style="mitre")
        if any(grown.intersection(place).area > 1e-9 for place in (fixed or {}).get(robot, ())):
            return None
    return keep


def _unit(p: ArrayLike, q: ArrayLike) -> np.ndarray | None:
    """The unit vector from `p` to `q` (``None`` when they coincide)."""
    d = np.asarray(q, float) - np.asarray(p, float)
    length = float(np.hypot(*d))
    return d / length if length > 1e-9 else None


def _hits(
    walls: Sequence[_Wall], origin: np.ndarray, direction: np.ndarray, reach: float
) -> list[tuple[float, int]]:
    """``(distance, wall index)`` of every wall the ray from `origin` along `direction` meets
    within `reach` mm."""
    out = []
    for i, (s, e) in enumerate(walls):
        w = e - s
        det = direction[0] * (-w[1]) + w[0] * direction[1]
        if abs(det) < 1e-12:
            continue  # parallel
        rel = s - origin
        t = (rel[0] * (-w[1]) + w[0] * rel[1]) / det
        v = (direction[0] * rel[1] - direction[1] * rel[0]) / det
        if 0.0 <= t <= reach and -1e-9 <= v <= 1.0 + 1e-9:
            out.append((float(t), i))
    return out


def _along_wall(walls: Sequence[_Wall], centre: np.ndarray, u: np.ndarray, reach: float) -> np.ndarray:
    """The lanes' direction: along the nearest wall across `u` from `centre` when it runs
    within 45 degrees of `u` (an aisle's side), else `u` itself."""
    n = np.array([-u[1], u[0]])
    hits = sorted(_hits(walls, centre, n, reach) + _hits(walls, centre, -n, reach))
    for _, i in hits:
        w = _unit(*walls[i])
        if w is not None and abs(float(w @ u)) >= math.cos(math.radians(45.0)):
            return w if float(w @ u) > 0 else -w
        break
    return u


def _free_width(
    walls: Sequence[_Wall],
    centre: np.ndarray,
    u: np.ndarray,
    n: np.ndarray,
    span: tuple[float, float],
    reach: float,
) -> tuple[float, float]:
    """How far across (along `n`, from `centre`) the place is free on each side, the least over
    its two ends and its middle (at most `reach` mm each way): ``(-below, above)``."""
    below = above = reach
    for s in (span[0], (span[0] + span[1]) / 2.0, span[1]):
        point = centre + s * u
        above = min([above, *(t for t, _ in _hits(walls, point, n, reach))])
        below = min([below, *(t for t, _ in _hits(walls, point, -n, reach))])
    return -below, above


def _upper(
    a: str, b: str, drives: Mapping[str, Segment], centre: np.ndarray, n: np.ndarray, da: np.ndarray
) -> str:
    """Which robot takes the side towards `n`: the one whose drive lies more that way; when
    neither does, the one whose right that is (each keeps right)."""
    offset = {r: float((np.add(*map(np.asarray, drives[r])) / 2.0 - centre) @ n) for r in (a, b)}
    if abs(offset[a] - offset[b]) > 1e-6:
        return a if offset[a] > offset[b] else b
    right_of_a = np.array([da[1], -da[0]])
    return a if float(right_of_a @ n) > 0 else b


def _rectangle(
    centre: np.ndarray, u: np.ndarray, n: np.ndarray, along: tuple[float, float], across: tuple[float, float]
) -> Polygon:
    """The rectangle of points ``centre + s u + t n`` with `s` in `along` and `t` in `across`."""
    corners = [centre + s * u + t * n for s, t in ((along[0], across[0]), (along[1], across[0]))]
    corners += [centre + s * u + t * n for s, t in ((along[1], across[1]), (along[0], across[1]))]
    return Polygon([(float(x), float(y)) for x, y in corners])
