"""Commit a mission that leaves choices open to its cheapest way, costed by the robots' plans.

The bottom-up half of allocation (the top-down half is :mod:`cosmop.missions.allocation`):
every word a robot may be given is planned (once, through the pipeline's planner, in parallel
across robots), the costs go to :func:`~cosmop.missions.allocation.choose` (a DFA with choices)
or :func:`~cosmop.missions.allocation.assign` (deliveries), and the chosen words, with the
messages that keep the order K needs, go on to the usual loop.  `planner` is the pipeline's:
``run(jobs)`` synthesises a word per robot and ``forbidden`` holds each robot's objects it may
not request.
"""

from __future__ import annotations

from dataclasses import replace
from types import MappingProxyType

from cosmop.automata import DFA
from cosmop.events import Event, parse_event
from cosmop.missions.allocation import (
    Alternative,
    Alternatives,
    Choice,
    alternatives,
    assign,
    choose,
    others,
    own_choices,
)
from cosmop.missions.mission import GlobalMission
from cosmop.missions.ordering import order_words, with_messages
from cosmop.planning.synthesis import Synthesis
from cosmop.planning.timing import step_durations
from cosmop.scene import Scenario

__all__ = ["allocate"]

_EXPLAINED = 3  # unplannable words a failed allocation explains with the solver (each costs a core)
_BATCH = 8  # alternatives planned together before the bound is looked at again


def allocate(
    scenario: Scenario, mission: GlobalMission, planner
) -> tuple[dict[str, tuple[Event, ...]], dict[str, tuple[str, str]], list[str], Choice]:
    """Commit the team to the alternative of least makespan (:mod:`cosmop.missions.allocation`).

    Every robot's word in every alternative is planned (each once; in parallel across robots),
    the cheapest alternative is ordered by messages, and its words go on to the usual loop.
    """
    robots = tuple(scenario.scene.robots)
    if scenario.mission.deliveries is not None:
        return _allocate_deliveries(scenario, mission, planner)
    found = alternatives(mission)
    objects = frozenset(scenario.scene.objects)

    def unanswerable(alt, robot: str) -> frozenset[str]:  # requests nobody in `alt` can answer
        return objects - {o for o, r in alt.movers(mission).items() if r != robot}

    found, costs, settled = _settle_own_choices(planner, found, mission, unanswerable)
    found = _plan_bounded(planner, found, mission, unanswerable, costs)
    planner.forbidden = {}

    def synthesis(alt, robot: str) -> Synthesis:
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
        why = {}
        for robot, word in list(choice.unplannable)[:_EXPLAINED]:  # the first few, with the solver's why
            forbidden = next((k[2] for k in costs if k[:2] == (robot, word)), frozenset())
            why[(robot, word)] = _explained(planner, robot, [mission.events[e] for e in word], forbidden)
        choice = replace(choice, unplannable=MappingProxyType({**choice.unplannable, **why}))
        return {r: () for r in robots}, {}, [_no_alternative(choice, found.exhaustive)], choice
    words = dict(choice.alternative.words)
    # the loop starts from the plans costed here: same words, same requests ruled out
    planner.forbidden = {r: unanswerable(choice.alternative, r) for r in robots if words.get(r)}
    order = order_words(mission.complete, words)
    placed, messages = with_messages(words, order.edges)
    notes = {
        name: ("order", f"the mission orders {b}'s {words[b][j]} after {a}'s {words[a][i]}")
        for name, ((a, i), (b, j)) in messages
    }
    events = {r: tuple(parse_event(e) for e in placed.get(r, ())) for r in robots}
    return events, notes, [], choice


