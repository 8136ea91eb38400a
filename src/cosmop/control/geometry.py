"""Chebyshev (L-infinity) gaps between axis-aligned squares, wall segments and boxes.

Robots, objects and people are axis-aligned squares (the scenario contract), and the square of
half side :math:`h` centred at :math:`c` is the L-infinity ball :math:`\\{p : \\lVert p - c
\\rVert_\\infty \\le h\\}`.  The L-infinity gap between such a square and a set :math:`S` is
therefore :math:`\\max(0, d_\\infty(c, S) - h)`, the quantity :math:`\\lVert p_r - p_o
\\rVert_\\infty` of the paper's passive-safety condition.  Every function is vectorised over
centres (any leading shape) and obstacles (last axis); units are millimetres.
"""

from __future__ import annotations

import numpy as np

__all__ = ["box_gaps", "point_segment_linf", "segment_array"]


def segment_array(segments) -> np.ndarray:
    """Segments ``[((x1, y1), (x2, y2)), ...]`` as a float array of shape ``(n, 4)``."""
    out = np.asarray([[a[0], a[1], b[0], b[1]] for a, b in segments], dtype=float)
    return out.reshape(-1, 4)


def point_segment_linf(points: np.ndarray, segments: np.ndarray) -> np.ndarray:
    """L-infinity distance from points to segments.

    :math:`d_\\infty(p, [a, b]) = \\min_{t \\in [0, 1]} \\max(|a_x + t d_x - p_x|, |a_y + t d_y -
    p_y|)` with :math:`d = b - a`.  The function of `t` is convex and piecewise linear, so its
    minimum lies at an end point or a break point: where either term is zero or where the two
    terms are equal; all six candidates are evaluated.  An axis-parallel segment is a
    degenerate box, for which the distance is the larger of the two interval distances.

    Parameters
    ----------
    points : ndarray, shape (..., 2)
        Points (mm).
    segments : ndarray, shape (m, 4)
        Segments ``x1, y1, x2, y2`` (mm).

    Returns
    -------
    ndarray, shape (..., m)
        Distances (mm).
    """
    segments = np.asarray(segments, dtype=float)
    straight = (segments[:, 0] == segments[:, 2]) | (segments[:, 1] == segments[:, 3])
    if straight.all():
        return _axis_aligned(points, segments)
    if straight.any():
        out = np.empty((*np.shape(points)[:-1], len(segments)))
        out[..., straight] = _axis_aligned(points, segments[straight])
        out[..., ~straight] = _general(points, segments[~straight])
        return out
    return _general(points, segments)


def _axis_aligned(points: np.ndarray, segments: np.ndarray) -> np.ndarray:
    """An axis-parallel segment is a degenerate box: the larger of the two interval distances."""
    p = np.asarray(points, dtype=float)[..., None, :]
    lo = np.minimum(segments[:, :2], segments[:, 2:])
    hi = np.maximum(segments[:, :2], segments[:, 2:])
    d = np.maximum(np.maximum(lo - p, p - hi), 0.0)
    return np.maximum(d[..., 0], d[..., 1])


def _general(points: np.ndarray, segments: np.ndarray) -> np.ndarray:
    p = np.asarray(points, dtype=float)[..., None, :]
    ax = segments[:, 0] - p[..., 0]
    ay = segments[:, 1] - p[..., 1]
    dx = segments[:, 2] - segments[:, 0]
    dy = segments[:, 3] - segments[:, 1]
    ax, ay = np.broadcast_arrays(ax, ay)
    best = np.maximum(np.abs(ax), np.abs(ay))
    end = np.maximum(np.abs(ax + dx), np.abs(ay + dy))
    np.minimum(best, end, out=best)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for num, den in ((-ax, dx), (-ay, dy), (ay - ax, dx - dy), (-(ax + ay), dx + dy)):
            t = np.where(den != 0, num / np.where(den != 0, den, 1.0), 0.0)
            np.clip(t, 0.0, 1.0, out=t)
            value = np.maximum(np.abs(ax + t * dx), np.abs(ay + t * dy))
            np.minimum(best, value, out=best)
    return best


def box_gaps(centres: np.ndarray, half: float | np.ndarray, boxes: np.ndarray) -> np.ndarray:
    """L-infinity gaps between squares and boxes (negative when they overlap).

    Parameters
    ----------
    centres : ndarray, shape (..., 2)
        Centres of the squares (mm).
    half : float or ndarray broadcastable to ``centres.shape[:-1] + (1,)``
        Their half sides (mm).
    boxes : ndarray, shape (m, 3)
        Boxes as ``x, y, half side`` (mm).

    Returns
    -------
    ndarray, shape (..., m)
        :math:`\\max(|\\Delta x|, |\\Delta y|) - h - k`, mm.
    """
    c = np.asarray(centres, dtype=float)[..., None, :]
    d = np.maximum(np.abs(c[..., 0] - boxes[:, 0]), np.abs(c[..., 1] - boxes[:, 1]))
    return d - half - boxes[:, 2]
