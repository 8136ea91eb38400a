"""Seeded warehouse scenarios like the paper's 10x10 example, for any number of robots.

The room is a row of 10 m bays.  Each bay has up to 10 robots (size 500) in two columns on
its left, up to 10 objects (size 100) on its right in *strings* of 1 to 3 adjacent goods
(200 mm apart, as in the paper; at most two strings per row) and 10 drop points along its top.
Robot ``i`` of a bay picks object ``i`` of the bay (objects numbered from the far end of each
string, so the deeper goods need the others moved away first), drops it at point ``i`` and
returns.

``python benchmarks/warehouse_gen.py N [--seed S] [-o FILE]`` writes a scenario file.
"""

from __future__ import annotations

import random

from _harness import generator_main

BAY = 10_000


def warehouse(n: int, seed: int = 0) -> dict:
    """The scenario (as the data of a YAML file) with ``n`` robots and ``n`` objects."""
    rng = random.Random(seed)
    bays = (n + 9) // 10
    left, right, bottom, top = -5000, -5000 + BAY * bays, -5000, 5000
    walls = [
        [[left, bottom], [right, bottom]],
        [[right, bottom], [right, top]],
        [[right, top], [left, top]],
        [[left, top], [left, bottom]],
    ]
    robots, objects, workspaces, tasks = {}, {}, {}, {}
    index = 0
    for b in range(bays):
        x0 = left + BAY * b
        count = min(10, n - 10 * b)
        sizes = []
        while sum(sizes) < count:
            sizes.append(min(rng.randint(1, 3), count - sum(sizes)))
        slots = [(row, slot) for row in range(5) for slot in range(2)]
        rng.shuffle(slots)
        placed = []
        for size, (row, slot) in zip(sizes, sorted(slots[: len(sizes)]), strict=False):
            far = x0 + 9000 - 1500 * slot  # the far end of the string
            y = -1000 * row
            placed += [(far - 200 * k, y) for k in range(size)]
        for k in range(count):
            index += 1
            r, o, w = f"R{index}", f"O{index}", f"W{index}"
            robots[r] = {"size": 500, "pose": [x0 + 1000 + 1000 * (k // 5), -1000 * (k % 5), 0]}
            objects[o] = {"size": 100, "position": list(placed[k])}
            workspaces[w] = {"point": [x0 + 750 + 1000 * k, 4000]}
            tasks[r] = [f"pick {o}", f"drop {o} at {w}", "return"]
    return {
        "name": f"warehouse-{n}-seed{seed}",
        "scene": {"obstacles": walls, "robots": robots, "objects": objects, "workspaces": workspaces},
        "mission": {"tasks": tasks},
    }


def main(argv: list[str] | None = None) -> int:
    return generator_main(__doc__, warehouse, ("n",), argv)


if __name__ == "__main__":
    raise SystemExit(main())
