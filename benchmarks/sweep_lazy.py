"""Lazy against eager geometry on many generated scenes: the same horizons and requests, and the time.

Scenes (seeded):

* ``shelves``: one-robot shelf rooms (``tests/rooms.py``), a third of them needing a request;
* ``aisles``: one-lane aisle warehouses (``aisle_gen.py``), every robot;
* ``movingai``: the MovingAI warehouse map (``movingai_gen.py``), every robot.

Every robot is solved both ways in one process; the sweep counts the robots whose horizon,
number of requests or set of requests differ (it must be 0), how many obstacles the lazy
loop added, and the total time of each way.  Writes ``results/sweep_lazy.json``.

Usage: ``python benchmarks/sweep_lazy.py [--shelves 100] [--aisles 5] [--movingai 1]``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from _harness import save_results

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))


def _scenes(args) -> list[tuple[str, dict]]:
    from aisle_gen import aisle_warehouse
    from movingai_gen import movingai_warehouse
    from rooms import shelves

    out = [(f"shelves-{s}", shelves(s)) for s in range(args.shelves)]
    out += [(f"aisles-6-{s}", aisle_warehouse(6, s)) for s in range(args.aisles)]
    out += [(f"movingai-8-{s}", movingai_warehouse(8, s)) for s in range(args.movingai)]
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--shelves", type=int, default=100)
    parser.add_argument("--aisles", type=int, default=5)
    parser.add_argument("--movingai", type=int, default=1)
    args = parser.parse_args()
    from cosmop.planning.checker import check_robot_plan
    from cosmop.planning.synthesis import synthesize
    from cosmop.scenario import parse_scenario

    rows, differ = [], 0
    for name, data in _scenes(args):
        scenario = parse_scenario(data)
        for robot, tasks in scenario.mission.tasks.items():
            row = {"scene": name, "robot": robot}
            for way in ("eager", "lazy"):
                t = time.perf_counter()
                res = synthesize(scenario.scene, robot, tasks, max_horizon=12, lazy=way == "lazy")
                row[f"{way}_s"] = time.perf_counter() - t
                row[way] = [res.feasible, res.horizon, sorted(res.requests)]
                if way == "lazy":
                    row["admitted"] = res.admitted
                    clean = res.feasible and check_robot_plan(scenario.scene, robot, res.plan) == []
                    row["checked"] = clean or not res.feasible
            row["same"] = row["eager"] == row["lazy"]
            differ += not row["same"] or not row["checked"]
            rows.append(row)
        print(f"{name}: {sum(r['scene'] == name for r in rows)} robots, differ so far {differ}", flush=True)
    kinds: dict[str, dict] = {}
    for r in rows:
        empty = {"robots": 0, "eager_s": 0.0, "lazy_s": 0.0, "admitted": 0}
        kind = kinds.setdefault(r["scene"].split("-")[0], empty)
        kind["robots"] += 1
        kind["eager_s"] += r["eager_s"]
        kind["lazy_s"] += r["lazy_s"]
        kind["admitted"] += r["admitted"]
    for kind, k in kinds.items():
        print(
            f"{kind:9s} {k['robots']:4d} robots  eager {k['eager_s']:7.1f} s  lazy {k['lazy_s']:7.1f} s  "
            f"({k['eager_s'] / k['lazy_s']:.2f}x)  obstacles added by the loop {k['admitted']}"
        )
    print(f"robots whose answers differ or whose plan fails the checker: {differ}")
    save_results("sweep_lazy", rows)
    return 1 if differ else 0


if __name__ == "__main__":
    raise SystemExit(main())
