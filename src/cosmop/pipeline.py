"""The top-down ↔ bottom-up loop (the paper's Fig. "Overall framework").

1. *Decompose* the global mission into local missions (sequences of events).
2. *Synthesize* every robot's shortest plan.
3. *Coordinate*: each Req(O) of robot A becomes the pair ``away(O, A, B)`` with B the robot whose
   mission picks O, placed deadlock-free (:mod:`cosmop.missions.coordination`).
4. *Re-synthesize* the robots whose missions changed (responders gain their Res).
5. Repeat from 3 until no plan asks for anything new (capped; the cap is reported).
6. *Verify*: the coordinated local missions satisfy the global mission (assume-guarantee over
   the factors) and can always complete (no deadlock), and every plan passes the exact checker.

A request that no robot's mission can answer (no mission picks the object) is refused with a
reason naming the object and who needed it; re-allocating the task of moving it is not done.
"""

from __future__ import annotations

import multiprocessing
import os
import time
from collections.abc import Callable, Mapping
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from types import MappingProxyType

from cosmop.missions.coordination import Coordinated, coordinate, requests_by_phase
from cosmop.missions.events import Event
from cosmop.missions.mission import GlobalMission, sequence_automaton
from cosmop.missions.verification import Verification, verify
from cosmop.planning.checker import CheckReport, check_plan
from cosmop.planning.plan import Coordination, PlanSet
from cosmop.planning.synthesis import DEFAULT_RLIMIT, Synthesis, synthesize
from cosmop.planning.team import local_sequences
from cosmop.scenario import Scenario


@dataclass(frozen=True)
class TeamResult:
    """Result of :func:`plan_team`.

    Attributes
    ----------
    plans : PlanSet
        Every robot's plan and the coordination pairs (the plan file's content).
    results : Mapping[str, Synthesis]
        The last synthesis of each robot.
    coordination : Coordinated or None
    verification : Verification or None
        Whether the coordinated local missions satisfy the global mission.
    report : CheckReport
        The exact checker's verdict on ``plans`` (always ok for a feasible result).
    iterations : int
        Coordinate/re-synthesize rounds.
    converged : bool
        False when the iteration cap stopped the loop.
    phases : Mapping[str, float]
        Seconds spent in decompose, synthesize, coordinate, verify, check.
    """

    plans: PlanSet
    results: Mapping[str, Synthesis]
    coordination: Coordinated | None
    verification: Verification | None
    report: CheckReport
    iterations: int
    converged: bool
    phases: Mapping[str, float]


def _base_index(sequence: tuple[Event, ...], index: int) -> int:
    """Index in the uncoordinated sequence of the event at ``index`` of a coordinated one."""
    return sum(1 for e in sequence[:index] if e.kind != "away")


def plan_team(
    scenario: Scenario,
    *,
    max_horizon: int = 16,
    rlimit: int = DEFAULT_RLIMIT,
    max_iterations: int = 5,
    workers: int | None = None,
    on_robot: Callable[[str, Synthesis], None] | None = None,
) -> TeamResult:
    """Plan, coordinate and verify the whole team (see the module docstring).

    Parameters
    ----------
    scenario : Scenario
    max_horizon, rlimit
        Passed to :func:`cosmop.planning.synthesis.synthesize`.
    max_iterations : int
        Cap on coordinate/re-synthesize rounds.
    workers : int, optional
        Worker processes for the robots' syntheses (default: one per core, at most one per
        robot; 1 plans in this process).  The result does not depend on it.
    on_robot : callable, optional
        Called after every synthesis (progress display).

    Raises
    ------
    AssertionError
        If a plan fails the exact checker (an encoding bug, never a user error).
    """
    phases = dict.fromkeys(("decompose", "synthesize", "coordinate", "verify", "check"), 0.0)
    t = time.perf_counter()
    base = local_sequences(scenario)
    phases["decompose"] = time.perf_counter() - t

    n_workers = min(os.cpu_count() or 1, len(base)) if workers is None else max(1, workers)
    pool = _pool(n_workers) if n_workers > 1 else None

    def plan_all(jobs: dict[str, tuple[Event, ...]]) -> dict[str, Synthesis]:
        t0 = time.perf_counter()
        out: dict[str, Synthesis] = {}
        if pool is None or len(jobs) < 2:
            for robot, events in jobs.items():
                out[robot] = _synthesize((scenario.scene, robot, events, max_horizon, rlimit))
                if on_robot is not None:
                    on_robot(robot, out[robot])
        else:
            futures = {
                pool.submit(_synthesize, (scenario.scene, robot, events, max_horizon, rlimit)): robot
                for robot, events in jobs.items()
            }
            for future in as_completed(futures):
                out[futures[future]] = future.result()
                if on_robot is not None:
                    on_robot(futures[future], out[futures[future]])
        phases["synthesize"] += time.perf_counter() - t0
        return {robot: out[robot] for robot in jobs}  # team order, whatever finished first

    try:
        return _loop(scenario, base, plan_all, phases, max_iterations)
    finally:
        if pool is not None:
            pool.shutdown()


