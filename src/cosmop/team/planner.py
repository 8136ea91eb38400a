"""The team's planner: every robot's synthesis under the restrictions the team puts on it.

A robot's shortest plan (:func:`cosmop.planning.synthesis.synthesize`) depends on its mission
and on what the rest of the team asks of it: goods it may not ask to have moved (requests nobody
answers), walls around the space others keep (detours), goods it finds where another robot
hands them over, drops pinned to a slot.  :class:`Planner` holds those restrictions, runs the
syntheses (in worker processes or on a cluster when given an executor), answers a question it
has seen before from its cache, and times the phases of :func:`cosmop.team.loop.plan_team`.
"""

from __future__ import annotations

import multiprocessing
import signal
import time
from collections.abc import Callable, Hashable, Mapping, Sequence
from concurrent.futures import Executor, Future, ProcessPoolExecutor
from dataclasses import dataclass, field, replace
from typing import Any, ParamSpec, TypeVar

from cosmop.automata import DFA
from cosmop.events import Event, parse_event
from cosmop.io import uninterrupted
from cosmop.planning.plan_types import MAX_STEPS, AddedTask
from cosmop.planning.synthesis import DEFAULT_RLIMIT, Synthesis, synthesize
from cosmop.scene import Scenario, Scene, Wall
from cosmop.team.handover import Handover

__all__ = [
    "Checkpoint",
    "Planner",
    "Replanned",
    "Restrictions",
    "SynthesisJob",
    "Workers",
    "default_horizon",
    "ends_away",
    "goods_at",
]

_P = ParamSpec("_P")
_T = TypeVar("_T")

LocalMission = tuple[Event, ...] | DFA
"""A robot's local mission: a word of events, or a branching mission (a DFA over event names)."""

Window = tuple[int, int]
"""Plan lengths a synthesis searches, ``(least, most)`` steps."""


@dataclass(frozen=True)
class SynthesisJob:
    """One robot's synthesis, as sent to a worker process.

    Attributes
    ----------
    scene : Scene
        The robot's scene: the team's walls for it added, goods where it finds them.
    robot : str
        The robot's id.
    events : tuple of Event, or DFA
        Its mission.
    max_horizon, rlimit : int
        The longest plan searched (steps) and the solver's resource limit.
    unrequestable : frozenset of str
        Goods it may not ask another robot to move away.
    explain : bool
        Whether an infeasible answer says why (an unsat core: more solver calls).
    spots : tuple
        Drops pinned for a hand-over: ``(drop event, (x, y) mm)``.
    min_horizon : int
        No shorter plan exists (a re-plan with more walls starts here).
    home : bool
        The plan ends at the robot's home although its mission does not say so (the last of
        `events` is a ``return`` added for it: the plan's word leaves it out).
    """

    scene: Scene
    robot: str
    events: LocalMission
    max_horizon: int
    rlimit: int
    unrequestable: frozenset[str] = frozenset()
    explain: bool = True
    spots: tuple[tuple[Event, tuple[float, float]], ...] = ()
    min_horizon: int = 0
    home: bool = False


def ends_away(events: Sequence[Event]) -> bool:
    """Whether a robot's word `events` lets its plan end away from home (it has no ``return``).

    Parameters
    ----------
    events : sequence of Event
        The robot's word.
    """
    return not any(e.kind == "return" for e in events)


