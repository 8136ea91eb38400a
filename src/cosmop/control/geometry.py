"""Chebyshev (L-infinity) gaps between axis-aligned squares, wall segments and boxes.

Robots, objects and people are axis-aligned squares (the scenario contract), and the square of
half side :math:`h` centred at :math:`c` is the L-infinity ball :math:`\\{p : \\lVert p - c
\\rVert_\\infty \\le h\\}`.  The L-infinity gap between such a square and a set :math:`S` is
therefore :math:`\\max(0, d_\\infty(c, S) - h)`, the quantity :math:`\\lVert p_r - p_o
\\rVert_\\infty` of the paper's passive-safety condition.  Every function is vectorised over
centres (any leading shape) and obstacles (last axis); units are millimetres.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "box_gaps",
    "per_row",
    "point_segment_linf",
    "rect_gaps",
    "segment_array",
    "segment_bounds",
    "swept_box_gaps",
    "swept_wall_gaps",
]


def segment_array(segments: Iterable[Sequence[Sequence[float]]]) -> NDArray[np.float64]:
    """Segments ``[((x1, y1), (x2, y2)), ...]`` as a float array of shape ``(n, 4)``.

    Parameters
    ----------
    segments : iterable of pairs of points
        Each segment's two ends ``(x, y)``, mm.
    """
    out = np.asarray([[a[0], a[1], b[0], b[1]] for a, b in segments], dtype=float)
    return out.reshape(-1, 4)


def segment_bounds(segments: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Each segment's bounding box ``x1, y1, x2, y2`` as lower and upper corners ``(n, 2)``, mm.

    Parameters
    ----------
    segments : ndarray, shape (n, 4)
        Segments ``x1, y1, x2, y2`` (mm), as from :func:`segment_array`.
    """
    ends = np.asarray(segments, dtype=float).reshape(-1, 2, 2)
    return ends.min(axis=1), ends.max(axis=1)


def rect_gaps(
    lo: NDArray[np.float64], hi: NDArray[np.float64], lows: NDArray[np.float64], highs: NDArray[np.float64]
) -> NDArray[np.float64]:
    """L-infinity distance from the box ``[lo, hi]`` to each box ``[lows, highs]`` (0 when they meet).

    It bounds from below the distance from any point of ``[lo, hi]`` to anything inside the
    other box (a wall segment lies in its bounding box, :func:`segment_bounds`).  Corners
    ``(2,)`` against boxes ``(n, 2)`` give ``(n,)``; several boxes at once, ``(G, 1, 2)``, give
    ``(G, n)``.

    Parameters
    ----------
    lo, hi : ndarray, shape (2,) or (G, 1, 2)
        Lower and upper corners of the box (or boxes), mm.
    lows, highs : ndarray, shape (n, 2)
        Lower and upper corners of the other boxes, mm.
    """
    d = np.maximum(np.maximum(lows - hi, lo - highs), 0.0)
    gaps: NDArray[np.float64] = d.max(axis=-1)
    return gaps


def point_segment_linf(points: NDArray[np.float64], segments: NDArray[np.float64]) -> NDArray[np.float64]:
    """L-infinity distance from points to segments.

    :math:`d_\\infty(p, [a, b]) = \\min_{t \\in [0, 1]} \\max(|a_x + t d_x - p_x|, |a_y + t d_y -
    p_y|)` with :math:`d = b - a`.  The function of `t` is convex and piecewise linear, so its
    minimum lies at an end point or a break point: where either term is zero or where the two
    terms are equal; all six candidates are evaluated.  An axis-parallel segment is a
    degenerate box, for which the distance is the larger of the two interval distances; a
    segment with infinite ends is infinitely far (padding, see :func:`per_row`).

    Parameters
    ----------
    points : ndarray, shape (..., 2)
        Points (mm).
    segments : ndarray, shape (m, 4) or (R, m, 4)
        Segments ``x1, y1, x2, y2`` (mm); with three axes, one set per row of `points`
        (``points`` then has shape ``(R, ..., 2)``).

    Returns
    -------
    ndarray, shape (..., m)
        Distances (mm).
    """
    seg = per_row(np.asarray(segments, dtype=float), np.ndim(points))
    straight = (seg[..., 0] == seg[..., 2]) | (seg[..., 1] == seg[..., 3])
    if straight.all():
        return _axis_aligned(points, seg)
    if seg.ndim > 2:  # one set per row: both formulas, each kept where it holds
        return np.where(straight, _axis_aligned(points, seg), _general(points, seg))
    if straight.any():
        out = np.empty((*np.shape(points)[:-1], len(seg)))
        out[..., straight] = _axis_aligned(points, seg[straight])
        out[..., ~straight] = _general(points, seg[~straight])
        return out
    return _general(points, seg)


