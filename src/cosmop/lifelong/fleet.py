"""A lifelong run: a fleet that keeps working while orders stream in and robots fail.

:func:`run_fleet` simulates the scenario's world as :func:`cosmop.sim.simulate` does, cycle by
cycle (:func:`cosmop.sim.simulation.advance`), and between cycles it

1. releases the orders whose time has come into a pool (:mod:`.dispatch`);
2. every ``dispatch_every`` seconds, and at once when a robot has just dropped its goods (it
   competes from the dock, so that it goes home only when no work waits), gives pooled orders
   to idle robots, each the order of least work among the oldest few (``reveal`` orders per
   robot, :func:`~cosmop.lifelong.dispatch.choose_assignment`); each robot is tried once per
   dispatch.  The robot's next mission (pick, drop, home unless a failed robot took it) is
   planned from where it stands, with the robots that stand (idle or failed) as obstacles
   (:func:`cosmop.sim.replan.replan`, every plan passing the exact checker), then ordered
   against the plans the others have committed to, by the same messages and exact checks as a
   planned team (:func:`cosmop.sim.recoordinate.recoordinate_world`: the conflicts of every
   robot's rest are ordered again and the team proved deadlock-free); only then is it handed
   over.  The robots not involved keep their plans and keep moving.
   An order whose plan is refused stays in the pool and waits ``retry_after`` seconds, twice
   as long after each refusal up to ``max_retry_after``: in a world that moves, a refusal
   says "not now", never "never", so refusals alone do not lose an order.  A robot that
   finds no plan says why once (:func:`cosmop.sim.replan.why_no_plan`, the robots standing
   named), and the order goes to another idle robot first;
3. every ``dispatch_every`` seconds too, orders again the conflicts of the robots that have
   stood longest for another's conflict message (``reorder_after`` seconds; at most
   ``max_reorders`` a dispatch): an order chosen at a hand-over from the times expected then
   may hold a robot back for one still far from the shared place, and ordered again from the
   times expected now, the robot that gets there first goes first
   (:func:`cosmop.sim.recoordinate.reorder_world`, the same checks as a hand-over; a refusal
   keeps the order).  A try that brings the robot's message neither ``reorder_after``
   seconds nearer nor within ``reorder_after`` seconds (its sender stands in the way, or is
   held up itself) doubles the time before the same wait is tried again;
4. ships delivered goods: once the drop is recorded the goods leave the world, so docks do not
   fill up (:meth:`cosmop.sim.world.World.ship`);
5. fails robots (:class:`Failure`): a failed robot brakes and stands for good, its order
   returns to the pool unless it carries the goods (then the order is lost, and the goods are
   reported where they stand), and once it stands the others are ordered again around it;
   where a committed route runs through it, the robots still to move are re-planned around
   it, nearest first, until they can be (:func:`_settle_failures`).  A robot whose home it
   stands on has no way home any more: it is re-planned first, and from then on its plans end
   where they drop the goods, the next order taking it on from there.

Units: mm, degrees, seconds.
"""

from __future__ import annotations

import itertools
import math
import re
import time
from collections.abc import Callable, Collection, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from cosmop.control.geometry import box_gaps
from cosmop.lifelong.dispatch import Offer, OrderState, choose_assignment, delivery_events, window_size
from cosmop.lifelong.fleet_result import FleetResult
from cosmop.planning.plan_types import PlanSet
from cosmop.scene import Order, Scenario
from cosmop.sim.recoordinate import (
    Remaining,
    message_due_in,
    order_around_failure,
    recoordinate_world,
    reorder_world,
)
from cosmop.sim.recording import Recorder
from cosmop.sim.replan import (
    Rectangle,
    grown,
    mission_left,
    replan,
    robot_room,
    start_state,
    why_no_plan,
)
from cosmop.sim.result import SimSettings
from cosmop.sim.simulation import advance
from cosmop.sim.world import Agent, World
from cosmop.team.conflicts import ConflictSettings

__all__ = ["Failure", "FleetInterrupted", "FleetSettings", "run_fleet"]


