"""A lifelong workload on the MovingAI warehouse: N robots and a Poisson stream of orders.

The map is ``warehouse-10-20-10-2-1`` (``movingai_gen.py``).  Robot ``i`` (500 mm) waits at a
parking cell of the dock areas; goods (200 mm) lie against the top or bottom faces of the shelf
blocks, at random faces; docks (1 m x 1 m) stand in both dock areas, one column in from the
shelves.  Orders arrive as a Poisson process of ``rate`` orders per hour for ``hours`` of
simulated time (the League of Robot Runners' task pool: set the rate above the fleet's capacity
and a backlog forms); each names a good not ordered before and the docks of the dock area
nearest it (either of two).

``python benchmarks/orders_gen.py N [--rate R] [--hours H] [--seed S] [-o FILE]`` writes the
scenario (``orders:`` and no ``mission:``).
"""

from __future__ import annotations

import argparse
import random
import sys
from pathlib import Path

from _harness import emit_scenario
from movingai_gen import (
    CELL,
    COLS,
    DOCK,
    GOOD,
    ROBOT,
    ROWS,
    _centre,
    movingai_warehouse,
    shelf_faces,
)

DOCK_COLUMNS = {"left": DOCK - 2, "right": COLS - DOCK + 1}  # one column in from the shelves


def orders_warehouse(n: int, seed: int = 0, rate: float = 600.0, hours: float = 1.0) -> dict:
    """The scenario data: `n` robots, the goods of a Poisson stream of `rate` orders per hour
    over `hours`, and docks on both sides (``orders``, no ``mission``)."""
    rng = random.Random(seed)
    walls = movingai_warehouse(1, seed)["scene"]["obstacles"]
    parking = [(r, c) for r in range(2, ROWS - 2, 2) for c in (3, 6, 9, COLS - 4, COLS - 7, COLS - 10)]
    rng.shuffle(parking)
    robots = {f"R{i + 1}": {"size": ROBOT, "pose": [*_centre(*parking[i]), 0]} for i in range(n)}
    docks = {}
    for side, col in DOCK_COLUMNS.items():
        for k, row in enumerate(range(4, ROWS - 4, 6)):
            x, y = _centre(row, col)
            docks[f"D{side[0].upper()}{k + 1}"] = {
                "x": [x - CELL / 2, x + CELL / 2],
                "y": [y - CELL / 2, y + CELL / 2],
            }
    times, t = [], rng.expovariate(rate / 3600.0)
    while t < hours * 3600.0:
        times.append(round(t, 1))
        t += rng.expovariate(rate / 3600.0)
    faces = rng.sample(shelf_faces(), len(times))
    objects, orders = {}, []
    for k, (at, (row, col, below)) in enumerate(zip(times, faces, strict=True)):
        oid = f"O{k + 1}"
        x, y = _centre(row, col)
        objects[oid] = {"size": GOOD, "position": [x, y - below * (CELL - GOOD) / 2]}
        side = "DL" if col < COLS // 2 else "DR"
        near = sorted((w for w in docks if w.startswith(side)), key=lambda w: abs(docks[w]["y"][0] - y))[:2]
        orders.append({"at": at, "object": oid, "to": near})
    return {
        "name": f"movingai-orders-{n}-seed{seed}",
        "scene": {"obstacles": walls, "robots": robots, "objects": objects, "workspaces": docks},
        "orders": orders,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("n", type=int)
    parser.add_argument(
        "--rate", type=float, default=600.0, help="orders per hour (20 robots serve about 300)"
    )
    parser.add_argument("--hours", type=float, default=1.0)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("-o", "--output", type=Path)
    args = parser.parse_args(argv)
    emit_scenario(orders_warehouse(args.n, args.seed, args.rate, args.hours), args.output)
    return 0


if __name__ == "__main__":
    sys.exit(main())
