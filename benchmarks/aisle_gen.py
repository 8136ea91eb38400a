"""Seeded warehouses with one-lane aisles, where robots must take turns.

Shelf blocks (1 m wide, 6 m long) stand in a row, with an aisle of 700 mm between two blocks:
room for one robot of 400 mm beside the goods, never two side by side.  Robots park in the open area below the
shelves, docks lie in the open area above.  Every robot fetches one good lying against the
east face of some aisle (about three goods per aisle, at random places) and drops it at its
dock, then comes home: robots meet in the aisles, in both directions.

``python benchmarks/aisle_gen.py N [--seed S] [-o FILE]`` writes a scenario file.
"""

from __future__ import annotations

import random

from _harness import generator_main

AISLE, SHELF, LENGTH, PITCH = 700, 1000, 6000, 1200
ROBOT, GOOD = 400, 100


def _box(x0: float, y0: float, x1: float, y1: float) -> list[list[list[float]]]:
    return [
        [[x0, y0], [x1, y0]],
        [[x1, y0], [x1, y1]],
        [[x1, y1], [x0, y1]],
        [[x0, y1], [x0, y0]],
    ]


def aisle_warehouse(n: int, seed: int = 0, per_aisle: int = 3) -> dict:
    """The scenario (as the data of a YAML file) with ``n`` robots and ``n`` goods."""
    rng = random.Random(seed)
    aisles = max(2, -(-n // per_aisle))
    width = SHELF + aisles * (AISLE + SHELF)
    per_row = max(1, int((width - 1000) // PITCH))  # parking places and docks per row
    rows = -(-n // per_row)
    bottom = -LENGTH / 2 - 1400 - PITCH * (rows - 1)
    top = LENGTH / 2 + 1400 + PITCH * (rows - 1)
    walls = _box(0, bottom, width, top)
    for a in range(aisles + 1):  # shelf blocks between and beside the aisles
        x0 = a * (AISLE + SHELF)
        walls += _box(x0, -LENGTH / 2, x0 + SHELF, LENGTH / 2)
    slots = [(a, y) for a in range(aisles) for y in range(-LENGTH // 2 + 600, LENGTH // 2 - 500, 900)]
    rng.shuffle(slots)
    robots, objects, workspaces, tasks = {}, {}, {}, {}
    for i in range(n):
        r, o, w = f"R{i + 1}", f"O{i + 1}", f"W{i + 1}"
        row, col = divmod(i, per_row)
        x = 1000 + PITCH * col
        robots[r] = {"size": ROBOT, "pose": [x, -LENGTH / 2 - 800 - PITCH * row, 0]}
        a, y = slots[i]
        east = (a + 1) * (AISLE + SHELF)  # the east face of aisle a
        objects[o] = {"size": GOOD, "position": [east - GOOD / 2, y]}
        dock_y = LENGTH / 2 + 800 + PITCH * row
        workspaces[w] = {"x": [x - 100, x + 300], "y": [dock_y - 150, dock_y + 150]}
        tasks[r] = [f"pick {o}", f"drop {o} at {w}", "return"]
    return {
        "name": f"aisles-{n}-seed{seed}",
        "scene": {"obstacles": walls, "robots": robots, "objects": objects, "workspaces": workspaces},
        "mission": {"tasks": tasks},
    }


def main(argv: list[str] | None = None) -> int:
    return generator_main(__doc__, aisle_warehouse, ("n",), argv)


if __name__ == "__main__":
    raise SystemExit(main())
