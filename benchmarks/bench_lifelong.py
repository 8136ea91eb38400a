"""A stream of orders served by a running fleet: cosmop beside a rolling PIBT on the grid.

The same workload (``orders_gen.py``: the MovingAI warehouse, N robots, a Poisson stream of
orders) is served twice, in one run:

* by cosmop, as a user runs it: ``cosmop run SCENARIO --until S --summary FILE`` in a fresh
  process (continuous geometry, square robots with safety margins, messages, passive-safe
  control; every hand-over planned, ordered and checked while the others move);
* by a grid peer: pymapf's PIBT (the ``bench`` extra) stepping one cell per step at the robots'
  cruise speed (750 mm/s: 1.33 s per 1 m cell), each agent's goal replaced as it arrives
  (rolling horizon: good, dock, home), with cosmop's dispatcher rule
  (``cosmop.lifelong.dispatch.choose_assignment``: among the oldest ``reveal`` orders per
  robot, each idle agent the order of least L1 work, an order passed over as often as the
  window holds orders served next).  Picking and dropping take no time on the grid, and two
  agents may stand in neighbouring cells (cosmop keeps 100 mm between robots and docks in
  about 3 s).

Both report deliveries per hour and the waits from release to delivery (p50, p95, max).
``python benchmarks/bench_lifelong.py [--sizes 20] [--rate 600] [--until 900] [--seed S]
[--reveal R] [--out NAME]`` prints a row per size and engine and writes ``results/NAME.json``.
"""

from __future__ import annotations

import argparse
import json
import random
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _harness import emit_scenario, save_results

HERE = Path(__file__).resolve().parent
CRUISE = 750.0  # mm/s, the robots' top speed


def cosmop_row(data: dict, until: float, timeout: float, reveal: float = 1.0) -> dict:
    """``cosmop run`` on the workload in a fresh process, timed as a user feels it."""
    with tempfile.TemporaryDirectory() as tmp:
        scenario, summary = Path(tmp) / "s.yaml", Path(tmp) / "summary.json"
        emit_scenario(data, scenario)
        t = time.perf_counter()
        cmd = [
            sys.executable,
            "-m",
            "cosmop",
            "run",
            str(scenario),
            "--until",
            str(until),
            "--summary",
            str(summary),
            "--reveal",
            str(reveal),
        ]
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
        except subprocess.TimeoutExpired:
            return {"engine": "cosmop", "status": f"timeout after {timeout:.0f} s"}
        wall = time.perf_counter() - t
        if not summary.exists():
            return {"engine": "cosmop", "status": f"exit {proc.returncode}", "stderr": proc.stderr[-400:]}
        s = json.loads(summary.read_text())
    return {
        "engine": "cosmop",
        "status": "ok",
        "wall_s": round(wall, 1),
        "released": s["orders"]["released"],
        "delivered": s["orders"]["delivered"],
        "lost": s["orders"]["lost"],
        "deliveries_per_hour": s["deliveries_per_hour"],
        "wait_s": s["wait_s"],
        "contacts_while_moving": s["contacts_while_moving"],
        "messages": s["messages"],
        "handover_wall_s": s.get("handover_wall_s"),
        "handover_plan_wall_s_p50": _median(
            [e["plan_wall_s"] for e in s["dispatch_log"] if "plan_wall_s" in e]
        ),
        "handovers_refused": sum(1 for e in s["dispatch_log"] if not e["accepted"]),
        "reorders": s.get("reorders"),  # waits ordered again (tried, accepted, wall time)
        "utilisation_mean": round(sum(s["utilisation"].values()) / max(len(s["utilisation"]), 1), 3),
    }


def _median(values: list[float]) -> float | None:
    return round(statistics.median(values), 3) if values else None


