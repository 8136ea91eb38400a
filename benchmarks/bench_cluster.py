"""Local worker processes against a Dask cluster of as many workers, side by side.

For each team size N (generated warehouses, ``warehouse_gen.py``, seeded) and each repeat, one
fresh process plans the team with :func:`cosmop.team.loop.plan_team` in local worker processes
and the next plans it on a Dask ``LocalCluster`` of the same number of worker processes (one
thread each), reached through :func:`cosmop.team.cluster.dask_executor` by its address, as a user
reaches a cluster.  The runs alternate, so the machine's drift hits both alike.  The cluster
is started and connected to before the clock starts (a user's cluster is already running);
its start-up and the connection (which checks and warms every worker) are recorded apart.
The plans of both engines must be byte-identical.

Usage: ``python benchmarks/bench_cluster.py [--sizes 10,20] [--repeats 3] [--workers 2]``.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import resource
import sys
import time
from pathlib import Path

from _harness import alternate, median_of, save_results

HERE = Path(__file__).resolve().parent


def child(n: int, seed: int, engine: str, workers: int) -> dict:
    sys.path.insert(0, str(HERE))
    from cosmop.scenario import parse_scenario
    from cosmop.team.loop import plan_team
    from warehouse_gen import warehouse

    scenario = parse_scenario(warehouse(n, seed))
    start = connect = 0.0
    if engine == "dask":
        from distributed import LocalCluster

        from cosmop.team.cluster import dask_executor

        t = time.perf_counter()
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, dashboard_address=":0")
        cluster.wait_for_workers(workers)
        start = time.perf_counter() - t
        t = time.perf_counter()
        with cluster, dask_executor(cluster.scheduler_address) as executor:
            connect = time.perf_counter() - t
            t = time.perf_counter()
            result = plan_team(scenario, max_horizon=20, executor=executor)
            total = time.perf_counter() - t
    else:
        t = time.perf_counter()
        result = plan_team(scenario, max_horizon=20, workers=workers)
        total = time.perf_counter() - t
    return {
        "n": n,
        "engine": engine,
        "feasible": result.plans.feasible,
        "checked": result.report.ok,
        "plans_sha256": hashlib.sha256(
            json.dumps(result.plans.to_dict(), sort_keys=True).encode()
        ).hexdigest(),
        "total_s": total,
        "synthesize_s": result.phases["synthesize"],
        "cluster_start_s": start,
        "connect_s": connect,
        "peak_main_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
        "peak_worker_mib": resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024,
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="10,20")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--child", nargs=2, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        print(json.dumps(child(int(args.child[0]), args.seed, args.child[1], args.workers)))
        return 0
    rows, summary = [], []
    extra = ("--seed", str(args.seed), "--workers", str(args.workers))
    for n in (int(s) for s in args.sizes.split(",")):
        runs = alternate(__file__, n, ("local", "dask"), args.repeats, *extra, timeout=7200)
        rows += runs["rows"]
        median = median_of(runs, "total_s")
        same = len({r["plans_sha256"] for r in runs["rows"]}) == 1
        summary.append({"n": n, **{f"{e}_median_s": t for e, t in median.items()}, "identical_plans": same})
        print(
            f"N={n:3d} local {median['local']:7.1f} s  dask {median['dask']:7.1f} s  "
            f"ratio {median['dask'] / median['local']:.3f}  identical plans: {same}",
            flush=True,
        )
    save_results("cluster", [*rows, *({"summary": s} for s in summary)])
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
