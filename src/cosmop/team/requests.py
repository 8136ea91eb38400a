"""Step 3 of the loop: every request for goods to be moved away gets a robot that answers it.

A robot's plan may ask for goods in its way to be moved (``Req(O)``).  Each request becomes
the message ``away(O, A, B)`` from the robot B whose mission picks O
(:func:`cosmop.team.coordination_events.coordinate`), and the robots that answer are re-planned,
until no plan asks for anything new.  A request that nobody can answer, or that would deadlock
the team, is forbidden and the requester re-planned (its next best plan asks for less, or is a
step longer); goods that block a robot and that no mission moves get a helper that sets them
aside (the paper's re-allocation).
"""

from __future__ import annotations

import itertools
import time
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, replace

from cosmop.events import Event
from cosmop.planning.plan_types import MAX_STEPS, AddedTask, PlanSet, RobotPlan
from cosmop.planning.realisation import request_phases
from cosmop.planning.synthesis import Synthesis
from cosmop.squares import square
from cosmop.team.aside import ROOM, place_aside
from cosmop.team.conflicts import ConflictSettings
from cosmop.team.coordination_events import Coordinated, coordinate
from cosmop.team.mission_proof import stuck_waits
from cosmop.team.planner import Planner, Replanned
from cosmop.team.walls import walls_around
from cosmop.units import show_point

__all__ = ["RequestsAnswered", "coordinate_requests"]

_AROUND = ConflictSettings(clearance=2 * ROOM)  # walls around goods set aside: ROOM off them

Requests = Mapping[str, list[tuple[str, int]]]
"""Per robot, the goods its plan asks for and the index of the event each request prepares."""


@dataclass(frozen=True)
class RequestsAnswered:
    """What step 3 did: the words with their away messages, or why the requests cannot be met.

    Attributes
    ----------
    results : mapping of str to Synthesis
        Every robot's synthesis now.
    base : mapping of str to tuple of Event
        The robots' words without away messages; a helper's gains the goods it sets aside.
    current : mapping of str to tuple of Event
        The words with the away messages that answer the requests.
    coordinated : Coordinated or None
        The request/response pairs (``None``: no round ran).
    iterations : int
        Rounds of coordination.
    converged : bool
        Whether no plan asks for anything new.
    replans : tuple of str
        Why robots were re-planned, in plain words.
    reasons : tuple of str
        Why the team cannot be planned (empty: the requests are answered).
    """

    results: Mapping[str, Synthesis]
    base: Mapping[str, tuple[Event, ...]]
    current: Mapping[str, tuple[Event, ...]]
    coordinated: Coordinated | None
    iterations: int
    converged: bool
    replans: tuple[str, ...] = ()
    reasons: tuple[str, ...] = ()

    @property
    def ok(self) -> bool:
        """Whether the step worked (no reasons)."""
        return not self.reasons


def coordinate_requests(
    base: Mapping[str, tuple[Event, ...]],
    results: Mapping[str, Synthesis],
    planner: Planner,
    max_iterations: int,
) -> RequestsAnswered:
    """Turn requests into away messages until no plan asks for anything new (step 3).

    Parameters
    ----------
    base : mapping of str to tuple of Event
        Each robot's word (its mission's events and messages).
    results : mapping of str to Synthesis
        Each robot's first plan.
    planner : Planner
        The team's planner (forbidden requests and goods set aside are kept there).
    max_iterations : int
        Rounds after which the loop stops unsettled (a reason says so).
    """
    base, results = dict(base), dict(results)
    current, coordinated, iterations = dict(base), None, 0
    asked: Requests | None = {r: [] for r in base}
    replans: list[str] = []

    def answered(converged: bool, reasons: Iterable[str] = ()) -> RequestsAnswered:
        return RequestsAnswered(
            results, base, current, coordinated, iterations, converged, tuple(replans), tuple(reasons)
        )

    while True:
        if any(not res.feasible for res in results.values()):
            return answered(False, [res.reason or "" for res in results.values() if not res.feasible])
        t0 = time.perf_counter()
        requests = _requests(results, current, planner)
        if requests == asked:
            planner.count_time("coordinate", time.perf_counter() - t0)
            return answered(True)
        if iterations >= max_iterations:
            return answered(False, [f"coordination did not settle within {max_iterations} rounds"])
        iterations, asked = iterations + 1, requests
        coordinated = coordinate(base, requests)
        planner.count_time("coordinate", time.perf_counter() - t0)
        forbid = _bad_requests(coordinated)
        if forbid:
            # when goods nobody moves are asked for, a failed trial leads to a helper: no reasons
            step = _forbid(forbid, base, planner, explain=not coordinated.unanswered)
            if not step.ok and coordinated.unanswered:  # nobody moves what blocks: give it a helper
                step = _move_aside(coordinated.unanswered, requests, base, results, planner)
                asked = None  # the same requests now have a responder: coordinate them again
            results.update(step.results)
            base.update(step.words)
            current.update(step.words)
            replans.extend(step.replans)
            if not step.ok:
                return answered(False, step.reasons)
            continue
        changed = {r: events for r, events in coordinated.sequences.items() if events != current[r]}
        current.update(changed)
        results.update(planner.run(changed))


