"""The top-down ↔ bottom-up loop (the paper's Fig. "Overall framework").

1. *Decompose* the global mission into local missions, one word of events per robot.  When the
   mission is not separable because it orders different robots' events, the order is kept by
   messages (:mod:`cosmop.missions.ordering`), never by dropping tasks; only when no placement
   of messages can work are tasks pruned, and then the plan is infeasible and names them.
2. *Synthesize* every robot's shortest plan (its messages are put in afterwards).
3. *Coordinate requests*: each Req(O) of robot A becomes the message ``away(O, A, B)`` from the
   robot B whose mission picks O (:mod:`cosmop.team.coordination_events`); the responders are
   re-planned; repeat until no plan asks for anything new (capped).  A request that nobody can
   answer, or that would deadlock the team, is forbidden and the requester re-planned: its next
   best plan asks for less, or is a step longer.
4. *Make the plans team-safe* (:mod:`cosmop.team.safe_plans`): every place two plans share is
   ordered by a message.  A conflict that no order resolves (a robot parked for good where
   another must pass) is resolved by re-planning one robot with the other's space as an
   obstacle; where neither side can move, goods are dropped or picked elsewhere; and a conflict
   between a robot waiting for goods to be moved and the robot that moves them (it must stand
   beside the waiting one), by forbidding the request and running steps 2-4 again.
5. *Verify*: the robots' words with all their messages cannot deadlock and do exactly what the
   global mission asks (:func:`cosmop.team.mission_proof.verify_team`); every plan set passes the
   exact checker (:func:`cosmop.team.plan_set_checker.check_plan`).
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Mapping
from concurrent.futures import Executor
from dataclasses import dataclass, replace
from types import MappingProxyType

from cosmop.errors import MissionTooLargeError
from cosmop.events import Event, parse_event
from cosmop.missions.allocation import Choice
from cosmop.missions.decomposition import decompose
from cosmop.missions.mission import GlobalMission, sequence_of
from cosmop.planning.checker import CheckReport
from cosmop.planning.plan_types import Coordination, PlanMessage, PlanSet, RobotPlan
from cosmop.planning.synthesis import DEFAULT_RLIMIT, Synthesis
from cosmop.scene import Scenario
from cosmop.team.choices import Allocation, allocate
from cosmop.team.conflicts import ConflictSettings
from cosmop.team.coordination_events import Coordinated
from cosmop.team.detours import OUT_OF_BUDGET, MadeSafe, make_safe, shorten_waits
from cosmop.team.handover import Handovers, handovers
from cosmop.team.initial_plans import pack_docks, plan_in_turn
from cosmop.team.mission_proof import TeamVerdict, check_words
from cosmop.team.plan_set_checker import check_plan
from cosmop.team.planner import Checkpoint, Planner, Workers
from cosmop.team.requests import RequestsAnswered, coordinate_requests
from cosmop.team.safe_plans import TeamSafety
from cosmop.team.timing import itinerary

__all__ = ["PHASES", "REQUEST_RETRIES", "WAYS_AROUND", "TeamResult", "plan_team"]

WAYS_AROUND = 4
"""Re-plans :func:`plan_team` tries, at most, to take a way around a long wait for a shared place."""

REQUEST_RETRIES = 3
"""Times :func:`plan_team` forbids requests, at most, whose wait and answer share a place (see
:func:`_answer_and_order`)."""

PHASES = ("decompose", "allocate", "synthesize", "coordinate", "conflicts", "verify", "check")
"""The phases whose seconds :attr:`TeamResult.phases` records."""


@dataclass(frozen=True)
class TeamResult:
    """Result of :func:`plan_team`.

    Attributes
    ----------
    plans : PlanSet
        Every robot's plan, the request/response pairs and the messages (the plan file).
    results : Mapping[str, Synthesis]
        The last synthesis of each robot.
    coordination : Coordinated or None
        The request/response pairs and the words with them.
    verification : TeamVerdict or None
        Whether the robots' words with their messages do exactly what the mission asks.
    report : CheckReport
        The exact checker's verdict on ``plans`` (always ok for a feasible result).
    iterations : int
        Coordinate/re-synthesize rounds.
    converged : bool
        False when the iteration cap stopped the loop.
    phases : Mapping[str, float]
        Seconds spent in each phase of :data:`PHASES`.
    safety : TeamSafety or None
        The conflicts between the plans and the messages that order them.
    replans : tuple of str
        Why robots were re-planned after their first plan (requests forbidden, conflicts).
    allocation : Choice or None
        When the mission left choices open: the alternative chosen, its cost, how many were
        compared (:mod:`cosmop.missions.allocation`).
    """

    plans: PlanSet
    results: Mapping[str, Synthesis]
    coordination: Coordinated | None
    verification: TeamVerdict | None
    report: CheckReport
    iterations: int
    converged: bool
    phases: Mapping[str, float]
    safety: TeamSafety | None = None
    replans: tuple[str, ...] = ()
    allocation: Choice | None = None


def plan_team(
    scenario: Scenario,
    *,
    max_horizon: int | None = None,
    rlimit: int = DEFAULT_RLIMIT,
    max_iterations: int = 5,
    workers: int | None = None,
    executor: Executor | None = None,
    on_robot: Callable[[str, Synthesis], None] | None = None,
    conflicts: ConflictSettings | None = None,
    ways_around: int = WAYS_AROUND,
    budget: float | None = None,
) -> TeamResult:
    """Plan, coordinate, make team-safe and verify the whole team (see the module docstring).

    Parameters
    ----------
    scenario : Scenario
    max_horizon, rlimit
        Passed to :func:`cosmop.planning.synthesis.synthesize`; without `max_horizon`, each
        robot's is :func:`default_horizon` of its mission.
    max_iterations : int
        Cap on coordinate/re-synthesize rounds.
    workers : int, optional
        Worker processes for the robots' syntheses (default: one per core, at most one per
        robot; 1 plans in this process).  Ignored when `executor` is given.
    executor : concurrent.futures.Executor, optional
        Where to run the syntheses: any ``submit``/``result`` executor, e.g. a Dask cluster's
        (:func:`cosmop.team.cluster.dask_executor`).  The caller owns it (it is not shut down
        here).  The result does not depend on it: each synthesis is deterministic.
    on_robot : callable, optional
        Called after every synthesis (progress display).
    conflicts : ConflictSettings, optional
        How conflicts between plans are found.
    ways_around : int
        Re-plans tried to take a way around a long wait for a shared place instead of waiting
        (:func:`_shorten_waits`; 0: none).
    budget : float, optional
        Seconds of wall time the planning may take (default: no limit).  Past it, nothing more
        is tried for a team not planned yet (no further round of re-plans around conflicts, no
        request forbidden to try again, no way around a wait): the team is called infeasible
        with a reason that says the budget ran out.  A budget makes the answer depend on the
        machine's speed; the rest of the planning is deterministic.

    Raises
    ------
    AssertionError
        If a plan set fails the exact checker (an encoding bug, never a user error).
    """
    phases = dict.fromkeys(PHASES, 0.0)
    t = time.perf_counter()
    mission = GlobalMission.from_scenario(scenario)
    try:
        start = _local_words(scenario, mission)
    except MissionTooLargeError as err:
        raise _in_file(err, scenario) from None
    phases["decompose"] = time.perf_counter() - t
    pool = None
    if executor is None:
        team = len(scenario.scene.robots)
        n_workers = min(os.cpu_count() or 1, team) if workers is None else max(1, workers)
        pool = Workers(n_workers) if n_workers > 1 else None
    planner = Planner(scenario, executor or pool, on_robot, max_horizon, rlimit, phases)
    planner.set_budget(budget)
    try:
        if start is None:  # the mission leaves choices open: commit to the cheapest way
            t = time.perf_counter()
            before = phases["synthesize"]
            try:
                start = allocate(scenario, mission, planner)
            except MissionTooLargeError as err:
                raise _in_file(err, scenario) from None
            planner.forbidden = dict(start.forbidden)
            phases["allocate"] = time.perf_counter() - t - (phases["synthesize"] - before)
        return _loop(
            scenario, mission, start, planner, max_iterations, conflicts or ConflictSettings(), ways_around
        )
    except BaseException:  # an interrupt or an error: do not wait for the workers' syntheses
        if pool is not None:
            pool.stop()
            pool = None
        raise
    finally:
        if pool is not None:
            pool.shutdown()


def _in_file(err: MissionTooLargeError, scenario: Scenario) -> MissionTooLargeError:
    """`err` naming the scenario's file."""
    return MissionTooLargeError(err.expected, file=scenario.source, field=err.field)