def per_row(obstacles: NDArray[np.float64], point_axes: int) -> NDArray[np.float64]:
    """`obstacles` ``(R, m, k)`` (one set per row) shaped to broadcast against points of
    `point_axes` axes ``(R, ..., 2)`` once those gain an obstacle axis; ``(m, k)`` as it is.

    Sets of different sizes are padded with obstacles at infinity (every coordinate
    ``inf``, sizes 0): their gaps are ``inf``, as if they were absent.

    Parameters
    ----------
    obstacles : ndarray, shape (m, k) or (R, m, k)
        Segments (``k = 4``) or boxes (``k = 3``), mm; with three axes, one set per row.
    point_axes : int
        The number of axes of the points they will meet, the last being ``x, y``.
    """
    if obstacles.ndim == 2:
        return obstacles
    R, m, k = obstacles.shape
    return obstacles.reshape(R, *(1,) * (point_axes - 2), m, k)


def _axis_aligned(points: NDArray[np.float64], segments: NDArray[np.float64]) -> NDArray[np.float64]:
    """An axis-parallel segment is a degenerate box: the larger of the two interval distances."""
    p = np.asarray(points, dtype=float)[..., None, :]
    lo = np.minimum(segments[..., :2], segments[..., 2:])
    hi = np.maximum(segments[..., :2], segments[..., 2:])
    d = np.maximum(np.maximum(lo - p, p - hi), 0.0)
    gaps: NDArray[np.float64] = np.maximum(d[..., 0], d[..., 1])
    return gaps


def _general(points: NDArray[np.float64], segments: NDArray[np.float64]) -> NDArray[np.float64]:
    p = np.asarray(points, dtype=float)[..., None, :]
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # padding: inf - inf
        ax = segments[..., 0] - p[..., 0]
        ay = segments[..., 1] - p[..., 1]
        dx = segments[..., 2] - segments[..., 0]
        dy = segments[..., 3] - segments[..., 1]
        ax, ay = np.broadcast_arrays(ax, ay)
        best: NDArray[np.float64] = np.maximum(np.abs(ax), np.abs(ay))
        end = np.maximum(np.abs(ax + dx), np.abs(ay + dy))
        np.minimum(best, end, out=best)
        for num, den in ((-ax, dx), (-ay, dy), (ay - ax, dx - dy), (-(ax + ay), dx + dy)):
            t = np.where(den != 0, num / np.where(den != 0, den, 1.0), 0.0)
            np.clip(t, 0.0, 1.0, out=t)
            value = np.maximum(np.abs(ax + t * dx), np.abs(ay + t * dy))
            np.minimum(best, value, out=best)
    return best


def box_gaps(
    centres: NDArray[np.float64], half: float | NDArray[np.float64], boxes: NDArray[np.float64]
) -> NDArray[np.float64]:
    """L-infinity gaps between squares and boxes (negative when they overlap).

    Parameters
    ----------
    centres : ndarray, shape (..., 2)
        Centres of the squares (mm).
    half : float or ndarray broadcastable to ``centres.shape[:-1] + (1,)``
        Their half sides (mm).
    boxes : ndarray, shape (m, 3) or (R, m, 3)
        Boxes as ``x, y, half side`` (mm); with three axes, one set per row of `centres`
        (padded with boxes at infinity, see :func:`per_row`).

    Returns
    -------
    ndarray, shape (..., m)
        :math:`\\max(|\\Delta x|, |\\Delta y|) - h - k`, mm.
    """
    c = np.asarray(centres, dtype=float)[..., None, :]
    b = per_row(boxes, np.ndim(centres))
    d: NDArray[np.float64] = (
        c[..., 0] - b[..., 0]
    )  # the same operations as max(|dx|, |dy|) - half - k, in place
    dy = c[..., 1] - b[..., 1]
    np.abs(d, out=d)
    np.maximum(d, np.abs(dy, out=dy), out=d)
    d = d - half  # (`half` may broadcast to more axes than the gaps have)
    d -= b[..., 2]
    return d


