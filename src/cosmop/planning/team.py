"""Each robot's local mission as a sequence of events, ready for the planner.

The planner needs one sequence of events per robot: the task list of the tasks form or, for an
explicit global DFA, its projection onto the robot when that is a single sequence.  The whole
team is planned, coordinated and checked by :func:`cosmop.pipeline.plan_team`.
"""

from __future__ import annotations

from cosmop.errors import ScenarioError
from cosmop.missions.decomposition import decompose
from cosmop.missions.events import Event
from cosmop.missions.mission import GlobalMission, sequence_of
from cosmop.scenario import Scenario


def local_sequences(scenario: Scenario) -> dict[str, tuple[Event, ...]]:
    """Each robot's local mission as a sequence of events (robots without tasks: empty)."""
    mission = scenario.mission
    if mission.tasks is not None:
        return {r: tuple(mission.tasks.get(r, ())) for r in scenario.scene.robots}
    gm = GlobalMission.from_scenario(scenario)
    local = decompose(gm).local_missions
    out = {}
    for robot, dfa in local.items():
        seq = sequence_of(dfa)
        if seq is None:
            raise ScenarioError(
                f"planning needs each local mission to be one sequence of events; {robot}'s has branches",
                file=str(scenario.source) if scenario.source else None,
                field="mission.dfa",
            )
        out[robot] = tuple(gm.events[e] for e in seq)
    return out
