"""Seeded warehouses with a deliveries mission: N robots, M goods, no robot named per good.

Shelf blocks (1 m wide, 5 m long) stand in a row with aisles of 1.5 m between them (two robots
pass).  Goods lie against the east faces of the blocks at random places; robots park below the
shelves, docks (1.4 m by 0.6 m, room for several goods) lie above.  Every fifth good may go to
either of two docks; every fourth may be moved by only two (random) robots.  ``return: true``.

``python benchmarks/delivery_gen.py N M [--seed S] [-o FILE]`` writes a scenario file.
"""

from __future__ import annotations

import random

from _harness import generator_main

AISLE, SHELF, LENGTH, PITCH = 1500, 1000, 5000, 1200
ROBOT, GOOD = 400, 100


def _box(x0: float, y0: float, x1: float, y1: float) -> list[list[list[float]]]:
    return [[[x0, y0], [x1, y0]], [[x1, y0], [x1, y1]], [[x1, y1], [x0, y1]], [[x0, y1], [x0, y0]]]


def delivery_warehouse(n: int, m: int, seed: int = 0) -> dict:
    """The scenario (as the data of a YAML file) with ``n`` robots and ``m`` goods."""
    rng = random.Random(seed)
    aisles = max(2, -(-m // 4))
    width = SHELF + aisles * (AISLE + SHELF)
    per_row = max(1, int((width - 1000) // PITCH))
    docks = max(2, n // 2)
    rows = max(-(-n // per_row), -(-docks // max(1, per_row // 2)))
    bottom = -LENGTH / 2 - 1400 - PITCH * (rows - 1)
    top = LENGTH / 2 + 1400 + PITCH * (rows - 1)
    walls = _box(0, bottom, width, top)
    for a in range(aisles + 1):
        x0 = a * (AISLE + SHELF)
        walls += _box(x0, -LENGTH / 2, x0 + SHELF, LENGTH / 2)
    slots = [(a, y) for a in range(aisles) for y in range(-LENGTH // 2 + 500, LENGTH // 2 - 400, 800)]
    rng.shuffle(slots)
    robots = {}
    for i in range(n):
        row, col = divmod(i, per_row)
        robots[f"R{i + 1}"] = {
            "size": ROBOT,
            "pose": [1000 + PITCH * col, -LENGTH / 2 - 800 - PITCH * row, 0],
        }
    workspaces = {}
    for k in range(docks):
        row, col = divmod(k, max(1, per_row // 2))
        x, y = 1000 + 2 * PITCH * col, LENGTH / 2 + 900 + PITCH * row
        workspaces[f"W{k + 1}"] = {"x": [x - 100, x + 1300], "y": [y - 300, y + 300]}
    objects, deliveries = {}, []
    for j in range(m):
        a, y = slots[j]
        east = (a + 1) * (AISLE + SHELF)
        o = f"O{j + 1}"
        objects[o] = {"size": GOOD, "position": [east - GOOD / 2, y]}
        to = rng.sample(sorted(workspaces), 2) if j % 5 == 4 else [rng.choice(sorted(workspaces))]
        delivery: dict = {"object": o, "to": to if len(to) > 1 else to[0]}
        if j % 4 == 3 and n > 2:
            delivery["by"] = sorted(rng.sample(sorted(robots), 2))
        deliveries.append(delivery)
    return {
        "name": f"deliveries-{n}x{m}-seed{seed}",
        "scene": {"obstacles": walls, "robots": robots, "objects": objects, "workspaces": workspaces},
        "mission": {"deliveries": deliveries, "return": True},
    }


def main(argv: list[str] | None = None) -> int:
    return generator_main(__doc__, delivery_warehouse, ("n", "m"), argv)


if __name__ == "__main__":
    raise SystemExit(main())
