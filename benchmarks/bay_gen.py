"""Seeded warehouses of bays that open to the north, some blocked by crates no task names.

A row of ``n`` bays (900 mm wide, 1500 mm deep, walls between them) stands along the south
wall; each holds one good (100 mm) at its back, on a shelf reached from the north only
(``sides: [north]``).  Robots (400 mm) park in a row in the open area above the bays, docks
(600 x 600 mm) line the north wall.  Robot *i* fetches the good of a bay drawn at random, drops
it at dock *i* and returns.  With ``--crates F``, a fraction ``F`` of the bays (drawn with the
same seed) has a crate of 300 mm in its mouth that no task names: the robot of that bay must
have it moved aside (issue 11).  The same seed with ``--crates 0`` is the same warehouse
without crates.

``python benchmarks/bay_gen.py N [--seed S] [--crates F] [-o FILE]`` writes a scenario file.
"""

from __future__ import annotations

import argparse
import random
from pathlib import Path

from _harness import emit_scenario

PITCH, DEPTH, OPEN = 900, 1500, 4000  # bay width, bay depth, open area above the bays (mm)


def bays(n: int, seed: int = 0, crates: float = 0.0) -> dict:
    """The scenario (as the data of a YAML file) with ``n`` robots, bays and goods."""
    rng = random.Random(seed)
    width = PITCH * n
    left, right, top = -PITCH, width + PITCH, DEPTH + OPEN
    walls = [
        [[left, 0], [right, 0]],
        [[right, 0], [right, top]],
        [[right, top], [left, top]],
        [[left, top], [left, 0]],
    ]
    walls += [[[PITCH * k, 0], [PITCH * k, DEPTH]] for k in range(n + 1)]
    order = list(range(n))
    rng.shuffle(order)
    blocked = set(rng.sample(range(n), round(crates * n)))
    robots, objects, workspaces, tasks = {}, {}, {}, {}
    for i in range(n):
        centre = PITCH * i + PITCH // 2
        objects[f"O{i + 1}"] = {"size": 100, "position": [centre, 150], "sides": ["north"]}
        if i in blocked:
            objects[f"C{i + 1}"] = {"size": 300, "position": [centre, DEPTH - 150]}
        robots[f"R{i + 1}"] = {"size": 400, "pose": [centre, DEPTH + 1500, 90]}
        workspaces[f"W{i + 1}"] = {"x": [centre - 300, centre + 300], "y": [top - 700, top - 100]}
    for i, bay in enumerate(order):
        tasks[f"R{i + 1}"] = [f"pick O{bay + 1}", f"drop O{bay + 1} at W{i + 1}", "return"]
    name = f"bays-{n}-seed{seed}" + (f"-crates{crates:g}" if crates else "")
    return {
        "name": name,
        "scene": {"obstacles": walls, "robots": robots, "objects": objects, "workspaces": workspaces},
        "mission": {"tasks": tasks},
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("n", type=int)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--crates", type=float, default=0.0)
    parser.add_argument("-o", "--output", type=Path)
    args = parser.parse_args(argv)
    emit_scenario(bays(args.n, args.seed, args.crates), args.output)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
