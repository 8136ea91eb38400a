"""Messages keep the mission's order, even around events that need no step; large orders end cleanly."""

from __future__ import annotations

import pytest

from cosmop.errors import MissionTooLargeError
from cosmop.missions.mission import GlobalMission
from cosmop.missions.ordering import order_words
from cosmop.scenario import parse_scenario
from cosmop.team.loop import plan_team


def _returns(*robots: str) -> dict:
    """Two robots in an empty room; the mission: the returns in the given order (a chain DFA)."""
    walls = [[[-2000, -2000], [2000, -2000]], [[2000, -2000], [2000, 2000]]]
    walls += [[[2000, 2000], [-2000, 2000]], [[-2000, 2000], [-2000, -2000]]]
    chain = [[f"q{i}", f"return({r})", f"q{i + 1}"] for i, r in enumerate(robots)]
    return {
        "name": "returns",
        "scene": {
            "obstacles": walls,
            "robots": {
                "R1": {"size": 400, "pose": [-1000, 0, 0]},
                "R2": {"size": 400, "pose": [1000, 0, 180]},
            },
        },
        "mission": {"dfa": {"initial": "q0", "transitions": chain}},
    }


@pytest.mark.parametrize("order", [("R1", "R2", "R1"), ("R1", "R2", "R1", "R2")])
def test_returns_in_turn_are_planned_in_the_missions_order(order):
    # a robot at home has returned without a step: the wait before its next return must still
    # come before that return, and a message it sends after it after the wait
    scenario = parse_scenario(_returns(*order))
    result = plan_team(scenario, workers=1)
    assert result.plans.feasible, result.plans.reason
    assert result.report.ok and result.verification.holds


def test_an_order_that_does_not_settle_is_a_mission_too_large():
    scenario = parse_scenario(_returns("R1", "R2", "R1", "R2", "R1"))
    mission = GlobalMission.from_scenario(scenario)
    words = {"R1": ["return(R1)"] * 3, "R2": ["return(R2)"] * 2}
    with pytest.raises(MissionTooLargeError, match="did not settle within 1 counterexamples") as err:
        order_words(mission.complete, words, max_rounds=1)
    assert err.value.field == "mission"
    assert order_words(mission.complete, words).feasible  # the default bound grows with the words
