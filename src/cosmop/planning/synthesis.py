"""Shortest plans: the smallest horizon K that satisfies a robot's specification, then fewest requests.

For K = K_min, K_min + 1, ... the specification of :mod:`cosmop.planning.specification` is
unrolled over instants ``0..K`` and solved with Z3: by default with one solver whose unrolling
grows (:class:`cosmop.logic.IncrementalUnrolling`, the horizon chosen by an assumption), or with
a fresh solver per K (:class:`cosmop.logic.Unrolling`).  The first
satisfiable K is the shortest plan length; unsatisfiability at K - 1 is part of the result.
Among the plans of that length, the number of Req steps is then minimised by tightening a
bound until unsat (a request costs another robot's time, DESIGN.md).  If no K up to the bound
works, the mission is searched prefix by prefix for the first event that cannot be reached.
An unsat core over the specification's named parts, at the bound, names what blocks it.

A branching local mission (a DFA over the robot's events) is solved the same way with the
automaton in the formula (:func:`cosmop.planning.specification.automaton_parts`): the first
satisfiable K is the shortest plan over *every* word of its marked language, the fewest
requests among those, and the plan records the word it performs.

Every Z3 solver gets a resource limit (``rlimit``), so the same input always gives the same
answer on any machine.  A horizon the solver cannot decide within it ends the search: the
result is infeasible with a reason that says so (shorter horizons were proved impossible, and
nothing is claimed beyond).
"""

from __future__ import annotations

import time
from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np
import z3

from cosmop.automata import DFA
from cosmop.automata.operations import project, trim
from cosmop.logic import IncrementalUnrolling, Signature, Unrolling, conj, to_fraction
from cosmop.missions.events import Event, parse_event
from cosmop.planning.messages import answer_early, place_mission_messages, strip_messages, wait_early
from cosmop.planning.plan import ObjectState, RobotPlan, State, Step
from cosmop.planning.reach import unreachable
from cosmop.planning.specification import (
    MOTION_MARGIN,
    NONE,
    RobotProblem,
    decode,
    events_of,
    request_codes,
    specification,
)
from cosmop.scenario import MAX_TASK_EVENTS, Scene

DEFAULT_RLIMIT = 50_000_000


