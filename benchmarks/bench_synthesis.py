"""Shortest-plan synthesis: incremental vs fresh-solver K search; time against horizon and objects.

1. The paper's 10x10 example: every robot planned (shortest K, fewest requests, checked) with
   the incremental unrolling (one solver, growing horizon) and with a fresh solver per K;
   median of ``--repeats`` runs; per-robot horizon and time.
2. Objects: R2 of the 2x2 example with 0..N extra objects lying out of its way (the encoding
   grows with every object: GoTo clearance, DropOff separation, Req actions).

Writes ``benchmarks/results/synthesis.json`` and, with matplotlib, ``synthesis.png``.
Usage: ``python benchmarks/bench_synthesis.py [--repeats 3]``.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import tempfile
import time
from dataclasses import replace
from pathlib import Path

from cosmop.planning.checker import check_robot_plan
from cosmop.planning.synthesis import synthesize
from cosmop.scenario import load_scenario
from cosmop.scene import MovableObject

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results"


def ten_by_ten(incremental: bool) -> tuple[float, list[dict]]:
    sc = load_scenario(ROOT / "examples" / "02_warehouse_10x10" / "scenario.yaml")
    rows, t0 = [], time.perf_counter()
    for robot, tasks in sc.mission.tasks.items():
        t = time.perf_counter()
        res = synthesize(sc.scene, robot, tasks, max_horizon=12, incremental=incremental)
        elapsed = time.perf_counter() - t
        assert res.feasible and check_robot_plan(sc.scene, robot, res.plan) == []
        rows.append({"robot": robot, "horizon": res.horizon, "requests": list(res.requests), "s": elapsed})
    return time.perf_counter() - t0, rows


def with_objects(n: int, incremental: bool = True) -> tuple[float, int]:
    sc = load_scenario(ROOT / "examples" / "01_warehouse_2x2" / "scenario.yaml")
    objects = dict(sc.scene.objects)
    for i in range(n):  # a row of goods along the bottom wall, out of R2's way
        objects[f"X{i}"] = MovableObject(f"X{i}", 100, (-1400.0 + 150 * i, -2400.0))
    scene = replace(sc.scene, objects=objects)
    t = time.perf_counter()
    res = synthesize(scene, "R2", sc.mission.tasks["R2"], incremental=incremental)
    elapsed = time.perf_counter() - t
    assert res.feasible and check_robot_plan(scene, "R2", res.plan) == []
    return elapsed, res.horizon


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    data: dict = {
        "date": time.strftime("%Y-%m-%d"),
        "cpu_count": os.cpu_count(),
        "ten_by_ten": {},
        "objects": [],
    }
    for mode in ("incremental", "fresh"):
        totals, per_robot = [], {}
        for _ in range(args.repeats):
            total, rows = ten_by_ten(mode == "incremental")
            totals.append(total)
            for row in rows:
                per_robot.setdefault(row["robot"], []).append(row)
        robots = [{**runs[0], "s": statistics.median(r["s"] for r in runs)} for runs in per_robot.values()]
        data["ten_by_ten"][mode] = {
            "total_median_s": statistics.median(totals),
            "totals": totals,
            "robots": robots,
        }
        print(
            f"10x10 {mode:11s}: all ten robots in {statistics.median(totals):.2f} s "
            f"(median of {args.repeats})"
        )
    for robot in data["ten_by_ten"]["incremental"]["robots"]:
        fresh = next(r for r in data["ten_by_ten"]["fresh"]["robots"] if r["robot"] == robot["robot"])
        print(
            f"  {robot['robot']:4s} K={robot['horizon']:2d} requests={','.join(robot['requests']) or '-':8s} "
            f"incremental {robot['s']:.2f} s  fresh {fresh['s']:.2f} s"
        )
    for n in (0, 4, 8, 16, 24):
        times = [with_objects(n)[0] for _ in range(args.repeats)]
        data["objects"].append({"extra_objects": n, "objects": n + 2, "median_s": statistics.median(times)})
        print(f"R2 of 2x2 with {n + 2:2d} objects: {statistics.median(times):.2f} s")
    OUT.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=OUT, suffix=".tmp")
    with os.fdopen(fd, "w") as fh:
        json.dump(data, fh, indent=2)
    os.replace(tmp, OUT / "synthesis.json")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return 0
    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4))
    for mode, marker in (("incremental", "o"), ("fresh", "s")):
        rows = data["ten_by_ten"][mode]["robots"]
        a.scatter([r["horizon"] for r in rows], [r["s"] for r in rows], marker=marker, label=mode)
    a.set_xlabel("shortest horizon K")
    a.set_ylabel("synthesis time per robot [s]")
    a.set_title("10x10 example: time against horizon")
    a.legend()
    b.plot([r["objects"] for r in data["objects"]], [r["median_s"] for r in data["objects"]], marker="o")
    b.set_xlabel("objects in the scene")
    b.set_ylabel("synthesis time [s]")
    b.set_title("2x2 example, R2: time against objects")
    fig.tight_layout()
    fig.savefig(OUT / "synthesis.png", dpi=100)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