@dataclass(frozen=True)
class Failure:
    """A robot that stops for good at time `at` (s).

    Attributes
    ----------
    robot : str
        The robot that fails.
    at : float
        When it stops, s from the start of the run.

    Examples
    --------
    >>> Failure.parse("R3@600")
    Failure(robot='R3', at=600.0)
    """

    robot: str
    at: float

    @classmethod
    def parse(cls, text: str) -> Failure:
        """``ROBOT@SECONDS``, e.g. ``R3@600``.

        Parameters
        ----------
        text : str
            The robot's id and the time it fails, s (as ``--fail`` gives them).

        Raises
        ------
        ValueError
            When `text` is not of that form or the time is negative.
        """
        match = re.fullmatch(r"\s*([A-Za-z_][A-Za-z0-9_-]*)@([0-9]+(?:\.[0-9]*)?)\s*", text)
        if match is None:
            raise ValueError(f"expected ROBOT@SECONDS such as R3@600, got {text!r}")
        return cls(match.group(1), float(match.group(2)))


@dataclass(frozen=True)
class FleetSettings:
    """How the dispatcher works.

    Attributes
    ----------
    until : float
        Simulated seconds the run lasts.
    dispatch_every : float
        Seconds between two dispatches (each may hand over several orders).
    retry_after : float
        Seconds an order waits after its first refused plan before it is tried again; the
        wait doubles after each further refusal.
    max_retry_after : float
        The longest wait between two tries, s.
    max_horizon : int
        Longest plan of one order (steps).
    rlimit : int
        The solver's resource limit per plan.
    reorder_after : float or None
        Seconds a robot stands waiting for another's conflict message before its conflicts are
        ordered again from the times expected then (:func:`~cosmop.sim.recoordinate.reorder_world`),
        and again at most this often (twice as long after each try that brought its
        message neither this much nearer nor this near); ``None``: orders are kept as handed over.
    max_reorders : int
        Most robots ordered again at one dispatch, the longest waiting first (each costs an
        ordering of the team, like a hand-over).
    reveal : float
        Orders per robot the dispatcher chooses among: the oldest ``ceil(reveal * robots)``
        pooled orders, at least one (the League of Robot Runners' ``numTasksReveal``);
        0 gives each order, oldest first, to the idle robot nearest to it
        (:func:`~cosmop.lifelong.dispatch.choose_assignment`).
    """

    until: float
    dispatch_every: float = 1.0
    retry_after: float = 5.0
    max_retry_after: float = 60.0
    max_horizon: int = 16
    rlimit: int = 50_000_000
    reorder_after: float | None = 15.0
    max_reorders: int = 2
    reveal: float = 1.0


@dataclass
class _Run:
    """The dispatcher's state during a run (mutable)."""

    world: World
    states: list[OrderState]
    fleet: FleetSettings
    pool: list[OrderState] = field(default_factory=list)
    busy: dict[str, OrderState] = field(default_factory=dict)
    busy_since: dict[str, float] = field(default_factory=dict)
    busy_time: dict[str, float] = field(default_factory=dict)
    failed: dict[str, dict[str, Any]] = field(default_factory=dict)  # JSON records of the summary
    failure_retry: dict[str, float] = field(default_factory=dict)  # robot: next try to order around it, s
    homeless: set[str] = field(default_factory=set)  # robots whose home a failed robot stands on
    log: list[dict[str, Any]] = field(default_factory=list)
    reorders: list[dict[str, Any]] = field(default_factory=list)  # JSON records of the summary
    waits: dict[str, tuple[int, float]] = field(default_factory=dict)  # robot: (step, since), s
    # robot: (the wait last re-ordered, when, seconds from that re-ordering of it to the next)
    reordered: dict[str, tuple[tuple[int, float], float, float]] = field(default_factory=dict)
    seen_events: int = 0
    delivered: int = 0


