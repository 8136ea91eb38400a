"""Commit a mission that leaves choices open to its cheapest way, costed by the robots' plans.

The bottom-up half of allocation (the top-down half is :mod:`cosmop.missions.allocation`):
every word a robot may be given is planned (once, through the pipeline's planner, in parallel
across robots), the costs go to :func:`~cosmop.missions.allocation.choose` (a DFA with choices)
or :func:`~cosmop.missions.allocation.assign` (deliveries), and the chosen words, with the
messages that keep the order K needs, go on to the usual loop.  Every synthesis goes through
the team's :class:`~cosmop.team.planner.Planner`, so the loop reuses the plans costed here.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable, Mapping, Sequence
from dataclasses import dataclass, replace
from types import MappingProxyType
from typing import TypeVar

from cosmop.automata import DFA
from cosmop.events import Event, parse_event
from cosmop.missions.allocation import (
    Alternative,
    Alternatives,
    Choice,
    Words,
    alternatives,
    assign,
    choose,
    others,
    own_choices,
)
from cosmop.missions.mission import GlobalMission
from cosmop.missions.ordering import order_words, with_messages
from cosmop.planning.synthesis import Synthesis
from cosmop.scene import Scenario
from cosmop.team.planner import LocalMission, Planner
from cosmop.team.timing import step_durations

__all__ = ["Allocation", "allocate"]

_EXPLAINED = 3  # unplannable words a failed allocation explains with the solver (each costs a core)
_BATCH = 8  # alternatives planned together before the bound is looked at again

_Job = TypeVar("_Job", bound=Hashable)  # one question for a robot, as its caller keys it
_Costs = dict[tuple[str, tuple[str, ...], frozenset[str]], Synthesis]  # (robot, word, forbidden)
_Unanswerable = Callable[[Alternative, str], frozenset[str]]  # requests nobody in an alternative answers


@dataclass(frozen=True)
class Allocation:
    """The words a mission with choices is committed to, or why none can be planned.

    Attributes
    ----------
    words : mapping of str to tuple of Event
        Each robot's word, with the messages that keep the mission's order (empty words when
        no alternative can be planned).
    notes : mapping of str to (str, str)
        What each message is for: ``(kind, plain words)``.
    reasons : tuple of str
        Why no alternative can be planned (empty: one was chosen).
    choice : Choice or None
        The alternative chosen, its cost and how many were compared (``None``: the mission
        left no choice).
    forbidden : mapping of str to frozenset of str
        Per robot, the goods it may not request in the chosen alternative (nobody there
        answers): the loop starts from the plans costed with these.
    """

    words: Mapping[str, tuple[Event, ...]]
    notes: Mapping[str, tuple[str, str]]
    reasons: tuple[str, ...]
    choice: Choice | None
    forbidden: Mapping[str, frozenset[str]]


def allocate(scenario: Scenario, mission: GlobalMission, planner: Planner) -> Allocation:
    """Commit the team to the alternative of least makespan (:mod:`cosmop.missions.allocation`).

    Every robot's word in every alternative is planned (each once; in parallel across robots),
    the cheapest alternative is ordered by messages, and its words go on to the usual loop.

    Parameters
    ----------
    scenario : Scenario
        The scenario; its mission leaves choices open (a DFA with choices, or deliveries).
    mission : GlobalMission
        The scenario's mission, as an automaton.
    planner : Planner
        The team's planner: it runs and remembers the syntheses that cost the words.
    """
    robots = tuple(scenario.scene.robots)
    assert scenario.mission is not None  # a scenario of orders only is served by cosmop.lifelong
    if scenario.mission.deliveries is not None:
        return _allocate_deliveries(scenario, mission, planner)
    found = alternatives(mission)
    objects = frozenset(scenario.scene.objects)

    def unanswerable(alt: Alternative, robot: str) -> frozenset[str]:  # requests nobody in `alt` can answer
        return objects - {o for o, r in alt.movers(mission).items() if r != robot}

    found, costs, settled = _settle_own_choices(planner, found, mission, unanswerable)
    found = _plan_bounded(planner, found, mission, unanswerable, costs)

    def synthesis(alt: Alternative, robot: str) -> Synthesis:
        return costs[(robot, alt.words[robot], unanswerable(alt, robot))]

    choice = choose(
        found,
        lambda alt, r: synthesis(alt, r).horizon if synthesis(alt, r).feasible else None,
        lambda alt, r: synthesis(alt, r).reason or "no plan within the horizon",
    )
    if settled:
        how = f"{', '.join(settled)}'s own choices planned as one branching mission each"
        choice = replace(choice, method=f"{choice.method}; {how}")
    if choice.alternative is None:
        why: dict[tuple[str, tuple[str, ...]], str] = {}
        for robot, word in list(choice.unplannable)[:_EXPLAINED]:  # the first few, with the solver's why
            forbidden = next((k[2] for k in costs if k[:2] == (robot, word)), frozenset())
            why[(robot, word)] = _explained(planner, robot, [mission.events[e] for e in word], forbidden)
        choice = replace(choice, unplannable=MappingProxyType({**choice.unplannable, **why}))
        none = {r: () for r in robots}
        return Allocation(none, {}, (_no_alternative(choice, found.exhaustive),), choice, {})
    words = dict(choice.alternative.words)
    # the loop starts from the plans costed here: same words, same requests ruled out
    ruled_out = {r: unanswerable(choice.alternative, r) for r in robots if words.get(r)}
    assert mission.complete is not None  # built with the mission
    order = order_words(mission.complete, words)
    placed, messages = with_messages(words, order.edges)
    notes = {
        name: ("order", f"the mission orders {b}'s {words[b][j]} after {a}'s {words[a][i]}")
        for name, ((a, i), (b, j)) in messages
    }
    events = {r: tuple(parse_event(e) for e in placed.get(r, ())) for r in robots}
    return Allocation(events, notes, (), choice, ruled_out)


def _plan_bounded(
    planner: Planner, found: Alternatives, mission: GlobalMission, unanswerable: _Unanswerable, costs: _Costs
) -> Alternatives:
    """Plan the alternatives' words, cheapest lower bound first, until none left can win.

    No plan is shorter than a step per event but ``return``, so an alternative whose bound
    (makespan, then total) exceeds the best planned one's cost cannot be chosen
    (:func:`~cosmop.missions.allocation.choose`); such alternatives are never planned
    (branch and bound; the choice is the same as planning all).  `costs` gains the
    syntheses; the alternatives planned are returned.
    """

    def bound(alt: Alternative) -> tuple[int, int]:
        steps = [sum(1 for e in w if mission.events[e].kind != "return") for w in alt.words.values()]
        return max(steps, default=0), sum(steps)

    def cost(alt: Alternative) -> tuple[int, int] | None:
        keys = [(r, w, unanswerable(alt, r)) for r, w in alt.words.items() if w]
        steps = [h for k in keys if k in costs and (h := costs[k].horizon) is not None and costs[k].feasible]
        if len(steps) < len(keys):
            return None
        return max(steps, default=0), sum(steps)

    order = sorted(range(len(found.items)), key=lambda n: bound(found.items[n]))
    planned: set[int] = set()
    best: tuple[int, int] | None = None
    while order and (best is None or bound(found.items[order[0]]) <= best):
        # the alternatives of the least bound left (a few at a time), planned together
        level = bound(found.items[order[0]])
        batch = [n for n in order[:_BATCH] if bound(found.items[n]) == level]
        order = order[len(batch) :]
        pending: dict[str, list[tuple[tuple[str, ...], frozenset[str]]]] = {}
        for alt in (found.items[n] for n in batch):
            for robot, word in alt.words.items():
                job = (word, unanswerable(alt, robot))
                if word and (robot, word, job[1]) not in costs and job not in pending.setdefault(robot, []):
                    pending[robot].append(job)
        planned_now = _plan_all(
            planner, pending, lambda r, job: tuple(mission.events[e] for e in job[0]), lambda r, job: job[1]
        )
        costs.update({(r, word, forbidden): res for (r, (word, forbidden)), res in planned_now.items()})
        planned.update(batch)
        for n in batch:
            c = cost(found.items[n])
            best = c if c is not None and (best is None or c < best) else best
    items = tuple(alt for n, alt in enumerate(found.items) if n in planned)
    return Alternatives(items, found.exhaustive, found.explored)


def _settle_own_choices(
    planner: Planner, found: Alternatives, mission: GlobalMission, unanswerable: _Unanswerable
) -> tuple[Alternatives, _Costs, list[str]]:
    """Plan the choices each robot makes alone as branching missions; keep the cheapest word.

    Robot after robot (:func:`~cosmop.missions.allocation.own_choices`): each group of its
    words that go with the same words of the others is planned once over the automaton of the
    group (:func:`~cosmop.planning.synthesis.synthesize` with a DFA), the shortest plan over
    all of them, and the alternatives keep only the word that plan performs (exact, see
    :mod:`cosmop.missions.allocation`).  That synthesis also answers the plain question for its
    word (no shorter plan of it exists), so the planning loop reuses it.  Costs are keyed like
    :func:`allocate`'s; the robots that had such choices are returned last.
    """
    costs: _Costs = {}
    settled = []
    for robot in mission.robots:
        groups = own_choices(found, robot, mission)
        if not groups:
            continue
        settled.append(robot)
        jobs: list[tuple[Words, frozenset[str]]] = []
        where: dict[Words, tuple[Words, frozenset[str]]] = {}
        for alt in found.items:
            rest = others(alt, robot)
            if rest in groups:
                where[rest] = (groups[rest], unanswerable(alt, robot))
                if where[rest] not in jobs:
                    jobs.append(where[rest])
        results = _plan_all(
            planner, {robot: jobs}, lambda r, job: DFA.from_words(job[0]), lambda r, job: job[1]
        )
        for (r, (words, forbidden)), res in results.items():
            if res.plan is not None:
                costs[(r, res.plan.word, forbidden)] = res
                planner.remember(r, res.plan.mission, forbidden, res)
            else:  # no word of the group can be planned: each keeps the reason
                costs.update({(r, w, forbidden): res for w in words})

        def cheapest(
            alt: Alternative,
            robot: str = robot,
            where: Mapping[Words, tuple[Words, frozenset[str]]] = where,
            results: Mapping[tuple[str, tuple[Words, frozenset[str]]], Synthesis] = results,
        ) -> bool:
            job = where.get(others(alt, robot))
            if job is None:
                return True
            plan = results[(robot, job)].plan
            return plan is None or plan.word == alt.words[robot]

        found = Alternatives(tuple(a for a in found.items if cheapest(a)), found.exhaustive, found.explored)
    return found, costs, settled


def _allocate_deliveries(scenario: Scenario, mission: GlobalMission, planner: Planner) -> Allocation:
    """Deliveries: cost each (robot, object, workspace) alone, then :func:`assign`.

    A delivery alone is the robot's shortest plan from home that picks the object, drops it
    in the workspace (and comes home, with ``return``).  A robot's words: its deliveries in the
    file's order.  No robot's events order another's (each object is moved by one robot), so
    the words need no messages.
    """
    spec = scenario.mission
    assert spec is not None and spec.deliveries is not None  # the caller's test
    deliveries, returns = spec.deliveries, spec.returns
    robots = tuple(scenario.scene.robots)
    nobody = frozenset(scenario.scene.objects) - {d.object for d in deliveries}
    pending: dict[str, list[tuple[str, str]]] = {}
    for d in deliveries:
        for r in d.by:
            pending.setdefault(r, []).extend((d.object, w) for w in d.to)
    planned = _plan_all(
        planner, pending, lambda r, job: _delivery_word(r, job[0], job[1], returns), lambda r, job: nobody
    )
    costs = {(r, o, w): res for (r, (o, w)), res in planned.items()}
    options = {d.object: [(r, w) for r in d.by for w in d.to] for d in deliveries}
    steps = {key: (res.horizon if res.feasible else None) for key, res in costs.items()}
    home = scenario.scene.robots
    seconds = {
        key: sum(step_durations(res.plan, home[key[0]].pose, home[key[0]].dynamics))
        for key, res in costs.items()
        if res.plan is not None
    }
    chosen = assign(options, steps, seconds=seconds)
    method = "branch and bound over (robot, workspace) per object, each delivery costed alone"
    if chosen.stuck:
        failed = [(r, o, w) for o in chosen.stuck for r, w in options[o] if not costs[(r, o, w)].feasible]
        for robot, obj, workspace in failed[:_EXPLAINED]:  # the solver's why (each costs a core)
            word = _delivery_word(robot, obj, workspace, returns)
            why = _explained(planner, robot, word, nobody)
            costs[(robot, obj, workspace)] = replace(costs[(robot, obj, workspace)], reason=why)
        why = "; ".join(_undeliverable(o, options[o], costs) for o in chosen.stuck)
        none = Choice(None, None, None, chosen.nodes, method=method, costs=MappingProxyType(steps))
        return Allocation({r: () for r in robots}, {}, (why,), none, {})
    words: dict[str, list[str]] = {r: [] for r in robots}
    for d in deliveries:
        r, w = chosen.tasks[d.object]
        words[r] += [f"pick({r},{d.object})", f"drop({r},{d.object},{w})"]
    for r, names in words.items():
        if names and returns:
            names.append(f"return({r})")
    alternative = Alternative({r: tuple(w) for r, w in words.items()})
    choice = Choice(
        alternative, chosen.makespan, chosen.total, chosen.nodes, {}, chosen.exhaustive, method, steps
    )
    events = {r: tuple(mission.events[e] for e in w) for r, w in words.items()}
    return Allocation(events, {}, (), choice, {r: nobody for r in robots if words[r]})


def _plan_all(
    planner: Planner,
    pending: Mapping[str, Sequence[_Job]],
    word: Callable[[str, _Job], LocalMission],
    forbid: Callable[[str, _Job], frozenset[str]],
) -> dict[tuple[str, _Job], Synthesis]:
    """Plan every robot's jobs, one job per robot at a time (the robots in parallel).

    ``word(robot, job)`` is the mission to plan; ``forbid(robot, job)`` the objects the robot
    may not request for it.  The results are keyed ``(robot, job)``.  These are
    trials: an infeasible one only says so (an explanation is an unsat core per event, which
    cost minutes over many alternatives); :func:`_explained` explains those a reason names.
    """
    costs: dict[tuple[str, _Job], Synthesis] = {}
    for rank in range(max((len(jobs) for jobs in pending.values()), default=0)):
        batch = {r: jobs[rank] for r, jobs in pending.items() if rank < len(jobs)}
        forbidden = {r: forbid(r, job) for r, job in batch.items()}
        jobs = {r: word(r, job) for r, job in batch.items()}
        results = planner.run(jobs, forbidden=forbidden, explain=False)
        costs.update({(r, batch[r]): res for r, res in results.items()})
    return costs


def _explained(planner: Planner, robot: str, events: Sequence[Event], forbidden: frozenset[str]) -> str:
    """Why `robot` cannot plan `events` with `forbidden` requests ruled out (the solver's why)."""
    result = planner.run({robot: tuple(events)}, forbidden={robot: forbidden})[robot]
    return result.reason or "no plan within the horizon"


def _delivery_word(robot: str, obj: str, workspace: str, returns: bool) -> tuple[Event, ...]:
    word = [Event("pick", robot, obj=obj), Event("drop", robot, obj=obj, workspace=workspace)]
    return tuple(word + ([Event("return", robot)] if returns else []))


def _undeliverable(
    obj: str, options: Sequence[tuple[str, str]], costs: Mapping[tuple[str, str, str], Synthesis]
) -> str:
    """Why no robot can deliver `obj`: each robot and workspace tried, with what blocks it."""
    tried = [f"{r} to {w}: {costs[(r, obj, w)].reason or 'no plan within the horizon'}" for r, w in options]
    return f"no robot can deliver {obj} (tried {'; '.join(tried)})"


def _no_alternative(choice: Choice, exhaustive: bool) -> str:
    """Why no way of completing the mission can be planned: each robot's word that fails."""
    if not choice.considered:
        bound = "" if exhaustive else " within the search bound"
        return f"no way to complete the mission was found{bound}"
    tried = [f"{r} cannot do {' '.join(w)} ({why})" for (r, w), why in choice.unplannable.items()]
    return f"none of the {choice.considered} ways to complete the mission can be planned: " + "; ".join(tried)
