"""Axis-aligned squares, the footprint of every body in a scene, and the area one sweeps.

The one place these are built: the exact checker, the conflicts between plans, the free space
of a scene and the global paths all grow walls and motions by the same square.
"""

from __future__ import annotations

from collections.abc import Iterable
from functools import lru_cache

import numpy as np
import shapely
from numpy.typing import NDArray
from shapely import LineString, Point, Polygon, box

from cosmop.docking import DOCKING_HEADINGS, docking_pose

__all__ = ["docking_places", "overlap_depths", "rectangle", "square", "swept_square"]


def square(x: float, y: float, side: float) -> Polygon:
    """The axis-aligned square of side `side` centred at ``(x, y)`` (mm).

    Parameters
    ----------
    x, y : float
        The centre, mm.
    side : float
        The side, mm.

    Returns
    -------
    shapely.Polygon
        Given arrays instead, an array of squares, one per element (shapely builds them at once).
    """
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

    Parameters
    ----------
    x, y : iterable of float
        The ranges ``(lo, hi)`` of the object's centre, mm.
    gap : float
        The centre distance at which the robot's and the object's squares touch, mm.
    headings : iterable of int, optional
        The docking headings to take, degrees (default all four).

    Returns
    -------
    list of shapely geometries
        One point, segment or rectangle per heading, in the order of `headings`.

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
    segment when it has no width or no height (a zero-area polygon would intersect nothing).

    Parameters
    ----------
    x, y : iterable of float
        The ranges ``(lo, hi)``, mm.

    Returns
    -------
    shapely.Point, shapely.LineString or shapely.Polygon
    """
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
    return _swept(float(x0), float(y0), float(x1), float(y1), float(side))


@lru_cache(maxsize=1 << 14)  # a running fleet asks again for every robot's drives at every hand-over
def _swept(x0: float, y0: float, x1: float, y1: float, side: float) -> Polygon:
    first = square(x0, y0, side)
    if abs(x1 - x0) == 0 and abs(y1 - y0) == 0:
        return first
    return first.union(square(x1, y1, side)).convex_hull


def overlap_depths(
    shapes: NDArray[np.object_], left: NDArray[np.intp], right: NDArray[np.intp]
) -> NDArray[np.float64]:
    """How deep the pairs ``(shapes[left[n]], shapes[right[n]])`` of convex polygons overlap (mm).

    By the separating axis theorem, two convex polygons' interiors overlap iff their
    projections overlap on the unit normal of every edge of both.  The depth is the least of
    those overlaps: positive when the interiors overlap, at most 0 when the polygons only touch
    or lie apart (then minus the gap along the axis that separates them).  A shape that is not a
    convex polygon without holes (within 1e-6 mm) gives its pairs NaN.

    Parameters
    ----------
    shapes : numpy.ndarray of shapely geometries
        The shapes, mm.
    left, right : numpy.ndarray of int
        Indices into `shapes`: the pairs to compare, of equal length.

    Returns
    -------
    numpy.ndarray of float
        One depth per pair, mm (NaN where a shape is not a convex polygon).

    Examples
    --------
    >>> shapes = np.array([square(0, 0, 2), square(1.5, 0, 2), square(5, 0, 2)])
    >>> overlap_depths(shapes, np.array([0, 0]), np.array([1, 2])).round(6).tolist()
    [0.5, -3.0]
    """
    corners, normals, edges, convex = _convex(shapes)
    axes = np.concatenate([normals[left], normals[right]], axis=1)  # (pairs, axes, 2)
    real = np.concatenate([edges[left], edges[right]], axis=1)
    a = np.einsum("pkd,pvd->pkv", axes, corners[left])  # projections (pairs, axes, corners)
    b = np.einsum("pkd,pvd->pkv", axes, corners[right])
    overlap = np.minimum(a.max(axis=2), b.max(axis=2)) - np.maximum(a.min(axis=2), b.min(axis=2))
    depth = np.where(real, overlap, np.inf).min(axis=1)
    return np.where(convex[left] & convex[right], depth, np.nan)


def _convex(
    shapes: NDArray[np.object_],
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_], NDArray[np.bool_]]:
    """Each shape's corners ``(m, V, 2)`` (the last repeated up to V), its edges' unit normals
    ``(m, V, 2)`` with whether each edge is real (not of zero length), and whether it is a
    convex polygon without holes (every corner on the inner side of every edge)."""
    polygon = (shapely.get_type_id(shapes) == 3) & (shapely.get_num_interior_rings(shapes) == 0)
    rings = shapely.get_exterior_ring(np.where(polygon, shapes, np.array(None)))
    coords, owner = shapely.get_coordinates(rings, return_index=True)
    count = np.bincount(owner, minlength=len(shapes)) - 1  # the ring closes on its first corner
    polygon &= count >= 3
    first = np.concatenate([[0], np.cumsum(count + 1)[:-1]])
    at = first[:, None] + np.minimum(
        np.arange(max(int(count.max(initial=3)), 3)), np.maximum(count - 1, 0)[:, None]
    )
    corners = coords[np.minimum(at, len(coords) - 1)] if len(coords) else np.zeros((*at.shape, 2))
    side = np.roll(corners, -1, axis=1) - corners
    length = np.hypot(side[..., 0], side[..., 1])
    edges = length > 0
    normals = np.stack([-side[..., 1], side[..., 0]], axis=-1) / np.where(edges, length, 1.0)[..., None]
    # signed distances of every corner from every edge's line, one sign for a convex ring
    offset = corners[:, None, :, :] - corners[:, :, None, :]  # (m, edge, corner, 2)
    distance = np.einsum("mekd,med->mek", offset, normals)
    inner = np.where(edges[..., None], distance, 0.0)
    convex = polygon & ((inner >= -1e-6).all(axis=(1, 2)) | (inner <= 1e-6).all(axis=(1, 2)))
    return corners, normals, edges, convex
