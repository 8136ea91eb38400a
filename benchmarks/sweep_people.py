"""People crossing the 2x2 warehouse: 200 seeded runs of example 03 (the suite keeps 30).

The example is planned once; each seed draws the people's random walks.  A run counts when it
completes, with every good in its dock and no contact while a robot moves; contacts in which a
person walks into a standing robot are counted too, to show the people did meet the robots.
Writes ``results/sweep_people.json``.

Usage: ``python benchmarks/sweep_people.py [--seeds 200] [--workers 2]``.
"""

from __future__ import annotations

import argparse
import multiprocessing
import time
from pathlib import Path

from _harness import save_results
from cosmop.scenario import load_scenario
from cosmop.sim import SimSettings, simulate
from cosmop.team.loop import plan_team

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "03_people_2x2" / "scenario.yaml"


def run(job) -> dict:
    scenario, plans, seed = job
    start = time.perf_counter()
    result = simulate(scenario, plans, seed=seed, settings=SimSettings(max_time=600))
    return {
        "seed": seed,
        "completed": result.completed,
        "delivered": all(result.objects_in_workspaces(scenario, plans).values()),
        "contacts_while_moving": result.contacts_while_moving,
        "contacts": len(result.contacts),
        "sim_time_s": round(result.sim_time_s, 3),
        "wall_s": round(time.perf_counter() - start, 3),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=200)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args(argv)
    scenario = load_scenario(EXAMPLE)
    plans = plan_team(scenario).plans
    with multiprocessing.get_context("fork").Pool(args.workers) as pool:
        rows = pool.map(run, [(scenario, plans, seed) for seed in range(args.seeds)])
    save_results("sweep_people", rows)
    good = sum(r["completed"] and r["delivered"] and r["contacts_while_moving"] == 0 for r in rows)
    print(
        f"{len(rows)} runs: {good} completed and delivered without a contact while moving; "
        f"{sum(r['contacts'] for r in rows)} contacts with standing robots"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
