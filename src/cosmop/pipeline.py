"""The top-down ↔ bottom-up loop (the paper's Fig. "Overall framework").

1. *Decompose* the global mission into local missions, one word of events per robot.  When the
   mission is not separable because it orders different robots' events, the order is kept by
   messages (:mod:`cosmop.missions.ordering`), never by dropping tasks; only when no placement
   of messages can work are tasks pruned, and then the plan is infeasible and names them.
2. *Synthesize* every robot's shortest plan (its messages are put in afterwards).
3. *Coordinate requests*: each Req(O) of robot A becomes the message ``away(O, A, B)`` from the
   robot B whose mission picks O (:mod:`cosmop.missions.coordination`); the responders are
   re-planned; repeat until no plan asks for anything new (capped).  A request that nobody can
   answer, or that would deadlock the team, is forbidden and the requester re-planned: its next
   best plan asks for less, or is a step longer.
4. *Make the plans team-safe* (:mod:`cosmop.planning.teamsafety`): every place two plans share is
   ordered by a message.  A conflict that no order resolves (a robot parked for good where
   another must pass) is resolved by re-planning one robot with the other's space as an
   obstacle.
5. *Verify*: the robots' words with all their messages cannot deadlock and do exactly what the
   global mission asks (:func:`cosmop.missions.team.verify_team`); every plan set passes the
   exact checker (:func:`cosmop.planning.checker.check_plan`).
"""

from __future__ import annotations

import itertools
import multiprocessing
import os
import signal
import time
from collections.abc import Callable, Iterable, Mapping
from concurrent.futures import Executor, ProcessPoolExecutor
from dataclasses import dataclass, replace
from types import MappingProxyType

import shapely

from cosmop.allocate import allocate
from cosmop.automata import DFA
from cosmop.errors import MissionTooLargeError
from cosmop.events import Event, Primitive, parse_event
from cosmop.io import uninterrupted
from cosmop.missions.allocation import Choice
from cosmop.missions.coordination import Coordinated, coordinate
from cosmop.missions.decomposition import decompose
from cosmop.missions.handover import Handover, Handovers, handovers
from cosmop.missions.mission import GlobalMission, sequence_of
from cosmop.missions.team import TeamVerdict, blocking_word, check_words
from cosmop.planning.aside import ROOM, dock_slots, handover_spot, place_aside
from cosmop.planning.checker import CheckReport, check_plan
from cosmop.planning.conflicts import ConflictSettings
from cosmop.planning.lanes import lanes
from cosmop.planning.plan_types import MAX_STEPS, AddedTask, Coordination, PlanMessage, PlanSet, RobotPlan
from cosmop.planning.realisation import request_phases
from cosmop.planning.synthesis import DEFAULT_RLIMIT, Synthesis, synthesize
from cosmop.planning.teamsafety import TeamSafety, make_team_safe
from cosmop.planning.timing import itinerary
from cosmop.scene import Scenario, Scene, Wall
from cosmop.squares import square
from cosmop.units import show_point

__all__ = ["TeamResult", "plan_team"]

_AROUND = ConflictSettings(clearance=2 * ROOM)  # walls around goods set aside: ROOM off them

WAYS_AROUND = 4
"""Re-plans :func:`plan_team` tries, at most, to take a way around a long wait for a shared place."""

TRIAL_STEPS = 2
"""Steps a way around may add to a robot's plan: a trial searches no longer plans."""

MIN_WAIT = 2.0
"""Expected seconds of a wait below which no way around is tried: a detour rarely costs less."""

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


@dataclass(frozen=True)
class _Job:
    """One robot's synthesis, as sent to a worker process."""

    scene: Scene
    robot: str
    events: tuple[Event, ...] | DFA
    max_horizon: int
    rlimit: int
    unrequestable: frozenset[str] = frozenset()
    explain: bool = True  # an infeasible answer says why (costs more solver calls)
    spots: tuple[tuple[Event, tuple[float, float]], ...] = ()  # drops pinned for a hand-over
    min_horizon: int = 0  # no shorter plan exists (a re-plan with more walls)


def _automaton_key(dfa: DFA) -> tuple:
    """A branching mission by value (DFAs compare by identity)."""
    return ("automaton", dfa.alphabet, dfa.delta.tobytes(), dfa.initial, dfa.marked.tobytes())


def _synthesize(job: _Job) -> Synthesis:
    """One robot's synthesis (module level, so worker processes can run it)."""
    return synthesize(
        job.scene,
        job.robot,
        job.events,
        max_horizon=job.max_horizon,
        rlimit=job.rlimit,
        unrequestable=job.unrequestable,
        explain=job.explain,
        spots=job.spots,
        min_horizon=job.min_horizon,
    )


