"""Shortest plans: the smallest horizon K that satisfies a robot's specification, then fewest requests.

For K = K_min, K_min + 1, ... the specification of :mod:`cosmop.planning.specification` is
unrolled over instants ``0..K`` and solved with Z3: by default with one solver whose unrolling
grows (:class:`cosmop.logic.IncrementalUnrolling`, the horizon chosen by an assumption), or with
a fresh solver per K (:class:`cosmop.logic.Unrolling`).  The first
satisfiable K is the shortest plan length; unsatisfiability at K - 1 is part of the result.
Among the plans of that length, the number of Req steps is then minimised by tightening a
bound until unsat (a request costs another robot's time: it must come and move the goods).
Asked (``route_rounds``), the length of the route is then made shorter, with as few requests,
for a few rounds (:func:`_shortest_route`): the solver's first model is any plan of K steps,
and one may drive a long way round where another of the same K drives straight.  A robot
re-planned among others already moving (:func:`cosmop.sim.replan.replan`: a lifelong hand-over,
a stall) asks for it.  A team planned robot by robot does not: there the routes are only a
start for the conflict step, and shortest ones, measured on aisle warehouses, run more robots
through the same aisles (ten scenes: six planned later, three sooner).
If no K up to the bound works, the mission is searched prefix by prefix for the first event
that cannot be reached.  An unsat core over the specification's named parts, at the bound,
names what blocks it.

A branching local mission (a DFA over the robot's events) is solved the same way with the
automaton in the formula (:func:`cosmop.planning.specification.automaton_parts`): the first
satisfiable K is the shortest plan over *every* word of its marked language, the fewest
requests among those, and the plan records the word it performs.

Every Z3 solver gets a resource limit (``rlimit``), so the same input always gives the same
answer on any machine.  A horizon the solver cannot decide within it ends the search: the
result is infeasible with a reason that says so (shorter horizons were proved impossible, and
nothing is claimed beyond).

A synthesis runs with Python's cyclic garbage collector paused (:func:`cosmop.io.collector_paused`):
the encoding makes millions of short-lived objects that reference counting frees, and some
hundred cycles a synthesis, which the collector frees once it runs again.  Running, it walked the
whole heap again and again; in a Dask worker, whose heap is large, that made every synthesis a
quarter slower than in a local worker process.
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any

import numpy as np
import shapely
import z3

from cosmop.automata import DFA
from cosmop.automata.operations import project, trim
from cosmop.events import MESSAGE_KINDS, Event, Primitive, parse_event
from cosmop.io import collector_paused
from cosmop.logic import Formula, IncrementalUnrolling, Signature, Unrolling, assert_all, conj, to_fraction
from cosmop.planning.messages import answer_early, place_mission_messages, strip_messages, wait_early
from cosmop.planning.obstacles import Geometry
from cosmop.planning.plan_types import ObjectState, ObjectStates, RobotPlan, State, Step
from cosmop.planning.reach import event_place, least_drives, least_route, unreachable
from cosmop.planning.specification import (
    MOTION_MARGIN,
    NONE,
    ObstaclePart,
    PartName,
    RobotProblem,
    decode,
    events_of,
    request_codes,
    specification,
)
from cosmop.scene import MAX_TASK_EVENTS, Scene

DEFAULT_RLIMIT = 50_000_000
ROUTE_ROUNDS = 4
"""How many times a re-planned robot asks for a shorter route (:func:`_shortest_route`)."""
ROUTE_RLIMIT = 2_000_000
"""Z3 resource limit of each solver check of an ask for a shorter route (:func:`_shortest_route`),
below the search's: a shorter route is worth a bounded effort.  Asks that found one took at most
1.7 million on the MovingAI hand-overs measured (``benchmarks/BENCHMARKS.md``, 2026-12-07,
sixth); the proofs that none is shorter took up to 7 million (3 s), for nothing."""


@dataclass(frozen=True)
class Synthesis:
    """Result of :func:`synthesize` for one robot.

    Attributes
    ----------
    robot : str
        The robot's id.
    feasible : bool
        Whether a plan was found.
    plan : RobotPlan or None
        The shortest plan (fewest requests among the shortest).
    horizon : int or None
        Its length K; no plan of length K - 1 exists.
    requests : tuple of str
        Objects the plan asks to be moved away (Req), the feedback for the top-down layer.
    reason : str or None
        When infeasible: which event cannot be reached and what blocks it.
    blocking : tuple of str
        Names of the specification parts in the unsat core (walls, objects, ...).
    solve_s : float
        Seconds the synthesis took.
    checks : int
        Solver calls made.
    unsat_horizons : tuple of int
        The horizons proved unsatisfiable before the plan was found (evidence that ``horizon``
        is minimal: every shorter length is among them or below the lower bound, one step per
        non-return event, or with ``from_bound`` the counted drives too).
    admitted : int
        Obstacles the lazy geometry added to the solver after a plan broke them.
    route_mm : float
        The plan's route length in the Manhattan metric, mm (:func:`_shortest_route`; 0 when
        infeasible).
    """

    robot: str
    feasible: bool
    plan: RobotPlan | None
    horizon: int | None
    requests: tuple[str, ...] = ()
    reason: str | None = None
    blocking: tuple[str, ...] = ()
    solve_s: float = 0.0
    checks: int = field(default=0, repr=False)
    unsat_horizons: tuple[int, ...] = ()
    admitted: int = field(default=0, repr=False)
    route_mm: float = field(default=0.0, repr=False)


def _solver(rlimit: int, ctx: z3.Context) -> z3.Solver:
    s = z3.Solver(ctx=ctx)
    # Z3 would take Ctrl-C for itself and answer "unknown", like a spent resource limit: leave
    # it to Python, which raises KeyboardInterrupt when the check returns
    s.set("ctrl_c", False)
    s.set("rlimit", rlimit)
    s.set("random_seed", 0)
    return s


def _value(v: Any) -> float:
    f = float(v)
    return int(f) if f.is_integer() else f


def _plan(
    p: RobotProblem, unrolling: Unrolling | IncrementalUnrolling, model: z3.ModelRef
) -> tuple[RobotPlan, tuple[str, ...]]:
    trace = unrolling.trace(model)
    word = p.mission
    if p.automaton is not None:  # the events the steps perform, in order
        word = tuple(p.mission[int(s["event"]) - 1] for s in trace if int(s["event"]) > 0)
    steps: list[Step] = []
    requested: list[str] = []
    # most objects have no variable (the plan never moves them): read once, kept in every step
    varying = p.varying_objects
    every = ObjectStates({o: _object_state(p, o, trace[0]) for o in p.scene.objects})
    for state in trace[1:]:
        action = decode(p, int(state["pi"]))
        if action.primitive == Primitive.REQ:
            assert action.obj is not None  # a request names its object
            requested.append(action.obj)
        objects = every.updated({o: _object_state(p, o, state) for o in varying})
        steps.append(
            Step(
                action.primitive,
                action.obj,
                (_value(state["x"]), _value(state["y"]), _value(state["heading"])),
                objects,
            )
        )
    return RobotPlan.from_steps(word, steps), tuple(requested)


def _object_state(p: RobotProblem, obj: str, state: Mapping[str, Any]) -> ObjectState:
    """Object `obj` at one instant of a trace."""
    x, y, carried, away = p.obj(obj).read(state)
    return ObjectState((_value(x), _value(y)), bool(carried), bool(away))


def _count_requests(p: RobotProblem, unrolling: Unrolling | IncrementalUnrolling) -> z3.ArithRef:
    codes = list(request_codes(p))
    return z3.Sum(
        [z3.If(z3.Or([unrolling["pi", k] == c for c in codes]), 1, 0) for k in range(1, unrolling.K + 1)]
    )


def _feasible_within(p: RobotProblem, events: tuple[Event, ...], K: int, rlimit: int) -> bool:
    """Whether some plan of at most ``K`` steps realises `events` (one solver, the horizon grown)."""
    geometry = Geometry(p, events, lazy=True)
    horizons = _horizons(geometry, max(1, _least_steps(events)), K, rlimit, incremental=True)
    return any(h.check(geometry)[1] is not None for h in horizons)


@collector_paused()  # many objects, next to no cycles (module docstring)
def synthesize(
    scene: Scene,
    robot: str,
    mission: Iterable[Event | str] | DFA,
    *,
    requests: bool = True,
    max_horizon: int = 16,
    rlimit: int = DEFAULT_RLIMIT,
    incremental: bool = True,
    start: State | None = None,
    explain: bool = True,
    unrequestable: frozenset[str] = frozenset(),
    margin: float | Fraction = MOTION_MARGIN,
    lazy: bool = True,
    spots: tuple[tuple[Event, tuple[float, float]], ...] = (),
    min_horizon: int = 0,
    route_rounds: int = 0,
    copies: bool = False,
    from_bound: bool = False,
    near_lines: bool = False,
) -> Synthesis:
    """The shortest safe plan of motion primitives for one robot's local mission.

    Parameters
    ----------
    scene : Scene
        The scene (walls, robots, objects, workspaces; mm).
    robot : str
        The robot's id.
    mission : iterable of Event or str, or DFA
        The local mission: a sequence of events, or a DFA over the robot's events whose
        marked words are the ways it may complete (a branching mission; the plan performs
        one of them, found by the solver).
    requests : bool
        Allow Req (asking another robot to move an object away).
    max_horizon : int
        Largest K tried.
    rlimit : int
        Z3 resource limit per solver call.
    incremental : bool
        Search K with one solver whose unrolling grows (:class:`cosmop.logic.IncrementalUnrolling`,
        the default: 2.5x faster on the 10x10 example) instead of a fresh solver per K.
    start : State, optional
        Instant 0 if not the scenario (replanning mid-mission; mm and degrees).
    explain : bool
        When infeasible, search for the first unreachable event and an unsat core (the
        ``reason``); a replan that only needs yes or no skips it.
    unrequestable : frozenset of str
        Objects the plan may not request.
    margin : float or Fraction
        mm a motion keeps from walls and resting objects between its ends
        (:data:`~cosmop.planning.specification.MOTION_MARGIN`; 0 allows sliding along them).
    lazy : bool
        Lazy geometry (the default): the solver starts with the walls and objects near the
        robot's route and adds those a plan breaks, until none does
        (:mod:`cosmop.planning.obstacles`); the same horizon and number of requests as the
        eager encoding (``False``: every obstacle from the start), proved there.
    spots : tuple of (Event, (float, float))
        Drops pinned to one spot (:attr:`~cosmop.planning.specification.RobotProblem.spots`).
    min_horizon : int
        A length below which the caller knows that no plan exists (the robot re-planned with
        more walls than a plan of this length had): the search starts there, and
        ``unsat_horizons`` lists only the horizons searched.
    route_rounds : int
        How many times a shorter route is asked for among the shortest plans with the fewest
        requests (:func:`_shortest_route`; 0, the default: the solver's first such plan;
        :data:`ROUTE_ROUNDS` for a robot re-planned among others moving).
    copies : bool
        Unroll by copying the transition constraints between instants
        (:class:`cosmop.logic.IncrementalUnrolling`'s ``copies``): the same shortest horizon and
        fewest requests, found faster, but the solver may return another of the equally short
        plans.  Off by default: a team planned at once takes the solver's first plan of each
        robot, and how well the team's plans interleave depends on which plan that is
        (``benchmarks/BENCHMARKS.md``); a robot re-planned among others moving asks for
        shorter routes anyway (`route_rounds`).
    from_bound : bool
        Start the search at the counted lower bound (a step per event but ``return``, and the
        drives between the places the events need, :func:`~cosmop.planning.reach.least_drives`)
        instead of the events' count: the same shortest horizon without proving the lengths
        below the bound one by one, but the solver's first plan there may be another (off by
        default, as `copies`).
    near_lines : bool
        With `lazy`, the solver starts with the obstacles near the straight lines between the
        mission's places instead of the whole box around them (:class:`Geometry`'s ``lines``):
        the same shortest horizon and fewest requests, found sooner where the places lie far
        apart, but the solver's first plan may be another (off by default, as `copies`).

    Returns
    -------
    Synthesis

    Notes
    -----
    ``msg`` events of the mission move nothing: the solver plans the rest, and the messages are
    put in afterwards (:func:`cosmop.planning.messages.place_mission_messages`).
    """
    t0 = time.perf_counter()
    m = _local_mission(scene, robot, mission, start, max_horizon)
    if m.walled_off is not None:  # no horizon can do it: say so without the solver
        return Synthesis(robot, False, None, None, reason=m.walled_off, solve_s=time.perf_counter() - t0)
    p = _problem(
        scene,
        robot,
        m,
        requests=requests,
        start=start,
        unrequestable=unrequestable,
        margin=margin,
        spots=spots,
    )
    least = _least_horizon(p, m, max_horizon, counted=from_bound)
    if least > max_horizon:  # counting alone rules every plan out: say so without the solver
        why = (
            f"{robot}'s mission needs at least {least} steps (one per pick and drop, and the drives "
            f"between the places they need, around the walls), more than the horizon {max_horizon} "
            "(raise --max-horizon)"
        )
        return Synthesis(robot, False, None, None, reason=why, solve_s=time.perf_counter() - t0)
    # by default the search starts at the events' count: starting at `least` finds plans as
    # short, but the solver's first plan there may differ (`from_bound`)
    first = max(m.lower, min_horizon, least if from_bound else 0)
    floor = _route_floor(p, m) if route_rounds else 0.0
    found = _shortest_plan(
        p, first, max_horizon, rlimit, incremental, lazy, route_rounds, copies, floor, near_lines
    )
    if found.plan is not None:
        return found.synthesis(robot, t0, plan=_place_messages(p, found.plan, m.full))
    if found.gave_up is not None:  # the solver could not decide a horizon: claim nothing beyond
        return found.synthesis(robot, t0, reason=found.gave_up)
    reason, blocking = _why_no_plan(p, max_horizon, rlimit, explain)
    return found.synthesis(robot, t0, reason, blocking)


@dataclass(frozen=True)
class _Mission:
    """A robot's local mission as the solver sees it, before any solver call.

    Attributes
    ----------
    automaton : DFA or None
        A branching mission without its messages and the events walls rule out; ``None`` for a
        sequence.
    full : tuple of Event
        A sequence mission with its messages (placed after solving); the automaton's events.
    events : tuple of Event
        What the solver plans.
    lower : int
        Fewest steps of any plan: the first horizon searched.
    walled_off : str or None
        Why no horizon can work, found without the solver.
    """

    automaton: DFA | None
    full: tuple[Event, ...]
    events: tuple[Event, ...]
    lower: int
    walled_off: str | None


def _local_mission(
    scene: Scene, robot: str, mission: Iterable[Event | str] | DFA, start: State | None, max_horizon: int
) -> _Mission:
    """The events to plan, the least horizon, and what rules the mission out before solving.

    Walls (:func:`~cosmop.planning.reach.unreachable`), the number of tasks planned at once
    (:data:`~cosmop.scene.MAX_TASK_EVENTS`, sequences only; the messages coordination adds do
    not count) and a least horizon beyond
    `max_horizon` each make ``walled_off`` say why no plan is searched.
    """
    origin = start.robot[:2] if start is not None else None
    if isinstance(mission, DFA):
        automaton, walled_off = _plannable(scene, robot, mission, origin)
        full = events = tuple(parse_event(e) for e in automaton.alphabet)
        lower = _fewest_steps(automaton, events)
    else:
        automaton, full = None, events_of(mission)
        events = strip_messages(full)
        walled_off = _out_of_hand(robot, events, start) or unreachable(scene, robot, events, origin)
        lower = _least_steps(events)
    tasks = sum(1 for e in events if e.kind not in MESSAGE_KINDS)  # what the scenario bounds too
    if walled_off is None and automaton is None and tasks > MAX_TASK_EVENTS:
        walled_off = (
            f"{robot}'s mission has {tasks} tasks (pick, drop, return); at most {MAX_TASK_EVENTS} are "
            "planned at once"
        )
    if walled_off is None and lower > max_horizon:
        walled_off = (
            f"{robot}'s mission needs at least {lower} steps, more than the longest plan searched "
            f"({max_horizon} steps)"
        )
    return _Mission(automaton, full, events, lower, walled_off)


def _out_of_hand(robot: str, events: Iterable[Event], start: State | None) -> str | None:
    """Why no plan can do `events` in that order by what the robot holds: it carries one good at
    a time, picks only with empty hands and drops only what it carries (``None``: it can)."""
    held = None
    if start is not None:
        held = next((o for o, state in start.objects.items() if state.carried), None)
    for n, event in enumerate(events, 1):
        if event.kind == "pick":
            if held is not None:
                why = f"while it carries {held}: it carries one good at a time"
                return f"{robot} cannot {event.name} (event {n}) {why}"
            held = event.obj
        elif event.kind == "drop":
            if held != event.obj:
                holding = f"it carries {held}" if held is not None else "its hands are empty"
                return f"{robot} cannot {event.name} (event {n}): {holding}"
            held = None
    return None


def _least_steps(events: Iterable[Event]) -> int:
    """Fewest steps of a plan that performs `events`: one per event but ``return``."""
    return sum(1 for e in events if e.kind != "return")


def _least_horizon(p: RobotProblem, m: _Mission, max_horizon: int, *, counted: bool = False) -> int:
    """Fewest steps of a plan of the sequence mission `m`: a step per event but ``return``
    (:func:`_least_steps`), and the drives between the places the events need the robot at
    (:func:`~cosmop.planning.reach.least_drives`); 0 for a branching mission (not bounded here).
    A horizon below it has no plan: a mission that needs more steps than the search allows is
    refused without the solver.  When at most two drives a place cannot exceed `max_horizon`,
    the events' count is returned without the geometry (when it is only asked whether the
    search may be skipped), unless `counted` (the search starts there).
    """
    if m.automaton is not None:
        return 0
    located = sum(1 for e in m.events if e.kind in ("pick", "drop", "return"))
    if not counted and m.lower + 2 * located <= max_horizon:  # least_drives counts at most two per place
        return m.lower
    places = _places(p, m)
    if places is None:
        return m.lower
    origin = p.start.robot[:2] if p.start is not None else None
    return m.lower + least_drives(p.scene, p.robot, places, origin)


def _places(p: RobotProblem, m: _Mission) -> list[shapely.Geometry] | None:
    """Where the events of the sequence mission `m` need the robot's centre, in order
    (:func:`_place`), or None when a place is not known before solving (goods picked again
    where the mission put them, or a branching mission)."""
    if m.automaton is not None:
        return None
    dropped: set[str | None] = set()
    for e in m.events:
        if e.kind == "pick" and e.obj in dropped:
            return None
        if e.kind == "drop":
            dropped.add(e.obj)
    return [where for e in m.events if (where := _place(p, e)) is not None]


def _route_floor(p: RobotProblem, m: _Mission) -> float:
    """A length (mm) below which no route of `m` lies (:func:`~cosmop.planning.reach.least_route`,
    less a millimetre for floating point), 0 when the places are not known before solving."""
    places = _places(p, m)
    if places is None:
        return 0.0
    origin = p.start.robot[:2] if p.start is not None else p.scene.robots[p.robot].pose[:2]
    return max(least_route(places, (float(origin[0]), float(origin[1]))) - 1.0, 0.0)


def _place(p: RobotProblem, event: Event) -> shapely.Geometry | None:
    """Where `event` needs the robot's centre (:func:`~cosmop.planning.reach.event_place`), with
    the goods where `p` starts them and a drop's spot where it is pinned."""
    if event.kind == "pick":
        assert event.obj is not None  # a pick names its goods
        return event_place(p.scene, p.robot, event, at=p.at_start(event.obj)[0])
    if event.kind == "drop":
        return event_place(p.scene, p.robot, event, centres=p.drop_centres(event))
    return event_place(p.scene, p.robot, event)