def _synthesize(job: tuple) -> Synthesis:
    """One robot's synthesis (module level, so worker processes can run it)."""
    scene, robot, events, max_horizon, rlimit = job
    return synthesize(scene, robot, events, max_horizon=max_horizon, rlimit=rlimit)


def _pool(workers: int) -> ProcessPoolExecutor:
    """Worker processes (forked where the platform allows: no re-import of the package)."""
    methods = multiprocessing.get_all_start_methods()
    context = multiprocessing.get_context("fork" if "fork" in methods else "spawn")
    return ProcessPoolExecutor(max_workers=workers, mp_context=context)


def _loop(
    scenario: Scenario,
    base: dict[str, tuple[Event, ...]],
    plan_all: Callable[[dict[str, tuple[Event, ...]]], dict[str, Synthesis]],
    phases: dict[str, float],
    max_iterations: int,
) -> TeamResult:
    """Coordinate, re-plan, verify and check (steps 3-6 of the module docstring)."""
    current = dict(base)
    results = plan_all(dict(base))
    requests: dict[str, list[tuple[str, int]]] = {r: [] for r in base}
    coordinated: Coordinated | None = None
    reasons: list[str] = []
    iterations, converged = 0, False
    while not reasons:
        infeasible = [r.reason for r in results.values() if not r.feasible]
        if infeasible:
            reasons += infeasible
            break
        t0 = time.perf_counter()
        fresh = False
        for robot, res in results.items():
            known = {obj for obj, _ in requests[robot]}
            steps = [(s.primitive, s.object) for s in res.plan.steps]
            for obj, index in requests_by_phase(steps, current[robot]):
                if obj not in known:
                    requests[robot].append((obj, _base_index(current[robot], index)))
                    known.add(obj)
                    fresh = True
        if not fresh:
            phases["coordinate"] += time.perf_counter() - t0
            converged = True
            break
        if iterations >= max_iterations:
            phases["coordinate"] += time.perf_counter() - t0
            reasons.append(f"coordination did not settle within {max_iterations} rounds")
            break
        iterations += 1
        coordinated = coordinate(base, requests)
        phases["coordinate"] += time.perf_counter() - t0
        for obj, requester in coordinated.unanswered:
            reasons.append(f"{requester} needs {obj} moved away, but no robot's mission picks {obj}")
        if not coordinated.deadlock_free:
            reasons.append(
                f"the coordinated missions can deadlock after: {' '.join(coordinated.blocking or ())}"
            )
        if reasons:
            break
        changed = {r: events for r, events in coordinated.sequences.items() if events != current[r]}
        current.update(changed)
        results.update(plan_all(changed))
    verification = None
    if not reasons:
        t0 = time.perf_counter()
        local = {r: sequence_automaton([e.name for e in events]) for r, events in current.items()}
        verification = verify(GlobalMission.from_scenario(scenario), local)
        phases["verify"] = time.perf_counter() - t0
        if not verification.holds:
            reasons.append(
                f"the coordinated missions violate the global mission: {verification.counterexample}"
            )
    pairs = coordinated.pairs if coordinated is not None else ()
    plans = PlanSet(
        scenario=scenario.name,
        feasible=not reasons,
        robots={r: res.plan for r, res in results.items() if res.plan is not None},
        coordination=tuple(Coordination(p.obj, p.requester, p.responder) for p in pairs),
        reason="; ".join(reasons) if reasons else None,
    )
    t0 = time.perf_counter()
    report = check_plan(scenario, plans)
    phases["check"] = time.perf_counter() - t0
    if plans.feasible and not report.ok:
        raise AssertionError(f"a synthesised plan failed the exact checker: {report.violations[0].message}")
    return TeamResult(
        plans=plans,
        results=MappingProxyType(results),
        coordination=coordinated,
        verification=verification,
        report=report,
        iterations=iterations,
        converged=converged,
        phases=MappingProxyType(phases),
    )
