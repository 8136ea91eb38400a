"""Deliveries without named robots: the planner chooses who moves each good, and to which dock.

Run from anywhere: ``python examples/05_deliveries/run.py``.  Plans the team (each delivery
costed alone, the busiest robot's load minimised), shows who moves what and why R2-R4 never
touch O1 (the cold store is walled off), simulates the plans and checks the run.
"""

from pathlib import Path

import cosmop
from cosmop.missions.mission import GlobalMission
from cosmop.planning.synthesis import synthesize
from cosmop.sim import footprint_overlaps
from cosmop.team.loop import plan_team

HERE = Path(__file__).resolve().parent

scenario = cosmop.load(HERE / "scenario.yaml")
mission = GlobalMission.from_scenario(scenario)
walled = synthesize(scenario.scene, "R2", [mission.events["pick(R2,O1)"]])
print(f"R2 alone cannot fetch O1: {not walled.feasible} ({walled.reason})")

result = plan_team(scenario)
choice = result.allocation
print(f"planned: {result.plans.feasible}; proved the best allocation: {choice.exhaustive}")
for obj, robot in result.plans.allocation.items():
    print(f"  {obj} by {robot}")
print(f"  busiest robot's load {choice.makespan} steps, {choice.total} in all ({choice.method})")
heavy = result.plans.allocation["O5"] in ("R3", "R4")
print(f"O5 moved by R3 or R4, as the mission allows: {heavy}")
run = cosmop.simulate(scenario, result.plans)
print(f"completed in {run.sim_time_s:.1f} s: {run.completed}")
print(f"the run is a complete word of the mission: {mission.is_complete_word(run.executed_word())}")
picked = sorted(e.split(",")[1].rstrip(")") for _, _, e in run.events if e.startswith("pick("))
print(f"each good was moved by exactly one robot: {picked == sorted(scenario.scene.objects)}")
print(f"no two robots ever overlap: {not footprint_overlaps(scenario.scene, run)}")
print(f"no contact while moving: {run.contacts_while_moving == 0}")