def _cell(point) -> tuple[int, int]:
    from movingai_gen import CELL, ROWS

    return ROWS - 1 - int(point[1] // CELL), int(point[0] // CELL)


def peer_row(data: dict, until: float, seed: int, reveal: float = 1.0) -> dict:
    """The rolling PIBT on the grid (module docstring)."""
    import pymapf
    from pymapf.algorithms.pibt import distance_table, pibt_step

    from cosmop.lifelong.dispatch import Offer, choose_assignment, window_size
    from cosmop.scenario import parse_scenario

    sys.path.insert(0, str(HERE))
    from movingai_gen import CELL, COLS, ROWS, _centre, blocked_cells

    blocked = blocked_cells()
    grid = pymapf.GridMap([[1 if (r, c) in blocked else 0 for c in range(COLS)] for r in range(ROWS)])
    scene = data["scene"]
    home = {r: _cell(v["pose"]) for r, v in scene["robots"].items()}
    goods = {o: _cell(v["position"]) for o, v in scene["objects"].items()}
    docks = {
        w: _cell(((v["x"][0] + v["x"][1]) / 2, (v["y"][0] + v["y"][1]) / 2))
        for w, v in scene["workspaces"].items()
    }
    scenario = parse_scenario(data)  # the same orders and docks as cosmop's dispatcher sees
    orders = sorted(scenario.orders, key=lambda o: o.at)
    window = window_size(reveal, len(scene["robots"]))
    tables: dict = {}

    def dist(goal, cell):
        if goal not in tables:
            tables[goal] = distance_table(grid, goal)
        return tables[goal].get(cell, 10**9)

    names = list(home)
    at, goal = dict(home), dict(home)
    task: dict[str, dict | None] = {r: None for r in names}  # the order being served, and its leg
    priorities = {r: 0.0 for r in names}
    released = delivered = 0
    pool: list[tuple[object, int]] = []  # (order, times passed over for younger ones)
    waits: list[float] = []
    rng = random.Random(seed)
    step_s = CELL / CRUISE
    t0 = time.perf_counter()
    for k in range(int(until / step_s)):
        t = k * step_s
        while released < len(orders) and orders[released].at <= t:
            pool.append((orders[released], 0))
            released += 1
        while True:
            idle = [(r, tuple(_centre(*at[r]))) for r in names if task[r] is None and at[r] == home[r]]
            offers = [
                Offer(o, tuple(scene["objects"][o.object]["position"]), overdue=n >= window)
                for o, n in pool[:window]
            ]
            chosen = choose_assignment(scenario.scene, offers, idle) if idle and offers else None
            if chosen is None:
                break
            j, r = chosen
            order = offers[j].order
            g = goods[order.object]
            dock = min(order.to, key=lambda w: abs(docks[w][0] - g[0]) + abs(docks[w][1] - g[1]))
            task[r] = {"order": order, "leg": "good", "dock": docks[dock]}
            goal[r] = g
            pool = [(o, n + (i < j)) for i, (o, n) in enumerate(pool) if i != j]
        nxt = pibt_step(grid, names, at, goal, priorities, lambda name, cell: dist(goal[name], cell), rng=rng)
        if nxt is None:
            continue
        at = dict(nxt)
        for r in names:
            priorities[r] = 0.0 if at[r] == goal[r] else priorities[r] + 1.0
            job = task[r]
            if job is None or at[r] != goal[r]:
                continue
            if job["leg"] == "good":
                job["leg"], goal[r] = "dock", job["dock"]
            elif job["leg"] == "dock":
                delivered += 1
                waits.append(t + step_s - job["order"].at)
                job["leg"], goal[r] = "home", home[r]
            else:
                task[r] = None
    waits.sort()
    return {
        "engine": "pibt (grid)",
        "status": "ok",
        "wall_s": round(time.perf_counter() - t0, 1),
        "released": released,
        "delivered": delivered,
        "lost": 0,
        "deliveries_per_hour": round(delivered * 3600.0 / until, 3),
        "wait_s": {
            "p50": round(statistics.median(waits), 1) if waits else None,
            "p95": round(waits[min(len(waits) - 1, int(0.95 * len(waits)))], 1) if waits else None,
            "max": round(waits[-1], 1) if waits else None,
        },
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="20")
    parser.add_argument("--rate", type=float, default=600.0, help="orders per hour")
    parser.add_argument("--until", type=float, default=900.0, help="simulated seconds")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--timeout", type=float, default=3600.0)
    parser.add_argument("--reveal", type=float, default=1.0, help="orders per robot dispatched among")
    parser.add_argument("--out", default="lifelong")
    args = parser.parse_args(argv)
    sys.path.insert(0, str(HERE))
    from orders_gen import orders_warehouse

    rows = []
    for n in map(int, args.sizes.split(",")):
        data = orders_warehouse(n, args.seed, args.rate, args.until / 3600.0)
        peer = peer_row(data, args.until, args.seed, args.reveal)
        for row in (cosmop_row(data, args.until, args.timeout, args.reveal), peer):
            row = {
                "n": n,
                "rate_per_hour": args.rate,
                "until_s": args.until,
                "seed": args.seed,
                "reveal": args.reveal,
                **row,
            }
            rows.append(row)
            print(json.dumps(row), flush=True)
    print(f"wrote {save_results(args.out, rows)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
