"""MovingAI benchmark maps (the ``.map`` format of the grid pathfinding benchmarks).

The format is four header lines, then the rows of the map, top row first::

    type octile
    height 12
    width 20
    map
    ....................
    ..@@@@......TTT.....

Passable cells are ``.`` (ground), ``G`` (ground) and ``S`` (swamp, passable at a cost that
cosmop ignores); blocked cells are ``@`` and ``O`` (out of bounds), ``T`` (trees) and ``W``
(water: passable from water only, so blocked for ground robots, which cosmop's are).
"""

from __future__ import annotations

import os

import numpy as np

from cosmop.io import read_text
from cosmop.maps.grid import MapError, OccupancyGrid

__all__ = ["BLOCKED", "PASSABLE", "parse_movingai", "read_movingai"]

PASSABLE = frozenset(".GS")
"""Characters of passable cells."""

BLOCKED = frozenset("@OTW")
"""Characters of blocked cells (``W``, water, is blocked for ground robots)."""


def _header_value(lines: list[str], index: int, key: str, file: str | None) -> int:
    line = lines[index].strip() if index < len(lines) else ""
    parts = line.split()
    if len(parts) != 2 or parts[0].lower() != key or not parts[1].isdigit() or int(parts[1]) < 1:
        got = repr(line) if index < len(lines) else "the end of the file"
        raise MapError(f"expected '{key} N' with N >= 1, got {got}", file=file, field=key, line=index + 1)
    return int(parts[1])


def parse_movingai(
    text: str, cell_size: float, *, origin: tuple[float, float] = (0.0, 0.0), file: str | None = None
) -> OccupancyGrid:
    """Parse the text of a MovingAI ``.map`` file.

    Parameters
    ----------
    text : str
        The file's text.
    cell_size : float
        Side of a cell, mm (the format has no scale).
    origin : tuple of float, optional
        Where the lower-left corner of the map goes, mm (default ``(0, 0)``).
    file : str, optional
        The file name, for error messages.

    Returns
    -------
    OccupancyGrid
        Row 0 is the map's bottom row (the file's last).

    Raises
    ------
    MapError
        If the header is not ``type``, ``height``, ``width``, ``map``, a row has the wrong
        length, or a character is not a known terrain; the error names the line and column.
    """
    lines = text.splitlines()
    first = lines[0].strip().split() if lines else []
    if len(first) != 2 or first[0].lower() != "type":
        raise MapError("expected 'type octile' on the first line", file=file, field="type", line=1)
    height = _header_value(lines, 1, "height", file)
    width = _header_value(lines, 2, "width", file)
    if len(lines) < 4 or lines[3].strip().lower() != "map":
        raise MapError("expected the line 'map' before the rows", file=file, field="map", line=4)
    rows = [line.rstrip("\r\n ") for line in lines[4 : 4 + height]]
    if len(rows) < height:
        raise MapError(f"expected {height} rows after 'map', got {len(rows)}", file=file, field="map")
    blocked = np.zeros((height, width), dtype=bool)
    for r, row in enumerate(rows):
        line = 5 + r
        if len(row) != width:
            raise MapError(
                f"expected a row of {width} cells, got {len(row)}", file=file, field="map", line=line
            )
        for c, char in enumerate(row):
            if char not in PASSABLE and char not in BLOCKED:
                raise MapError(
                    f"unknown terrain {char!r}; expected one of . G S (passable) or @ O T W (blocked)",
                    file=file,
                    field="map",
                    line=line,
                    column=c + 1,
                )
            blocked[height - 1 - r, c] = char in BLOCKED
    extra = [line for line in lines[4 + height :] if line.strip()]
    if extra:
        raise MapError(
            f"expected {height} rows (the header's height), found more",
            file=file,
            field="map",
            line=5 + height,
        )
    return OccupancyGrid(blocked, cell_size, origin)


def read_movingai(
    path: str | os.PathLike[str], cell_size: float = 1000.0, *, origin: tuple[float, float] = (0.0, 0.0)
) -> OccupancyGrid:
    """Read a MovingAI ``.map`` file (see :func:`parse_movingai`); cells are 1 m by default.

    Parameters
    ----------
    path : str or os.PathLike
        The ``.map`` file.
    cell_size : float, optional
        Side of a cell, mm (default 1000).
    origin : tuple of float, optional
        Where the lower-left corner of the map goes, mm (default ``(0, 0)``).

    Returns
    -------
    OccupancyGrid
    """
    file = os.fspath(path)
    return parse_movingai(
        read_text(path, MapError, "a MovingAI .map file"), cell_size, origin=origin, file=file
    )