def _plan_bounded(
    planner, found: Alternatives, mission: GlobalMission, unanswerable, costs: dict
) -> Alternatives:
    """Plan the alternatives' words, cheapest lower bound first, until none left can win.

    No plan is shorter than a step per event but ``return``, so an alternative whose bound
    (makespan, then total) exceeds the best planned one's cost cannot be chosen
    (:func:`~cosmop.missions.allocation.choose`); such alternatives are never planned
    (branch and bound; the choice is the same as planning all).  `costs` gains the
    syntheses; the alternatives planned are returned.
    """

    def bound(alt) -> tuple[int, int]:
        steps = [sum(1 for e in w if mission.events[e].kind != "return") for w in alt.words.values()]
        return max(steps, default=0), sum(steps)

    def cost(alt) -> tuple[int, int] | None:
        keys = [(r, w, unanswerable(alt, r)) for r, w in alt.words.items() if w]
        if not all(k in costs and costs[k].feasible for k in keys):
            return None
        steps = [costs[k].horizon for k in keys]
        return max(steps, default=0), sum(steps)

    order = sorted(range(len(found.items)), key=lambda n: bound(found.items[n]))
    planned: set[int] = set()
    best = None
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
        costs.update(
            _plan_all(
                planner,
                pending,
                lambda r, job: tuple(mission.events[e] for e in job[0]),
                lambda r, job: job[1],
            )
        )
        planned.update(batch)
        for n in batch:
            c = cost(found.items[n])
            best = c if c is not None and (best is None or c < best) else best
    items = tuple(alt for n, alt in enumerate(found.items) if n in planned)
    return Alternatives(items, found.exhaustive, found.explored)


def _settle_own_choices(
    planner, found: Alternatives, mission: GlobalMission, unanswerable
) -> tuple[Alternatives, dict[tuple, Synthesis], list[str]]:
    """Plan the choices each robot makes alone as branching missions; keep the cheapest word.

    Robot after robot (:func:`~cosmop.missions.allocation.own_choices`): each group of its
    words that go with the same words of the others is planned once over the automaton of the
    group (:func:`~cosmop.planning.synthesis.synthesize` with a DFA), the shortest plan over
    all of them, and the alternatives keep only the word that plan performs (exact, see
    :mod:`cosmop.missions.allocation`).  That synthesis also answers the plain question for its
    word (no shorter plan of it exists), so the planning loop reuses it.  Costs are keyed like
    :func:`allocate`'s; the robots that had such choices are returned last.
    """
    costs: dict[tuple, Synthesis] = {}
    settled = []
    for robot in mission.robots:
        groups = own_choices(found, robot, mission)
        if not groups:
            continue
        settled.append(robot)
        jobs: list[tuple[tuple, frozenset[str]]] = []
        where = {}
        for alt in found.items:
            rest = others(alt, robot)
            if rest in groups:
                where[rest] = (groups[rest], unanswerable(alt, robot))
                if where[rest] not in jobs:
                    jobs.append(where[rest])
        results = _plan_all(
            planner, {robot: jobs}, lambda r, job: DFA.from_words(job[0]), lambda r, job: job[1]
        )
        for (r, words, forbidden), res in results.items():
            if res.feasible:
                costs[(r, res.plan.mission, forbidden)] = res
                planner.remember(r, res.plan.events, forbidden, res)
            else:  # no word of the group can be planned: each keeps the reason
                costs.update({(r, w, forbidden): res for w in words})

        def cheapest(alt, robot=robot, where=where, results=results) -> bool:
            job = where.get(others(alt, robot))
            if job is None:
                return True
            res = results[(robot, *job)]
            return not res.feasible or res.plan.mission == alt.words[robot]

        found = Alternatives(tuple(a for a in found.items if cheapest(a)), found.exhaustive, found.explored)
    return found, costs, settled


