"""Occupancy grids: which cells of a regular grid are blocked, and where the grid lies.

A grid's row 0 is its *bottom* row (y grows upwards, REP 103), so cell ``(i, j)`` covers
``x0 + j*c <= x <= x0 + (j+1)*c`` and ``y0 + i*c <= y <= y0 + (i+1)*c`` (mm), with ``c`` the
cell size and ``(x0, y0)`` the grid's lower-left corner. Image-like formats list their top row
first; the readers flip them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cosmop.errors import CosmopInputError

__all__ = ["MapError", "OccupancyGrid"]


class MapError(CosmopInputError):
    """A map file (MovingAI ``.map``, ROS ``map.yaml`` or its image) that cannot be read."""


@dataclass(frozen=True, eq=False)
class OccupancyGrid:
    """A grid of blocked and free cells.

    Parameters
    ----------
    blocked : numpy.ndarray
        Boolean array of shape ``(rows, columns)``; ``blocked[i, j]`` is the cell in row ``i``
        counted from the bottom and column ``j`` counted from the left. Copied, read-only.
    cell_size : float
        Side of a cell, mm (> 0).
    origin : tuple of float, optional
        The lower-left corner of cell ``(0, 0)``, mm (default ``(0, 0)``).
    """

    blocked: NDArray[np.bool_]
    cell_size: float
    origin: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self) -> None:
        cells = np.array(self.blocked, dtype=bool)
        if cells.ndim != 2 or 0 in cells.shape:
            raise ValueError(f"a grid needs a non-empty 2-D array of cells, got shape {cells.shape}")
        cells.setflags(write=False)
        object.__setattr__(self, "blocked", cells)
        if not (math.isfinite(self.cell_size) and self.cell_size > 0):
            raise ValueError(f"the cell size must be a positive number of mm, got {self.cell_size!r}")
        object.__setattr__(self, "cell_size", float(self.cell_size))
        object.__setattr__(self, "origin", (float(self.origin[0]), float(self.origin[1])))

    @property
    def shape(self) -> tuple[int, int]:
        """``(rows, columns)``."""
        return self.blocked.shape

    def point(self, row: int, column: int) -> tuple[float, float]:
        """The grid corner ``(row, column)`` (a corner index, 0 to rows / columns), in mm.

        Parameters
        ----------
        row, column : int
            The corner's indices, counted from the bottom left.
        """
        return (
            self.origin[0] + column * self.cell_size,
            self.origin[1] + row * self.cell_size,
        )

    def center(self, row: int, column: int) -> tuple[float, float]:
        """The centre of cell ``(row, column)``, mm.

        Parameters
        ----------
        row, column : int
            The cell's indices, counted from the bottom left.
        """
        x, y = self.point(row, column)
        return x + self.cell_size / 2, y + self.cell_size / 2
