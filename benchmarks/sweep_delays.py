"""Robots delayed at random on the paper's 10x10 warehouse: every run completes, nobody is hit.

Issue 36, point 6.  The example is planned once (``cosmop plan``); each seed then runs ``cosmop
simulate --plan PLAN --delays P:MIN:MAX --seed S --summary ...`` in a fresh process, as a user
does (the delay model of the League of Robot Runners' 2026 start-kit: every simulated second
each robot still executing its plan stops with probability P for MIN to MAX s).  Each run is set
beside the same seed without delays: the makespan the delays cost is the difference of the two
realised makespans (one run alone cannot say it).  The seed drives the people and the delays
only, so a scenario without people has one run without delays for every seed.

A row: ``seed``, ``completed``, ``contacts_while_moving``, ``makespan`` (realised, s), ``plain``
(the same seed without delays), ``lost`` (their difference), ``stops`` and ``stopped_s`` (every
robot's delays, in all), ``worst_robot_s`` (the most seconds one robot stood), ``replans`` and
``wall_s``.  Writes ``results/NAME.json`` (default ``sweep_delays``) and prints a row per seed
and the totals.

Usage: ``python benchmarks/sweep_delays.py [--scenario FILE] [--delays 0.01:2:10] [--seeds 20]
[--workers 2] [--out NAME]``.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import yaml

from _harness import save_results

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "02_warehouse_10x10" / "scenario.yaml"
COSMOP = [sys.executable, "-m", "cosmop"]


def simulate(scenario: Path, plan: Path, seed: int, delays: str | None, folder: Path) -> dict:
    """One ``cosmop simulate`` in a fresh process; the row of its summary."""
    tag = f"{seed}_{'plain' if delays is None else 'delayed'}"
    summary = folder / f"summary_{tag}.json"
    args = [*COSMOP, "simulate", str(scenario), "--plan", str(plan), "--seed", str(seed)]
    args += ["--summary", str(summary)] + ([] if delays is None else ["--delays", delays])
    start = time.perf_counter()
    run = subprocess.run(args, capture_output=True, text=True)
    wall = round(time.perf_counter() - start, 2)
    if not summary.exists():
        return {"seed": seed, "exit": run.returncode, "error": run.stderr.strip()[-300:]}
    data = json.loads(summary.read_text())
    report = data["delays"] or {"count": 0, "seconds": 0.0, "robots": {}}
    return {
        "seed": seed,
        "exit": run.returncode,
        "completed": data["completed"],
        "contacts_while_moving": data["contacts_while_moving"],
        "makespan": data["makespan"]["realised"],
        "sim_time_s": data["sim_time_s"],
        "stops": report["count"],
        "stopped_s": report["seconds"],
        "worst_robot_s": max((r["seconds"] for r in report["robots"].values()), default=0.0),
        "replans": data["replans"],
        "messages": len(data["messages"]),
        "wall_s": wall,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", type=Path, default=EXAMPLE)
    parser.add_argument("--delays", default="0.01:2:10")
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--out", default="sweep_delays")
    args = parser.parse_args(argv)
    people = bool(yaml.safe_load(args.scenario.read_text())["scene"].get("humans"))
    seeds = list(range(args.seeds))
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        plan = folder / "plan.json"
        planned = [*COSMOP, "plan", str(args.scenario), "-o", str(plan)]
        subprocess.run(planned, check=True, capture_output=True)
        jobs = [(s, args.delays) for s in seeds] + [(s, None) for s in (seeds if people else seeds[:1])]
        with ThreadPoolExecutor(args.workers) as pool:
            done = list(pool.map(lambda job: simulate(args.scenario, plan, *job, folder), jobs))
    delayed, plain = done[: len(seeds)], {r["seed"]: r for r in done[len(seeds) :]}
    rows = []
    for row in delayed:
        base = plain.get(row["seed"], plain[seeds[0]])
        lost = None
        if row.get("makespan") is not None and base.get("makespan") is not None:
            lost = round(row["makespan"] - base["makespan"], 3)
        rows.append({**row, "delays": args.delays, "plain": base.get("makespan"), "lost": lost})
        print(json.dumps(rows[-1]))
    save_results(args.out, rows)
    good = [r for r in rows if r.get("completed") and r.get("contacts_while_moving") == 0]
    lost = [r["lost"] for r in rows if r["lost"] is not None]
    print(
        f"{len(good)}/{len(rows)} runs completed with no contact while moving; without delays "
        f"{plain[seeds[0]].get('makespan')} s; lost to the delays: median {statistics.median(lost):.1f} s, "
        f"{min(lost):.1f}-{max(lost):.1f} s; stopped in all: median "
        f"{statistics.median(r['stopped_s'] for r in rows):.1f} s over "
        f"{statistics.median(r['stops'] for r in rows):.0f} stops"
    )
    return 0 if len(good) == len(rows) else 1


if __name__ == "__main__":
    raise SystemExit(main())
