"""Plan the team, then execute the plans in the simulator with the people of this scenario.

Run from anywhere: ``python examples/03_people_2x2/run.py [seed]``.  Prints whether every robot finished,
whether every object lies in its workspace, and that no robot ever moved while touching
anything (people may walk into a standing robot; passive safety rules out the rest).
"""

import sys
from pathlib import Path

import cosmop

HERE = Path(__file__).resolve().parent
seed = int(sys.argv[1]) if len(sys.argv) > 1 else 0

scenario = cosmop.load(HERE / "scenario.yaml")
plans = cosmop.plan(scenario)
result = cosmop.simulate(scenario, plans, seed=seed)
delivered = result.objects_in_workspaces(scenario, plans)
print(f"{scenario.name}, seed {seed}: {result.sim_time_s:.1f} s simulated in {result.wall_time_s:.1f} s")
print(f"every robot finished: {result.completed}")
print(f"every object in its workspace: {all(delivered.values())}")
print(
    f"no contact while moving: {result.contacts_while_moving == 0} ({len(result.contacts)} contacts at rest)"
)
print(f"messages: {', '.join(m.event for m in result.messages)}; replan attempts: {result.replan_attempts}")
