"""A person blocks the only doorway to W1: R1 waits (and tries to replan), then completes.

Run from anywhere: ``python examples/04_doorway_2x2/run.py``.  Prints when R1 got into the left
room compared with when the person left the doorway, and the simulator's verdict.
"""

from pathlib import Path

import numpy as np

import cosmop
from cosmop.viz.explain import Explainer

HERE = Path(__file__).resolve().parent

scenario = cosmop.load(HERE / "scenario.yaml")
plans = cosmop.plan(scenario)
result = cosmop.simulate(scenario, plans)
frames, r1 = result.frames, result.robot_ids.index("R1")
entered = float(frames["t"][np.argmax(frames["pose"][:, r1, 1] > 0)])  # above y = 0: the left room
leaves = scenario.scene.humans["H1"].path[0][2]
print(f"the person leaves the doorway at {leaves:.0f} s; R1 enters the room at {entered:.1f} s")
print(f"R1 waited for the doorway: {entered >= leaves}; replan attempts: {result.replan_attempts}")
# the trace records whom a standing robot gives way to; the pictures say it in words
said = {
    Explainer(scenario.scene, plans).yields(who) for who in result.trace().yields_to[:, r1].tolist() if who
}
print(f"the run says why R1 stood ({', '.join(sorted(said))}): {'waits for H1 (a person) to pass' in said}")
print(
    f"every robot finished: {result.completed}; no contact while moving: {result.contacts_while_moving == 0}"
)
print(f"every object in its workspace: {all(result.objects_in_workspaces(scenario, plans).values())}")