def _allocate_deliveries(
    scenario: Scenario, mission: GlobalMission, planner
) -> tuple[dict[str, tuple[Event, ...]], dict[str, tuple[str, str]], list[str], Choice]:
    """Deliveries: cost each (robot, object, workspace) alone, then :func:`assign`.

    A delivery alone is the robot's shortest plan from home that picks the object, drops it
    in the workspace (and comes home, with ``return``).  A robot's words: its deliveries in the
    file's order.  No robot's events order another's (each object is moved by one robot), so
    the words need no messages.
    """
    spec = scenario.mission
    robots = tuple(scenario.scene.robots)
    nobody = frozenset(scenario.scene.objects) - {d.object for d in spec.deliveries}
    pending: dict[str, list[tuple[str, str]]] = {}
    for d in spec.deliveries:
        for r in d.by:
            pending.setdefault(r, []).extend((d.object, w) for w in d.to)
    planner.forbidden = {r: nobody for r in pending}
    costs = _plan_all(planner, pending, lambda r, job: _delivery_word(r, *job, spec.returns))
    options = {d.object: [(r, w) for r in d.by for w in d.to] for d in spec.deliveries}
    steps = {key: (res.horizon if res.feasible else None) for key, res in costs.items()}
    home = scenario.scene.robots
    seconds = {
        key: sum(step_durations(res.plan, home[key[0]].pose, home[key[0]].dynamics))
        for key, res in costs.items()
        if res.feasible
    }
    chosen = assign(options, steps, seconds=seconds)
    method = "branch and bound over (robot, workspace) per object, each delivery costed alone"
    if chosen.stuck:
        failed = [(r, o, w) for o in chosen.stuck for r, w in options[o] if not costs[(r, o, w)].feasible]
        for robot, obj, workspace in failed[:_EXPLAINED]:  # the solver's why (each costs a core)
            word = _delivery_word(robot, obj, workspace, spec.returns)
            why = _explained(planner, robot, word, nobody)
            costs[(robot, obj, workspace)] = replace(costs[(robot, obj, workspace)], reason=why)
        why = "; ".join(_undeliverable(o, options[o], costs) for o in chosen.stuck)
        failed = Choice(None, None, None, chosen.nodes, method=method, costs=MappingProxyType(steps))
        return {r: () for r in robots}, {}, [why], failed
    words: dict[str, list[str]] = {r: [] for r in robots}
    for d in spec.deliveries:
        r, w = chosen.tasks[d.object]
        words[r] += [f"pick({r},{d.object})", f"drop({r},{d.object},{w})"]
    for r, word in words.items():
        if word and spec.returns:
            word.append(f"return({r})")
    alternative = Alternative({r: tuple(w) for r, w in words.items()})
    choice = Choice(
        alternative, chosen.makespan, chosen.total, chosen.nodes, {}, chosen.exhaustive, method, steps
    )
    planner.forbidden = {r: nobody for r in robots if words[r]}
    events = {r: tuple(mission.events[e] for e in w) for r, w in words.items()}
    return events, {}, [], choice


def _plan_all(planner, pending: dict[str, list[tuple]], word, forbid=None) -> dict[tuple, Synthesis]:
    """Plan every robot's jobs, one job per robot at a time (the robots in parallel).

    ``word(robot, job)`` is the mission to plan; ``forbid(robot, job)``, if given, the objects
    the robot may not request for it.  The results are keyed ``(robot, *job)``.  These are
    trials: an infeasible one only says so (an explanation is an unsat core per event, which
    cost minutes over many alternatives); :func:`_explained` explains those a reason names.
    """
    costs: dict[tuple, Synthesis] = {}
    for rank in range(max((len(jobs) for jobs in pending.values()), default=0)):
        batch = {r: jobs[rank] for r, jobs in pending.items() if rank < len(jobs)}
        if forbid is not None:
            planner.forbidden = {r: forbid(r, job) for r, job in batch.items()}
        results = planner.run({r: word(r, job) for r, job in batch.items()}, explain=False)
        costs.update({(r, *batch[r]): res for r, res in results.items()})
    return costs


def _explained(planner, robot: str, events, forbidden: frozenset[str]) -> str:
    """Why `robot` cannot plan `events` with `forbidden` requests ruled out (the solver's why)."""
    saved = planner.forbidden
    planner.forbidden = {robot: forbidden}
    try:
        return planner.run({robot: tuple(events)})[robot].reason or "no plan within the horizon"
    finally:
        planner.forbidden = saved


def _delivery_word(robot: str, obj: str, workspace: str, returns: bool) -> tuple[Event, ...]:
    word = [Event("pick", robot, obj=obj), Event("drop", robot, obj=obj, workspace=workspace)]
    return tuple(word + ([Event("return", robot)] if returns else []))


def _undeliverable(obj: str, options, costs) -> str:
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
