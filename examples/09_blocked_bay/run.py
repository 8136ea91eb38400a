"""A crate no task names blocks the bay where R1's goods lie: the planner has it set aside.

Run from anywhere: ``python examples/09_blocked_bay/run.py``.  Plans the team (R1 asks for C9
to be moved away; no mission moves C9, so the planner adds a task that sets it down at a free
place), simulates the plans, and prints the added task, the side O1 is picked from, and the
simulator's verdict.
"""

from pathlib import Path

import cosmop
from cosmop.missions.mission import GlobalMission

HERE = Path(__file__).resolve().parent

scenario = cosmop.load(HERE / "scenario.yaml")
plans = cosmop.plan(scenario)
(task,) = plans.added
print(f"added: {task.robot} sets {task.object} down at {task.point}: {task.why}")
pick = next(s for s in plans.robots["R1"].steps if s.primitive == "PickUp" and s.object == "O1")
print(f"R1 picks O1 from the north, facing south: {pick.robot[2] % 360 == 270}")
run = cosmop.simulate(scenario, plans)
print(f"completed in {run.sim_time_s:.1f} s: {run.completed}")
print(f"no contact while moving: {run.contacts_while_moving == 0}")
placed = run.objects_in_workspaces(scenario, plans)
print(f"every good in its dock and {task.object} at its new place: {all(placed.values())}")
(x, y), _ = run.objects[task.object]
print(f"{task.object} lies where the plan set it down: {abs(x - task.point[0]) + abs(y - task.point[1]) < 1}")
mission = GlobalMission.from_scenario(scenario)
print(f"the run is a complete word of the mission: {mission.is_complete_word(run.executed_word())}")