class _Workers(ProcessPoolExecutor):
    """The pipeline's worker processes: Ctrl-C is the parent's, and an interrupt ends them at once.

    A terminal sends Ctrl-C (SIGINT) to every process of its foreground job, these workers too.
    A worker ignores it (its initializer, :func:`_leave_interrupts`); the parent answers it, and
    :meth:`stop` ends the workers.  Workers are forked where the platform allows (no re-import of
    the package), inside :meth:`submit`: the parent holds Ctrl-C back while it submits
    (:func:`cosmop.io.uninterrupted`), so that an interrupt can neither stop it between starting
    a worker and recording it (a worker nobody would end) nor reach a worker before its
    initializer runs (the worker is born with the parent's noting handler, which only notes it).
    """

    def __init__(self, workers: int) -> None:
        methods = multiprocessing.get_all_start_methods()
        context = multiprocessing.get_context("fork" if "fork" in methods else "spawn")
        super().__init__(max_workers=workers, mp_context=context, initializer=_leave_interrupts)

    def submit(self, fn, /, *args, **kwargs):
        with uninterrupted():
            return super().submit(fn, *args, **kwargs)

    def stop(self) -> None:
        """End the workers now, then the pool, leaving no process and no thread behind.

        A synthesis can run for minutes and a worker ignores Ctrl-C: waiting for it, as
        ``shutdown`` and the interpreter's exit after it do, would hang the program.  So the
        pool is told to shut down and cancel the work not started (its manager thread drops
        that work first), the workers are killed and reaped, and the manager thread, which then
        finds them gone, is joined.  The writing end of the results' pipe that this process
        holds is closed before: should the manager be reading a result that a killed worker
        had half sent, it reads the end of the pipe instead of waiting forever.  Ctrl-C is held back
        meanwhile (a second one must not leave the pool half stopped); it arrives right after.
        (Python 3.14 has ``kill_workers``; before it, the processes are private.)
        """
        with uninterrupted():
            processes = list((self._processes or {}).values())
            manager, results = self._executor_manager_thread, self._result_queue
            self.shutdown(wait=False, cancel_futures=True)
            for process in processes:
                process.kill()
            for process in processes:
                process.join()
            if results is not None:
                results._writer.close()  # stdlib: the queue has no public way to close its end
            if manager is not None:
                manager.join()
            if results is not None:
                results.close()