def _local_words(scenario: Scenario, mission: GlobalMission) -> Allocation | None:
    """Each robot's word and what each message in them is for; ``None`` when the mission
    leaves choices open (see :func:`cosmop.team.choices.allocate`)."""
    robots = tuple(scenario.scene.robots)
    notes: dict[str, tuple[str, str]] = {}
    spec = scenario.mission
    assert spec is not None  # a scenario of orders only is planned by cosmop.lifelong
    if spec.tasks is not None:
        words = {r: tuple(spec.tasks.get(r, ())) for r in robots}
        for r, word in words.items():
            for e in word:
                if e.kind == "msg" and e.sender == r:
                    notes[e.name] = ("mission", f"the mission orders {e.receiver} to wait for {r} here")
        return _given(words, notes)
    if spec.deliveries is not None:
        return None  # who moves what is the planner's to choose
    result = decompose(mission)
    if result.messaging is not None:
        plain = {r: sequence_of(d) or () for r, d in result.local_missions.items()}
        for name, ((a, i), (b, j)) in result.messaging.messages:
            notes[name] = ("order", f"the mission orders {b}'s {plain[b][j]} after {a}'s {plain[a][i]}")
        local: dict[str, tuple[str, ...] | None] = {r: tuple(w) for r, w in result.messaging.words.items()}
    else:
        local = {r: sequence_of(d) for r, d in result.local_missions.items()}
        if not result.separable or any(seq is None for seq in local.values()):
            # choices between robots or tasks: allocate (messages then order the chosen words;
            # the paper's pruning, which would drop tasks, is never needed)
            return None
    return _given({r: tuple(parse_event(e) for e in local.get(r) or ()) for r in robots}, notes)


