"""An order between robots kept by a message, not by dropping R2's tasks.

Run from anywhere: ``python examples/08_ordered/run.py``.  Decomposes the mission (not
separable: it orders R2's pick after R1's drop), shows the message that keeps the order and
that no task is lost (the paper's pruning would lose all of R2's), plans and simulates the
team, and checks that R2 picked O2 only after R1 had dropped O1.
"""

from pathlib import Path

import cosmop
from cosmop.missions.decomposition import decompose, resynthesize
from cosmop.missions.mission import GlobalMission
from cosmop.sim import footprint_overlaps
from cosmop.team.loop import plan_team

HERE = Path(__file__).resolve().parent

scenario = cosmop.load(HERE / "scenario.yaml")
mission = GlobalMission.from_scenario(scenario)
split = decompose(mission)
pruned = resynthesize(mission, split.local_missions)
lost = sum(len(events) for events in pruned.lost_events.values())
print(f"separable: {'yes' if split.separable else 'no'}; pruning would lose {lost} events")
print(f"  of R2: {', '.join(pruned.lost_events['R2'])}")
for name, ((a, i), (b, j)) in split.messaging.messages:
    print(f"message {name}: {b} waits before event {j + 1} until {a} has done event {i + 1}")
print(f"no task lost: {split.resynthesis is None and split.messaging is not None}")

result = plan_team(scenario)
print(f"planned: {result.plans.feasible}; messages: {[m.event for m in result.plans.messages]}")
run = cosmop.simulate(scenario, result.plans)
when = {event: t for t, _, event in run.events}
print(f"completed in {run.sim_time_s:.1f} s: {run.completed}")
print(f"R1 dropped O1 at {when['drop(R1,O1,W1)']:.1f} s, R2 picked O2 at {when['pick(R2,O2)']:.1f} s")
print(f"the order was kept: {when['pick(R2,O2)'] > when['drop(R1,O1,W1)']}")
print(f"the run is a complete word of the mission: {mission.is_complete_word(run.executed_word())}")
print(f"no two robots ever overlap: {not footprint_overlaps(scenario.scene, run)}")
print(f"no contact while moving: {run.contacts_while_moving == 0}")
