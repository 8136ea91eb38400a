"""Motions that pass an obstacle's end clear: how close plans come, and what the rule costs.

Every robot of a scenario is planned alone (``synthesize``, as the pipeline's first pass) and
its plan checked with the exact checker. For every GoTo and every wall or resting good (goods
where they start), the least gap between the robot's square and the obstacle along the
motion is sampled every millimetre; a *pass* is a least gap strictly inside the motion and
below the gaps at both ends (the motion comes closer in the middle than where it starts and
stops: it passes a corner). The row counts passes under 2 mm and 0.2 mm, gives the closest,
the horizons, and the seconds of synthesis (imports excluded).

Workloads: ``aisles:N:SEED`` (``aisle_gen.py``, one-lane aisles between shelves, goods on the
shelves' faces) and ``10x10`` (the paper's example). Variants, each in a fresh process,
alternated ``--repeats`` times: ``before`` (the code at ``--before PATH``, a checkout's
``src``) and ``now`` (this checkout).  Writes ``results/ends.json``.

Usage: ``python benchmarks/bench_ends.py [--repeats 3] [--before /tmp/before/src]
[--workloads aisles:20:1 aisles:20:2 10x10]``.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from _harness import alternate, median_of, save_results

ROOT = Path(__file__).resolve().parents[1]
WORKLOADS = ("aisles:20:1", "aisles:20:2", "aisles:20:3", "10x10")


def _scenario(workload: str):
    from cosmop.scenario import load_scenario, parse_scenario

    if workload == "10x10":
        return load_scenario(ROOT / "examples" / "02_warehouse_10x10" / "scenario.yaml")
    from aisle_gen import aisle_warehouse

    _, n, seed = workload.split(":")
    return parse_scenario(aisle_warehouse(int(n), int(seed)))


def _passes(scene, robot: str, plan, moving: set[str]) -> list[float]:
    """The closest passes (mm) of `plan`'s motions by walls and the goods not in `moving`."""
    import numpy as np
    import shapely

    half = scene.robots[robot].size / 2
    bodies = [shapely.LineString([w.start, w.end]) for w in scene.obstacles]
    for o, ob in scene.objects.items():
        if o not in moving:
            x, y, h = *ob.position, ob.size / 2
            bodies.append(shapely.box(x - h, y - h, x + h, y + h))
    points = [scene.robots[robot].pose[:2], *(s.robot[:2] for s in plan.steps)]
    out = []
    for k, step in enumerate(plan.steps):
        a, b = np.asarray(points[k], float), np.asarray(points[k + 1], float)
        length = float(np.hypot(*(b - a)))
        if step.primitive != "GoTo" or length < 1:
            continue
        c = a + np.linspace(0, 1, max(50, int(length)))[:, None] * (b - a)
        squares = shapely.box(c[:, 0] - half, c[:, 1] - half, c[:, 0] + half, c[:, 1] + half)
        for body in bodies:
            gap = shapely.distance(squares, body)
            i = int(np.argmin(gap))
            if 0 < i < len(gap) - 1 and gap[i] < min(gap[0], gap[-1]) - 1e-6:
                out.append(float(gap[i]))
    return out


def child(workload: str, variant: str) -> dict:
    """One run: every robot synthesised, checked and measured."""
    from cosmop.planning.checker import check_robot_plan
    from cosmop.planning.synthesis import synthesize

    scenario = _scenario(workload)
    horizons, passes, seconds = {}, [], 0.0
    for robot, tasks in sorted(scenario.mission.tasks.items()):
        start = time.perf_counter()
        res = synthesize(scenario.scene, robot, tasks, max_horizon=20)
        seconds += time.perf_counter() - start
        assert res.feasible and check_robot_plan(scenario.scene, robot, res.plan) == []
        horizons[robot] = res.horizon
        moving = {e.obj for e in tasks if e.obj} | set(res.requests)  # its goods, and those sent away
        passes += _passes(scenario.scene, robot, res.plan, moving)
    return {
        "workload": workload,
        "s": seconds,
        "K": sum(horizons.values()),
        "horizons": horizons,
        "under_2mm": sum(p < 2 for p in passes),
        "under_0.2mm": sum(p < 0.2 for p in passes),
        "closest": min(passes, default=None),
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--before", help="the src directory of an older checkout")
    parser.add_argument("--child", nargs=2, help=argparse.SUPPRESS)
    parser.add_argument("--workloads", nargs="*", default=list(WORKLOADS))
    args = parser.parse_args()
    if args.child:
        print(json.dumps(child(*args.child)))
        return 0
    variants = (("before",) if args.before else ()) + ("now",)
    env_of = {"before": {"PYTHONPATH": args.before}}.get
    rows = []
    for workload in args.workloads:
        runs = alternate(__file__, workload, variants, args.repeats, env_of=env_of, timeout=3600)
        rows += runs["rows"]
        seconds = median_of(runs, "s")
        for v in variants:
            last = runs["by"][v][-1]
            print(
                f"{workload} {v}: {seconds[v]:.2f} s, K {last['K']}, passes under 2 mm "
                f"{last['under_2mm']} (under 0.2 mm {last['under_0.2mm']}), closest {last['closest']}"
            )
        if "before" in seconds:
            print(f"{workload}: now / before {seconds['now'] / seconds['before']:.2f}x")
    print(f"wrote {save_results('ends', rows)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
