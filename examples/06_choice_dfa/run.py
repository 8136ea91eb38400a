"""A mission with choices: who moves O1, and to which dock O2 goes, chosen by the planner.

Run from anywhere: ``python examples/06_choice_dfa/run.py``.  Lists the ways the mission can be
completed, plans the team (each way costed by the robots' shortest plans; the cheapest kept),
simulates it, and checks that the run is a complete word of the mission.
"""

from pathlib import Path

import cosmop
from cosmop.missions.allocation import alternatives
from cosmop.missions.mission import GlobalMission
from cosmop.sim import footprint_overlaps
from cosmop.team.loop import plan_team

HERE = Path(__file__).resolve().parent

scenario = cosmop.load(HERE / "scenario.yaml")
mission = GlobalMission.from_scenario(scenario)
ways = alternatives(mission)
print(f"{len(ways.items)} ways to complete the mission (all found: {ways.exhaustive}):")
for way in ways.items:
    print(f"  {way.label()}")

result = plan_team(scenario)
choice = result.allocation
print(f"planned: {result.plans.feasible}; chosen: {choice.alternative.label()}")
print(f"  longest plan {choice.makespan} steps, {choice.total} in all")
print(f"  who moves what: {dict(result.plans.allocation)}")
print(f"messages: {[m.event for m in result.plans.messages]}")
run = cosmop.simulate(scenario, result.plans)
print(f"completed in {run.sim_time_s:.1f} s: {run.completed}")
print(f"the run is a complete word of the mission: {mission.is_complete_word(run.executed_word())}")
picked = sorted(e.split(",")[1].rstrip(")") for _, _, e in run.events if e.startswith("pick("))
print(f"each object was moved by exactly one robot: {picked == sorted(scenario.scene.objects)}")
print(f"no two robots ever overlap: {not footprint_overlaps(scenario.scene, run)}")
print(f"no contact while moving: {run.contacts_while_moving == 0}")