def _problem(
    scene: Scene,
    robot: str,
    m: _Mission,
    *,
    requests: bool,
    start: State | None,
    unrequestable: frozenset[str],
    margin: float | Fraction,
    spots: tuple[tuple[Event, tuple[float, float]], ...] = (),
) -> RobotProblem:
    """The solver's problem for the events of `m` (options as in :func:`synthesize`)."""
    return RobotProblem(
        scene,
        robot,
        m.events,
        requests,
        start=start,
        unrequestable=frozenset(unrequestable),
        automaton=m.automaton,
        margin=to_fraction(margin),
        spots=tuple(spots),
    )


@dataclass(frozen=True)
class _Horizon:
    """One horizon ``K`` ready to check: ``solver.check(*assumptions)`` decides it.

    Attributes
    ----------
    K : int
        The horizon: the number of steps.
    solver : z3.Solver
        Holds the specification unrolled over instants ``0..K``.
    unrolling : Unrolling or IncrementalUnrolling
        The unrolling, to read a model's trace and to count requests.
    assumptions : tuple of z3.BoolRef
        The literal choosing the horizon of a growing unrolling; empty for a fixed one.
    """

    K: int
    solver: z3.Solver
    unrolling: Unrolling | IncrementalUnrolling
    assumptions: tuple[z3.BoolRef, ...]

    def add(self, formula: Formula) -> None:
        """Assert `formula` (at instant 0) from now on, at this horizon and every later one."""
        if isinstance(self.unrolling, IncrementalUnrolling):
            assert_all(self.solver, self.unrolling.require(formula))
        else:
            self.solver.add(self.unrolling.encode(formula))

    def check(self, geometry: Geometry, *bound: z3.BoolRef) -> tuple[Any, z3.ModelRef | None, int]:
        """Solve, with `bound` asserted for this call only, until the model breaks no obstacle.

        A model that breaks obstacles the solver does not hold yet (:meth:`Geometry.broken`)
        makes them held (asserted outside the bound's scope) and the check is repeated; see
        :mod:`cosmop.planning.obstacles` for why the answer is the eager encoding's.

        Returns
        -------
        verdict, model (when sat), checks made
        """
        checks = 0
        while True:
            checks += 1
            self.solver.push()
            self.solver.add(*bound)
            verdict = self.solver.check(*self.assumptions)
            model = self.solver.model() if verdict == z3.sat else None
            broken = geometry.broken(self.unrolling.trace(model)) if model is not None else []
            self.solver.pop()
            if not broken:
                return verdict, model, checks
            self.add(geometry.admit(broken))