def _given(words: Mapping[str, tuple[Event, ...]], notes: Mapping[str, tuple[str, str]]) -> Allocation:
    """Words the mission fixes: nothing chosen, no request ruled out."""
    return Allocation(words, notes, (), None, {})


def _loop(
    scenario: Scenario,
    mission: GlobalMission,
    start: Allocation,
    planner: Planner,
    max_iterations: int,
    settings: ConflictSettings,
    ways_around: int,
) -> TeamResult:
    """Coordinate requests, make the plans team-safe, verify and check (steps 2-5).

    Each step returns what it did (:class:`~cosmop.team.requests.RequestsAnswered`,
    :class:`~cosmop.team.detours.MadeSafe`); the first that gives reasons ends the loop, and
    the plan file says them.
    """
    base = dict(start.words)
    givers = handovers(base)
    reasons = tuple(start.reasons) + tuple(givers.refused)
    if not reasons:
        reasons = pack_docks(base, planner)
    answered, made = None, None
    if not reasons:
        answered, made = _answer_and_order(base, givers, planner, max_iterations, settings, ways_around)
        reasons = answered.reasons if made is None else made.reasons
        if reasons and planner.over_budget() and not reasons[0].startswith(OUT_OF_BUDGET):
            # the search was cut short, whatever the last round found: say so first
            reasons = (f"{OUT_OF_BUDGET} of {planner.budget:g} s ({reasons[0]})", *reasons[1:])
    results = made.results if made is not None else answered.results if answered is not None else {}
    plans = dict(made.safety.plans) if made is not None else _plans_of(results)
    verdict = None
    if not reasons:
        t0 = time.perf_counter()
        verdict = check_words(mission, {r: p.word for r, p in plans.items()})
        planner.phases["verify"] = time.perf_counter() - t0
        if not verdict.holds:
            reasons = (verdict.reason() or "the coordinated missions violate the global mission",)
    return _result(scenario, mission, start, planner, answered, made, verdict, plans, reasons)


def _answer_and_order(
    base: Mapping[str, tuple[Event, ...]],
    givers: Handovers,
    planner: Planner,
    max_iterations: int,
    settings: ConflictSettings,
    ways_around: int,
) -> tuple[RequestsAnswered, MadeSafe | None]:
    """Steps 2-4 from each robot's word: its first plan, the requests answered, the plans made
    team-safe (``None`` when the requests could not be).

    A robot that asks for goods to be moved waits for them where it stands; when the robot that
    moves them must stand within the clearance of that place to pick them (the requester's start
    beside the goods, say), neither can go first: the conflict is stuck.  When picking them from
    another side does not help either (step 4 tries it), the request is forbidden (the requester
    drives around the goods, or asks for less), as a request that deadlocks the team's words is
    in step 3, and the steps run again from the start, at most :data:`REQUEST_RETRIES` times.
    When that does not plan the team, the first outcome stands, and with it its reason.
    """
    start, forbidden, notes = planner.checkpoint(), dict[str, frozenset[str]](), list[str]()
    first: tuple[RequestsAnswered, MadeSafe | None, Checkpoint] | None = None
    for attempt in range(REQUEST_RETRIES + 1):
        planner.rewind(start)
        for robot, goods in forbidden.items():
            planner.forbid(robot, goods)
        answered = coordinate_requests(base, plan_in_turn(base, givers, planner), planner, max_iterations)
        made = None
        if answered.ok:  # the scenario with the places of goods set aside, if any
            # a try after the first is a trial: if it fails, the first outcome's reason stands
            made = make_safe(answered.current, answered.results, planner, settings, explain=attempt == 0)
            if made.ok and ways_around > 0:
                made = shorten_waits(answered.current, made, planner, settings, ways_around)
            if made.ok:
                return replace(answered, replans=(*notes, *answered.replans)), made
        if first is None:
            first = (answered, made, planner.checkpoint())
        more = {
            robot: new
            for robot, goods in _requests_in_the_way(answered, made).items()
            if (new := goods - forbidden.get(robot, frozenset()))
        }
        if not more or attempt == REQUEST_RETRIES or planner.over_budget():
            break  # nothing new to forbid, or no try (or time) left
        for robot, goods in more.items():
            forbidden[robot] = forbidden.get(robot, frozenset()) | goods
            assert made is not None and made.stuck is not None  # (what `more` comes from)
            notes.append(
                f"{robot} re-planned without requesting {', '.join(sorted(goods))}: waiting for them "
                f"where it stands, it is in the way of the robot that moves them ({made.stuck.describe()})"
            )
    assert first is not None  # (the loop runs at least once)
    answered, made, mark = first
    planner.rewind(mark)
    return answered, made


