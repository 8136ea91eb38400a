"""Axis-aligned squares, the footprint of every body in a scene, and the area one sweeps.

The one place these are built: the exact checker, the conflicts between plans, the free space
of a scene and the global paths all grow walls and motions by the same square.
"""

from __future__ import annotations

from collections.abc import Iterable

from shapely import Polygon, box

__all__ = ["square", "swept_square"]


def square(x: float, y: float, side: float) -> Polygon:
    """The axis-aligned square of side `side` centred at ``(x, y)`` (mm)."""
    half = side / 2.0
    return box(x - half, y - half, x + half, y + half)


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