def _horizons(
    geometry: Geometry, first: int, last: int, rlimit: int, *, incremental: bool, copies: bool = False
) -> Iterator[_Horizon]:
    """The specification unrolled for ``K = first .. last`` in turn, each in a solver ready to check.

    Parameters
    ----------
    geometry : Geometry
        The specification and which obstacle parts the solver holds.
    first, last : int
        The horizons, both included.
    rlimit : int
        Z3 resource limit per solver call.
    incremental : bool
        One solver whose unrolling grows (the horizon chosen by an assumption), else a fresh
        context and solver per horizon.
    copies : bool
        Unroll by copies between instants (:class:`~cosmop.logic.IncrementalUnrolling`).
    """
    signature = Signature.of(geometry.held)  # every variable is in the initial state
    grow: IncrementalUnrolling | None = None
    for K in range(first, last + 1):
        if incremental:  # one solver; the horizon grows under the assumption ``end``
            if grow is None:
                ctx = z3.Context()
                grow = IncrementalUnrolling(signature, K, ctx=ctx, copies=copies)
                s = _solver(rlimit, ctx)
                assert_all(s, grow.require(geometry.held))
            else:
                assert_all(s, grow.extend(K))
            yield _Horizon(K, s, grow, (grow.end,))
        else:  # a fresh context and solver per horizon: answers never depend on earlier calls
            ctx = z3.Context()
            u = Unrolling(signature, K, ctx=ctx, copies=copies)
            s = _solver(rlimit, ctx)
            s.add(u.encode(geometry.held))
            yield _Horizon(K, s, u, ())