def run_fleet(
    scenario: Scenario,
    orders: Sequence[Order] | None = None,
    *,
    fleet: FleetSettings,
    seed: int = 0,
    settings: SimSettings | None = None,
    failures: Sequence[Failure] = (),
    on_cycle: Callable[[float, int, int], None] | None = None,
) -> FleetResult:
    """Run the fleet while `orders` (by default the scenario's) are released over time.

    Parameters
    ----------
    scenario : Scenario
        The scene; its ``mission`` is not used (a lifelong run serves orders).
    orders : sequence of Order, optional
        The stream; by default ``scenario.orders``.
    fleet : FleetSettings
        How long the run lasts and how the dispatcher works.
    seed : int
        Seeds the people's walks and the delays.
    settings : SimSettings, optional
        The simulator's settings (``delays`` included); ``max_time`` is ignored.
    failures : sequence of Failure
        Robots that stop for good, and when.
    on_cycle : callable, optional
        Called every cycle with ``(t, delivered, released)`` (a progress line).

    Returns
    -------
    FleetResult

    Raises
    ------
    ValueError
        For a failure naming no robot of the scene.
    FleetInterrupted
        On Ctrl-C (KeyboardInterrupt), with the run up to then.
    """
    for failure in failures:
        if failure.robot not in scenario.scene.robots:
            raise ValueError(f"--fail names {failure.robot}, which is not a robot of the scene")
    stream = sorted(orders if orders is not None else scenario.orders, key=lambda o: o.at)
    world = World(scenario, PlanSet(scenario.name, True, {}), seed, settings or SimSettings())
    world.conflict_settings = ConflictSettings(shipped_on_drop=True)  # delivered goods leave the world
    run = _Run(world, [OrderState(o, k) for k, o in enumerate(stream)], fleet)
    run.busy_time = {rid: 0.0 for rid in world.robot_ids}
    recorder = Recorder()
    recorder.record(world)
    due = sorted(failures, key=lambda f: f.at)
    released, next_dispatch = 0, 0.0
    try:
        for _ in range(math.ceil(fleet.until / world.dt)):
            while released < len(run.states) and run.states[released].order.at <= world.t:
                run.pool.append(run.states[released])
                released += 1
            while due and due[0].at <= world.t:
                _fail(run, due.pop(0).robot)
            if world.t >= next_dispatch:
                _settle_failures(run)
                _dispatch(run)
                _reorder_long_waits(run)
                next_dispatch = world.t + fleet.dispatch_every
            advance(world)
            _deliveries(run)  # before the frame is recorded: delivered goods are gone from it
            _idle_again(run)
            _note_waits(run)
            recorder.record(world)
            if on_cycle is not None:
                on_cycle(world.t, run.delivered, released)
    except KeyboardInterrupt:
        raise FleetInterrupted(_result(run, recorder, interrupted=True)) from None
    return _result(run, recorder)


class FleetInterrupted(KeyboardInterrupt):
    """Ctrl-C during :func:`run_fleet`: the run up to the last whole cycle, in :attr:`result`
    (``interrupted`` set, ``until`` the time reached), so that what was delivered can still be
    reported.

    Attributes
    ----------
    result : FleetResult
    """

    def __init__(self, result: FleetResult) -> None:
        super().__init__("interrupted")
        self.result = result


def _result(run: _Run, recorder: Recorder, *, interrupted: bool = False) -> FleetResult:
    """What the run did up to now (each robot still busy counted busy until now)."""
    world = run.world
    busy = dict(run.busy_time)
    for rid, since in run.busy_since.items():
        busy[rid] += world.t - since
    return FleetResult.of(
        world.scenario,
        world,
        recorder.frames(world),
        run.states,
        busy,
        run.failed,
        run.log,
        reorders=run.reorders,
        interrupted=interrupted,
        window=_window(run),
    )


