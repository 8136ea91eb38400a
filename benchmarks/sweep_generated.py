"""Do the plans that ``cosmop plan`` calls feasible execute?  A seeded sweep (issue 12, point 5).

Each seed draws a scene: a square room of 6 to 9 m with 1 to 4 random axis-aligned inner walls,
2 to 5 robots (side 400 mm), one good per robot (side 100 mm) and one 600 x 600 mm dock per
robot; robot *i* picks good *i*, drops it in dock *i* and returns.  Positions lie on a 100 mm
grid; a draw the loader refuses (a body overlapping a wall or another body, a dock that cannot
hold its good) is drawn again from the same seed's generator, so every seed gives a valid scene.

Each scene is planned (``cosmop plan``) and, when feasible, simulated from that plan
(``cosmop simulate --plan``) as a user runs them, one fresh process each.  A row records the
plan's verdict, whether the run completed, the contacts while moving, the simulated and wall
times.

With ``--mixed`` the scenes are harder and closer to what users write: 2 to 7 robots of one
side from 300 to 500 mm with headings in radians, 0 to 5 inner walls, as many goods as robots
or up to two more (a robot may move several, one after another), at most as many docks as
robots (several goods may go into one dock), goods of 100 to 200 mm, docks of 600 to 800 mm,
and a fifth of the robots ending where they drop their last goods (no ``return``).  Its draws
are another stream of the same seeds.

With ``--alone`` (issue 36, point 4: complete as a team), every scene the team is not planned
for (infeasible or out of time) is planned again robot by robot, each alone in the same scene
(the other robots removed, every object kept): ``alone`` is true when every robot alone has a
plan, so that the team's verdict is one a team planner should not give.  The row keeps the
plan's reason.

Usage: ``python benchmarks/sweep_generated.py [--seeds 0:200] [--timeout 600] [--alone] [--mixed]
[--out NAME]`` (``results/NAME.json``; default ``sweep_generated``).
"""

from __future__ import annotations

import argparse
import json
import math
import random
import tempfile
from pathlib import Path

from _harness import plan_and_simulate, save_results
from cosmop.errors import ScenarioError
from cosmop.scenario import parse_scenario

GRID = 100


def _spot(rng: random.Random, half: int, margin: int) -> list[int]:
    return [rng.randrange(-half + margin, half - margin + 1, GRID) for _ in range(2)]


def draw(rng: random.Random) -> dict:
    """One candidate scene (may be physically impossible; :func:`scene` filters)."""
    half = rng.choice([3000, 3500, 4000, 4500])
    walls = [
        [[-half, -half], [half, -half]],
        [[half, -half], [half, half]],
        [[half, half], [-half, half]],
        [[-half, half], [-half, -half]],
    ]
    for _ in range(rng.randint(1, 4)):
        x, y = _spot(rng, half, 500)
        length = rng.randrange(1000, 3001, GRID)
        end = [min(x + length, half), y] if rng.random() < 0.5 else [x, min(y + length, half)]
        walls.append([[x, y], end])
    n = rng.randint(2, 5)
    robots = {f"R{i}": {"size": 400, "pose": [*_spot(rng, half, 300), 0]} for i in range(1, n + 1)}
    objects = {f"O{i}": {"size": 100, "position": _spot(rng, half, 400)} for i in range(1, n + 1)}
    workspaces = {}
    for i in range(1, n + 1):
        x, y = _spot(rng, half, 700)
        workspaces[f"W{i}"] = {"x": [x, x + 600], "y": [y, y + 600]}
    tasks = {f"R{i}": [f"pick O{i}", f"drop O{i} at W{i}", "return"] for i in range(1, n + 1)}
    return {
        "name": "generated",
        "scene": {"obstacles": walls, "robots": robots, "objects": objects, "workspaces": workspaces},
        "mission": {"tasks": tasks},
    }


