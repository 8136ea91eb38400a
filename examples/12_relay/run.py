"""A relay: one robot carries goods to a hand-over area, another carries them on.

Run from anywhere: ``python examples/12_relay/run.py``.  Plans the team (R2 is planned with O1
where R1's plan puts it down, and waits for R1's message before it picks it up), checks that
R2's pick is where R1's drop is, simulates the run and prints whether it did exactly what the
mission asks, with no replan and no contact.
"""

from pathlib import Path

import cosmop
from cosmop.missions.mission import GlobalMission
from cosmop.sim import footprint_overlaps
from cosmop.team.loop import plan_team

HERE = Path(__file__).resolve().parent

scenario = cosmop.load(HERE / "scenario.yaml")
result = plan_team(scenario)
plans = result.plans
r1, r2 = plans.robots["R1"], plans.robots["R2"]
dropped = next(s for s in r1.steps if s.primitive == "DropOff").objects["O1"].position
picked = next(s for s in r2.steps if s.primitive == "PickUp").objects["O1"].position
print(f"planned: {plans.feasible}; R1 drops O1 at {dropped}, R2 picks it at {picked}")
print(f"R2 picks O1 where R1 puts it down: {dropped == picked}")
print(f"the exact checker accepts the plans: {result.report.ok}")
run = cosmop.simulate(scenario, plans)
when = {event: t for t, _, event in run.events}
print(f"completed in {run.sim_time_s:.1f} s: {run.completed}; replans: {run.replans}")
print(f"R1 dropped O1 at {when['drop(R1,O1,H)']:.1f} s, R2 picked it at {when['pick(R2,O1)']:.1f} s")
print(f"no replan was needed: {run.replans == 0}")
mission = GlobalMission.from_scenario(scenario)
print(f"the run is a complete word of the mission: {mission.is_complete_word(run.executed_word())}")
print(f"no two robots ever overlap: {not footprint_overlaps(scenario.scene, run)}")
print(f"no contact while moving: {run.contacts_while_moving == 0}")
