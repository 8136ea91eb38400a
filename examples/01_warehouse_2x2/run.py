"""The paper's Example 1, top-down: decompose the global mission and prove the local missions.

Run from anywhere: ``python examples/01_warehouse_2x2/run.py``.  It loads both forms of the
mission (tasks and the explicit 16-state DFA of Fig. "Global specification"), projects them
onto each robot, decides separability and verifies the local missions by assume-guarantee
reasoning with an L*-learned assumption (Fig. A1).
"""

from pathlib import Path

import cosmop
from cosmop.automata import equivalent
from cosmop.missions.decomposition import decompose
from cosmop.missions.mission import GlobalMission
from cosmop.missions.verification import verify

HERE = Path(__file__).resolve().parent

tasks = GlobalMission.from_scenario(cosmop.load(HERE / "scenario.yaml"))
explicit = GlobalMission.from_scenario(cosmop.load(HERE / "scenario_dfa.yaml"))
k = explicit.automaton.components[0]
same = equivalent(k, tasks.automaton.build())
print(f"global mission: {k.n_states} states; same language as the tasks form: {same}")

result = decompose(explicit)
for robot, local in result.local_missions.items():
    print(f"K_{robot} = P_{robot}(K): " + " -> ".join(e for _, e, _ in local.transitions()))
print(f"separable: {result.separable}")

proof = verify(explicit, result.local_missions, method="assume-guarantee")
(report,) = proof.assumptions
print(
    f"assumption learned for {report.guarantor} ({report.assumption.n_states} states, "
    f"{report.membership_queries} membership / {report.equivalence_queries} equivalence queries):"
)
for source, event, target in report.assumption.transitions():
    print(f"  {source} --{event}--> {target}")
print(f"<A> K_R1 <K> and <true> K_R2 <A> hold, so K_R1 || K_R2 satisfies K: {proof.holds}")