@dataclass(frozen=True)
class _Search:
    """What the search over horizons found, before messages are placed or failure explained.

    Attributes
    ----------
    plan : RobotPlan or None
        The shortest plan with the fewest requests, without the mission's messages.
    horizon : int or None
        Its length.
    requests : tuple of str
        Objects it requests.
    gave_up : str or None
        Why the search stopped undecided (the solver's resource limit).
    checks : int
        Solver calls made.
    unsat : tuple of int
        The horizons proved unsatisfiable.
    admitted : int
        Obstacles the lazy geometry added after a plan broke them.
    route_mm : float
        The plan's route length (Manhattan metric), mm.
    """

    plan: RobotPlan | None = None
    horizon: int | None = None
    requests: tuple[str, ...] = ()
    gave_up: str | None = None
    checks: int = 0
    unsat: tuple[int, ...] = ()
    admitted: int = 0
    route_mm: float = 0.0

    def synthesis(
        self,
        robot: str,
        t0: float,
        reason: str | None = None,
        blocking: tuple[str, ...] = (),
        *,
        plan: RobotPlan | None = None,
    ) -> Synthesis:
        """The result for `robot`: feasible when given `plan`, timed from `t0`."""
        return Synthesis(
            robot,
            plan is not None,
            plan,
            self.horizon,
            self.requests,
            reason=reason,
            blocking=blocking,
            solve_s=time.perf_counter() - t0,
            checks=self.checks,
            unsat_horizons=self.unsat,
            admitted=self.admitted,
            route_mm=self.route_mm,
        )