def _dispatch(run: _Run, at_dock: Agent | None = None) -> None:
    """Hand pooled orders to idle robots, each the order of least work among the oldest few
    (module docstring, step 2; :func:`~cosmop.lifelong.dispatch.choose_assignment`).

    `at_dock`, a robot that has just dropped its goods, competes with the idle robots for the
    orders: if it is given one, the way home left in its plan is replaced by that order (whose
    mission ends at home again, for when no more work waits); if not, it goes home (it stays
    where it is when a failed robot has taken its home).
    """
    world = run.world
    idle = {a.id: a for a in world.agents if a.done and a.id not in run.busy and a.id not in run.failed}
    if at_dock is not None:
        idle[at_dock.id] = at_dock
    window = _window(run)
    while idle:
        offered = list(itertools.islice(_offers(run, idle), window))
        offers = [Offer(s.order, goods, frozenset(s.no_plan_by), s.passed >= window) for s, goods in offered]
        at = [(r, tuple(world.pose[a.index, :2])) for r, a in idle.items()]
        chosen = choose_assignment(world.scenario.scene, offers, at)
        if chosen is None:
            return
        k, robot = chosen
        state, goods = offered[k]
        _hand_over(run, idle[robot], state, goods)
        if state.robot == robot:  # given: the older orders it could have had were passed over
            for older, _ in offered[:k]:
                older.passed += robot in older.order.by
        del idle[robot]  # given the order, or refused: one plan tried per robot and dispatch


def _window(run: _Run) -> int:
    """Orders the dispatcher chooses among at a time (:func:`~cosmop.lifelong.dispatch.window_size`)."""
    return window_size(run.fleet.reveal, len(run.world.robot_ids))


def _offers(run: _Run, idle: Collection[str]) -> Iterator[tuple[OrderState, tuple[float, ...]]]:
    """The pooled orders that may be given now to one of the `idle` robots, oldest first, with
    where their goods lie."""
    for state in run.pool:
        if state.retry_at > run.world.t:
            continue
        if all(robot in run.failed for robot in state.order.by):
            # said once, in the order's record; it stays in the pool, never served
            state.refused = state.refused or _unservable(run, state.order.by)
            continue
        goods = _goods_at_rest(run.world, state)
        if goods is not None and any(robot in idle for robot in state.order.by):
            yield state, goods


def _unservable(run: _Run, robots: Sequence[str]) -> str:
    """Why an order that only failed `robots` may serve waits for good."""
    failed = ", ".join(f"{r} failed at {run.failed[r]['t']:.1f} s" for r in robots)
    return f"no robot may serve it: {'only ' if len(robots) == 1 else ''}{'/'.join(robots)} may, and {failed}"


def _goods_at_rest(world: World, state: OrderState) -> tuple[float, ...] | None:
    """Where the order's goods lie, or None while a robot carries them or they are shipped."""
    j = world.object_ids.index(state.order.object)
    if world.carried_by[j] >= 0 or world.shipped[j]:
        return None  # another order's robot has these goods: wait for them to rest again
    return tuple(float(v) for v in world.object_xy[j])


def _hand_over(run: _Run, agent: Agent, state: OrderState, goods: tuple[float, ...]) -> None:
    """Plan `agent`'s mission for `state`'s order, order it with the others' and hand it over;
    a refusal leaves the order in the pool, to be tried again later (module docstring, step 2)."""
    world, fleet = run.world, run.fleet
    scene = world.scenario.scene
    began = time.perf_counter()  # the hand-over's wall time: dispatch, plan, coordinate, check
    events = delivery_events(scene, agent.id, state.order, goods, home=agent.id not in run.homeless)
    start = start_state(world, agent, {state.order.object})
    sensed, labels = _standing(run, agent)
    bounds = {"max_horizon": fleet.max_horizon, "rlimit": fleet.rlimit}
    plan = replan(scene, agent.id, events, start, sensed, labels=labels, **bounds)
    planned = time.perf_counter()
    if plan is not None:
        accepted, why, _ = recoordinate_world(world, agent, plan, start)
    elif agent.id in state.no_plan_by:  # explained the first time this robot found none
        accepted, why = False, f"no plan from where it stands (as at {state.no_plan_by[agent.id]:.1f} s)"
    else:  # the reason, once per robot: explaining costs another search
        accepted, why = False, why_no_plan(scene, agent.id, events, start, sensed, labels=labels, **bounds)
        state.no_plan_by[agent.id] = world.t
    run.log.append(
        {
            "t": round(world.t, 6),
            "order": state.index,
            "robot": agent.id,
            "accepted": accepted,
            "why": why or None,
            "wall_s": round(time.perf_counter() - began, 3),
            "plan_wall_s": round(planned - began, 3),  # the rest: ordering it with the others
        }
    )
    if not accepted:
        state.tries += 1
        state.refused = f"{agent.id} at {world.t:.1f} s: {why}"
        state.retry_at = world.t + min(fleet.retry_after * 2 ** (state.tries - 1), fleet.max_retry_after)
        return
    state.robot, state.served_by, state.assigned = agent.id, agent.id, world.t
    run.pool.remove(state)
    run.busy[agent.id] = state
    run.busy_since.setdefault(agent.id, world.t)  # a robot given work at a dock stays busy


