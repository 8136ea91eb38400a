"""Seeded one-robot rooms (tests and benchmarks share them): a room with a branching delivery
mission, and a room of shelves with a good to fetch."""

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
        "mission": {"tasks": {"R1": ["return"]}},  # a scene to plan in: the tests give the missions
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


def shelves(seed: int) -> dict:
    """A 12 m x 6 m room with shelf blocks in a 4 x 2 grid of bays; one robot fetches a good
    lying against a shelf face (boxed in by other goods one time in three, so that it needs a
    request) and brings it to a
    dock across the room."""
    rng = random.Random(seed)
    walls = box_walls(0, 0, 12000, 6000)
    bays = [(bx, by) for bx in range(4) for by in range(2)]
    rng.shuffle(bays)
    for bx, by in bays[:5]:  # a shelf block of 1 m x 1.6 m in five of the eight bays
        x0, y0 = 3000 * bx + 1000, 3000 * by + 700
        walls += box_walls(x0, y0, x0 + 1000, y0 + 1600)
    shelf = bays[0]
    x0, y0 = 3000 * shelf[0] + 1000, 3000 * shelf[1] + 700
    gy = y0 + 350 + 100 * rng.randrange(0, 10)
    objects = {"O1": {"size": 100, "position": [x0 + 1050, gy]}}  # against the block's east face
    if seed % 3 == 0:  # goods above and below leave no room there; the one in front must go
        objects |= {
            "O2": {"size": 100, "position": [x0 + 1050, gy + 300]},
            "O3": {"size": 100, "position": [x0 + 1050, gy - 300]},
            "O4": {"size": 100, "position": [x0 + 1150, gy]},
        }
    free = bays[5:]
    (rx, ry), (dx, dy) = free[0], free[-1]
    robot = [3000 * rx + 1500, 3000 * ry + 1500, rng.choice([0, 90, 180, 270])]
    dock = {"x": [3000 * dx + 1000, 3000 * dx + 2000], "y": [3000 * dy + 1000, 3000 * dy + 2000]}
    return {
        "name": f"shelves-{seed}",
        "scene": {
            "obstacles": walls,
            "robots": {"R1": {"size": 400, "pose": robot}},
            "objects": objects,
            "workspaces": {"W1": dock},
        },
        "mission": {"tasks": {"R1": ["pick O1", "drop O1 at W1", "return"]}},
    }