def _requests(
    results: Mapping[str, Synthesis], current: Mapping[str, tuple[Event, ...]], planner: Planner
) -> dict[str, list[tuple[str, int]]]:
    """What each robot's plan asks for, indexed in its word without away events."""
    scene = planner.scenario.scene  # with the places of goods moved aside so far
    out = {}
    for r, res in results.items():
        assert res.plan is not None  # every robot has a plan by now
        out[r] = [(o, _base_index(current[r], i)) for o, i in request_phases(res.plan, r, scene, current[r])]
    return out


def _base_index(sequence: tuple[Event, ...], index: int) -> int:
    """Index in the sequence without away events of the event at ``index`` of `sequence`."""
    return sum(1 for e in sequence[:index] if e.kind != "away")


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
    for robot, k in stuck_waits(words).items():
        event = coordinated.sequences[robot][k - 1]
        if event.kind == "away" and event.obj is not None:
            obj = event.obj
            options.append({robot: {obj: f"waiting for {obj} deadlocks the team ({event.name})"}})
    return options


def _forbid(
    options: list[dict[str, dict[str, str]]],
    base: Mapping[str, tuple[Event, ...]],
    planner: Planner,
    explain: bool = True,
) -> Replanned:
    """Re-plan robots without the requests of the first option that leaves them a plan; the
    reasons of every option if none does (with `explain` false, reasons without the solver's why)."""
    why_not: list[str] = []
    for forbid in options:
        saved = planner.restrictions()
        for robot, why in forbid.items():
            planner.forbid(robot, frozenset(why))
        fresh = planner.run({r: base[r] for r in forbid}, explain=explain)
        failed = [(r, res) for r, res in fresh.items() if not res.feasible]
        if not failed:
            replans = tuple(
                f"{robot} re-planned without requesting {', '.join(sorted(why))}: {'; '.join(why.values())}"
                for robot, why in forbid.items()
            )
            return Replanned(fresh, replans=replans)
        planner.restore(saved)
        for robot, res in failed:
            for obj, why_obj in sorted(forbid[robot].items()):
                why_not.append(
                    f"{robot} needs {obj} moved away, but {why_obj}; without that request: {res.reason}"
                )
    return Replanned(reasons=tuple(why_not or ["the requests cannot be answered"]))


def _move_aside(
    unanswered: Iterable[tuple[str, str]],
    requests: Requests,
    base: Mapping[str, tuple[Event, ...]],
    results: Mapping[str, Synthesis],
    planner: Planner,
) -> Replanned:
    """Give goods that block a robot, and that no mission moves, a helper that sets them aside.

    The paper's re-allocation: the requester itself is tried first (no message needed), then
    the other robots, those whose plans end soonest first.  The helper's mission gains
    ``pick`` and ``drop`` of the goods at a free place (:func:`cosmop.team.aside.place_aside`)
    -- for the requester right before the event its request prepares (before the pick it is
    carrying from, if any), for another robot at its start, and the requester's request is then
    answered like any other (``away``).  The reasons, per goods and robot tried, say why some
    goods find no helper.
    """
    words, fresh, replans, why_not = dict(base), dict(results), [], []
    for obj, requester in unanswered:
        if any(task.object == obj for task in planner.added):
            continue  # another requester's helper moves it already: the next round answers this one
        index = next((i for o, i in requests.get(requester, ()) if o == obj), 0)
        plans = {r: res.plan for r, res in fresh.items() if res.plan is not None}
        others = sorted((r for r in words if r != requester), key=lambda r: (_length(plans.get(r)), r))
        for helper in (requester, *others):  # trials first: a failed one need not say why
            outcome = _set_aside(obj, requester, helper, index, plans, words, planner, explain=False)
            if isinstance(outcome, str):
                continue
            task, events, result = outcome
            planner.added.append(task)
            words[helper], fresh[helper] = events, result
            # the others never see the goods move (their models keep them where they were):
            # from now on their plans keep out of the place, as from a wall
            where = square(*task.point, planner.scenario.scene.objects[obj].size)
            walls = walls_around(where, _AROUND.clearance, f"the place {helper} sets {obj} down at")
            for other in words:
                if other != helper:
                    planner.wall_off(other, walls)
            place = show_point(task.point, planner.scenario.scene.units)
            replans.append(f"{helper} sets {obj} down at {place}: {task.why}")
            break
        else:
            tried = [
                f"{helper}: {_set_aside(obj, requester, helper, index, plans, words, planner)}"
                for helper in (requester, *others)
            ]
            why_not.append(
                f"{requester} needs {obj} moved away, but no mission moves it and no robot can set it "
                f"aside ({'; '.join(tried)})"
            )
    changed = {r: w for r, w in words.items() if w != base[r]}
    return Replanned({r: fresh[r] for r in changed}, changed, tuple(replans), tuple(why_not))


def _set_aside(
    obj: str,
    requester: str,
    helper: str,
    index: int,
    plans: Mapping[str, RobotPlan],
    base: Mapping[str, tuple[Event, ...]],
    planner: Planner,
    explain: bool = True,
) -> tuple[AddedTask, tuple[Event, ...], Synthesis] | str:
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
