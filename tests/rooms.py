"""A seeded one-robot room with a branching delivery mission (tests and benchmarks share it)."""

from __future__ import annotations

import random


def box_walls(x0: float, y0: float, x1: float, y1: float) -> list[list[list[float]]]:
    """The four wall segments of the rectangle ``[x0, x1] x [y0, y1]`` (mm), as scenario data."""
    return [[[x0, y0], [x1, y0]], [[x1, y0], [x1, y1]], [[x1, y1], [x0, y1]], [[x0, y1], [x0, y0]]]


def room(seed: int) -> dict:
    """A walled room with one robot, two goods and three docks placed at random (seeded)."""
    rng = random.Random(seed)

    def spot() -> list[int]:
        return [rng.randrange(-2400, 2401, 100), rng.randrange(-2400, 2401, 100)]

    a, b = spot(), spot()
    while abs(a[0] - b[0]) < 700 and abs(a[1] - b[1]) < 700:
        b = spot()
    docks = {}
    for name in ("W1", "W2", "W3"):
        x, y = rng.randrange(-2600, 2001, 100), rng.randrange(-2600, 2001, 100)
        docks[name] = {"x": [x, x + 500], "y": [y, y + 500]}
    return {
        "name": f"room-{seed}",
        "scene": {
            "obstacles": [
                [[-3000, -3000], [3000, -3000]],
                [[3000, -3000], [3000, 3000]],
                [[3000, 3000], [-3000, 3000]],
                [[-3000, 3000], [-3000, -3000]],
                [[0, -1000], [0, 1000]],
            ],
            "robots": {"R1": {"size": 400, "pose": [-2500, -2500, 0]}},
            "objects": {"O1": {"size": 100, "position": a}, "O2": {"size": 100, "position": b}},
            "workspaces": docks,
        },
        "mission": {"tasks": {"R1": []}},
    }


def branching_words() -> list[tuple[str, ...]]:
    """Both goods delivered, in either order, each to one of two docks, then home."""
    out = []
    for first, second in (("O1", "O2"), ("O2", "O1")):
        for w1 in ("W1", "W2"):
            for w2 in ("W2", "W3"):
                out.append(
                    (
                        f"pick(R1,{first})",
                        f"drop(R1,{first},{w1})",
                        f"pick(R1,{second})",
                        f"drop(R1,{second},{w2})",
                        "return(R1)",
                    )
                )
    return out
