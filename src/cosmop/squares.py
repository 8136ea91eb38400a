"""Axis-aligned squares, the footprint of every body in a scene, and the area one sweeps.

The one place these are built: the exact checker, the conflicts between plans, the free space
of a scene and the global paths all grow walls and motions by the same square.
"""

from __future__ import annotations

from collections.abc import Iterable

from shapely import LineString, Point, Polygon, box

from cosmop.docking import DOCKING_HEADINGS, docking_pose

__all__ = ["docking_places", "rectangle", "square", "swept_square"]


def square(x: float, y: float, side: float) -> Polygon:
    """The axis-aligned square of side `side` centred at ``(x, y)`` (mm)."""
    half = side / 2.0
    return box(x - half, y - half, x + half, y + half)


def docking_places(
    x: Iterable[float], y: Iterable[float], gap: float, headings: Iterable[int] = DOCKING_HEADINGS
) -> list[Point | LineString | Polygon]:
    """Robot centres that dock, from any of `headings` (:data:`DOCKING_HEADINGS`), to an object
    whose centre lies in the rectangle ``x[0] <= x <= x[1]``, ``y[0] <= y <= y[1]`` (mm; equal
    bounds: a point).

    One place per heading: the rectangle moved by :math:`-d\\,(\\cos h, \\sin h)`, `gap` being
    :math:`d`.

    Examples
    --------
    >>> [p.wkt for p in docking_places((0, 0), (0, 0), 250)]
    ['POINT (-250 0)', 'POINT (0 -250)', 'POINT (250 0)', 'POINT (0 250)']
    """
    (x0, x1), (y0, y1) = x, y
    out = []
    for heading in headings:  # the rectangle's corners, each moved to its docking pose
        (ax, ay), (bx, by) = docking_pose((x0, y0), gap, heading), docking_pose((x1, y1), gap, heading)
        out.append(rectangle((ax, bx), (ay, by)))
    return out


def rectangle(x: Iterable[float], y: Iterable[float]) -> Point | LineString | Polygon:
    """The closed rectangle ``x[0] <= x <= x[1]``, ``y[0] <= y <= y[1]`` (mm), as a point or a
    segment when it has no width or no height (a zero-area polygon would intersect nothing)."""
    (x0, x1), (y0, y1) = x, y
    if x0 == x1 and y0 == y1:
        return Point(x0, y0)
    if x0 == x1 or y0 == y1:
        return LineString([(x0, y0), (x1, y1)])
    return box(x0, y0, x1, y1)


def swept_square(start: Iterable[float], end: Iterable[float], side: float) -> Polygon:
    """The area swept by a square moving in a straight line: the convex hull of its two squares.

    Parameters
    ----------
    start, end : iterable of float
        Centres ``(x, y, ...)`` at the two ends (mm); further items (a heading) are ignored.
    side : float
        The square's side, mm.

    Returns
    -------
    shapely.Polygon
    """
    x0, y0, *_ = start
    x1, y1, *_ = end
    first = square(x0, y0, side)
    if abs(x1 - x0) == 0 and abs(y1 - y0) == 0:
        return first
    return first.union(square(x1, y1, side)).convex_hull