def _shortest_plan(
    p: RobotProblem,
    lower: int,
    max_horizon: int,
    rlimit: int,
    incremental: bool,
    lazy: bool,
    route_rounds: int = 0,
    copies: bool = False,
    floor: float = 0.0,
    near_lines: bool = False,
) -> _Search:
    """The first satisfiable horizon from `lower` to `max_horizon`, and its plan.

    Each horizon is checked in turn; at the first satisfiable one the number of requests is
    minimised (:func:`_fewest_requests`), then the route (:func:`_shortest_route`, `route_rounds`
    rounds, none asking below `floor` mm).  A horizon the solver cannot decide within `rlimit`
    ends the search with ``gave_up`` set.  With `lazy`, obstacles join the solver as plans
    break them (:class:`~cosmop.planning.obstacles.Geometry`; `near_lines`, its ``lines``).
    """
    geometry = Geometry(p, None, lazy, lines=near_lines)
    checks = 0
    unsat: list[int] = []
    for h in _horizons(geometry, lower, max_horizon, rlimit, incremental=incremental, copies=copies):
        verdict, model, made = h.check(geometry)
        checks += made
        if verdict == z3.unknown:  # no answer within the resource limit: say so, claim nothing more
            why = (
                f"{p.robot}: the solver gave up at K={h.K} ({h.solver.reason_unknown()}, resource limit "
                f"{rlimit}); no plan of at most {h.K - 1} steps exists, longer ones were not searched"
            )
            return _Search(gave_up=why, checks=checks, unsat=tuple(unsat), admitted=geometry.admitted)
        if model is None:
            unsat.append(h.K)
            continue
        model, more = _fewest_requests(p, h, geometry, model)
        model, route, shorter = _shortest_route(p, h, geometry, model, route_rounds, floor, rlimit)
        plan, asked = _plan(p, h.unrolling, model)
        checks += more + shorter
        return _Search(
            plan, h.K, asked, checks=checks, unsat=tuple(unsat), admitted=geometry.admitted, route_mm=route
        )
    return _Search(checks=checks, unsat=tuple(unsat), admitted=geometry.admitted)