def synthesize_job(job: SynthesisJob) -> Synthesis:
    """One robot's synthesis (module level, so worker processes can run it).

    Parameters
    ----------
    job : SynthesisJob
        The question, whole.
    """
    result = synthesize(
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
    if not job.home or result.plan is None:
        return result
    # the drive home is motion only: the word is the mission's, without the return added
    plan, last = result.plan, len(result.plan.mission) - 1
    while plan.mission[last].kind != "return":
        last -= 1
    return replace(result, plan=replace(plan, mission=plan.mission[:last] + plan.mission[last + 1 :]))


class Workers(ProcessPoolExecutor):
    """The planner's worker processes: Ctrl-C is the parent's, and an interrupt ends them at once.

    A terminal sends Ctrl-C (SIGINT) to every process of its foreground job, these workers too.
    A worker ignores it (its initializer, :func:`_leave_interrupts`); the parent answers it, and
    :meth:`stop` ends the workers.  Workers are forked where the platform allows (no re-import of
    the package), inside :meth:`submit`: the parent holds Ctrl-C back while it submits
    (:func:`cosmop.io.uninterrupted`), so that an interrupt can neither stop it between starting
    a worker and recording it (a worker nobody would end) nor reach a worker before its
    initializer runs (the worker is born with the parent's noting handler, which only notes it).

    Parameters
    ----------
    workers : int
        How many processes.
    """

    def __init__(self, workers: int) -> None:
        methods = multiprocessing.get_all_start_methods()
        context = multiprocessing.get_context("fork" if "fork" in methods else "spawn")
        super().__init__(max_workers=workers, mp_context=context, initializer=_leave_interrupts)

    def submit(self, fn: Callable[_P, _T], /, *args: _P.args, **kwargs: _P.kwargs) -> Future[_T]:
        """Start ``fn(*args, **kwargs)`` in a worker, with Ctrl-C held back meanwhile.

        Parameters
        ----------
        fn : callable
            A module-level function (it is pickled by name).
        *args, **kwargs
            Its arguments (pickled).
        """
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
            # the pool's private parts (typeshed types them loosely)
            manager: Any = self._executor_manager_thread
            results: Any = self._result_queue
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
    """The longest plan tried for a mission when the caller sets none.

    16, or 3 steps per mission event plus 6 when that is more (a robot with several deliveries
    needs the room; detours around the others' places add steps), never more than a plan file
    may hold.

    Parameters
    ----------
    events : tuple of Event
        The robot's mission (its messages are not counted).
    """
    return min(MAX_STEPS, max(16, 3 * sum(1 for e in events if not e.is_message) + 6))


def goods_at(scene: Scene, positions: Mapping[str, tuple[float, float]]) -> Scene:
    """`scene` with the goods of `positions` lying there instead.

    Parameters
    ----------
    scene : Scene
        The scene.
    positions : mapping of str to (float, float)
        Goods' ids to their new places, mm.
    """
    if not positions:
        return scene
    objects = {o: replace(v, position=positions.get(o, v.position)) for o, v in scene.objects.items()}
    return replace(scene, objects=objects)


def _automaton_key(dfa: DFA) -> tuple[Hashable, ...]:
    """A branching mission by value (DFAs compare by identity)."""
    return ("automaton", dfa.alphabet, dfa.delta.tobytes(), dfa.initial, dfa.marked.tobytes())


@dataclass(frozen=True)
class Restrictions:
    """What the team asks of its robots' syntheses at one moment (to try something, then undo it).

    Attributes
    ----------
    forbidden : mapping of str to frozenset of str
        Per robot, the goods it may not request.
    obstacles : mapping of str to tuple of Wall
        Per robot, walls added around the space others keep.
    """

    forbidden: Mapping[str, frozenset[str]]
    obstacles: Mapping[str, tuple[Wall, ...]]


@dataclass(frozen=True)
class Checkpoint:
    """All that the loop's steps change in a :class:`Planner` (its answers aside), to go back to.

    Attributes
    ----------
    restrictions : Restrictions
        The forbidden requests and added walls.
    added : tuple of AddedTask
        Goods moved aside.
    scenario : Scenario
        The scenario with their places.
    placed, spots : mapping
        The hand-overs' and shared docks' spots (:attr:`Planner.placed`, :attr:`Planner.spots`).
    homing : frozenset of str
        The robots sent home at the end (:attr:`Planner.homing`).
    """

    restrictions: Restrictions
    added: tuple[AddedTask, ...]
    scenario: Scenario
    placed: Mapping[str, Mapping[str, tuple[float, float]]]
    spots: Mapping[str, Mapping[Event, tuple[float, float]]]
    homing: frozenset[str] = frozenset()


@dataclass
class Planner:
    """Runs the robots' syntheses under the team's restrictions and keeps the phase times.

    The same question (mission and restrictions) is never solved twice: every answer is kept.

    Parameters
    ----------
    scenario : Scenario
        The scenario planned; it grows the places where goods are set aside
        (:class:`~cosmop.planning.plan_types.AddedTask`).
    executor : concurrent.futures.Executor, optional
        Where to run syntheses (worker processes, a Dask cluster); ``None`` runs them here.
    on_robot : callable, optional
        Called with the robot and its synthesis after each synthesis (progress).
    max_horizon : int, optional
        The longest plan searched; ``None``: :func:`default_horizon` of each mission.
    rlimit : int
        The solver's resource limit per call.
    phases : dict of str to float
        Seconds per phase of the loop (:meth:`count_time`); the planner adds the synthesis time
        to ``phases["synthesize"]``.

    Attributes
    ----------
    forbidden : dict of str to frozenset of str
        Per robot, the goods it may not request.
    added : list of AddedTask
        Goods moved aside; their places extend the scenario.
    obstacles : dict of str to tuple of Wall
        Per robot, walls around the space others keep.
    placed : dict of str to dict
        Hand-overs: per receiver, goods it finds where the giver drops them, ``{goods: (x, y)}`` mm.
    spots : dict of str to dict
        Hand-overs and shared docks: per robot, drops held to a spot, ``{drop event: (x, y)}`` mm.
    homing : set of str
        Robots whose plans end at home although their missions end elsewhere: a robot done
        where others must pass (in a dock they drop in, say) drives home out of their way.  The
        drive is motion only; the plan's word stays the mission's.
    budget, deadline : float or None
        The planning budget (s) and when it ends (:func:`time.perf_counter`), from
        :meth:`set_budget`; ``None``: no budget.
    cache : dict
        Every answer, by question (:meth:`key`).
    """

    scenario: Scenario
    executor: Executor | None = None
    on_robot: Callable[[str, Synthesis], None] | None = None
    max_horizon: int | None = None
    rlimit: int = DEFAULT_RLIMIT
    phases: dict[str, float] = field(default_factory=lambda: {"synthesize": 0.0})
    forbidden: dict[str, frozenset[str]] = field(default_factory=dict, init=False)
    added: list[AddedTask] = field(default_factory=list, init=False)
    obstacles: dict[str, tuple[Wall, ...]] = field(default_factory=dict, init=False)
    placed: dict[str, dict[str, tuple[float, float]]] = field(default_factory=dict, init=False)
    spots: dict[str, dict[Event, tuple[float, float]]] = field(default_factory=dict, init=False)
    homing: set[str] = field(default_factory=set, init=False)
    budget: float | None = field(default=None, init=False)
    deadline: float | None = field(default=None, init=False)
    cache: dict[tuple[Hashable, ...], Synthesis] = field(default_factory=dict, init=False)

    def count_time(self, phase: str, seconds: float) -> None:
        """Add `seconds` to the time of `phase` in :attr:`phases`.

        Parameters
        ----------
        phase : str
            A phase of the loop, e.g. ``"synthesize"``.
        seconds : float
            Wall time spent, s.
        """
        self.phases[phase] = self.phases.get(phase, 0.0) + seconds

    def set_budget(self, seconds: float | None) -> None:
        """From now on, the team's planning may take `seconds` (``None``: no limit): past it, the
        loop tries nothing more for a team it has not planned yet (:meth:`over_budget`).

        Parameters
        ----------
        seconds : float or None
            The budget, s of wall time.
        """
        self.budget = seconds
        self.deadline = None if seconds is None else time.perf_counter() + seconds

    def over_budget(self) -> bool:
        """Whether the planning budget (:meth:`set_budget`) is spent."""
        return self.deadline is not None and time.perf_counter() > self.deadline

    def restrictions(self) -> Restrictions:
        """The forbidden requests and added walls now, to :meth:`restore` after a trial."""
        return Restrictions(dict(self.forbidden), dict(self.obstacles))

    def restore(self, saved: Restrictions) -> None:
        """Put back the restrictions of :meth:`restrictions`.

        Parameters
        ----------
        saved : Restrictions
            What :meth:`restrictions` returned before the trial.
        """
        self.forbidden, self.obstacles = dict(saved.forbidden), dict(saved.obstacles)

    def checkpoint(self) -> Checkpoint:
        """Where the team's planning stands now, to :meth:`rewind` to after a try that failed."""
        return Checkpoint(
            self.restrictions(),
            tuple(self.added),
            self.scenario,
            {r: dict(p) for r, p in self.placed.items()},
            {r: dict(s) for r, s in self.spots.items()},
            frozenset(self.homing),
        )

    def rewind(self, mark: Checkpoint) -> None:
        """Go back to `mark` (:meth:`checkpoint`); the answers found since are kept.

        Parameters
        ----------
        mark : Checkpoint
            What :meth:`checkpoint` returned.
        """
        self.restore(mark.restrictions)
        self.added, self.scenario = list(mark.added), mark.scenario
        self.placed = {r: dict(p) for r, p in mark.placed.items()}
        self.spots = {r: dict(s) for r, s in mark.spots.items()}
        self.homing = set(mark.homing)

    def forbid(self, robot: str, objects: frozenset[str]) -> None:
        """From now on `robot` may not request `objects` either.

        Parameters
        ----------
        robot : str
            The robot.
        objects : frozenset of str
            Goods' ids.
        """
        self.forbidden[robot] = self.forbidden.get(robot, frozenset()) | objects

    def wall_off(self, robot: str, walls: tuple[Wall, ...]) -> None:
        """From now on `robot` plans with `walls` as obstacles too.

        Parameters
        ----------
        robot : str
            The robot.
        walls : tuple of Wall
            The walls (labelled with what they keep the robot out of).
        """
        self.obstacles[robot] = self.obstacles.get(robot, ()) + walls

    def _restricting(self, robot: str, forbidden: Mapping[str, frozenset[str]]) -> tuple[Hashable, ...]:
        """Everything besides the mission that decides `robot`'s synthesis (the places of the
        goods it sets aside too: after a :meth:`rewind`, goods set aside again take the same
        workspace name, maybe at another place)."""
        return (
            forbidden.get(robot, self.forbidden.get(robot, frozenset())),
            self.obstacles.get(robot, ()),
            tuple(sorted(self.placed.get(robot, {}).items())),
            tuple(sorted(self.spots.get(robot, {}).items())),
            tuple((t.workspace, t.object, t.point) for t in self.added if t.robot == robot),
            robot in self.homing,
        )

    def key(
        self,
        robot: str,
        events: LocalMission,
        explain: bool = True,
        window: Window | None = None,
        forbidden: Mapping[str, frozenset[str]] | None = None,
    ) -> tuple[Hashable, ...]:
        """The cache's key of a question.

        Parameters
        ----------
        robot : str
            The robot.
        events : tuple of Event, or DFA
            Its mission.
        explain : bool
            Whether the answer explains an infeasible mission.
        window : (int, int), optional
            The lengths searched, when not every one: it keys an answer that found no plan in it.
        forbidden : mapping of str to frozenset of str, optional
            Forbidden requests that replace the planner's for the robots they name.
        """
        mission = _automaton_key(events) if isinstance(events, DFA) else tuple(events)
        return (
            robot,
            mission,
            *self._restricting(robot, forbidden or {}),
            *(() if explain else ("unexplained",)),
            *(() if window is None else (window,)),
        )

    def remember(
        self, robot: str, events: tuple[Event, ...], forbidden: frozenset[str], result: Synthesis
    ) -> None:
        """Keep `result` as the answer for `events` with `forbidden` (one it answers exactly).

        Parameters
        ----------
        robot : str
            The robot.
        events : tuple of Event
            The word `result` plans.
        forbidden : frozenset of str
            The goods it was not allowed to request.
        result : Synthesis
            The answer.
        """
        self.cache[self.key(robot, events, forbidden={robot: forbidden})] = result

    def hand_over(self, handover: Handover, spot: tuple[float, float]) -> None:
        """From now on the receiver finds the goods at `spot` and the giver drops them there.

        Parameters
        ----------
        handover : Handover
            The giver, the receiver, the goods and the giver's drop.
        spot : (float, float)
            Where, mm.
        """
        self.placed.setdefault(handover.receiver, {})[handover.obj] = spot
        self.spots.setdefault(handover.giver, {})[handover.drop] = spot

    def job(
        self,
        robot: str,
        events: LocalMission,
        explain: bool = True,
        window: Window | None = None,
        forbidden: Mapping[str, frozenset[str]] | None = None,
    ) -> SynthesisJob:
        """The synthesis that answers a question (see :meth:`key` for the parameters).

        Parameters
        ----------
        robot : str
            The robot.
        events : tuple of Event, or DFA
            Its mission.
        explain : bool
            Whether an infeasible answer says why.
        window : (int, int), optional
            The least and most steps searched.
        forbidden : mapping of str to frozenset of str, optional
            Forbidden requests that replace the planner's for the robots they name.
        """
        scene = self.scenario.scene
        extra = self.obstacles.get(robot, ())
        if extra:
            scene = replace(scene, obstacles=scene.obstacles + extra)
        scene = goods_at(scene, self.placed.get(robot, {}))
        # a branching mission gets the horizon of its alphabet: no word of it has more events
        mission = tuple(parse_event(e) for e in events.alphabet) if isinstance(events, DFA) else tuple(events)
        home = self.sent_home(robot, events)
        if home:
            mission = (*mission, Event("return", robot))
        horizon = self.max_horizon if self.max_horizon is not None else default_horizon(mission)
        least = 0
        if window is not None:
            least, horizon = window[0], min(horizon, window[1])
        unrequestable = (forbidden or {}).get(robot, self.forbidden.get(robot, frozenset()))
        spots = tuple(sorted(self.spots.get(robot, {}).items()))
        return SynthesisJob(
            scene,
            robot,
            events if isinstance(events, DFA) else mission,
            horizon,
            self.rlimit,
            unrequestable,
            explain,
            spots,
            least,
            home,
        )

    def sent_home(self, robot: str, events: LocalMission) -> bool:
        """Whether `robot`'s plan of `events` gets a drive home its mission does not ask for
        (:attr:`homing`; a word, not a DFA, with no ``return`` of its own).

        Parameters
        ----------
        robot : str
            The robot.
        events : tuple of Event, or DFA
            Its mission.
        """
        return robot in self.homing and not isinstance(events, DFA) and ends_away(events)

    def run(
        self,
        jobs: Mapping[str, LocalMission],
        *,
        forbidden: Mapping[str, frozenset[str]] | None = None,
        explain: bool = True,
        windows: Mapping[str, Window] | None = None,
    ) -> dict[str, Synthesis]:
        """Each robot's synthesis of its mission in `jobs`, in parallel when there is an executor.

        Parameters
        ----------
        jobs : mapping of str to mission
            Robot to mission (a word of events or a DFA).
        forbidden : mapping of str to frozenset of str, optional
            Goods the robots named may not request, for this call only (in place of the
            planner's :attr:`forbidden`).
        explain : bool
            With `explain` false an infeasible answer only says so (a trial: cheaper).
        windows : mapping of str to (int, int), optional
            Per robot, the lengths to search, ``(least, most)``: the least known (no shorter plan
            exists), the most a trial's bound; a plan found is the shortest all the same.
        """
        t0 = time.perf_counter()
        windows = windows or {}
        out = self._cached(jobs, forbidden, explain, windows)
        work = {
            robot: self.job(robot, events, explain, windows.get(robot), forbidden)
            for robot, events in jobs.items()
            if robot not in out
        }
        out.update(self._solve(work))
        for robot, events in jobs.items():
            window = windows.get(robot) if not out[robot].feasible else None
            self.cache[self.key(robot, events, explain or out[robot].feasible, window, forbidden)] = out[
                robot
            ]
        self.count_time("synthesize", time.perf_counter() - t0)
        return {robot: out[robot] for robot in jobs}

    def _cached(
        self,
        jobs: Mapping[str, LocalMission],
        forbidden: Mapping[str, frozenset[str]] | None,
        explain: bool,
        windows: Mapping[str, Window],
    ) -> dict[str, Synthesis]:
        """The answers known already: an explained answer serves every call."""
        out: dict[str, Synthesis] = {}
        for robot, events in jobs.items():
            hit = self.cache.get(self.key(robot, events, forbidden=forbidden))
            if hit is None and not explain:
                hit = self.cache.get(self.key(robot, events, False, None, forbidden))
            if hit is None and robot in windows:
                hit = self.cache.get(self.key(robot, events, explain, windows[robot], forbidden))
            if hit is not None:
                out[robot] = hit
        return out

    def _solve(self, work: Mapping[str, SynthesisJob]) -> dict[str, Synthesis]:
        """Run the syntheses: here, or in the executor when there are several."""
        out: dict[str, Synthesis] = {}
        if self.executor is None or len(work) < 2:
            for robot, job in work.items():
                out[robot] = synthesize_job(job)
                if self.on_robot is not None:
                    self.on_robot(robot, out[robot])
            return out
        futures = {robot: self.executor.submit(synthesize_job, job) for robot, job in work.items()}
        try:
            for robot, future in futures.items():
                out[robot] = future.result()
                if self.on_robot is not None:
                    self.on_robot(robot, out[robot])
        except BaseException:  # an interrupt or a failed synthesis: leave no work queued
            # (the loop's own pool cancels its work as plan_team stops it: a future cancelled
            # behind its back breaks its manager thread before Python 3.12)
            if not isinstance(self.executor, Workers):
                for future in futures.values():
                    future.cancel()
            raise
        return out


@dataclass(frozen=True)
class Replanned:
    """What one step of the loop re-planned, why, and why it could not.

    Attributes
    ----------
    results : mapping of str to Synthesis
        The robots re-planned and their new syntheses.
    words : mapping of str to tuple of Event
        The robots whose words changed (goods set aside added to a helper's), and the words.
    replans : tuple of str
        Why each robot was re-planned, in plain words.
    reasons : tuple of str
        Why the step failed (empty: it worked).
    """

    results: Mapping[str, Synthesis] = field(default_factory=dict)
    words: Mapping[str, tuple[Event, ...]] = field(default_factory=dict)
    replans: tuple[str, ...] = ()
    reasons: tuple[str, ...] = ()

    @property
    def ok(self) -> bool:
        """Whether the step worked."""
        return not self.reasons
