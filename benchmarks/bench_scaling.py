"""End-to-end scaling on generated warehouses (``warehouse_gen.py``): N = 10, 20, 30, 50 robots.

Each N runs in a fresh subprocess: generate (seeded), then :func:`cosmop.pipeline.plan_team`
(decompose, plan, coordinate, re-plan, verify, check) with one worker process per core.
Recorded: wall time per phase, coordination pairs, and the peak resident memory of the main
process and of its largest worker.  Usage: ``python benchmarks/bench_scaling.py [--sizes ...]``.
"""

from __future__ import annotations

import argparse
import json
import resource
import sys
import time
from pathlib import Path

from _harness import child_row, save_results

HERE = Path(__file__).resolve().parent


def child(n: int, seed: int) -> dict:
    sys.path.insert(0, str(HERE))
    from cosmop.pipeline import plan_team
    from cosmop.scenario import parse_scenario
    from warehouse_gen import warehouse

    scenario = parse_scenario(warehouse(n, seed))
    t = time.perf_counter()
    result = plan_team(scenario, max_horizon=20)
    total = time.perf_counter() - t
    return {
        "n": n,
        "seed": seed,
        "feasible": result.plans.feasible,
        "reason": result.plans.reason,
        "checked": result.report.ok,
        "verified": bool(result.verification and result.verification.holds),
        "pairs": len(result.plans.coordination),
        "iterations": result.iterations,
        "total_s": total,
        **{f"{k}_s": v for k, v in result.phases.items()},
        "peak_main_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
        "peak_worker_mib": resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024,
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="10,20,30,50")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--child", type=int, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        print(json.dumps(child(args.child, args.seed)))
        return 0
    rows = []
    for n in (int(s) for s in args.sizes.split(",")):
        row = child_row(__file__, "--child", str(n), "--seed", str(args.seed), timeout=3600)
        rows.append(row)
        print(
            f"N={n:3d} total {row['total_s']:7.1f} s (synthesize {row['synthesize_s']:6.1f}, verify "
            f"{row['verify_s']:.2f}, check {row['check_s']:.2f})  pairs {row['pairs']:3d}  "
            f"feasible={row['feasible']} checked={row['checked']} verified={row['verified']}  "
            f"peak main {row['peak_main_mib']:.0f} MiB, worker {row['peak_worker_mib']:.0f} MiB",
            flush=True,
        )
    save_results("scaling", rows)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