def _fewest_requests(
    p: RobotProblem, h: _Horizon, geometry: Geometry, model: z3.ModelRef
) -> tuple[z3.ModelRef, int]:
    """A model of the satisfiable horizon `h` with the fewest Req steps, and the checks it took.

    Starting from `model`, the bound on the number of requests is tightened until unsat, each
    bound for one check only (:meth:`_Horizon.check`), so that `h`'s solver keeps no bound.
    """
    checks = 0
    if h.K > 0 and request_codes(p):  # at K = 0 there is no step to count
        count = _count_requests(p, h.unrolling)
        best = model.eval(count, model_completion=True).as_long()
        while best > 0:
            _, better, made = h.check(geometry, count <= best - 1)
            checks += made
            if better is None:
                break
            model, best = better, better.eval(count, model_completion=True).as_long()
    return model, checks


def _route_length(unrolling: Unrolling | IncrementalUnrolling) -> z3.ArithRef | None:
    """The route's length in the Manhattan metric, ``sum_k |x_k - x_(k-1)| + |y_k - y_(k-1)|``
    (mm), or None when the position never varies (no step, or a robot that cannot move).

    A linear term (the solver's arithmetic is linear), equal to the Euclidean length on the
    axis-parallel drives of aisles and grids, and never below it elsewhere.
    """
    terms = []
    for k in range(1, unrolling.K + 1):
        for axis in ("x", "y"):
            d = unrolling[axis, k] - unrolling[axis, k - 1]
            if z3.is_expr(d):  # a constant position moves nowhere
                terms.append(z3.If(d >= 0, d, -d))
    return z3.Sum(terms) if terms else None


def _number(value: Any) -> Fraction:
    """A model's integer or rational value, exactly."""
    if z3.is_int_value(value):
        return Fraction(value.as_long())
    return Fraction(value.numerator_as_long(), value.denominator_as_long())