def _note_waits(run: _Run) -> None:
    """Since when each robot stands for a conflict message at its current step."""
    world = run.world
    for agent in world.agents:
        k = agent.step_index
        step = agent.steps[k] if agent.waiting and k < len(agent.steps) else None
        if step is None or step.message not in world.conflict_messages or world.received(agent, step):
            run.waits.pop(agent.id, None)
        elif run.waits.get(agent.id, (None,))[0] != k:
            run.waits[agent.id] = (k, world.t)


def _reorder_long_waits(run: _Run) -> None:
    """Order again the conflicts of the robots that have stood longest for a conflict message
    (``FleetSettings.reorder_after``; at most ``max_reorders``): an order chosen at a hand-over,
    from the times expected then, may hold a robot back for one still far from the place
    (module docstring, step 3).  Only a robot whose message is expected no sooner than
    ``reorder_after`` seconds from now (:func:`~cosmop.sim.recoordinate.message_due_in`) is
    tried: a message that comes soon leaves little to gain.  A re-ordering that neither brings
    the message ``reorder_after`` seconds nearer nor within ``reorder_after`` seconds (the
    sender stands in the way, or is held up itself) doubles the time before the same wait is
    tried again (:func:`_gap`), with no bound: each try costs an ordering of the team, and one
    that changed nothing is likely to change nothing again until the wait ends."""
    world, after = run.world, run.fleet.reorder_after
    if after is None:
        return
    agents = {a.id: a for a in world.agents}
    last = {rid: at for rid, (_, at, _) in run.reordered.items()}  # each robot's last try
    due = sorted(
        (since, rid)
        for rid, (_, since) in run.waits.items()
        if world.t - since >= after and world.t - last.get(rid, -math.inf) >= _gap(run, rid)
    )
    tried = 0
    for since, rid in due:
        if tried == run.fleet.max_reorders:
            return
        agent = agents[rid]
        due_in = message_due_in(world, agent)
        if due_in is None or due_in < after:  # the message comes soon: little to gain
            continue
        tried += 1
        began = time.perf_counter()
        accepted, why, added = reorder_world(world, agent)
        wall = time.perf_counter() - began
        due_after = message_due_in(world, agent) if accepted else due_in
        # shortened: now due soon (not tried again anyway), or at least `after` seconds sooner
        shortened = due_after is None or due_after < after or due_after <= due_in - after
        run.reordered[rid] = (run.waits[rid], world.t, after if shortened else 2 * _gap(run, rid))
        run.reorders.append(
            {
                "t": round(world.t, 6),
                "robot": rid,
                "waited_s": round(world.t - since, 3),
                "due_in_s": round(due_in, 3),  # expected then, had the order stayed
                "accepted": accepted,
                "why": why or None,
                "messages": len(added),
                "due_after_s": None if due_after is None else round(due_after, 3),  # None: no wait left
                "shortened": shortened,
                "wall_s": round(wall, 3),
            }
        )


def _gap(run: _Run, robot: str) -> float:
    """Seconds between two re-orderings of `robot`'s current wait: ``reorder_after``, doubled
    after each try that did not shorten it (:func:`_reorder_long_waits`)."""
    after = run.fleet.reorder_after
    assert after is not None  # (re-orderings are on)
    wait, _, gap = run.reordered.get(robot, (None, -math.inf, after))
    return gap if wait == run.waits.get(robot) else after


