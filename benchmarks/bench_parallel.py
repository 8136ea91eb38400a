"""A fleet that works in parallel: the team's makespan against its slowest robot alone.

The *overhead* of a team plan is its makespan over the longest makespan of one of its robots
planned alone (the same scene with the other robots removed, its own tasks): 1.0 means the
team loses nothing to coordination.  It is measured planned (the itinerary's expected
makespan) and simulated (the run's time against the same robots-alone figure).  Each robot
alone is simulated too: ``over_simulated_alone`` sets the team's run beside the slowest robot's
run alone, which separates what coordination costs from the controller's own pace.

Workloads, each in a fresh subprocess:

* ``paper``: the paper's 10x10 example (``examples/02_warehouse_10x10``);
* ``aisles N``: warehouses with one-lane aisles (``aisle_gen.py``);
* ``movingai N``: the MovingAI map ``warehouse-10-20-10-2-1`` (``movingai_gen.py``, docks on
  the far side), and in the same run its grid version solved by pymapf (the ``bench`` extra):
  prioritized planning and LaCAM, the three legs (start -> good -> dock -> start) as three MAPF
  instances, the whole team waiting at the end of each leg; the peer's overhead is the sum of
  the legs' makespans over the longest sum of one agent's shortest legs (cells).

``python benchmarks/bench_parallel.py [--workloads paper,aisles:10,aisles:20,movingai:20]
[--seed S] [--no-sim] [--out NAME]`` prints a row per workload and writes
``results/NAME.json`` (default ``parallel``); ``--chart FILE`` draws the overheads against N.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections import deque
from dataclasses import replace
from pathlib import Path

from _harness import child_row, save_results

HERE = Path(__file__).resolve().parent
EXAMPLES = HERE.parent / "examples"


def _alone(scenario, robot):
    """The scenario with only `robot` and its tasks (the objects unchanged)."""
    from cosmop.scene import Mission

    scene = replace(scenario.scene, robots={robot: scenario.scene.robots[robot]})
    return replace(scenario, scene=scene, mission=Mission(tasks={robot: scenario.mission.tasks[robot]}))


def _scenario(workload: str, n: int, seed: int):
    from cosmop.scenario import load_scenario, parse_scenario

    sys.path.insert(0, str(HERE))
    if workload == "paper":
        return load_scenario(EXAMPLES / "02_warehouse_10x10" / "scenario.yaml")
    if workload == "aisles":
        from aisle_gen import aisle_warehouse

        return parse_scenario(aisle_warehouse(n, seed))
    from movingai_gen import movingai_warehouse

    return parse_scenario(movingai_warehouse(n, seed, docks="far"))


def cosmop_row(workload: str, n: int, seed: int, sim: bool) -> dict:
    """Plan (and simulate) the team, and every robot alone: the overheads."""
    from cosmop.sim import simulate
    from cosmop.team.loop import plan_team

    scenario = _scenario(workload, n, seed)
    t = time.perf_counter()
    team = plan_team(scenario, max_horizon=20)
    plan_s = time.perf_counter() - t
    alone, alone_run = {}, {}
    for robot, tasks in scenario.mission.tasks.items():
        if tasks:
            single = plan_team(_alone(scenario, robot), max_horizon=20)
            alone[robot] = single.safety.makespan if single.safety else float("nan")
            if sim and single.plans.feasible:  # the controller's own pace, nobody in the way
                alone_run[robot] = simulate(_alone(scenario, robot), single.plans).sim_time_s
    longest = max(alone.values())
    safety = team.safety
    row = {
        "workload": workload,
        "n": len(scenario.scene.robots),
        "seed": seed,
        "feasible": team.plans.feasible,
        "reason": team.plans.reason,
        "plan_s": round(plan_s, 2),
        "messages": len(team.plans.messages),
        "replans": len(team.replans),
        "flipped": safety.flipped if safety is not None else None,
        "chosen": safety.chosen if safety is not None else None,
        "planned_s": round(safety.makespan, 1) if safety else None,
        "alone_s": round(longest, 1),
        "planned_overhead": round(safety.makespan / longest, 3) if safety else None,
    }
    if sim and team.plans.feasible:
        run = simulate(scenario, team.plans)
        row |= {
            "completed": run.completed,
            "simulated_s": round(run.sim_time_s, 1),
            "simulated_overhead": round(run.sim_time_s / longest, 3),
            "alone_simulated_s": round(max(alone_run.values()), 1),
            "over_simulated_alone": round(run.sim_time_s / max(alone_run.values()), 3),
            "contacts_while_moving": run.contacts_while_moving,
            "sim_replans": run.replans,
        }
    return row


def peer_row(n: int, seed: int, solver: str) -> dict:
    """The grid version of a MovingAI instance solved by pymapf: three legs, three instances."""
    import pymapf

    sys.path.insert(0, str(HERE))
    from movingai_gen import COLS, ROWS, blocked_cells, movingai_cells

    blocked = blocked_cells()
    grid = pymapf.GridMap([[1 if (r, c) in blocked else 0 for c in range(COLS)] for r in range(ROWS)])
    starts, goods, docks = movingai_cells(n, seed, docks="far")
    legs = [(starts, goods), (goods, docks), (docks, starts)]
    t = time.perf_counter()
    makespans = []
    for origin, goal in legs:
        agents = [pymapf.Agent(f"a{i}", origin[i], goal[i]) for i in range(n)]
        solution = pymapf.solve(pymapf.MAPFProblem(grid, agents), solver)
        if solution is None or not solution.paths:
            return {"workload": "movingai", "peer": solver, "n": n, "seed": seed, "solved": False}
        makespans.append(max(len(p) - 1 for p in solution.paths.values()))
    plan_s = time.perf_counter() - t
    longest = max(sum(_steps(blocked, a[i], b[i]) for a, b in legs) for i in range(n))
    return {
        "workload": "movingai",
        "peer": solver,
        "n": n,
        "seed": seed,
        "solved": True,
        "plan_s": round(plan_s, 2),
        "planned_steps": sum(makespans),
        "alone_steps": longest,
        "planned_overhead": round(sum(makespans) / longest, 3),
    }


def _steps(blocked, start, goal) -> int:
    """The shortest 4-connected path from `start` to `goal` on the grid (cells)."""
    seen, queue = {start: 0}, deque([start])
    while queue:
        cell = queue.popleft()
        if cell == goal:
            return seen[cell]
        r, c = cell
        for nxt in ((r + 1, c), (r - 1, c), (r, c + 1), (r, c - 1)):
            if nxt not in blocked and nxt not in seen:
                seen[nxt] = seen[cell] + 1
                queue.append(nxt)
    raise ValueError(f"no path from {start} to {goal}")


def chart(rows: list[dict], path: Path) -> None:
    """Overheads against the number of robots, per workload (matplotlib)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4))
    series: dict[str, list[tuple[int, float]]] = {}
    for row in rows:
        if row.get("planned_overhead") is None:
            continue
        name = row["workload"] + (f" ({row['peer']})" if "peer" in row else " (cosmop, planned)")
        series.setdefault(name, []).append((row["n"], row["planned_overhead"]))
        if row.get("simulated_overhead") is not None:
            series.setdefault(row["workload"] + " (cosmop, simulated)", []).append(
                (row["n"], row["simulated_overhead"])
            )
    for name, points in sorted(series.items()):
        xs, ys = zip(*sorted(points), strict=True)
        ax.plot(xs, ys, marker="o", label=name)
    ax.set_xlabel("robots")
    ax.set_ylabel("makespan / slowest robot alone")
    ax.axhline(1.0, color="grey", lw=0.5)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workloads", default="paper,aisles:10,aisles:20,movingai:20")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--no-sim", action="store_true", help="planned overheads only")
    parser.add_argument("--peers", default="prioritized,lacam", help="pymapf solvers for MovingAI")
    parser.add_argument("--out", default="parallel")
    parser.add_argument("--chart", help="draw the overheads against N to this PNG")
    parser.add_argument("--child", nargs=3, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        kind, n, solver = args.child
        if kind == "peer":
            row = peer_row(int(n), args.seed, solver)
        else:
            row = cosmop_row(kind, int(n), args.seed, not args.no_sim)
        print(json.dumps(row))
        return 0
    rows = []
    for item in args.workloads.split(","):
        kind, _, n = item.partition(":")
        sim = ["--no-sim"] if args.no_sim else []
        jobs = [(kind, n or "0", "-")]
        if kind == "movingai":
            jobs += [("peer", n, solver) for solver in args.peers.split(",") if solver]
        for job in jobs:
            row = child_row(__file__, "--child", *job, "--seed", str(args.seed), *sim)
            rows.append(row)
            print(json.dumps(row), flush=True)
    path = save_results(args.out, rows)
    if args.chart:
        chart(rows, Path(args.chart))
    print(f"written {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