@dataclass(frozen=True)
class Synthesis:
    """Result of :func:`synthesize` for one robot.

    Attributes
    ----------
    robot : str
    feasible : bool
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
    checks : int
        Solver calls made.
    unsat_horizons : tuple of int
        The horizons proved unsatisfiable before the plan was found (evidence that ``horizon``
        is minimal: every shorter length is among them or below the lower bound, one step per
        non-return event).
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


def _solver(rlimit: int, ctx: z3.Context) -> z3.Solver:
    s = z3.Solver(ctx=ctx)
    # Z3 would take Ctrl-C for itself and answer "unknown", like a spent resource limit: leave
    # it to Python, which raises KeyboardInterrupt when the check returns
    s.set("ctrl_c", False)
    s.set("rlimit", rlimit)
    s.set("random_seed", 0)
    return s


def _value(v) -> float:
    f = float(v)
    return int(f) if f.is_integer() else f


def _plan(
    p: RobotProblem, unrolling: Unrolling | IncrementalUnrolling, model: z3.ModelRef
) -> tuple[RobotPlan, tuple[str, ...]]:
    trace = unrolling.trace(model)
    word = p.mission
    if p.automaton is not None:  # the events the steps perform, in order
        word = tuple(p.mission[int(s["event"]) - 1] for s in trace if int(s["event"]) > 0)
    steps, requested = [], []
    for state in trace[1:]:
        action = decode(p, int(state["pi"]))
        if action.primitive == "Req":
            requested.append(action.obj)
        objects = {
            o: ObjectState(
                (_value(state[f"{o}.x"]), _value(state[f"{o}.y"])),
                bool(state[f"{o}.p"]),
                bool(state[f"{o}.a"]),
            )
            for o in p.scene.objects
        }
        steps.append(
            Step(
                action.primitive,
                action.obj,
                (_value(state["x"]), _value(state["y"]), _value(state["heading"])),
                objects,
            )
        )
    return RobotPlan.from_steps([e.name for e in word], steps), tuple(requested)


def _count_requests(p: RobotProblem, unrolling: Unrolling | IncrementalUnrolling) -> z3.ArithRef:
    codes = list(request_codes(p))
    return z3.Sum(
        [z3.If(z3.Or([unrolling["pi", k] == c for c in codes]), 1, 0) for k in range(1, unrolling.K + 1)]
    )


def _feasible_within(p: RobotProblem, events: tuple[Event, ...], K: int, rlimit: int) -> bool:
    """Whether some plan of at most ``K`` steps realises `events` (one solver, the horizon grown)."""
    formula = conj(f for _, f in specification(p, events))
    ctx = z3.Context()
    grow, s = None, _solver(rlimit, ctx)
    for k in range(max(1, sum(1 for e in events if e.kind != "return")), K + 1):
        if grow is None:
            grow = IncrementalUnrolling(Signature.of(formula), k, ctx=ctx)
            s.add(grow.require(formula))
        else:
            s.add(grow.extend(k))
        if s.check(grow.end) == z3.sat:
            return True
    return False


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
    margin: float = MOTION_MARGIN,
) -> Synthesis:
    """The shortest safe plan of motion primitives for one robot's local mission.

    Parameters
    ----------
    scene : Scene
    robot : str
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
        Instant 0 if not the scenario (replanning mid-mission; integer mm and degrees).
    explain : bool
        When infeasible, search for the first unreachable event and an unsat core (the
        ``reason``); a replan that only needs yes or no skips it.
    unrequestable : frozenset of str
        Objects the plan may not request.
    margin : float
        mm a motion keeps from walls and resting objects between its ends
        (:data:`~cosmop.planning.specification.MOTION_MARGIN`; 0 allows sliding along them).

    Returns
    -------
    Synthesis

    Notes
    -----
    ``msg`` events of the mission move nothing: the solver plans the rest, and the messages are
    put in afterwards (:func:`cosmop.planning.messages.place_mission_messages`).
    """
    t0 = time.perf_counter()
    origin = start.robot[:2] if start is not None else None
    if isinstance(mission, DFA):
        automaton, walled_off = _plannable(scene, robot, mission, origin)
        full = events = tuple(parse_event(e) for e in automaton.alphabet)
        lower = _fewest_steps(automaton, events)
    else:
        automaton, full = None, events_of(mission)
        events = strip_messages(full)
        walled_off = unreachable(scene, robot, events, origin)
        lower = sum(1 for e in events if e.kind != "return")  # each such event takes a step
    if walled_off is None and automaton is None and len(events) > MAX_TASK_EVENTS:
        walled_off = (
            f"{robot}'s mission has {len(events)} events; at most {MAX_TASK_EVENTS} are planned at once"
        )
    if walled_off is None and lower > max_horizon:
        walled_off = (
            f"{robot}'s mission needs at least {lower} steps, more than the longest plan searched "
            f"({max_horizon} steps)"
        )
    if walled_off is not None:  # no horizon can do it: say so without the solver
        return Synthesis(robot, False, None, None, reason=walled_off, solve_s=time.perf_counter() - t0)
    forbid = frozenset(unrequestable)
    p = RobotProblem(
        scene,
        robot,
        events,
        requests,
        start=start,
        unrequestable=forbid,
        automaton=automaton,
        margin=to_fraction(margin),
    )
    formula = conj(f for _, f in specification(p))
    signature = Signature.of(formula)
    checks = 0
    grow: IncrementalUnrolling | None = None
    unsat: list[int] = []
    for K in range(lower, max_horizon + 1):
        if incremental:  # one solver; the horizon grows under the assumption ``end``
            if grow is None:
                ctx = z3.Context()
                grow = IncrementalUnrolling(signature, K, ctx=ctx)
                s = _solver(rlimit, ctx)
                s.add(grow.require(formula))
            else:
                s.add(grow.extend(K))
            u, assumptions = grow, [grow.end]
        else:  # a fresh context and solver per horizon: answers never depend on earlier calls
            ctx = z3.Context()
            u, assumptions = Unrolling(signature, K, ctx=ctx), []
            s = _solver(rlimit, ctx)
            s.add(u.encode(formula))
        checks += 1
        verdict = s.check(*assumptions)
        if verdict == z3.unknown:  # no answer within the resource limit: say so, claim nothing more
            why = (
                f"{robot}: the solver gave up at K={K} ({s.reason_unknown()}, resource limit {rlimit}); "
                f"no plan of at most {K - 1} steps exists, longer ones were not searched"
            )
            return Synthesis(
                robot,
                False,
                None,
                None,
                reason=why,
                solve_s=time.perf_counter() - t0,
                checks=checks,
                unsat_horizons=tuple(unsat),
            )
        if verdict != z3.sat:
            unsat.append(K)
            continue
        model = s.model()
        if K > 0 and request_codes(p):  # at K = 0 there is no step to count
            count = _count_requests(p, u)
            best = model.eval(count, model_completion=True).as_long()
            while best > 0:
                s.push()
                s.add(count <= best - 1)
                checks += 1
                if s.check(*assumptions) != z3.sat:
                    s.pop()
                    break
                model = s.model()
                best = model.eval(count, model_completion=True).as_long()
                s.pop()
        plan, asked = _plan(p, u, model)
        plan = answer_early(plan)
        if start is None:  # where a robot waits for answers: before it drives (no start state mid-run)
            plan = wait_early(scene, robot, plan)
        plan = place_mission_messages(scene, robot, plan, plan.events if automaton else full, start)
        return Synthesis(
            robot,
            True,
            plan,
            K,
            asked,
            solve_s=time.perf_counter() - t0,
            checks=checks,
            unsat_horizons=tuple(unsat),
        )
    if explain and automaton is not None:
        reason, blocking = _explain_automaton(p, max_horizon, rlimit)
    elif explain:
        reason, blocking = _explain(p, events, max_horizon, rlimit)
    else:
        reason, blocking = f"no plan of at most {max_horizon} steps", ()
    return Synthesis(
        robot,
        False,
        None,
        None,
        reason=reason,
        blocking=blocking,
        solve_s=time.perf_counter() - t0,
        checks=checks,
        unsat_horizons=tuple(unsat),
    )


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
    weight = [0 if e.kind == "return" else 1 for e in events]
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
    return _because(head, blocking, K), blocking or ()


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
    reason = _because(head, blocking, K)
    if event.kind in ("pick", "drop") and blocking:
        sides = p.scene.objects[event.obj].sides
        reason += f" (sides of {event.obj} tried: {', '.join(sides)})"
    return reason, blocking or ()


def _because(head: str, blocking: tuple[str, ...] | None, K: int) -> str:
    if blocking is None:
        return (
            f"{head}, even with no wall or object in the way: the mission needs more steps than "
            f"the horizon {K} (raise --max-horizon)"
        )
    what = ", ".join(blocking) if blocking else "the primitives' constraints"
    return f"{head}; blocked by: {what}"


def _is_obstacle(name: str) -> bool:
    """Whether a specification part keeps the robot or a good off a wall or an object."""
    return name.startswith(("wall", "object", "gripper", "room from")) or " dropped clear of " in name


def _core(p: RobotProblem, parts: list[tuple[str, object]], K: int, rlimit: int) -> tuple[str, ...] | None:
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
    names: dict[str, str] = {}
    guards = []
    for j, (name, f) in enumerate(parts):
        if _is_obstacle(name):
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


def _in_order(guards: list, core) -> list:
    """The guards that are in `core`, in the order of `guards` (a deterministic answer)."""
    kept = {str(c) for c in core}
    return [g for g in guards if str(g) in kept]


__all__ = ["NONE", "Synthesis", "synthesize"]
