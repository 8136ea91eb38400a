"""End to end: decompose, plan, coordinate, verify, check, on the paper's 10x10 example.

Median over ``--repeats`` fresh runs of :func:`cosmop.team.loop.plan_team` with one worker
process and with one per core, with the time per phase and the peak memory of this process
(worker processes not included).  Usage: ``python benchmarks/bench_pipeline.py``.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import tempfile
import time
from pathlib import Path

from cosmop.scenario import load_scenario
from cosmop.team.loop import plan_team

ROOT = Path(__file__).resolve().parents[1]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument(
        "--scenario", type=Path, default=ROOT / "examples" / "02_warehouse_10x10" / "scenario.yaml"
    )
    args = parser.parse_args()
    scenario = load_scenario(args.scenario)
    runs, summary = [], {}
    for workers in (1, os.cpu_count() or 1):
        for _ in range(args.repeats):
            t = time.perf_counter()
            result = plan_team(scenario, workers=workers)
            total = time.perf_counter() - t
            assert result.plans.feasible and result.report.ok and result.verification.holds
            runs.append(
                {"workers": workers, "total_s": total, **{f"{k}_s": v for k, v in result.phases.items()}}
            )
        mine = [r for r in runs if r["workers"] == workers]
        summary[f"workers={workers}"] = {k: statistics.median(r[k] for r in mine) for k in mine[0]}
    summary["peak_mib"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    summary["pairs"] = len(result.plans.coordination)
    summary["iterations"] = result.iterations
    print(json.dumps(summary, indent=2))
    out = ROOT / "benchmarks" / "results"
    out.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=out, suffix=".tmp")
    with os.fdopen(fd, "w") as fh:
        json.dump(
            {"date": time.strftime("%Y-%m-%d"), "scenario": scenario.name, "summary": summary, "runs": runs},
            fh,
            indent=2,
        )
    os.replace(tmp, out / "pipeline.json")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
