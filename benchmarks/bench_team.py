"""Team safety: the conflicts between robots' plans, the messages that order them, what they cost.

Three workloads, each in a fresh subprocess:

* ``corridor``: example 07 (two robots, a one-lane corridor, opposite directions): the
  simulated time of the team against the sum of each robot's time alone (the other robot
  removed from the scene);
* ``order``: example 08 (an order between robots): messages added, and the tasks the paper's
  pruning would lose against those the messages lose (none);
* ``aisles N``: generated warehouses with one-lane aisles (``aisle_gen.py``): conflicts found,
  messages added, the time of the conflict step against synthesis, re-plans, and the simulated
  run (complete? contacts while moving?).

``python benchmarks/bench_team.py [--sizes 10,20,50] [--seed S | --seeds 1:10] [--aisles-only]
[--max-time S] [--out NAME]`` writes ``results/team.json`` (or ``results/NAME.json``); with
``--seeds``, every size is run on every seed of the range (end excluded).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

from _harness import child_row, save_results

HERE = Path(__file__).resolve().parent
EXAMPLES = HERE.parent / "examples"


def _alone(scenario, robot):
    """The scenario with only `robot` (its tasks and objects unchanged)."""
    from dataclasses import replace

    from cosmop.scene import Mission

    scene = replace(scenario.scene, robots={robot: scenario.scene.robots[robot]})
    mission = Mission(tasks={robot: scenario.mission.tasks[robot]})
    return replace(scenario, scene=scene, mission=mission)


def corridor() -> dict:
    from cosmop.scenario import load_scenario
    from cosmop.sim import simulate
    from cosmop.team.loop import plan_team

    scenario = load_scenario(EXAMPLES / "07_corridor" / "scenario.yaml")
    team = plan_team(scenario)
    run = simulate(scenario, team.plans)
    alone = {}
    for robot in scenario.scene.robots:
        single = _alone(scenario, robot)
        alone[robot] = simulate(single, plan_team(single).plans).sim_time_s
    return {
        "workload": "corridor",
        "completed": run.completed,
        "team_s": run.sim_time_s,
        "alone_s": alone,
        "sum_alone_s": sum(alone.values()),
        "ratio": run.sim_time_s / sum(alone.values()),
        "messages": len(team.plans.messages),
        "contacts_while_moving": run.contacts_while_moving,
        "replans": run.replans,
    }


def order() -> dict:
    from cosmop.missions.decomposition import decompose, resynthesize
    from cosmop.missions.mission import GlobalMission
    from cosmop.scenario import load_scenario
    from cosmop.sim import simulate
    from cosmop.team.loop import plan_team

    scenario = load_scenario(EXAMPLES / "08_ordered" / "scenario.yaml")
    mission = GlobalMission.from_scenario(scenario)
    split = decompose(mission)
    pruned = resynthesize(mission, split.local_missions)
    team = plan_team(scenario)
    run = simulate(scenario, team.plans)
    return {
        "workload": "order",
        "order_messages": [m.event for m in team.plans.messages if m.kind == "order"],
        "messages": len(team.plans.messages),
        "lost_by_pruning": {r: list(e) for r, e in pruned.lost_events.items() if e},
        "lost_with_messages": 0 if split.messaging is not None else None,
        "completed": run.completed,
        "team_s": run.sim_time_s,
    }


def aisles(n: int, seed: int, max_time: float | None) -> dict:
    sys.path.insert(0, str(HERE))
    from aisle_gen import aisle_warehouse
    from cosmop.scenario import parse_scenario
    from cosmop.sim import SimSettings, simulate
    from cosmop.team.loop import plan_team

    scenario = parse_scenario(aisle_warehouse(n, seed))
    t = time.perf_counter()
    team = plan_team(scenario, max_horizon=20)
    planning = time.perf_counter() - t
    row = {
        "workload": f"aisles {n}",
        "n": n,
        "seed": seed,
        "feasible": team.plans.feasible,
        "reason": team.plans.reason,
        "plan_s": planning,
        **{f"{k}_s": v for k, v in team.phases.items()},
        "conflicts": team.safety.conflicts if team.safety else None,
        "messages": len(team.plans.messages),
        "replans": len(team.replans),
        "expected_makespan_s": team.safety.makespan if team.safety else None,
        "expected_alone_s": team.safety.makespan_alone if team.safety else None,
    }
    row["conflict_share"] = row["conflicts_s"] / max(row["synthesize_s"], 1e-9)
    if team.plans.feasible:
        run = simulate(scenario, team.plans, settings=SimSettings(max_time=max_time))
        row |= {
            "completed": run.completed,
            "sim_s": run.sim_time_s,
            "sim_wall_s": run.wall_time_s,
            "contacts": len(run.contacts),
            "contacts_while_moving": run.contacts_while_moving,
            "sim_replans": run.replans,
        }
    return row


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="10,20,50")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--seeds", help="a range of seeds, START:END (END excluded), instead of --seed")
    parser.add_argument("--aisles-only", action="store_true", help="without the corridor and order examples")
    parser.add_argument(
        "--max-time", type=float, default=None, help="simulated s (default: the simulator's, from the plan)"
    )
    parser.add_argument("--out", default="team", help="results/OUT.json (default: team)")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        if args.child == "corridor":
            row = corridor()
        elif args.child == "order":
            row = order()
        else:
            row = aisles(int(args.child), args.seed, args.max_time)
        print(json.dumps(row))
        return 0
    rows = []
    seeds = range(*map(int, args.seeds.split(":"))) if args.seeds else [args.seed]
    examples = [] if args.aisles_only else [("corridor", seeds[0]), ("order", seeds[0])]
    limit = [] if args.max_time is None else ["--max-time", str(args.max_time)]
    for job, seed in [*examples, *((size, seed) for seed in seeds for size in args.sizes.split(","))]:
        row = child_row(__file__, "--child", job, "--seed", str(seed), *limit)
        rows.append(row)
        print(json.dumps(row), flush=True)
    save_results(args.out, rows)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
