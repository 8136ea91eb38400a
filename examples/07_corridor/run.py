"""Two robots pass each other through a one-lane corridor without a stand-off.

Run from anywhere: ``python examples/07_corridor/run.py``.  Plans the team (the places the two
plans share are ordered by messages), simulates it, and prints whether every robot finished,
whether the robots were ever in the corridor together, whether a robot ever backed out of it,
and whether the run did exactly what the mission asks.
"""

from pathlib import Path

import numpy as np

import cosmop
from cosmop.missions.mission import GlobalMission
from cosmop.sim import footprint_overlaps
from cosmop.team.loop import plan_team

HERE = Path(__file__).resolve().parent

scenario = cosmop.load(HERE / "scenario.yaml")
result = plan_team(scenario)
plans = result.plans
print(f"plan: {len(plans.messages)} messages keep the robots apart, e.g.")
print(f"  {plans.messages[0].event}: {plans.messages[0].protects}")
run = cosmop.simulate(scenario, plans)
x, y = run.frames["pose"][:, :, 0], run.frames["pose"][:, :, 1]
inside = (np.abs(x) < 1500) & (np.abs(y) < 250)  # a robot's centre in the corridor
backed_out = False
for i in range(inside.shape[1]):  # every time a robot enters the corridor, it leaves on the far side
    edges = np.flatnonzero(np.diff(inside[:, i].astype(int)))
    for enter, leave in zip(edges[::2], edges[1::2], strict=False):
        backed_out |= np.sign(x[enter, i]) == np.sign(x[leave + 1, i])
print(f"completed in {run.sim_time_s:.1f} s: {run.completed}")
print(f"no contact while moving: {run.contacts_while_moving == 0}")
print(f"never two robots in the corridor: {not (inside.sum(axis=1) > 1).any()}")
print(f"no robot backed out of the corridor: {not backed_out}; replans: {run.replans}")
print(f"no two robots ever overlap: {not footprint_overlaps(scenario.scene, run)}")
mission = GlobalMission.from_scenario(scenario)
print(f"the run is a complete word of the mission: {mission.is_complete_word(run.executed_word())}")
