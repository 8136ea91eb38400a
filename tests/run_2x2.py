"""A real simulation of the 2x2 example with the hand-made plans (0.4 s), shared by the export,
viewer and animation tests: R2 answers R1's request about O2 with one message."""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

from cosmop.planning.plan_types import Coordination, PlanSet
from cosmop.planning.primitive_effects import plan_from_actions
from cosmop.scenario import load_scenario
from cosmop.scene import Scenario
from handmade_plans import R1_ACTIONS, R1_MISSION, R2_RES_ACTIONS, R2_RES_MISSION

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "01_warehouse_2x2" / "scenario.yaml"


@lru_cache(maxsize=1)
def run_2x2() -> tuple[Scenario, PlanSet, object]:
    """``(scenario, plans, SimResult)``; the result is computed once per test session."""
    from cosmop.sim import simulate

    scenario = load_scenario(EXAMPLE)
    plans = PlanSet(
        "warehouse-2x2",
        True,
        {
            "R1": plan_from_actions(scenario.scene, "R1", R1_MISSION, R1_ACTIONS),
            "R2": plan_from_actions(scenario.scene, "R2", R2_RES_MISSION, R2_RES_ACTIONS),
        },
        (Coordination("O2", "R1", "R2"),),
    )
    result = simulate(scenario, plans)
    assert result.completed and len(result.messages) == 1
    return scenario, plans, result