def _shortest_route(
    p: RobotProblem,
    h: _Horizon,
    geometry: Geometry,
    model: z3.ModelRef,
    rounds: int,
    floor: float = 0.0,
    rlimit: int = DEFAULT_RLIMIT,
) -> tuple[z3.ModelRef, float, int]:
    """A model of `h` with as few requests as `model` and a shorter route, if one is found.

    Up to `rounds` times the route length ``L`` (:func:`_route_length`) is bounded below the
    best found, ``L <= best - max(250 mm, 3 % of best)``, each bound for one check only; the
    first unsat (or undecided, within the resource limit) check ends the search.  So the
    route is within a step of the shortest of its K steps only when the rounds did not run out
    and the last ask was proved unsatisfiable (not undecided):
    a few rounds take most of what there is (the first model's detours) at a bounded cost.
    A bound below `floor` (no route is shorter, :func:`_route_floor`) is not asked: the solver
    would only prove it unsatisfiable, most of a round's time on a route already straight.
    Each solver check of an ask (more than one when the plan found breaks obstacles not yet
    held) has at most :data:`ROUTE_RLIMIT` of the solver's resources (`rlimit` if smaller),
    counted in Z3's deterministic units: the same input gives the same route.

    Returns
    -------
    model, its route length (mm), checks made
    """
    length = _route_length(h.unrolling)
    if length is None:
        return model, 0.0, 0
    best = _number(model.eval(length, model_completion=True))
    keep: list[z3.BoolRef] = []
    if request_codes(p):  # no more requests than the fewest found
        count = _count_requests(p, h.unrolling)
        keep.append(count <= model.eval(count, model_completion=True))
    checks = 0
    h.solver.set("rlimit", min(rlimit, ROUTE_RLIMIT) if rlimit > 0 else ROUTE_RLIMIT)  # 0: no limit
    try:
        for _ in range(rounds):
            bound = math.floor(best - max(Fraction(250), best * Fraction(3, 100)))
            if bound < floor:  # unsatisfiable: no route is that short
                break
            _, better, made = h.check(geometry, length <= bound, *keep)
            checks += made
            if better is None:  # none shorter, or not found within the budget
                break
            model, best = better, _number(better.eval(length, model_completion=True))
    finally:
        h.solver.set("rlimit", rlimit)
    return model, float(best), checks


def _place_messages(p: RobotProblem, plan: RobotPlan, full: tuple[Event, ...]) -> RobotPlan:
    """`plan` with answers early, requests before drives, and the mission's messages put in.

    A branching mission's messages follow the word the plan performs; a sequence's are those
    of `full`.
    """
    plan = answer_early(plan)
    if p.start is None:  # where a robot waits for answers: before it drives (no start state mid-run)
        plan = wait_early(p.scene, p.robot, plan)
    return place_mission_messages(p.scene, p.robot, plan, plan.mission if p.automaton else full, p.start)


def _why_no_plan(
    p: RobotProblem, max_horizon: int, rlimit: int, explain: bool
) -> tuple[str, tuple[str, ...]]:
    """The reason and the blocking parts when no plan of at most `max_horizon` steps exists.

    Without `explain` only the bound is named (no further solver calls).
    """
    if explain and p.automaton is not None:
        return _explain_automaton(p, max_horizon, rlimit)
    if explain:
        return _explain(p, p.mission, max_horizon, rlimit)
    return f"no plan of at most {max_horizon} steps", ()


def _plannable(
    scene: Scene, robot: str, dfa: DFA, origin: tuple[float, float] | None
) -> tuple[DFA, str | None]:
    """The branching mission without messages (planned afterwards) and events walls rule out.

    Messages are projected away.  An event :func:`~cosmop.planning.reach.unreachable` proves
    impossible loses its transitions, and the automaton is trimmed; if no marked word is left,
    the reason names the events ruled out.
    """
    moving = [e for e in dfa.alphabet if not parse_event(e).is_message]
    if len(moving) < len(dfa.alphabet):
        dfa = project(dfa, moving)
    delta = dfa.delta.copy()
    why = []
    for j, name in enumerate(dfa.alphabet):
        reason = unreachable(scene, robot, (parse_event(name),), origin)
        if reason is not None:
            delta[:, j] = -1
            why.append(reason)
    dfa = trim(DFA(dfa.alphabet, delta, dfa.initial, dfa.marked))
    used = [j for j in range(dfa.n_events) if (dfa.delta[:, j] >= 0).any()]
    dfa = DFA(tuple(dfa.alphabet[j] for j in used), dfa.delta[:, used], dfa.initial, dfa.marked)
    if not dfa.marked.any():
        reasons = "; ".join(why) if why else "its mission has no complete word"
        return dfa, f"{robot} can complete no word of its mission: {reasons}"
    return dfa, None


