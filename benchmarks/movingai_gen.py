"""The MovingAI benchmark warehouse ``warehouse-10-20-10-2-1`` and seeded fetch missions on it.

The map (63 rows x 161 columns, 1 m cells): a border of blocked cells; 200 shelf blocks of
10 x 2 cells in 20 rows and 10 columns, with one-cell aisles between them (a free row above
every block row and a free column between block columns); open dock areas of 25 columns on
the left and the right.  This is the layout of the standard MAPF benchmark map of that name,
written here from its parameters.

Robot ``i`` (500 mm) waits in one of the dock areas, fetches one good (200 mm) lying against
the top or bottom face of some shelf block (in an aisle, at random), drops it at a dock
(1 m x 1 m, in the dock area nearest that good) and returns.  The walls are the map's, as
``cosmop import-map`` makes them (816 segments).

``python benchmarks/movingai_gen.py N [--seed S] [-o FILE]`` writes a scenario file;
``--map FILE`` writes the ``.map`` file instead.
"""

from __future__ import annotations

import random
import sys
import tempfile
from pathlib import Path

from _harness import generator_main
from cosmop.maps.to_scenario import import_map

ROWS, COLS, DOCK, BLOCK_W, BLOCK_H, BLOCKS_X, BLOCKS_Y = 63, 161, 25, 10, 2, 10, 20
CELL, ROBOT, GOOD = 1000, 500, 200


def blocked_cells() -> set[tuple[int, int]]:
    """The blocked cells ``(row, column)``: the border and the shelf blocks."""
    cells = {(r, c) for r in range(ROWS) for c in range(COLS) if r in (0, ROWS - 1) or c in (0, COLS - 1)}
    for by in range(BLOCKS_Y):
        top = 2 + 3 * by  # a free aisle row above every pair of block rows
        for bx in range(BLOCKS_X):
            left = 1 + DOCK + (BLOCK_W + 1) * bx
            cells |= {(top + dr, left + dc) for dr in range(BLOCK_H) for dc in range(BLOCK_W)}
    return cells


def map_text() -> str:
    """The map in the MovingAI format (``@`` blocked, ``.`` free)."""
    blocked = blocked_cells()
    rows = ["".join("@" if (r, c) in blocked else "." for c in range(COLS)) for r in range(ROWS)]
    return "\n".join(["type octile", f"height {ROWS}", f"width {COLS}", "map", *rows]) + "\n"


def _centre(row: int, col: int) -> list[float]:
    """Cell centre in mm, y up (row 0 is the map's top line)."""
    return [col * CELL + CELL / 2, (ROWS - 1 - row) * CELL + CELL / 2]


def shelf_faces() -> list[tuple[int, int, int]]:
    """Where goods may lie: ``(aisle row, column, +1 when the block is below the good, -1 when
    above)`` for every cell along the top and bottom faces of the shelf blocks (not the ends)."""
    faces = []
    for by in range(BLOCKS_Y):
        top = 2 + 3 * by
        for bx in range(BLOCKS_X):
            left = 1 + DOCK + (BLOCK_W + 1) * bx
            faces += [(top - 1, left + dc, 1) for dc in range(1, BLOCK_W - 1)]
            faces += [(top + BLOCK_H, left + dc, -1) for dc in range(1, BLOCK_W - 1)]
    return faces


def _instance(n: int, seed: int, docks: str):
    """The cells of a seeded instance: robots' parking cells, goods ``(aisle row, column, +1
    when the block is below the good)`` and dock cells (docks ``"near"`` the good or on the
    ``"far"`` side)."""
    rng = random.Random(seed)
    parking = [(r, c) for r in range(2, ROWS - 2, 2) for c in (3, 6, 9, COLS - 4, COLS - 7, COLS - 10)]
    rng.shuffle(parking)
    chosen = rng.sample(shelf_faces(), n)
    columns = {"left": 18, "right": COLS - 19}
    places = {side: [(r, c) for r in range(3, ROWS - 3, 3)] for side, c in columns.items()}
    for cells in places.values():
        rng.shuffle(cells)
    # beyond 38 goods, a second column of docks three cells further out on each side, drawn
    # from a generator of its own so that smaller instances stay as they were
    spare = random.Random(seed + 1)
    more = {
        side: [(r, c - 3 if side == "left" else c + 3) for r in range(3, ROWS - 3, 3)]
        for side, c in columns.items()
    }
    for cells in more.values():
        spare.shuffle(cells)
    out = []
    for row, col, below in chosen:
        near, far = ("left", "right") if col < COLS // 2 else ("right", "left")
        first, second = (near, far) if docks == "near" else (far, near)
        pool = places[first] or places[second] or more[first] or more[second]
        out.append((row, col, below, pool.pop()))
    return parking[:n], out


def movingai_cells(n: int, seed: int = 0, docks: str = "near"):
    """The grid version of :func:`movingai_warehouse`'s instance: per robot its parking cell, the
    aisle cell of its good and its dock cell, ``(row, column)`` each."""
    parking, goods = _instance(n, seed, docks)
    return parking, [(row, col) for row, col, _, _ in goods], [dock for *_, dock in goods]


def movingai_warehouse(n: int, seed: int = 0, docks: str = "near") -> dict:
    """The scenario (as the data of a YAML file) with ``n`` robots and ``n`` goods; each good's
    dock is in the dock area nearest it (``docks="near"``) or on the far side (``"far"``)."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "warehouse-10-20-10-2-1.map"
        path.write_text(map_text())
        walls = [[list(a), list(b)] for a, b in import_map(path, cell_size=CELL).walls]
    parking, goods = _instance(n, seed, docks)
    robots, objects, workspaces, tasks = {}, {}, {}, {}
    for i, (row, col, below, dock) in enumerate(goods):
        r, o, w = f"R{i + 1}", f"O{i + 1}", f"W{i + 1}"
        robots[r] = {"size": ROBOT, "pose": [*_centre(*parking[i]), 0]}
        x, y = _centre(row, col)
        objects[o] = {"size": GOOD, "position": [x, y - below * (CELL - GOOD) / 2]}  # against the face
        dx, dy = _centre(*dock)
        workspaces[w] = {"x": [dx - CELL / 2, dx + CELL / 2], "y": [dy - CELL / 2, dy + CELL / 2]}
        tasks[r] = [f"pick {o}", f"drop {o} at {w}", "return"]
    far = "" if docks == "near" else "-far"
    return {
        "name": f"movingai-warehouse-{n}-seed{seed}{far}",
        "scene": {"obstacles": walls, "robots": robots, "objects": objects, "workspaces": workspaces},
        "mission": {"tasks": tasks},
    }


def main(argv: list[str] | None = None) -> int:
    return generator_main(__doc__, movingai_warehouse, ("n",), argv, map_text=map_text)


if __name__ == "__main__":
    sys.exit(main())