def _standing(run: _Run, agent: Agent, homes: bool = False) -> tuple[list[Rectangle], list[str]]:
    """The robots that stand still for now (idle or failed) as rectangles ``x0, y0, x1, y1``
    (mm), grown by the room the plans keep between robots (:func:`~cosmop.sim.replan.robot_room`:
    the clearance, or the gap they already stand at) short of the goods beside them
    (:func:`~cosmop.sim.replan.grown`): the new plan goes around them.  With `homes`, also the
    homes of the robots still to move, where they will rest in the end (so that two robots
    re-planned at once do not each route through the other's home).  With each, what it is in
    words, for a reason that names it."""
    world = run.world
    i = agent.index
    standing = [
        a
        for a in world.agents
        if a is not agent and (a.id in run.failed or (a.done and a.id not in run.busy))
    ]
    boxes = world.robot_boxes()[[a.index for a in standing]]
    labels = [
        f"{a.id}, failed at {run.failed[a.id]['t']:.1f} s" if a.id in run.failed else f"{a.id}, standing idle"
        for a in standing
    ]
    if homes:
        going = [a for a in world.agents if a is not agent and a not in standing and a.id not in run.homeless]
        boxes = np.vstack([boxes, _homes(world, going)])
        labels += [f"the home of {a.id}" for a in going]
    gaps = box_gaps(world.pose[i, :2], world.robot_half[i], boxes)
    goods = world.resting_boxes()
    # a home it stands on now cannot be kept out of; a robot that stands there is sensed anyway
    keep = [k for k, g in enumerate(gaps) if k < len(standing) or g > 0.0]
    return [grown(boxes[k], robot_room(gaps[k]), goods) for k in keep], [labels[k] for k in keep]


def _deliveries(run: _Run) -> None:
    """Record the drops of the cycle: the order is delivered and its goods are shipped."""
    world = run.world
    for t, robot, event in world.events[run.seen_events :]:
        state = run.busy.get(robot)
        if (
            event.kind == "drop"
            and state is not None
            and state.order.object == event.obj
            and state.delivered is None
        ):
            state.delivered = t
            run.delivered += 1
            world.ship(event.obj)
            state.robot = None
            if robot not in run.failed and run.pool:
                _dispatch(run, at_dock=next(a for a in world.agents if a.id == robot))
    run.seen_events = len(world.events)


def _idle_again(run: _Run) -> None:
    """Robots home again (their plan done) are idle: their order is over."""
    for agent in run.world.agents:
        state = run.busy.get(agent.id)
        if state is not None and agent.done:
            del run.busy[agent.id]
            run.busy_time[agent.id] += run.world.t - run.busy_since.pop(agent.id)
            if state.delivered is None and state.lost is None:
                state.lost = f"{agent.id} ended its plan without delivering it"
            state.robot = None


def _fail(run: _Run, robot: str) -> None:
    """`robot` stops for good (module docstring, step 5)."""
    world = run.world
    agent = next(a for a in world.agents if a.id == robot)
    if robot in run.failed:
        return
    agent.stop_for(world.t, math.inf)
    state = run.busy.pop(robot, None)
    carrying = [world.object_ids[j] for j in np.flatnonzero(world.carried_by == agent.index)]
    if robot in run.busy_since:
        run.busy_time[robot] += world.t - run.busy_since.pop(robot)
    if state is not None:
        state.robot = None
        if state.order.object in carrying:
            state.lost = f"{robot} failed at {world.t:.1f} s carrying {state.order.object}"
        elif state.delivered is None:
            state.assigned = None
            run.pool.insert(0, state)  # back to the pool, before the orders released later
    run.failed[robot] = {
        "t": round(world.t, 6),
        "at": [round(float(v), 3) for v in world.pose[agent.index, :2]],
        "carrying": carrying,
        "homes_taken": [],  # known once it stands
        "recoordinated": False,
        "why": "not yet ordered around: it brakes",
    }
    _settle_failures(run)


