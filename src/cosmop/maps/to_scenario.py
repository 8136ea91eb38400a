"""Turn an occupancy grid into the scene part of a scenario file (YAML).

:func:`import_map` reads a MovingAI ``.map`` or a ROS ``map.yaml``, covers the blocked cells
with rectangles and walls them in (:mod:`cosmop.maps.cover`); :func:`scenario_text` writes the
walls as ``scene.obstacles`` of a scenario, either alone (the user adds robots, objects,
workspaces and a mission) or merged into a template scenario whose obstacles it replaces
(:mod:`cosmop.maps.template` keeps the template's comments).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal, cast

import yaml

from cosmop.io import read_text
from cosmop.maps.cover import Rect, boundary_walls, rectangle_cover, rectangle_walls, walls_in_mm
from cosmop.maps.grid import MapError, OccupancyGrid
from cosmop.maps.movingai import read_movingai
from cosmop.maps.rosmap import read_ros_map
from cosmop.maps.template import merge_walls
from cosmop.reading import load_yaml
from cosmop.units import m_from_mm

__all__ = ["ImportedMap", "import_map", "scenario_text"]

Wall = tuple[tuple[float, float], tuple[float, float]]


@dataclass(frozen=True, eq=False)
class ImportedMap:
    """A map read from a file, with its blocked cells as rectangles and walls.

    Attributes
    ----------
    source : str
        The map file.
    grid : OccupancyGrid
    rectangles : list of (int, int, int, int)
        Disjoint rectangles of blocked cells, ``(row0, col0, row1, col1)`` half-open.
    walls : list of ((float, float), (float, float))
        The wall segments in mm.
    outline_walls : int
        How many walls the rectangles' full outlines would be (for comparison).
    """

    source: str
    grid: OccupancyGrid
    rectangles: list[Rect]
    walls: list[Wall]
    outline_walls: int


def import_map(
    path: str | os.PathLike[str],
    *,
    cell_size: float | None = None,
    origin: tuple[float, float] | None = None,
    unknown: Literal["blocked", "free"] = "blocked",
    walls: Literal["boundary", "rectangles"] = "boundary",
) -> ImportedMap:
    """Read a grid map and wall in its blocked cells.

    Parameters
    ----------
    path : str or os.PathLike
        A MovingAI ``.map`` file, or a ROS ``map_server`` ``.yaml`` file.
    cell_size : float, optional
        Side of a cell in mm; default 1000 for MovingAI maps, the YAML's resolution for ROS maps.
    origin : tuple of float, optional
        The map's lower-left corner in mm; default ``(0, 0)``, or the ROS map's origin.
    unknown : {"blocked", "free"}, optional
        ROS maps: what unknown cells are (default blocked).
    walls : {"boundary", "rectangles"}, optional
        ``boundary`` (default): only the edges between free cells and blocked cells or the
        map's edge, merged into maximal segments; ``rectangles``: every rectangle's outline and
        the map's four edges.

    Returns
    -------
    ImportedMap

    Raises
    ------
    MapError
        If the file cannot be read or has no known map suffix.
    """
    file = os.fspath(path)
    suffix = Path(file).suffix.lower()
    if suffix == ".map":
        grid = read_movingai(file, 1000.0 if cell_size is None else cell_size, origin=origin or (0.0, 0.0))
    elif suffix in (".yaml", ".yml"):
        grid = read_ros_map(file, unknown=unknown, cell_size=cell_size)
        if origin is not None:
            grid = OccupancyGrid(grid.blocked, grid.cell_size, origin)
    else:
        raise MapError("expected a MovingAI .map file or a ROS map .yaml file (by its suffix)", file=file)
    rects = rectangle_cover(grid.blocked)
    rows, cols = grid.shape
    border = [((0, 0), (0, cols)), ((rows, 0), (rows, cols)), ((0, 0), (rows, 0)), ((0, cols), (rows, cols))]
    outline = rectangle_walls(rects) + border  # the map's edge too: robots stay on the map
    chosen = boundary_walls(grid.blocked) if walls == "boundary" else outline
    return ImportedMap(file, grid, rects, walls_in_mm(grid, chosen), len(outline))


class _Dumper(yaml.SafeDumper):  # type: ignore[misc]  # PyYAML ships no type information
    """Lists of numbers (points, walls) on one line; everything else in block style."""


def _scalar_or_point(value: Any) -> bool:
    return not isinstance(value, list | dict) or (
        isinstance(value, list) and not any(isinstance(v, list | dict) for v in value)
    )


_Dumper.add_representer(
    list,
    lambda dumper, data: dumper.represent_sequence(
        "tag:yaml.org,2002:seq", data, flow_style=all(_scalar_or_point(v) for v in data)
    ),
)
_Dumper.add_representer(
    dict,
    lambda dumper, data: dumper.represent_mapping(
        "tag:yaml.org,2002:map", data.items(), flow_style=all(_scalar_or_point(v) for v in data.values())
    ),
)


def _number(value: float, units: str) -> int | float:
    v = m_from_mm(value) if units == "m" else value
    v = round(v, 9)
    return int(v) if float(v).is_integer() else v


def _load_template(path: str | os.PathLike[str]) -> tuple[str, dict[str, Any]]:
    """The template's text and what cosmop reads in it (its errors are the scenario loader's)."""
    file = os.fspath(path)
    text = read_text(path, MapError, "a scenario file")
    data, _ = load_yaml(text, file, MapError)
    if not isinstance(data, dict) or not isinstance(data.get("scene"), dict):
        raise MapError("expected a scenario with a scene mapping to take robots and mission from", file=file)
    return text, data


def scenario_text(
    imported: ImportedMap,
    *,
    name: str | None = None,
    units: Literal["mm", "m"] | None = None,
    template: str | os.PathLike[str] | None = None,
) -> str:
    """The YAML text of a scenario (or its scene part) whose obstacles are the map's walls.

    Parameters
    ----------
    imported : ImportedMap
    name : str, optional
        The scenario's name; default the template's, else the map file's stem.
    units : {"mm", "m"}, optional
        Units of the written numbers; default the template's, else mm. A template in other
        units than asked for is an error.
    template : str or os.PathLike, optional
        A scenario whose robots, objects, workspaces, people and mission are kept; its
        obstacles are replaced by the map's walls. Its text is kept as written, comments,
        blank lines, key order and one-line lists included (:func:`cosmop.maps.template.merge_walls`);
        should that not read back the same, it is written plainly, with a header line saying so.

    Returns
    -------
    str
        YAML text with a comment header saying where it came from.

    Raises
    ------
    MapError
        If the template cannot be read or its units differ from `units`.
    """
    text, data = _load_template(template) if template is not None else ("", {})
    file_units = data.get("units", "mm")
    if units is not None and template is not None and units != file_units:
        raise MapError(
            f"the template is in {file_units}, expected {units} (as asked)",
            file=os.fspath(template),
            field="units",
        )
    units = file_units if template is not None else (units or "mm")
    walls = [[[_number(v, units) for v in p] for p in wall] for wall in imported.walls]
    out: dict[str, Any] = {"name": name or data.get("name") or Path(imported.source).stem}
    if units == "m":
        out["units"] = "m"
    scene = dict(data.get("scene", {}))
    out["scene"] = {"obstacles": walls, **{k: v for k, v in scene.items() if k != "obstacles"}}
    out.update({k: v for k, v in data.items() if k not in ("name", "units", "scene")})
    header = _header(imported, units)
    if template is None:
        header.append("# Add robots, objects, workspaces and a mission to make it a scenario.")
        return "\n".join(header) + "\n" + _plain_yaml(out)
    expected = {**data, "name": out["name"], "scene": {**data["scene"], "obstacles": walls}}
    kept = _keep_template(text, expected, walls, out["name"] if out["name"] != data.get("name") else None)
    if kept is None:
        header.append("# (The template's comments could not be kept: ruamel.yaml read it otherwise.)")
    return "\n".join(header) + "\n" + (kept or _plain_yaml(out))


def _header(imported: ImportedMap, units: str) -> list[str]:
    """The comment lines that say where the walls came from."""
    g = imported.grid
    rows, cols = g.shape
    unit = "m" if units == "m" else "mm"
    return [
        f"# Imported by cosmop import-map from {Path(imported.source).name}: {cols} x {rows} cells of "
        f"{_number(g.cell_size, units)} {unit},",
        f"# {int(g.blocked.sum())} blocked cells in {len(imported.rectangles)} rectangles, walled in by "
        f"{len(imported.walls)} wall segments. Lengths in {unit}.",
    ]


def _plain_yaml(data: dict[str, Any]) -> str:
    return cast(str, yaml.dump(data, Dumper=_Dumper, sort_keys=False, width=110))


def _keep_template(
    text: str, expected: dict[str, Any], walls: list[list[list[float]]], name: str | None
) -> str | None:
    """The template's own text (comments, order, layout) with the new walls and name, or None
    when that text would not read back as `expected` (then the caller writes it plainly).

    ruamel.yaml reads YAML 1.2 and cosmop YAML 1.1, which differ on a few spellings (``0755``,
    ``1e-05``); rather than trust every corner, the result is read back the way cosmop will.
    """
    try:
        merged = merge_walls(text, walls, name)
        same = load_yaml(merged, None, MapError)[0] == expected
    except Exception:  # ruamel fails on odd input (or its comment bookkeeping does): write plainly
        return None
    return merged if same else None