def _leave_interrupts() -> None:
    """In a worker: Ctrl-C reaches the whole process group; the parent alone answers it."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def default_horizon(events: tuple[Event, ...]) -> int:
    """The longest plan tried for a mission when the caller sets none: 16, or 3 steps per
    mission event plus 6 when that is more (a robot with several deliveries needs the room;
    detours around the others' places add steps), never more than a plan file may hold."""
    return min(MAX_STEPS, max(16, 3 * sum(1 for e in events if not e.is_message) + 6))


class _Planner:
    """Runs syntheses (in an executor when there is one) and keeps the phase times."""

    def __init__(self, scenario, executor, on_robot, max_horizon, rlimit, phases) -> None:
        self.scenario = scenario
        self.executor = executor
        self.on_robot = on_robot
        self.max_horizon = max_horizon
        self.rlimit = rlimit
        self.phases = phases
        self.forbidden: dict[str, frozenset[str]] = {}
        self.added: list[AddedTask] = []  # goods moved aside; their places extend the scenario
        self.obstacles: dict[str, tuple[Wall, ...]] = {}
        # hand-overs: goods a robot picks where another drops them (its model starts with them
        # there), and the giver's drop held to that spot
        self.placed: dict[str, dict[str, tuple[float, float]]] = {}
        self.spots: dict[str, dict[Event, tuple[float, float]]] = {}
        self.cache: dict[tuple, Synthesis] = {}  # the same question is never solved twice

    def restrictions(self, robot: str) -> tuple:
        """Everything besides the mission that decides `robot`'s synthesis."""
        return (
            self.forbidden.get(robot, frozenset()),
            self.obstacles.get(robot, ()),
            tuple(sorted(self.placed.get(robot, {}).items())),
            tuple(sorted(self.spots.get(robot, {}).items())),
        )

    def key(
        self, robot: str, events: tuple[Event, ...] | DFA, explain: bool = True, window: tuple | None = None
    ) -> tuple:
        """The cache's key of a question; `window` (the lengths searched, when not every one)
        keys an answer that found no plan in it."""
        mission = _automaton_key(events) if isinstance(events, DFA) else tuple(events)
        return (
            robot,
            mission,
            *self.restrictions(robot),
            *(() if explain else ("unexplained",)),
            *(() if window is None else (window,)),
        )

    def remember(self, robot: str, events: tuple[Event, ...], forbidden: frozenset[str], result: Synthesis):
        """Keep `result` as the answer for `events` with `forbidden` (one it answers exactly)."""
        self.cache[(robot, tuple(events), forbidden, *self.restrictions(robot)[1:])] = result

    def hand_over(self, handover: Handover, spot: tuple[float, float]) -> None:
        """From now on the receiver's model has the goods at `spot` from the start, and the
        giver's drop puts them exactly there."""
        self.placed.setdefault(handover.receiver, {})[handover.obj] = spot
        self.spots.setdefault(handover.giver, {})[handover.drop] = spot

    def job(
        self, robot: str, events: tuple[Event, ...] | DFA, explain: bool = True, window: tuple | None = None
    ) -> _Job:
        scene = self.scenario.scene
        extra = self.obstacles.get(robot, ())
        if extra:
            scene = replace(scene, obstacles=scene.obstacles + extra)
        scene = _goods_at(scene, self.placed.get(robot, {}))
        branching = isinstance(events, DFA)
        # a branching mission gets the horizon of its alphabet: no word of it has more events
        mission = tuple(parse_event(e) for e in events.alphabet) if branching else tuple(events)
        horizon = self.max_horizon if self.max_horizon is not None else default_horizon(mission)
        least = 0
        if window is not None:
            least, horizon = window[0], min(horizon, window[1])
        forbidden = self.forbidden.get(robot, frozenset())
        spots = tuple(sorted(self.spots.get(robot, {}).items()))
        return _Job(
            scene,
            robot,
            events if branching else mission,
            horizon,
            self.rlimit,
            forbidden,
            explain,
            spots,
            least,
        )

    def run(
        self,
        jobs: Mapping[str, tuple[Event, ...]],
        explain: bool = True,
        windows: Mapping[str, tuple[int, int]] | None = None,
    ) -> dict[str, Synthesis]:
        """Each robot's synthesis; with `explain` false an infeasible one only says so (trials).

        `windows` gives robots the lengths to search, ``(least, most)``: the least known (no
        shorter plan exists), the most a trial's bound; a plan found is the shortest all the same.
        """
        t0 = time.perf_counter()
        windows = windows or {}
        out: dict[str, Synthesis] = {}
        for robot, events in jobs.items():
            hit = self.cache.get(self.key(robot, events))  # an explained answer serves every call
            if hit is None and not explain:
                hit = self.cache.get(self.key(robot, events, explain=False))
            if hit is None and robot in windows:
                hit = self.cache.get(self.key(robot, events, explain, windows[robot]))
            if hit is not None:
                out[robot] = hit
        work = {
            robot: self.job(robot, events, explain, windows.get(robot))
            for robot, events in jobs.items()
            if robot not in out
        }
        if self.executor is None or len(work) < 2:
            for robot, job in work.items():
                out[robot] = _synthesize(job)
                if self.on_robot is not None:
                    self.on_robot(robot, out[robot])
        else:
            futures = {robot: self.executor.submit(_synthesize, job) for robot, job in work.items()}
            try:
                for robot, future in futures.items():
                    out[robot] = future.result()
                    if self.on_robot is not None:
                        self.on_robot(robot, out[robot])
            except BaseException:  # an interrupt or a failed synthesis: leave no work queued
                # (the pipeline's own pool cancels its work as plan_team stops it: a future
                # cancelled behind its back breaks its manager thread before Python 3.12)
                if not isinstance(self.executor, _Workers):
                    for future in futures.values():
                        future.cancel()
                raise
        for robot, events in jobs.items():
            window = windows.get(robot) if not out[robot].feasible else None
            self.cache[self.key(robot, events, explain or out[robot].feasible, window)] = out[robot]
        self.phases["synthesize"] += time.perf_counter() - t0
        return {robot: out[robot] for robot in jobs}


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
        (:func:`cosmop.cluster.dask_executor`).  The caller owns it (it is not shut down
        here).  The result does not depend on it: each synthesis is deterministic.
    on_robot : callable, optional
        Called after every synthesis (progress display).
    conflicts : ConflictSettings, optional
        How conflicts between plans are found.
    ways_around : int
        Re-plans tried to take a way around a long wait for a shared place instead of waiting
        (:func:`_shorten_waits`; 0: none).

    Raises
    ------
    AssertionError
        If a plan set fails the exact checker (an encoding bug, never a user error).
    """
    phases = dict.fromkeys(PHASES, 0.0)
    t = time.perf_counter()
    mission = GlobalMission.from_scenario(scenario)
    try:
        words, notes, reasons = _local_words(scenario, mission)
    except MissionTooLargeError as err:
        raise _in_file(err, scenario) from None
    phases["decompose"] = time.perf_counter() - t
    pool = None
    if executor is None:
        team = len(scenario.scene.robots)
        n_workers = min(os.cpu_count() or 1, team) if workers is None else max(1, workers)
        pool = _Workers(n_workers) if n_workers > 1 else None
    planner = _Planner(scenario, executor or pool, on_robot, max_horizon, rlimit, phases)
    try:
        choice = None
        if words is None:  # the mission leaves choices open: commit to the cheapest way
            t = time.perf_counter()
            before = phases["synthesize"]
            try:
                words, notes, reasons, choice = allocate(scenario, mission, planner)
            except MissionTooLargeError as err:
                raise _in_file(err, scenario) from None
            phases["allocate"] = time.perf_counter() - t - (phases["synthesize"] - before)
        return _loop(
            scenario, mission, words, notes, reasons, planner, max_iterations, conflicts, choice, ways_around
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


def _local_words(
    scenario: Scenario, mission: GlobalMission
) -> tuple[dict[str, tuple[Event, ...]] | None, dict[str, tuple[str, str]], list[str]]:
    """Each robot's word, what each message in them is for, and why planning cannot start.

    The words are ``None`` when the mission leaves choices open (see :func:`cosmop.allocate.allocate`).
    """
    robots = tuple(scenario.scene.robots)
    notes: dict[str, tuple[str, str]] = {}
    if scenario.mission.tasks is not None:
        words = {r: tuple(scenario.mission.tasks.get(r, ())) for r in robots}
        for r, word in words.items():
            for e in word:
                if e.kind == "msg" and e.sender == r:
                    notes[e.name] = ("mission", f"the mission orders {e.receiver} to wait for {r} here")
        return words, notes, []
    if scenario.mission.deliveries is not None:
        return None, notes, []  # who moves what is the planner's to choose
    result = decompose(mission)
    if result.messaging is not None:
        plain = {r: sequence_of(d) or () for r, d in result.local_missions.items()}
        for name, ((a, i), (b, j)) in result.messaging.messages:
            notes[name] = ("order", f"the mission orders {b}'s {plain[b][j]} after {a}'s {plain[a][i]}")
        local = {r: tuple(w) for r, w in result.messaging.words.items()}
    else:
        local = {r: sequence_of(d) for r, d in result.local_missions.items()}
        if not result.separable or any(seq is None for seq in local.values()):
            # choices between robots or tasks: allocate (messages then order the chosen words;
            # the paper's pruning, which would drop tasks, is never needed)
            return None, notes, []
    words = {r: tuple(parse_event(e) for e in local.get(r) or ()) for r in robots}
    return words, notes, []


def _loop(
    scenario: Scenario,
    mission: GlobalMission,
    base: dict[str, tuple[Event, ...]],
    notes: dict[str, tuple[str, str]],
    reasons: list[str],
    planner: _Planner,
    max_iterations: int,
    settings: ConflictSettings | None,
    choice: Choice | None = None,
    ways_around: int = 0,
) -> TeamResult:
    """Coordinate requests, make the plans team-safe, verify and check (steps 2-5)."""
    phases = planner.phases
    replans: list[str] = []
    results: dict[str, Synthesis] = {}
    coordinated, current, iterations, converged = None, dict(base), 0, False
    givers = handovers(base)
    reasons.extend(givers.refused)
    if not reasons:
        reasons.extend(_pack_docks(base, planner))
    if not reasons:
        results = _plan_in_turn(base, givers, planner)
        coordinated, current, iterations, converged = _coordinate_requests(
            base, results, planner, max_iterations, reasons, replans
        )
    safety, plans = None, {r: res.plan for r, res in results.items() if res.plan is not None}
    if not reasons:  # the scenario with the places of goods set aside, if any
        safety = _make_safe(planner.scenario, current, results, planner, settings, reasons, replans)
        if not reasons and ways_around > 0:
            safety = _shorten_waits(current, results, planner, settings, safety, replans, ways_around)
        plans = dict(safety.plans)
    verdict = None
    if not reasons:
        t0 = time.perf_counter()
        verdict = check_words(mission, {r: p.mission for r, p in plans.items()})
        phases["verify"] = time.perf_counter() - t0
        if not verdict.holds:
            reasons.append(verdict.reason() or "the coordinated missions violate the global mission")
    messages = _plan_messages(plans, notes) + (list(safety.messages) if safety is not None else [])
    pairs = coordinated.pairs if coordinated is not None else ()
    plan_set = PlanSet(
        scenario=scenario.name,
        feasible=not reasons,
        robots=plans,
        coordination=tuple(Coordination(p.obj, p.requester, p.responder) for p in pairs),
        reason="; ".join(reasons) if reasons else None,
        messages=tuple(messages) if not reasons else (),
        allocation=choice.alternative.movers(mission) if choice and choice.alternative else {},
        added=tuple(planner.added),
        itinerary=itinerary(planner.scenario.scene, plans) if not reasons else None,
    )
    t0 = time.perf_counter()
    report = check_plan(scenario, plan_set)
    phases["check"] = time.perf_counter() - t0
    if plan_set.feasible and not report.ok:
        raise AssertionError(f"a synthesised plan failed the exact checker: {report.violations[0].message}")
    return TeamResult(
        plans=plan_set,
        results=MappingProxyType(results),
        coordination=coordinated,
        verification=verdict,
        report=report,
        iterations=iterations,
        converged=converged,
        phases=MappingProxyType(phases),
        safety=safety,
        replans=tuple(replans),
        allocation=choice,
    )


def _pack_docks(base: Mapping[str, tuple[Event, ...]], planner: _Planner) -> list[str]:
    """Give goods that several robots drop into one workspace a slot each; why not (``[]``: done).

    Each robot picks its own drop spot when planned alone, and robots sharing a dock would
    pick the same one: the goods are packed first (:func:`cosmop.planning.aside.dock_slots`),
    each robot's drop is pinned to its goods' slot, and a robot knows the goods packed before
    its own in their slots from the start (it docks beside them).  The conflict step then
    orders the drops.
    """
    drops: dict[str, dict[str, tuple[str, Event]]] = {}
    for robot, word in base.items():
        for event in word:
            if event.kind == "drop" and event.robot == robot:
                drops.setdefault(event.workspace, {}).setdefault(event.obj, (robot, event))
    why_not = []
    scene = planner.scenario.scene
    for workspace, goods in drops.items():
        if len({robot for robot, _ in goods.values()}) < 2:
            continue  # one robot's model holds all its goods: its plan packs them itself
        packing = dock_slots(scene, workspace, {o: robot for o, (robot, _) in goods.items()})
        if packing.left_out:
            size = scene.workspaces[workspace]
            why_not.append(
                f"{workspace} holds {len(packing.slots)} of the {len(goods)} goods dropped there: no "
                f"room to dock {', '.join(packing.left_out)} beside the others "
                f"({_extent(size)}, goods {', '.join(f'{o} {scene.objects[o].size:g}' for o in goods)})"
            )
            continue
        for n, (obj, spot) in enumerate(packing.slots):
            robot, event = goods[obj]
            planner.spots.setdefault(robot, {})[event] = spot
            for later, _ in packing.slots[n + 1 :]:
                if goods[later][0] != robot:
                    planner.placed.setdefault(goods[later][0], {})[obj] = spot
    return why_not


def _extent(workspace) -> str:
    """A rectangular workspace's size in words (mm)."""
    (x0, x1), (y0, y1) = workspace.ranges
    return f"{x1 - x0:g} x {y1 - y0:g} mm"


def _plan_in_turn(
    base: Mapping[str, tuple[Event, ...]], givers: Handovers, planner: _Planner
) -> dict[str, Synthesis]:
    """Every robot's first plan, givers of goods before their receivers.

    Robots that receive nothing are planned together; once a giver is planned, the spot where
    its plan drops the goods becomes the receiver's (:meth:`_Planner.hand_over`), and the
    receiver is planned in a later turn.  A receiver that cannot pick them there, and a cycle
    of givers and receivers, get a spot chosen for both
    (:func:`cosmop.planning.aside.handover_spot`): the giver is planned again to drop there.
    """
    results: dict[str, Synthesis] = {}
    for robots, chosen in givers.turns(tuple(base)):
        for h in chosen:
            _choose_spot(h, planner)
        results.update(planner.run({r: base[r] for r in robots}))
        for h in givers.items:
            if h.giver not in robots:
                continue
            pinned = planner.spots.get(h.giver, {}).get(h.drop)
            plan = results[h.giver].plan
            spot = pinned if pinned is not None else _drop_spot(plan, h) if plan is not None else None
            if spot is None:
                continue
            planner.hand_over(h, spot)
            if pinned is None:  # its plan drops there already: its answer with the spot pinned too
                planner.cache[planner.key(h.giver, base[h.giver])] = results[h.giver]
        stuck = [h for h in givers.items if h.receiver in robots and not results[h.receiver].feasible]
        for h in stuck:  # the giver's spot does not suit the receiver: one for both
            if _choose_spot(h, planner):
                results.update(planner.run({r: base[r] for r in (h.giver, h.receiver)}))
    return results


def _choose_spot(handover: Handover, planner: _Planner) -> bool:
    """Give `handover` a spot both robots can dock to, clear of the spots other goods are
    handed over at; whether there is a new one."""
    scene = planner.scenario.scene
    spots = {o: p for placed in planner.placed.values() for o, p in placed.items() if o != handover.obj}
    scene = _goods_at(scene, spots)
    robots = (handover.giver, handover.receiver)
    spot = handover_spot(scene, handover.obj, handover.drop.workspace, robots)
    if spot is None or planner.placed.get(handover.receiver, {}).get(handover.obj) == spot:
        return False
    planner.hand_over(handover, spot)
    return True


def _goods_at(scene: Scene, positions: Mapping[str, tuple[float, float]]) -> Scene:
    """`scene` with the goods of `positions` lying there (mm) instead."""
    if not positions:
        return scene
    objects = {o: replace(v, position=positions.get(o, v.position)) for o, v in scene.objects.items()}
    return replace(scene, objects=objects)


def _drop_spot(plan: RobotPlan, handover: Handover) -> tuple[float, float] | None:
    """Where `plan` puts the goods of `handover` down: its `nth` DropOff of them."""
    drops = [s for s in plan.steps if s.primitive == Primitive.DROPOFF and s.object == handover.obj]
    if handover.nth >= len(drops):
        return None
    return tuple(drops[handover.nth].objects[handover.obj].position)


def _plan_messages(plans: Mapping[str, RobotPlan], notes: Mapping[str, tuple[str, str]]) -> list[PlanMessage]:
    """The plan file's entries for the messages of the mission (orders, user's messages)."""
    out = []
    for robot, plan in plans.items():
        for name in plan.mission:
            if name in notes and name.startswith("msg(") and name.split(",")[0][4:] == robot:
                kind, text = notes[name]
                out.append(PlanMessage(name, kind, text))
    return out


def _base_index(sequence: tuple[Event, ...], index: int) -> int:
    """Index in the sequence without away events of the event at ``index`` of `sequence`."""
    return sum(1 for e in sequence[:index] if e.kind != "away")


def _coordinate_requests(
    base: dict[str, tuple[Event, ...]],
    results: dict[str, Synthesis],
    planner: _Planner,
    max_iterations: int,
    reasons: list[str],
    replans: list[str],
) -> tuple[Coordinated | None, dict[str, tuple[Event, ...]], int, bool]:
    """Turn requests into away messages until no plan asks for anything new (step 3)."""
    current, coordinated, iterations = dict(base), None, 0
    asked: dict[str, list[tuple[str, int]]] | None = {r: [] for r in base}
    while True:
        if any(not res.feasible for res in results.values()):
            reasons += [res.reason for res in results.values() if not res.feasible]
            return coordinated, current, iterations, False
        t0 = time.perf_counter()
        scene = planner.scenario.scene  # with the places of goods moved aside so far
        requests = {
            r: [(o, _base_index(current[r], i)) for o, i in request_phases(res.plan, r, scene, current[r])]
            for r, res in results.items()
        }
        if requests == asked:
            planner.phases["coordinate"] += time.perf_counter() - t0
            return coordinated, current, iterations, True
        if iterations >= max_iterations:
            reasons.append(f"coordination did not settle within {max_iterations} rounds")
            return coordinated, current, iterations, False
        iterations, asked = iterations + 1, requests
        coordinated = coordinate(base, requests)
        planner.phases["coordinate"] += time.perf_counter() - t0
        forbid = _bad_requests(coordinated)
        if forbid:
            # when goods nobody moves are asked for, a failed trial leads to a helper: no reasons
            why_not = _forbid(forbid, base, results, planner, replans, explain=not coordinated.unanswered)
            if why_not and coordinated.unanswered:  # nobody moves what blocks: give it a helper
                why_not = _move_aside(
                    coordinated.unanswered, requests, base, current, results, planner, replans
                )
                asked = None  # the same requests now have a responder: coordinate them again
            if why_not:
                reasons.extend(why_not)
                return coordinated, current, iterations, False
            continue
        changed = {r: events for r, events in coordinated.sequences.items() if events != current[r]}
        current.update(changed)
        results.update(planner.run(changed))


def _bad_requests(coordinated: Coordinated) -> list[dict[str, dict[str, str]]]:
    """Ways out of bad requests, to try in order: ``{robot: {object: why}}`` to forbid.

    Requests nobody can answer are all forbidden at once.  Of the requests that close a wait
    cycle, forbidding one robot's may break the cycle for everyone: one option per waiting robot.
    """
    unanswered: dict[str, dict[str, str]] = {}
    for obj, requester in coordinated.unanswered:
        unanswered.setdefault(requester, {})[obj] = f"no robot's mission picks {obj}"
    if unanswered or coordinated.deadlock_free:
        return [unanswered] if unanswered else []
    words = {r: [e.name for e in seq] for r, seq in coordinated.sequences.items()}
    options = []
    for line in blocking_word(words) or ():
        if line.startswith("[") and " waits for away(" in line:
            robot, _, event = line[1:-1].partition(" waits for ")
            obj = event[5:].split(",")[0]
            options.append({robot: {obj: f"waiting for {obj} deadlocks the team ({event})"}})
    return options


def _forbid(
    options: list[dict[str, dict[str, str]]],
    base: dict[str, tuple[Event, ...]],
    results: dict[str, Synthesis],
    planner: _Planner,
    replans: list[str],
    explain: bool = True,
) -> list[str]:
    """Re-plan robots without the requests of the first option that leaves them a plan; the
    reasons of every option if none does (``[]``: done; with `explain` false, reasons without
    the solver's why)."""
    why_not: list[str] = []
    for forbid in options:
        saved = dict(planner.forbidden)
        for robot, why in forbid.items():
            planner.forbidden[robot] = planner.forbidden.get(robot, frozenset()) | frozenset(why)
        fresh = planner.run({r: base[r] for r in forbid}, explain=explain)
        failed = [(r, res) for r, res in fresh.items() if not res.feasible]
        if not failed:
            results.update(fresh)
            for robot, why in forbid.items():
                asked = ", ".join(sorted(why))
                replans.append(f"{robot} re-planned without requesting {asked}: {'; '.join(why.values())}")
            return []
        planner.forbidden = saved
        for robot, res in failed:
            for obj, why in sorted(forbid[robot].items()):
                why_not.append(
                    f"{robot} needs {obj} moved away, but {why}; without that request: {res.reason}"
                )
    return why_not or ["the requests cannot be answered"]


def _move_aside(
    unanswered: Iterable[tuple[str, str]],
    requests: Mapping[str, list[tuple[str, int]]],
    base: dict[str, tuple[Event, ...]],
    current: dict[str, tuple[Event, ...]],
    results: dict[str, Synthesis],
    planner: _Planner,
    replans: list[str],
) -> list[str]:
    """Give goods that block a robot, and that no mission moves, a helper that sets them aside.

    The paper's re-allocation: the requester itself is tried first (no message needed), then
    the other robots, those whose plans end soonest first.  The helper's mission gains
    ``pick`` and ``drop`` of the goods at a free place (:func:`cosmop.planning.aside.place_aside`)
    -- for the requester right before the event its request prepares (before the pick it is
    carrying from, if any), for another robot at its start, and the requester's request is then
    answered like any other (``away``).  Returns the reasons, per goods and robot tried, when
    some goods find no helper (``[]``: every one found one).
    """
    why_not = []
    for obj, requester in unanswered:
        if any(task.object == obj for task in planner.added):
            continue  # another requester's helper moves it already: the next round answers this one
        index = next((i for o, i in requests.get(requester, ()) if o == obj), 0)
        plans = {r: res.plan for r, res in results.items() if res.plan is not None}
        others = sorted((r for r in base if r != requester), key=lambda r: (_length(plans.get(r)), r))
        for helper in (requester, *others):  # trials first: a failed one need not say why
            outcome = _set_aside(obj, requester, helper, index, plans, base, planner, explain=False)
            if isinstance(outcome, str):
                continue
            task, events, result = outcome
            planner.added.append(task)
            base[helper] = current[helper] = events
            results[helper] = result
            # the others never see the goods move (their models keep them where they were):
            # from now on their plans keep out of the place, as from a wall
            where = square(*task.point, planner.scenario.scene.objects[obj].size)
            walls = _walls_around(where, _AROUND, f"the place {helper} sets {obj} down at")
            for other in base:
                if other != helper:
                    planner.obstacles[other] = planner.obstacles.get(other, ()) + walls
            place = show_point(task.point, planner.scenario.scene.units)
            replans.append(f"{helper} sets {obj} down at {place}: {task.why}")
            break
        else:
            tried = [
                f"{helper}: {_set_aside(obj, requester, helper, index, plans, base, planner)}"
                for helper in (requester, *others)
            ]
            why_not.append(
                f"{requester} needs {obj} moved away, but no mission moves it and no robot can set it "
                f"aside ({'; '.join(tried)})"
            )
    return why_not


def _set_aside(obj, requester, helper, index, plans, base, planner, explain: bool = True) -> tuple | str:
    """``(task, mission, synthesis)`` of `helper` with the goods set aside added to its
    mission, or why it cannot."""
    scene = planner.scenario.scene
    moved = {t.object: replace(scene.objects[t.object], position=t.point) for t in planner.added}
    point = place_aside(replace(scene, objects={**scene.objects, **moved}), obj, helper, plans)
    if point is None:
        return f"no free place near {obj} that it can dock to"
    workspace = next(
        w for n in itertools.count() if (w := f"aside_{obj}" + (f"_{n}" if n else "")) not in scene.workspaces
    )
    how = (
        "does it itself"
        if helper == requester
        else f"moves it and tells {requester} (of the robots that can, its plan ends soonest)"
    )
    why = f"{requester} needs {obj} moved out of its way and no mission moves it; {helper} {how}"
    task = AddedTask(helper, obj, workspace, point, why)
    events = _with_task(base[helper], task, index if helper == requester else 0)
    saved = planner.scenario
    planner.scenario = PlanSet(saved.name, True, added=(task,)).extend(saved)
    result = planner.run({helper: events}, explain=explain)[helper]
    if not result.feasible:
        planner.scenario = saved
        return f"cannot move it ({result.reason})"
    return task, events, result


def _length(plan: RobotPlan | None) -> int:
    return plan.horizon if plan is not None else MAX_STEPS


def _with_task(events: tuple[Event, ...], task: AddedTask, at: int) -> tuple[Event, ...]:
    """`events` with the task's pick and drop inserted at `at`, or earlier, before the pick of
    goods the robot still carries there (it carries one thing at a time)."""
    carrying = None
    for k, event in enumerate(events[:at]):
        if event.kind == "pick":
            carrying = k
        elif event.kind == "drop" and carrying is not None and events[carrying].obj == event.obj:
            carrying = None
    at = carrying if carrying is not None else at
    return (*events[:at], *task.events, *events[at:])


def _make_safe(
    scenario: Scenario,
    current: dict[str, tuple[Event, ...]],
    results: dict[str, Synthesis],
    planner: _Planner,
    settings: ConflictSettings | None,
    reasons: list[str],
    replans: list[str],
    max_rounds: int = 6,
    max_total: int = 16,
) -> TeamSafety:
    """Order every conflict by messages; re-plan around the ones no order resolves (step 4).

    Each round, the robots that give way in unresolved conflicts (:func:`_give_way`) are
    re-planned with the space of the other side as an obstacle, until the conflicts are
    ordered, or `max_rounds` rounds pass without fewer unresolved conflicts than before (a
    large team may need more rounds, each resolving some), or `max_total` rounds are spent.
    A robot that cannot keep clear is given back its plan and the other side gives way instead,
    where it can.
    """
    settings = settings or ConflictSettings()
    best, since = None, 0
    for n in range(max_total + 1):
        if reasons:
            return make_team_safe(
                scenario.scene, {r: res.plan for r, res in results.items()}, settings=settings
            )
        safety = _team_safe(planner, {r: res.plan for r, res in results.items()}, settings)
        if safety.safe:
            return safety
        left = len(safety.unresolved)
        best, since = (left, 0) if best is None or left < best else (best, since + 1)
        last = since >= max_rounds or n == max_total
        stuck = [c for c in safety.unresolved if not safety.detours(c)]
        if stuck or last:
            conflict = (stuck or list(safety.unresolved))[0]
            reasons.append(
                f"no order or re-plan keeps {' and '.join(conflict.robots)} apart: {conflict.describe()}"
            )
            return safety
        moves = _give_way(safety, safety.unresolved)
        fresh, failed = _detour(planner, current, moves, settings, replans)
        instead = _give_way(safety, [c for r in failed for c, _ in moves[r]], set(failed))
        if instead:  # the other side of their conflicts gives way instead, where it can
            again, failed = _detour(planner, current, instead, settings, replans)
            fresh.update(again)
        for robot, (conflict, why) in failed.items():
            reasons.append(
                f"{robot} cannot keep clear of the space it shares with another robot "
                f"({conflict.describe()}): {why}"
            )
        if reasons:
            return safety
        results.update(fresh)
    return safety


def _team_safe(planner: _Planner, plans: Mapping[str, RobotPlan], settings: ConflictSettings) -> TeamSafety:
    """:func:`make_team_safe` of `plans`, its new messages named apart from those the plans
    already send, timed as the conflict phase."""
    used = {name for p in plans.values() for name in p.mission if name.startswith("msg(")}
    t0 = time.perf_counter()
    safety = make_team_safe(planner.scenario.scene, plans, settings=settings, used=used)
    planner.phases["conflicts"] += time.perf_counter() - t0
    return safety


def _give_way(
    safety: TeamSafety, conflicts, exclude: frozenset[str] | set[str] = frozenset()
) -> dict[str, list]:
    """Who gives way in which of `conflicts`: ``robot -> [(conflict, space to avoid)]``.

    Each conflict's best way (:meth:`TeamSafety.detours`), the conflicts with the best ways
    first, except that two robots never avoid each other in one round (each would wall itself
    off from the other's old places, both may be shut out, as two goods meant for one dock
    spot were): such a conflict waits for the next round, when the other's new plan may have
    settled it.  Robots in `exclude` keep their plans.
    """
    moves: dict[str, list] = {}
    avoids: set[tuple[str, str | None]] = set()
    best = {
        c: next(((n, r, k) for n, r, k in safety.detours(c) if r not in exclude), None) for c in conflicts
    }
    for conflict in sorted((c for c in best if best[c] is not None), key=lambda c: best[c][0]):
        _, robot, keep = best[conflict]
        keeper = next((r for r in conflict.robots if r != robot), None)
        if (keeper, robot) in avoids:
            continue  # the two would avoid each other: next round
        moves.setdefault(robot, []).append((conflict, keep))
        avoids.add((robot, keeper))
    return moves


def _detour(planner, current, moves, settings, replans) -> tuple[dict[str, Synthesis], dict[str, tuple]]:
    """Re-plan every robot in `moves` around its spaces; a robot that fails gets its walls back.

    Returns the new syntheses and, for each robot that failed, its first conflict and why."""
    saved = dict(planner.obstacles)
    walls = {}
    for robot, items in moves.items():
        walls[robot] = tuple(
            w for _, keep in items for w in _walls_around(keep.region, settings, f"the space of {keep.label}")
        )
        replans.append(f"{robot} re-planned around the space it shares: {items[0][0].describe()}")
    fresh = _replan_within(planner, current, walls)
    failed = {}
    for robot, res in list(fresh.items()):
        if not res.feasible:
            failed[robot] = (moves[robot][0][0], res.reason)
            planner.obstacles[robot] = saved.get(robot, ())
            if not planner.obstacles[robot]:
                del planner.obstacles[robot]
            del fresh[robot]
    return fresh, failed


def _replan_within(
    planner: _Planner,
    current: Mapping[str, tuple[Event, ...]],
    walls: Mapping[str, tuple[Wall, ...]],
    explain: bool = True,
    windows: Mapping[str, tuple[int, int]] | None = None,
) -> dict[str, Synthesis]:
    """Every robot of `walls` re-planned with them added to its walls (kept in the planner).

    The requests are settled by now: a re-plan may ask only for goods the robot already asks
    for.  With `explain` false an infeasible answer only says so (a trial); `windows` bounds
    the lengths searched (:meth:`_Planner.run`).
    """
    objects = frozenset(planner.scenario.scene.objects)
    for robot, extra in walls.items():
        planner.obstacles[robot] = planner.obstacles.get(robot, ()) + extra
        asked = {e.obj for e in current[robot] if e.kind == "away" and e.receiver == robot}
        planner.forbidden[robot] = planner.forbidden.get(robot, frozenset()) | (objects - asked)
    return planner.run({robot: current[robot] for robot in walls}, explain, windows)


def _shorten_waits(
    current: Mapping[str, tuple[Event, ...]],
    results: dict[str, Synthesis],
    planner: _Planner,
    settings: ConflictSettings | None,
    safety: TeamSafety,
    replans: list[str],
    budget: int,
) -> TeamSafety:
    """Where waiting for a shared place costs the team more than a way around, take the way around.

    Each robot was planned alone, so its route ignores the others; the conflict step then makes
    robots wait for each other.  The waits on the itinerary's critical path
    (:attr:`~cosmop.planning.teamsafety.Wait.critical`; no other wait, shortened, ends the team
    sooner), the longest first, get the ways around that apply (:func:`_ways_around`): the
    two robots re-planned to pass each other in lanes, or the waiting robot re-planned with the
    other's occupancy as walls.  A way is kept when the plans stay team-safe and the team's
    expected makespan goes down; else the robots keep their plans and walls.  At most `budget`
    ways are tried (each one synthesis per robot re-planned, both robots' at once, of at most
    :data:`TRIAL_STEPS` steps more than its plan, and one conflict step), so that planning time
    stays bounded.
    """
    settings = settings or ConflictSettings()
    scene = planner.scenario.scene
    tried: set = set()
    while budget > 0:
        worth = (w for w in safety.waits if w.critical and w.seconds >= MIN_WAIT)
        way = next(
            (way for w in worth for way in _ways_around(w, safety, scene, settings) if way[0] not in tried),
            None,
        )
        if way is None:
            break
        key, why, walls = way
        tried.add(key)
        budget -= 1
        saved = dict(planner.obstacles), dict(planner.forbidden)
        # with more walls no plan is shorter than the robot's; a way much longer is no way round
        windows = {r: (results[r].horizon, results[r].horizon + TRIAL_STEPS) for r in walls}
        fresh = _replan_within(planner, current, walls, False, windows)
        if all(res.feasible for res in fresh.values()):
            candidate = _team_safe(
                planner, {r: (fresh.get(r) or res).plan for r, res in results.items()}, settings
            )
            if candidate.safe and candidate.makespan < safety.makespan - 1e-6:
                replans.append(
                    f"{why}: the team is expected done in {candidate.makespan:.1f} s instead of "
                    f"{safety.makespan:.1f} s"
                )
                results.update(fresh)
                safety = candidate
                continue
        planner.obstacles, planner.forbidden = saved
    return safety


def _ways_around(wait, safety: TeamSafety, scene: Scene, settings: ConflictSettings) -> list[tuple]:
    """The ways around one wait, to try in order: ``(key, why, robot -> walls)``.

    Two robots that drive head-on through a place wide enough for both pass each other in
    lanes (:func:`cosmop.planning.lanes.lanes`); the waiting robot can keep out of what it
    waits for, where that leaves its fixed places free (:meth:`TeamSafety.detours`).
    """
    out = []
    robot, other = wait.robot, wait.other
    if wait.drives is not None:
        shared = wait.first.region.intersection(wait.then.region)
        drives = {other: wait.drives[0], robot: wait.drives[1]}
        keep = lanes(scene, drives, shared, settings.clearance, safety.fixed)
        if keep is not None:
            walls = {
                r: _walls_around(region, settings, f"the lane {next(o for o in keep if o != r)} keeps to")
                for r, region in keep.items()
            }
            key = (
                "lanes",
                *sorted((r, tuple(round(v) for v in region.bounds)) for r, region in keep.items()),
            )
            why = (
                f"{robot} and {other} re-planned to pass each other in lanes instead of {robot} waiting "
                f"{wait.seconds:.1f} s where {wait.conflict.describe()}"
            )
            out.append((key, why, walls))
    for _, mover, keep in safety.detours(wait.conflict):
        if mover == robot:
            walls = {robot: _walls_around(keep.region, settings, f"the space of {keep.label}")}
            why = (
                f"{robot} re-planned around the space of {keep.label} instead of waiting {wait.seconds:.1f} s"
            )
            out.append((("around", robot, keep.label), why, walls))
            break
    return out


def _walls_around(region, settings: ConflictSettings, label: str) -> tuple[Wall, ...]:
    """Wall segments around `region`, grown by half the clearance (for a robot to keep out),
    labelled with what they keep it out of (reasons name that, never the piece)."""
    grown = region.buffer(settings.clearance / 2.0, join_style="mitre")
    ring = list(shapely.get_coordinates(grown.exterior))
    return tuple(
        Wall((float(p[0]), float(p[1])), (float(q[0]), float(q[1])), label)
        for p, q in itertools.pairwise(ring)
        if tuple(p) != tuple(q)
    )