def _fewest_steps(dfa: DFA, events: tuple[Event, ...]) -> int:
    """Fewest steps of any plan: the fewest non-return events on a marked word (0-1 search)."""
    weight = [_least_steps((e,)) for e in events]
    best = np.full(dfa.n_states, np.iinfo(np.int64).max, dtype=np.int64)
    best[dfa.initial] = 0
    todo = [dfa.initial]
    while todo:  # Bellman-Ford rounds: the automaton is small
        nxt = []
        for s in todo:
            for j, t in enumerate(dfa.delta[s]):
                if t >= 0 and best[s] + weight[j] < best[t]:
                    best[t] = best[s] + weight[j]
                    nxt.append(int(t))
        todo = nxt
    return int(best[dfa.marked].min(initial=best.max()))  # no marked state: walled off, unused


def _explain_automaton(p: RobotProblem, K: int, rlimit: int) -> tuple[str, tuple[str, ...]]:
    """Why no word of a branching mission can be planned within ``K`` steps (a minimal core)."""
    blocking = _core(p, specification(p), K, rlimit)
    head = f"{p.robot} cannot complete any word of its mission within {K} steps"
    return _because(head, _as_written(p.scene, blocking), K), tuple(part.text for part in blocking or ())


def _explain(p: RobotProblem, events: tuple[Event, ...], K: int, rlimit: int) -> tuple[str, tuple[str, ...]]:
    """The first event no plan of length ``<= K`` reaches, and a minimal core naming what blocks it."""
    for i in range(1, len(events) + 1):
        if not _feasible_within(p, events[:i], K, rlimit):
            break
    else:  # every prefix alone is feasible (cannot happen for the whole mission): report the last
        i = len(events)
    blocking = _core(p, specification(p, events[:i]), K, rlimit)
    event = events[i - 1]
    head = f"{p.robot} cannot reach {event.name} (event {i} of its mission) within {K} steps"
    reason = _because(head, _as_written(p.scene, blocking), K)
    if event.kind in ("pick", "drop") and blocking:
        assert event.obj is not None  # picks and drops name their object
        sides = p.scene.objects[event.obj].sides
        reason += f" (sides of {event.obj} tried: {', '.join(sides)})"
    return reason, tuple(part.text for part in blocking or ())


def _as_written(scene: Scene, blocking: tuple[ObstaclePart, ...] | None) -> tuple[str, ...] | None:
    """`blocking` in the user's words: a wall the planner added is named by its label (what it
    keeps the robot out of), and parts that name the same thing are said once."""
    if blocking is None:
        return None

    def name(part: ObstaclePart) -> str:
        wall = part.obstacle.wall
        label = scene.obstacles[wall].label if wall is not None else None
        return part.text if label is None else part.labelled(label)

    return tuple(dict.fromkeys(name(part) for part in blocking))


def _because(head: str, blocking: tuple[str, ...] | None, K: int) -> str:
    if blocking is None:
        return (
            f"{head}, even with no wall or object in the way: the mission needs more steps than "
            f"the horizon {K} (raise --max-horizon)"
        )
    what = ", ".join(blocking) if blocking else "the primitives' constraints"
    return f"{head}; blocked by: {what}"


def _core(
    p: RobotProblem, parts: Sequence[tuple[PartName, Formula]], K: int, rlimit: int
) -> tuple[ObstaclePart, ...] | None:
    """A minimal set of obstacle parts of `parts` that leaves no plan of ``K`` steps.

    Every other part (the initial state, the primitives' effects, the mission) is asserted;
    each obstacle part is guarded by a literal.  ``None`` when even no obstacle leaves a plan:
    then the horizon, not the scene, is the cause.  Otherwise the solver's core is shrunk by
    deletion (drop one part; if still unsat, keep it dropped): no part of the answer can be
    left out.  A check that spends its resource limit keeps the part (a larger core, never a
    wrong one).  ``()`` when the solver cannot tell.
    """
    ctx = z3.Context()
    u = Unrolling(Signature.of(conj(f for _, f in parts)), K, ctx=ctx)
    s = _solver(rlimit, ctx)
    names: dict[str, ObstaclePart] = {}
    guards = []
    for j, (name, f) in enumerate(parts):
        if isinstance(name, ObstaclePart):
            label = z3.Bool(f"part{j}", ctx)
            names[str(label)] = name
            guards.append(label)
            s.add(z3.Implies(label, u.encode(f)))
        else:
            s.add(u.encode(f))
    if s.check() == z3.unsat:
        return None
    if s.check(*guards) != z3.unsat:
        return ()
    core = _in_order(guards, s.unsat_core())
    k = 0
    while k < len(core):
        trial = core[:k] + core[k + 1 :]
        if s.check(*trial) == z3.unsat:
            core = _in_order(trial, s.unsat_core())
        else:
            k += 1
    return tuple(names[str(c)] for c in core)


def _in_order(guards: list[Any], core: Any) -> list[Any]:
    """The guards that are in `core`, in the order of `guards` (a deterministic answer)."""
    kept = {str(c) for c in core}
    return [g for g in guards if str(g) in kept]


__all__ = ["NONE", "Synthesis", "synthesize"]
