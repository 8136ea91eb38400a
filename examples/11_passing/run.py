"""Two robots pass each other in an aisle 1 m wide.

Run from anywhere: ``python examples/11_passing/run.py``.  Planned alone, R1 (west to east)
and R2 (east to west) both drive down the middle of the aisle; ordered as they are, one would
wait outside until the other had crossed.  The aisle has room for both robots side by side with
the clearance between them, so ``plan_team`` re-plans them into two lanes and the team is done
as soon as its slower robot would be alone.  The run then shows both robots inside the aisle at
once, moving, with no overlap and no contact while moving.
"""

from pathlib import Path

import numpy as np

import cosmop
from cosmop.missions.mission import GlobalMission
from cosmop.sim import footprint_overlaps
from cosmop.team.loop import plan_team

HERE = Path(__file__).resolve().parent
AISLE_X = (-3000.0, 3000.0)  # the aisle's ends, mm (scenario.yaml)

scenario = cosmop.load(HERE / "scenario.yaml")
result = plan_team(scenario)
plans, safety = result.plans, result.safety
print(f"planned: {plans.feasible}; the exact checker accepts the plans: {result.report.ok}")
for line in result.replans:
    print(f"  {line}")
print(
    f"expected makespan {safety.makespan:.1f} s; "
    f"its robots' own plans at most {safety.makespan_alone:.1f} s: "
    f"overhead {safety.makespan / safety.makespan_alone:.2f}"
)
alone = safety.makespan <= safety.makespan_alone + 1e-6
print(f"the team takes no longer than its slowest robot's own plan: {alone}")

run = cosmop.simulate(scenario, plans)
x = run.frames["pose"][:, :, 0]
v = run.frames["v"]
inside = np.all((x > AISLE_X[0]) & (x < AISLE_X[1]), axis=1) & np.all(v > 1.0, axis=1)
print(f"completed in {run.sim_time_s:.1f} s: {run.completed}; replans: {run.replans}")
print(f"both robots in the aisle at once, moving, for {inside.sum() * run.dt:.1f} s: {bool(inside.any())}")
mission = GlobalMission.from_scenario(scenario)
print(f"the run is a complete word of the mission: {mission.is_complete_word(run.executed_word())}")
print(f"no two robots ever overlap: {not footprint_overlaps(scenario.scene, run)}")
print(f"no contact while moving: {run.contacts_while_moving == 0}")