def swept_box_gaps(
    start: Sequence[float] | NDArray[np.float64],
    end: Sequence[float] | NDArray[np.float64],
    half: float,
    boxes: NDArray[np.float64],
) -> NDArray[np.float64]:
    """L-infinity gaps between the square swept straight from `start` to `end` and boxes.

    The square of half side :math:`h` swept along :math:`[a, b]` is the Minkowski sum of the
    segment and the square, so its gap to the box of centre :math:`c` and half side :math:`k`
    is :math:`d_\\infty(c, [a, b]) - h - k` (:func:`point_segment_linf`), exactly.

    Parameters
    ----------
    start, end : sequence of float
        The square's centre at the two ends ``x, y`` (mm).
    half : float
        Its half side (mm).
    boxes : ndarray, shape (m, 3)
        Boxes as ``x, y, half side`` (mm).

    Returns
    -------
    ndarray, shape (m,)
        Gaps, mm (negative when the swept square overlaps a box).
    """
    way = np.array([[start[0], start[1], end[0], end[1]]], dtype=float)
    gaps: NDArray[np.float64] = point_segment_linf(boxes[:, :2], way)[:, 0] - half - boxes[:, 2]
    return gaps


def swept_wall_gaps(
    start: Sequence[float] | NDArray[np.float64],
    end: Sequence[float] | NDArray[np.float64],
    half: float,
    walls: NDArray[np.float64],
) -> NDArray[np.float64]:
    """L-infinity gaps between the square swept straight from `start` to `end` and wall segments.

    The swept square is the Minkowski sum of :math:`[a, b]` and the square of half side
    :math:`h`, so its gap to a wall :math:`[p, q]` is :math:`d_\\infty([a, b], [p, q]) - h`.
    Two segments that do not cross are nearest at an end of one of them (the distance is a
    norm of :math:`x - y` over the parallelogram :math:`[a, b] - [p, q]`, least on its
    boundary unless that holds 0), so the four end-to-segment distances give it exactly;
    segments that cross are at distance 0.  Exact where samples along the way are not: a
    square swept diagonally past a wall's end cuts the corner between two samples.

    Parameters
    ----------
    start, end : sequence of float
        The square's centre at the two ends ``x, y`` (mm).
    half : float
        Its half side (mm).
    walls : ndarray, shape (m, 4)
        Wall segments ``x1, y1, x2, y2`` (mm).

    Returns
    -------
    ndarray, shape (m,)
        Gaps, mm (negative when the swept square overlaps a wall).
    """
    walls = np.asarray(walls, dtype=float)
    a, b = np.asarray(start[:2], dtype=float), np.asarray(end[:2], dtype=float)
    way = np.array([[a[0], a[1], b[0], b[1]]])
    ends = point_segment_linf(np.stack([a, b]), walls).min(axis=0)
    back = np.minimum(
        point_segment_linf(walls[:, :2], way)[:, 0], point_segment_linf(walls[:, 2:], way)[:, 0]
    )
    p, q = walls[:, :2], walls[:, 2:]

    def cross(o: NDArray[np.float64], u: NDArray[np.float64], v: NDArray[np.float64]) -> NDArray[np.float64]:
        return (u[..., 0] - o[..., 0]) * (v[..., 1] - o[..., 1]) - (u[..., 1] - o[..., 1]) * (
            v[..., 0] - o[..., 0]
        )

    crossing = (cross(a, b, p) * cross(a, b, q) < 0) & (cross(p, q, a) * cross(p, q, b) < 0)
    gaps: NDArray[np.float64] = np.where(crossing, 0.0, np.minimum(ends, back)) - half
    return gaps