FAILURE_RETRY = 5.0
"""Seconds between two tries to order the fleet around a failed robot that the last refused."""

FAILURE_REPLANS = 4
"""Robots re-planned around a failed robot, at most, in one try (each costs a hand-over)."""


def _settle_failures(run: _Run) -> None:
    """Order the others around every failed robot that stands still and is not yet ordered
    around (:func:`~cosmop.sim.recoordinate.order_around_failure`: its plan emptied, its
    messages that will never come dropped).  Where no order keeps the others apart from it (a
    committed route runs through it), the robots still to move are re-planned around it from
    where they are, nearest first (:data:`FAILURE_REPLANS` at most), until the fleet can be
    ordered around it; else it is tried again :data:`FAILURE_RETRY` seconds later.  Until
    then the robots that wait for its messages wait: they are ordered, never unordered."""
    world = run.world
    for robot, record in run.failed.items():
        agent = next(a for a in world.agents if a.id == robot)
        if (
            record["recoordinated"]
            or world.v[agent.index] != 0
            or world.t < run.failure_retry.get(robot, 0.0)
        ):
            continue
        record["at"] = [round(float(v), 3) for v in world.pose[agent.index, :2]]  # where it came to rest
        record["homes_taken"] = _homes_taken(run, agent)
        run.homeless.update(record["homes_taken"])
        accepted, why, _ = order_around_failure(world, agent, {})
        replanned: dict[str, Remaining] = {}
        for other in [] if accepted else _in_the_way(run, agent)[:FAILURE_REPLANS]:
            rest = _replanned(run, other)
            if rest is None:
                continue
            replanned[other.id] = rest
            accepted, why, _ = order_around_failure(world, agent, replanned)
            if accepted:
                break
        record.update(
            recoordinated=accepted, why=why or None, replanned=sorted(replanned) if accepted else []
        )
        run.failure_retry[robot] = world.t + FAILURE_RETRY


def _in_the_way(run: _Run, failed: Agent) -> list[Agent]:
    """The robots still to move (not done, not failed): those whose home it took first (their
    way home is gone), then the nearest to `failed` first."""
    world = run.world
    moving = [a for a in world.agents if not a.done and a.id not in run.failed]
    at = world.pose[failed.index, :2]
    return sorted(
        moving,
        key=lambda a: (a.id not in run.homeless, float(np.hypot(*(world.pose[a.index, :2] - at))), a.id),
    )


def _homes_taken(run: _Run, failed: Agent) -> list[str]:
    """The robots whose home `failed` stands on for good, the clearance between robots
    included: they cannot end a plan there any more, so they stay where their plans end."""
    world = run.world
    room = (world.conflict_settings or ConflictSettings()).clearance
    others = [a for a in world.agents if a is not failed]
    gaps = box_gaps(world.pose[failed.index, :2], world.robot_half[failed.index], _homes(world, others))
    return [a.id for a, gap in zip(others, gaps, strict=True) if gap < room]


def _homes(world: World, agents: Sequence[Agent]) -> NDArray[np.float64]:
    """The `agents`' homes as squares ``x, y, half side`` (mm), shape ``(n, 3)``."""
    homes = [(*world.scenario.scene.robots[a.id].pose[:2], world.robot_half[a.index]) for a in agents]
    return np.asarray(homes, dtype=float).reshape(-1, 3)


def _replanned(run: _Run, agent: Agent) -> Remaining | None:
    """`agent`'s mission left, re-planned from where it stands around the robots that stand
    (failed ones included), or None when it has no plan."""
    world, fleet = run.world, run.fleet
    remaining, start = mission_left(world, agent)
    if agent.id in run.homeless:
        remaining = [e for e in remaining if e.kind != "return"]
    sensed, labels = _standing(run, agent, homes=True)
    plan = replan(
        world.scenario.scene,
        agent.id,
        remaining,
        start,
        sensed,
        labels=labels,
        max_horizon=fleet.max_horizon,
        rlimit=fleet.rlimit,
    )
    return None if plan is None else Remaining(plan.steps, plan.mission, start)
