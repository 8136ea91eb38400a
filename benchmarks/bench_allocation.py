"""Allocation of deliveries: plan time end to end, the makespan, and how far from the best.

Generated warehouses in the deliveries form (``delivery_gen.py``), N robots and M goods, each
planned in a fresh subprocess with :func:`cosmop.team.loop.plan_team`:

* ``plan_s``: the whole planning (costing every (robot, good, dock) alone, the assignment,
  synthesis, coordination, team safety, verification, the checker);
* the allocation's cost (the busiest robot's load and the sum, in primitive steps, each
  delivery costed alone), whether branch and bound proved it, and the nodes it visited;
* the plans' makespan (longest plan, steps) and expected seconds to finish;
* for small sizes the brute-force optimum over *all* allocations under the same costs (the gap
  must be 0); for large ones a lower bound (the dearest good alone; the sum of the cheapest
  options shared evenly) and the gap to it.

``python benchmarks/bench_allocation.py [--sizes 4x6,10x15,20x30] [--seed S]`` writes
``results/allocation.json``.
"""

from __future__ import annotations

import argparse
import itertools
import json
import math
import sys
import time
from pathlib import Path

from _harness import child_row, save_results

HERE = Path(__file__).resolve().parent
BRUTE_FORCE_LIMIT = 2_000_000  # allocations enumerated at most


def _brute_force(options: dict, costs: dict) -> tuple[int, int] | None:
    best = None
    for picks in itertools.product(*options.values()):
        loads: dict[str, int] = {}
        for obj, (r, w) in zip(options, picks, strict=True):
            c = costs[(r, obj, w)]
            if c is None:
                break
            loads[r] = loads.get(r, 0) + c
        else:
            key = (max(loads.values()), sum(loads.values()))
            best = key if best is None or key < best else best
    return best


def _lower_bound(options: dict, costs: dict, n: int) -> int:
    cheapest = [min(c for r, w in opts if (c := costs[(r, o, w)]) is not None) for o, opts in options.items()]
    return max(max(cheapest), math.ceil(sum(cheapest) / n))


def one(n: int, m: int, seed: int) -> dict:
    sys.path.insert(0, str(HERE))
    from cosmop.scenario import parse_scenario
    from cosmop.team.loop import plan_team
    from delivery_gen import delivery_warehouse

    scenario = parse_scenario(delivery_warehouse(n, m, seed))
    t = time.perf_counter()
    team = plan_team(scenario)
    row = {
        "n": n,
        "m": m,
        "seed": seed,
        "plan_s": time.perf_counter() - t,
        **{f"{k}_s": v for k, v in team.phases.items()},
        "feasible": team.plans.feasible,
        "reason": team.plans.reason,
    }
    choice = team.allocation
    options = {d.object: [(r, w) for r in d.by for w in d.to] for d in scenario.mission.deliveries}
    costs = dict(choice.costs)
    row |= {
        "load_makespan": choice.makespan,
        "load_total": choice.total,
        "proved_best": choice.exhaustive,
        "nodes": choice.considered,
        "options": sum(len(v) for v in options.values()),
        "allocations": math.prod(len(v) for v in options.values()),
    }
    if row["allocations"] <= BRUTE_FORCE_LIMIT:
        best = _brute_force(options, costs)
        row["brute_force"] = best
        row["gap"] = None if best is None else choice.makespan - best[0]
    else:
        bound = _lower_bound(options, costs, n)
        row["lower_bound"] = bound
        row["gap_to_bound"] = choice.makespan - bound
    if team.plans.feasible:
        horizons = [p.horizon for p in team.plans.robots.values()]
        row |= {
            "plan_makespan_steps": max(horizons),
            "plan_total_steps": sum(horizons),
            "expected_s": team.safety.makespan if team.safety else None,
            "movers": len({r for r in team.plans.allocation.values()}),
        }
    return row


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="4x6,10x15,20x30")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--child", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        n, m = map(int, args.child.split("x"))
        print(json.dumps(one(n, m, args.seed)))
        return 0
    rows = []
    for size in args.sizes.split(","):
        row = child_row(__file__, "--child", size, "--seed", str(args.seed))
        rows.append(row)
        print(json.dumps(row), flush=True)
    save_results("allocation", rows)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
