"""Simulation speed: the 10x10 example against real time, and the cost of a cycle against N.

``python benchmarks/bench_sim.py [--repeats 3] [--sizes 10,20,30,40,50] [--cycles 300]``

1. The paper's 10x10 example (``examples/02_warehouse_10x10``) is planned once and simulated
   ``--repeats`` times at its cycle of 0.1 s; the ratio simulated time / wall time is reported
   (median; target: at least 50, the paper's MobileSim runs at 1).
2. Per-cycle cost: generated warehouses (``warehouse_gen.py``) with N robots, each driving a
   GoTo across its bay and back (plans built directly, without the solver: only the local
   layer is timed), for ``--cycles`` cycles; median wall time per cycle and per robot-cycle.

Results go to ``benchmarks/results/sim.json`` and a chart ``sim_cycle.png``.
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from cosmop.events import Event  # noqa: E402
from cosmop.planning import PlanSet, plan_from_actions  # noqa: E402
from cosmop.scenario import load_scenario, parse_scenario  # noqa: E402
from cosmop.sim import SimSettings, simulate  # noqa: E402
from cosmop.team.loop import plan_team  # noqa: E402
from warehouse_gen import warehouse  # noqa: E402


def real_time_ratio(repeats: int) -> dict:
    scenario = load_scenario(HERE.parent / "examples" / "02_warehouse_10x10" / "scenario.yaml")
    plans = plan_team(scenario).plans
    runs = []
    for _ in range(repeats):
        result = simulate(scenario, plans)
        runs.append(
            {
                "completed": result.completed,
                "sim_time_s": result.sim_time_s,
                "wall_time_s": result.wall_time_s,
                "ratio": result.sim_time_s / result.wall_time_s,
                "cycles": result.cycles,
                "contacts_while_moving": result.contacts_while_moving,
                "replan_attempts": result.replan_attempts,
            }
        )
    return {"runs": runs, "median_ratio": statistics.median(r["ratio"] for r in runs)}


def bay_drives(n: int):
    """A generated warehouse of `n` robots (seed 1) whose robots each drive a GoTo across their
    bay and back: plans built directly, without the solver, so that only the local layer runs."""
    scenario = parse_scenario(warehouse(n, seed=1))
    robots = {}
    for rid, robot in scenario.scene.robots.items():
        x, y, _ = robot.pose
        actions = [("GoTo", (x + 6000 - 1000 * (x % 2000 > 0), y, 0)), ("GoTo", (x, y, 0))]
        robots[rid] = plan_from_actions(scenario.scene, rid, [Event("return", rid)], actions)
    return scenario, PlanSet(scenario.name, True, robots)


def cycle_cost(n: int, cycles: int) -> dict:
    scenario, plans = bay_drives(n)
    settings = SimSettings(max_time=cycles * 0.1, replan=False)
    t0 = time.perf_counter()
    result = simulate(scenario, plans, settings=settings)
    wall = time.perf_counter() - t0
    return {
        "robots": n,
        "cycles": result.cycles,
        "ms_per_cycle": 1000 * wall / result.cycles,
        "us_per_robot_cycle": 1e6 * wall / result.cycles / n,
        "contacts_while_moving": result.contacts_while_moving,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--sizes", default="10,20,30,40,50")
    parser.add_argument("--cycles", type=int, default=300)
    args = parser.parse_args(argv)
    ratio = real_time_ratio(args.repeats)
    print(f"10x10: median {ratio['median_ratio']:.1f}x real time; runs {ratio['runs']}")
    sizes = [cycle_cost(int(n), args.cycles) for n in args.sizes.split(",")]
    for row in sizes:
        print(row)
    out = {
        "date": time.strftime("%Y-%m-%d"),
        "machine": f"{platform.machine()} {platform.processor() or ''} python {platform.python_version()}",
        "real_time": ratio,
        "cycle_cost": sizes,
    }
    (HERE / "results").mkdir(exist_ok=True)
    (HERE / "results" / "sim.json").write_text(json.dumps(out, indent=2) + "\n")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(5, 3.5))
        ax.plot([r["robots"] for r in sizes], [r["ms_per_cycle"] for r in sizes], marker="o")
        ax.axhline(100.0 / 50, color="grey", ls="--", lw=1, label="50x real time at 0.1 s")
        ax.set_xlabel("robots")
        ax.set_ylabel("wall time per cycle [ms]")
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(HERE / "results" / "sim_cycle.png", dpi=110)
    except ImportError:  # the chart needs the viz extra
        pass
    return 0


if __name__ == "__main__":
    sys.exit(main())
