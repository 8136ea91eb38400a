"""The paper's 10-robot warehouse, top-down: ten local missions without the 4^10-state product.

Run from anywhere: ``python examples/02_warehouse_10x10/run.py``.  The global mission is the
parallel composition of ten task sequences (1,048,576 states as one DFA); decomposition and
verification work on its factors and never build it.
"""

from pathlib import Path

import cosmop
from cosmop.missions.decomposition import decompose
from cosmop.missions.mission import GlobalMission
from cosmop.missions.verification import verify

mission = GlobalMission.from_scenario(cosmop.load(Path(__file__).resolve().parent / "scenario.yaml"))
result = decompose(mission)
proof = verify(mission, result.local_missions)
for robot, local in result.local_missions.items():
    print(f"K_{robot}: " + " -> ".join(e for _, e, _ in local.transitions()))
print(f"separable: {result.separable}; verified ({proof.method}): {proof.holds}")
print(
    f"largest automaton built: {max(result.stats.largest_automaton, proof.largest_automaton)} states "
    f"(the product would have {4 ** len(mission.robots):,})"
)
