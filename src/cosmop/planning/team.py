"""Plan every robot of a scenario on its own and check the plans (issue 3; coordination is next).

Each robot's local mission must be one sequence of events: the task list of the tasks form,
or, for an explicit global DFA, its projection when that is a single sequence.  Every plan
the tool returns is run through the exact checker (:mod:`cosmop.planning.checker`); a plan that
fails it is a bug in the encoding and raises instead of being returned.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType

from cosmop.automata import DFA
from cosmop.errors import ScenarioError
from cosmop.missions.decomposition import decompose
from cosmop.missions.events import Event
from cosmop.missions.mission import GlobalMission
from cosmop.planning.checker import CheckReport, check_plan
from cosmop.planning.plan import PlanSet
from cosmop.planning.synthesis import DEFAULT_RLIMIT, Synthesis, synthesize
from cosmop.scenario import Scenario


def sequence_of(dfa: DFA) -> tuple[str, ...] | None:
    """The events of a linear DFA (one path, no branching), or ``None``."""
    q, seq, seen = dfa.initial, [], {dfa.initial}
    while True:
        out = [j for j in range(dfa.n_events) if dfa.delta[q, j] >= 0]
        if not out:
            return tuple(seq)
        if len(out) > 1:
            return None
        seq.append(dfa.alphabet[out[0]])
        q = int(dfa.delta[q, out[0]])
        if q in seen:
            return None
        seen.add(q)


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


@dataclass(frozen=True)
class TeamPlan:
    """Plans of every robot, planned independently, with the checker's report.

    Attributes
    ----------
    plans : PlanSet
        The plan file's content (``coordination`` is empty: robots are planned on their own).
    results : Mapping[str, Synthesis]
        Per robot: horizon, requests, solve time, reason if infeasible.
    report : CheckReport
        The exact checker's verdict on ``plans`` (always ok for the plans returned).
    time_s : float
    """

    plans: PlanSet
    results: Mapping[str, Synthesis]
    report: CheckReport
    time_s: float


def plan_robots(
    scenario: Scenario,
    *,
    max_horizon: int = 16,
    rlimit: int = DEFAULT_RLIMIT,
    on_robot: Callable[[str, Synthesis], None] | None = None,
) -> TeamPlan:
    """Shortest plan for each robot's local mission, each robot on its own.

    Parameters
    ----------
    scenario : Scenario
    max_horizon, rlimit
        Passed to :func:`cosmop.planning.synthesis.synthesize`.
    on_robot : callable, optional
        Called after each robot with its result (progress display).

    Raises
    ------
    AssertionError
        If a synthesised plan fails the exact checker (an encoding bug, never a user error).
    """
    t0 = time.perf_counter()
    results: dict[str, Synthesis] = {}
    for robot, events in local_sequences(scenario).items():
        results[robot] = synthesize(scenario.scene, robot, events, max_horizon=max_horizon, rlimit=rlimit)
        if on_robot is not None:
            on_robot(robot, results[robot])
    feasible = all(r.feasible for r in results.values())
    reason = None if feasible else "; ".join(r.reason for r in results.values() if not r.feasible)
    plans = PlanSet(
        scenario=scenario.name,
        feasible=feasible,
        robots={r: res.plan for r, res in results.items() if res.plan is not None},
        coordination=(),
        reason=reason,
    )
    report = check_plan(scenario, plans)
    if not report.ok:
        raise AssertionError(f"a synthesised plan failed the exact checker: {report.violations[0].message}")
    return TeamPlan(plans, MappingProxyType(results), report, time.perf_counter() - t0)