def draw_mixed(rng: random.Random) -> dict:
    """One candidate scene of the ``--mixed`` kind (module docstring; may be physically impossible)."""
    half = rng.choice([2500, 3000, 3500, 4000, 4500])
    walls = [
        [[-half, -half], [half, -half]],
        [[half, -half], [half, half]],
        [[half, half], [-half, half]],
        [[-half, half], [-half, -half]],
    ]

    def spot(margin: int) -> list[int]:  # on a 50 mm grid
        return [rng.randrange(-half + margin, half - margin + 1, GRID // 2) for _ in range(2)]

    for _ in range(rng.randint(0, 5)):
        x, y = spot(400)
        length = rng.randrange(500, 3001, GRID // 2)
        walls.append(
            [[x, y], [min(x + length, half), y] if rng.random() < 0.5 else [x, min(y + length, half)]]
        )
    n, side = rng.randint(2, 7), rng.choice([300, 350, 400, 450, 500])
    headings = [0.0, 0.0, math.pi / 2, math.pi, -math.pi / 2]
    robots = {}
    for i in range(1, n + 1):
        heading = rng.choice([*headings, round(rng.uniform(-3.14, 3.14), 3)])
        robots[f"R{i}"] = {"size": side, "pose": [*spot(300), heading]}
    goods, size = n + rng.randint(0, 2), rng.choice([100, 100, 150, 200])
    objects = {f"O{i}": {"size": size, "position": spot(400)} for i in range(1, goods + 1)}
    docks, width = rng.randint(max(1, n - 2), n), rng.choice([600, 600, 700, 800])
    workspaces = {}
    for i in range(1, docks + 1):
        x, y = spot(300 + width)
        workspaces[f"W{i}"] = {"x": [x, x + width], "y": [y, y + width]}
    tasks: dict[str, list[str]] = {f"R{i}": [] for i in range(1, n + 1)}
    for j in range(1, goods + 1):
        tasks[f"R{(j - 1) % n + 1}"] += [f"pick O{j}", f"drop O{j} at W{rng.randint(1, docks)}"]
    for words in tasks.values():
        if rng.random() < 0.8:
            words.append("return")
    return {
        "name": "generated-mixed",
        "scene": {"obstacles": walls, "robots": robots, "objects": objects, "workspaces": workspaces},
        "mission": {"tasks": tasks},
    }


def scene(seed: int, mixed: bool = False) -> dict:
    """The first physically possible draw of `seed`'s generator (`mixed`: of the ``--mixed``
    kind, from a stream apart from the plain draws')."""
    rng = random.Random(seed * 7919 + 13 if mixed else seed)
    while True:
        data = draw_mixed(rng) if mixed else draw(rng)
        try:
            parse_scenario(data)
        except ScenarioError:
            continue
        data["name"] = f"generated-{'mixed-' if mixed else ''}{seed}"
        return data


def run_seed(seed: int, timeout: float, folder: Path, alone: bool = False, mixed: bool = False) -> dict:
    data = scene(seed, mixed)
    row = {"seed": seed, "robots": len(data["scene"]["robots"]), "walls": len(data["scene"]["obstacles"])}
    row |= plan_and_simulate(data, folder / f"scene_{seed}", timeout)
    if alone and row["plan"] != "feasible":
        plan = folder / f"scene_{seed}_plan.json"
        if plan.exists():
            row["reason"] = json.loads(plan.read_text()).get("reason")
        row["alone"] = all(_alone_feasible(data, robot) for robot in data["scene"]["robots"])
    return row


def _alone_feasible(data: dict, robot: str) -> bool:
    """Whether `robot` has a plan in the scene of `data` with the other robots removed."""
    from cosmop.team.loop import plan_team

    one = json.loads(json.dumps(data))
    one["scene"]["robots"] = {robot: data["scene"]["robots"][robot]}
    one["mission"]["tasks"] = {robot: data["mission"]["tasks"][robot]}
    return plan_team(parse_scenario(one), workers=1).plans.feasible


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", default="0:200", help="first:last (exclusive)")
    parser.add_argument("--timeout", type=float, default=600.0)
    parser.add_argument("--alone", action="store_true", help="plan each robot of a team not planned alone")
    parser.add_argument(
        "--mixed", action="store_true", help="harder scenes: shared docks, no return, radians"
    )
    parser.add_argument("--out", default="sweep_generated", help="results/OUT.json")
    args = parser.parse_args(argv)
    first, last = (int(v) for v in args.seeds.split(":"))
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for seed in range(first, last):
            rows.append(run_seed(seed, args.timeout, Path(tmp), args.alone, args.mixed))
            print(json.dumps(rows[-1]), flush=True)
    save_results(args.out, rows)
    feasible = [r for r in rows if r["plan"] == "feasible"]
    done = [r for r in feasible if r.get("completed")]
    print(
        f"{len(rows)} scenes: {len(feasible)} feasible, {len(done)} completed in simulation, "
        f"{sum(r.get('contacts_while_moving', 0) for r in feasible)} contacts while moving"
    )
    if args.alone:
        wrong = [r["seed"] for r in rows if r.get("alone")]
        print(f"not planned as a team although every robot alone is: {len(wrong)} {wrong}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
