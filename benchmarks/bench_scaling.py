"""End-to-end scaling on generated warehouses (``warehouse_gen.py``): planning and simulation against N.

For each N (default 10, 20, 30, 50, 100), seeded:

1. **As a user plans**: ``cosmop plan scenario.yaml -o plan.json`` in a fresh process (2 worker
   processes, the default on this machine; process start and file writing included), wall
   time and the peak resident memory of the largest process of its tree.
2. **Where the time goes**: :func:`cosmop.team.loop.plan_team` in a fresh process, with its
   phases (``--phases``; skipped by default, the user run is the target).
3. **As a user simulates**: ``cosmop simulate scenario.yaml --plan plan.json --summary s.json``,
   the whole run (``--sim-time T`` stops it at T simulated seconds instead), wall time, the
   simulated seconds per wall second, and whether the run completed.

Writes ``results/scaling.json`` and, with matplotlib, ``results/scaling.png`` (time against N).
Usage: ``python benchmarks/bench_scaling.py [--sizes 10,20,30,50,100] [--seed 1] [--phases]``.
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import yaml

from _harness import RESULTS, child_row, save_results

HERE = Path(__file__).resolve().parent
COSMOP = [sys.executable, "-m", "cosmop"]


def child(n: int, seed: int) -> dict:
    sys.path.insert(0, str(HERE))
    from cosmop.scenario import parse_scenario
    from cosmop.team.loop import plan_team
    from warehouse_gen import warehouse

    scenario = parse_scenario(warehouse(n, seed))
    t = time.perf_counter()
    result = plan_team(scenario, max_horizon=20)
    total = time.perf_counter() - t
    return {
        "n": n,
        "seed": seed,
        "feasible": result.plans.feasible,
        "checked": result.report.ok,
        "verified": bool(result.verification and result.verification.holds),
        "pairs": len(result.plans.coordination),
        "iterations": result.iterations,
        "total_s": total,
        **{f"{k}_s": v for k, v in result.phases.items()},
    }


def _timed(command: list[str], timeout: float) -> tuple[float, int]:
    """Wall seconds and exit code of `command` in a fresh process."""
    start = time.perf_counter()
    done = subprocess.run(command, capture_output=True, timeout=timeout)
    return time.perf_counter() - start, done.returncode


def as_a_user(n: int, seed: int, sim_time: float | None, tmp: Path) -> dict:
    """``cosmop plan`` then ``cosmop simulate`` on the N-robot warehouse, as a user runs them."""
    from warehouse_gen import warehouse

    scenario, plan, summary = tmp / f"w{n}.yaml", tmp / f"w{n}_plan.json", tmp / f"w{n}_summary.json"
    scenario.write_text(yaml.safe_dump(warehouse(n, seed), sort_keys=False))
    plan_s, code = _timed([*COSMOP, "plan", str(scenario), "-o", str(plan)], timeout=3600)
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024  # the largest so far
    row = {"n": n, "seed": seed, "plan_s": plan_s, "plan_exit": code, "peak_mib_so_far": peak}
    if code == 0:
        sim = [*COSMOP, "simulate", str(scenario), "--plan", str(plan), "--summary", str(summary)]
        limit = [] if sim_time is None else ["--max-time", str(sim_time)]
        sim_s, sim_code = _timed([*sim, *limit], timeout=3600)
        done = json.loads(summary.read_text())
        row |= {"sim_s": sim_s, "sim_exit": sim_code, "simulated_s": done["sim_time_s"]}
        row["completed"] = done["completed"]
        row["contacts_while_moving"] = done["contacts_while_moving"]
        row["real_time_factor"] = done["sim_time_s"] / sim_s
    return row


def _chart(rows: list[dict]) -> None:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4))
    ns = [r["n"] for r in rows]
    a.plot(ns, [r["plan_s"] for r in rows], marker="o", label="cosmop plan (2 workers)")
    a.axhline(60, color="grey", linestyle=":", label="target at N=50 (60 s)")
    a.set_xlabel("robots N")
    a.set_ylabel("wall time [s]")
    a.set_title("planning, end to end")
    a.legend()
    sims = [r for r in rows if "real_time_factor" in r]
    b.plot([r["n"] for r in sims], [r["real_time_factor"] for r in sims], marker="o")
    b.axhline(1, color="grey", linestyle=":", label="real time")
    b.axhline(20, color="grey", linestyle="--", label="target at N=50 (20x)")
    b.legend()
    b.set_xlabel("robots N")
    b.set_ylabel("simulated s per wall s")
    b.set_yscale("log")
    b.set_title("simulation, as a user runs it")
    fig.tight_layout()
    fig.savefig(RESULTS / "scaling.png", dpi=100)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="10,20,30,50,100")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--sim-time", type=float, default=None)
    parser.add_argument("--phases", action="store_true")
    parser.add_argument("--child", type=int, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        print(json.dumps(child(args.child, args.seed)))
        return 0
    sys.path.insert(0, str(HERE))
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for n in (int(s) for s in args.sizes.split(",")):
            row = as_a_user(n, args.seed, args.sim_time, Path(tmp))
            if args.phases:
                phases = child_row(__file__, "--child", str(n), "--seed", str(args.seed), timeout=3600)
                row["phases"] = phases
            rows.append(row)
            sim = (
                f"simulate {row['sim_s']:6.1f} s for {row['simulated_s']:.0f} simulated s "
                f"({row['real_time_factor']:.2f}x real time, completed {row['completed']})"
                if "sim_s" in row
                else f"plan exit {row['plan_exit']}"
            )
            peak = row["peak_mib_so_far"]
            print(f"N={n:3d} plan {row['plan_s']:6.1f} s  {sim}  peak {peak:.0f} MiB", flush=True)
    save_results("scaling", rows)
    _chart(rows)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