def _requests_in_the_way(answered: RequestsAnswered, made: MadeSafe | None) -> dict[str, frozenset[str]]:
    """The requests between the two robots standing on the sides of the conflict stuck in
    `made` (the requester waits where it stands, the responder stands to pick): per requester,
    the goods it asks the other to move (``{}``: none, or nothing stuck)."""
    if made is None or made.stuck is None or answered.coordinated is None:
        return {}
    sides = (made.stuck.a, made.stuck.b)
    standing = {o.what for o in sides if o.what in o.parties and not o.is_drive}
    out: dict[str, frozenset[str]] = {}
    for pair in answered.coordinated.pairs:
        if pair.requester != pair.responder and {pair.requester, pair.responder} <= standing:
            out[pair.requester] = out.get(pair.requester, frozenset()) | {pair.obj}
    return out


def _plans_of(results: Mapping[str, Synthesis]) -> dict[str, RobotPlan]:
    return {r: res.plan for r, res in results.items() if res.plan is not None}


def _result(
    scenario: Scenario,
    mission: GlobalMission,
    start: Allocation,
    planner: Planner,
    answered: RequestsAnswered | None,
    made: MadeSafe | None,
    verdict: TeamVerdict | None,
    plans: Mapping[str, RobotPlan],
    reasons: tuple[str, ...],
) -> TeamResult:
    """The plan file of the loop's outcome, checked exactly, and the statistics with it."""
    safety = made.safety if made is not None else None
    messages = _plan_messages(plans, start.notes) + (list(safety.messages) if safety is not None else [])
    coordinated = answered.coordinated if answered is not None else None
    pairs = coordinated.pairs if coordinated is not None else ()
    choice = start.choice
    plan_set = PlanSet(
        scenario=scenario.name,
        feasible=not reasons,
        robots=dict(plans),
        coordination=tuple(Coordination(p.obj, p.requester, p.responder) for p in pairs),
        reason="; ".join(reasons) if reasons else None,
        messages=tuple(messages) if not reasons else (),
        allocation=choice.alternative.movers(mission) if choice and choice.alternative else {},
        added=tuple(planner.added),
        itinerary=itinerary(planner.scenario.scene, plans) if not reasons else None,
    )
    t0 = time.perf_counter()
    report = check_plan(scenario, plan_set)
    planner.phases["check"] = time.perf_counter() - t0
    if plan_set.feasible and not report.ok:
        raise AssertionError(f"a synthesised plan failed the exact checker: {report.violations[0].message}")
    results = made.results if made is not None else answered.results if answered is not None else {}
    return TeamResult(
        plans=plan_set,
        results=MappingProxyType(dict(results)),
        coordination=coordinated,
        verification=verdict,
        report=report,
        iterations=answered.iterations if answered is not None else 0,
        converged=answered.converged if answered is not None else False,
        phases=MappingProxyType(planner.phases),
        safety=safety,
        replans=(answered.replans if answered is not None else ())
        + (made.replans if made is not None else ()),
        allocation=choice,
    )


def _plan_messages(plans: Mapping[str, RobotPlan], notes: Mapping[str, tuple[str, str]]) -> list[PlanMessage]:
    """The plan file's entries for the messages of the mission (orders, user's messages)."""
    out = []
    for robot, plan in plans.items():
        for event in plan.mission:
            if event.kind == "msg" and event.sender == robot and event.name in notes:
                kind, text = notes[event.name]
                out.append(PlanMessage(event, kind, text))
    return out
