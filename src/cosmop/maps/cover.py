"""Blocked cells as few rectangles, and as the fewest wall segments around them.

Two views of the same blocked area:

* :func:`rectangle_cover` splits the blocked cells into disjoint axis-aligned rectangles with
  the greedy *row-run, then grow* rule: scanning the cells row by row from the bottom left, an
  uncovered blocked cell starts a rectangle that takes the whole run of uncovered blocked cells
  to its right, then grows upwards while the row above has that whole run blocked and
  uncovered. It is exact (the rectangles' union is the blocked cells, with no overlap) and runs
  in time linear in the number of cells; it is not always the minimum number of rectangles
  (finding that is the NP-hard rectangle-cover problem in general), but it merges every
  rectangular shelf or wall block of a map into one rectangle.
* :func:`boundary_walls` gives the walls a planner needs: the edges between a free cell and a
  blocked cell or the map's outside, merged into maximal straight segments. The edges that two
  blocked rectangles share, or that face the outside, carry no information for a robot in the
  free cells (every straight motion from free space into the blocked area crosses a boundary
  edge), and fewer walls make planning faster. :func:`rectangle_walls` gives every rectangle's
  full outline instead, for comparison.

Rectangles are ``(row0, col0, row1, col1)`` half-open corner indices (cells ``row0 <= i < row1``,
``col0 <= j < col1``); walls are pairs of grid corners ``((row, col), (row, col))``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from cosmop.maps.grid import OccupancyGrid

__all__ = ["Rect", "Segment", "boundary_walls", "rectangle_cover", "rectangle_walls", "walls_in_mm"]

Rect = tuple[int, int, int, int]
Segment = tuple[tuple[int, int], tuple[int, int]]


def rectangle_cover(blocked: NDArray[np.bool_]) -> list[Rect]:
    """Disjoint rectangles whose union is exactly the blocked cells (row-run, then grow).

    Parameters
    ----------
    blocked : numpy.ndarray
        Boolean array ``(rows, columns)``.

    Returns
    -------
    list of (int, int, int, int)
        ``(row0, col0, row1, col1)`` half-open, in scan order (bottom row first, left to right).
    """
    cells = np.asarray(blocked, dtype=bool)
    todo = cells.copy()
    rows, cols = cells.shape
    rects: list[Rect] = []
    for i in range(rows):
        j = 0
        while j < cols:
            if not todo[i, j]:
                j += 1
                continue
            end = j
            while end < cols and todo[i, end]:
                end += 1
            top = i + 1
            while top < rows and todo[top, j:end].all():
                top += 1
            todo[i:top, j:end] = False
            rects.append((i, j, top, end))
            j = end
    return rects


def _runs(mask: NDArray[np.bool_]) -> list[tuple[int, int]]:
    """Maximal runs ``[start, stop)`` of True in a 1-D boolean array."""
    padded = np.concatenate(([False], mask, [False])).astype(np.int8)
    change = np.flatnonzero(np.diff(padded))
    return list(zip(change[::2].tolist(), change[1::2].tolist(), strict=True))


def boundary_walls(blocked: NDArray[np.bool_]) -> list[Segment]:
    """The edges between free cells and blocked cells (or the outside), as maximal segments.

    Parameters
    ----------
    blocked : numpy.ndarray
        Boolean array ``(rows, columns)``; the map's outside counts as blocked.

    Returns
    -------
    list of ((int, int), (int, int))
        Segments between grid corners ``(row, col)``: the horizontal ones first (bottom to top),
        then the vertical ones (left to right), each from its lower or left end.
    """
    free = np.pad(~np.asarray(blocked, dtype=bool), 1, constant_values=False)
    horizontal = free[:-1, 1:-1] != free[1:, 1:-1]  # (rows + 1, cols): edge at y = k, x in [j, j+1]
    vertical = free[1:-1, :-1] != free[1:-1, 1:]  # (rows, cols + 1): edge at x = k, y in [i, i+1]
    walls: list[Segment] = []
    for k, line in enumerate(horizontal):
        walls += [((k, a), (k, b)) for a, b in _runs(line)]
    for k, line in enumerate(vertical.T):
        walls += [((a, k), (b, k)) for a, b in _runs(line)]
    return walls


def rectangle_walls(rects: list[Rect]) -> list[Segment]:
    """Every rectangle's four edges (shared and outer edges included).

    Parameters
    ----------
    rects : list of (int, int, int, int)
        Rectangles ``(row0, col0, row1, col1)``, half-open corner indices.

    Returns
    -------
    list of ((int, int), (int, int))
        Four segments between grid corners per rectangle: bottom, top, left, right.
    """
    walls: list[Segment] = []
    for r0, c0, r1, c1 in rects:
        walls += [((r0, c0), (r0, c1)), ((r1, c0), (r1, c1)), ((r0, c0), (r1, c0)), ((r0, c1), (r1, c1))]
    return walls


def walls_in_mm(
    grid: OccupancyGrid, walls: list[Segment]
) -> list[tuple[tuple[float, float], tuple[float, float]]]:
    """Segments between grid corners as wall segments ``((x1, y1), (x2, y2))`` in mm.

    Parameters
    ----------
    grid : OccupancyGrid
        The grid the corners belong to (its origin and cell size place them).
    walls : list of ((int, int), (int, int))
        Segments between grid corners ``(row, col)``.
    """
    return [(grid.point(*a), grid.point(*b)) for a, b in walls]
