"""Single-robot synthesis side by side: an older checkout, and eager against lazy geometry.

Workloads (every robot of the scenario planned in turn, one process, the checker run on each
plan; seconds from the first synthesis, imports excluded, as ``bench_synthesis.py`` times it):

* ``10x10``: the paper's example (``examples/02_warehouse_10x10``), 10 robots;
* ``movingai``: the MovingAI map ``warehouse-10-20-10-2-1`` (804 walls) with 4 robots
  (``movingai_gen.py 4``).

Variants, each in a fresh process, alternated ``--repeats`` times: ``before`` (the code at
``--before PATH``, a checkout's ``src``; skipped without it), ``eager`` and ``lazy`` (this
checkout).  Every variant must find the same horizon and the same number of requests for
every robot; the script stops otherwise.  Writes ``results/solve.json``.

Usage: ``python benchmarks/bench_solve.py [--repeats 3] [--before /tmp/before/src]``.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

from _harness import alternate, median_of, save_results

ROOT = Path(__file__).resolve().parents[1]
WORKLOADS = ("10x10", "movingai")


def _scenario(workload: str, tmp: Path) -> Path:
    if workload == "10x10":
        return ROOT / "examples" / "02_warehouse_10x10" / "scenario.yaml"
    import yaml

    from movingai_gen import movingai_warehouse

    path = tmp / "movingai-4.yaml"
    path.write_text(yaml.safe_dump(movingai_warehouse(4, seed=0), sort_keys=False))
    return path


def child(workload: str, variant: str) -> dict:
    """One run: every robot synthesised and checked; the row of times and answers."""
    from cosmop.planning.checker import check_robot_plan
    from cosmop.planning.synthesis import synthesize
    from cosmop.scenario import load_scenario

    with tempfile.TemporaryDirectory() as tmp:
        scenario = load_scenario(_scenario(workload, Path(tmp)))
    options = {} if variant == "before" else {"lazy": variant == "lazy"}
    answers, start = {}, time.perf_counter()
    for robot, tasks in scenario.mission.tasks.items():
        res = synthesize(scenario.scene, robot, tasks, max_horizon=12, **options)
        assert res.feasible and check_robot_plan(scenario.scene, robot, res.plan) == []
        answers[robot] = [res.horizon, len(res.requests), sorted(res.requests)]
    return {"workload": workload, "s": time.perf_counter() - start, "answers": answers}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--before", help="the src directory of an older checkout")
    parser.add_argument("--child", nargs=2, help=argparse.SUPPRESS)
    parser.add_argument("--workloads", nargs="*", default=list(WORKLOADS), choices=WORKLOADS)
    args = parser.parse_args()
    if args.child:
        print(json.dumps(child(*args.child)))
        return 0
    variants = (("before",) if args.before else ()) + ("eager", "lazy")
    env_of = {"before": {"PYTHONPATH": args.before}}.get
    rows = []
    for workload in args.workloads:
        runs = alternate(__file__, workload, variants, args.repeats, env_of=env_of, timeout=3600)
        answers = {json.dumps(r["answers"], sort_keys=True) for r in runs["rows"]}
        same_k = len({json.dumps({k: v[:2] for k, v in r["answers"].items()}) for r in runs["rows"]}) == 1
        if not same_k:
            print(f"{workload}: the variants disagree on a horizon or a number of requests", file=sys.stderr)
            return 1
        medians = median_of(runs, "s")
        rows += runs["rows"]
        line = "  ".join(f"{v} {s:.2f} s" for v, s in medians.items())
        if "before" in medians:
            line += f"  (before / lazy: {medians['before'] / medians['lazy']:.2f}x)"
        same = "yes" if len(answers) == 1 else "the same K and counts"
        print(f"{workload}: {line}; the same answers: {same}")
    print(f"wrote {save_results('solve', rows)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
