"""Re-coordination mid-run: a robot's new plan goes through the same team-safety layer.

When a stalled robot replans (:mod:`cosmop.sim.replan`), its new route may meet the other
robots' routes where its old one did not.  Its new plan is therefore not executed on its own:
the rest of every robot's plan, from where each robot is on its plan now (the point of its plan
nearest it: a robot tracks its plan within centimetres, and the rest keeps to lines the checker
passed), is ordered again by
:func:`cosmop.team.safe_plans.make_team_safe`, exactly as before the run --

* messages already sent stay sent: the steps that wait for them are done;
* the messages that kept the robot's old plan apart from the others and have not been sent yet
  are dropped (they protected places its new plan may no longer share) and its conflicts with
  the others are ordered afresh, proved free of deadlock, with new message names; the others'
  orders among themselves stay as they were, except those that passed through the robot: an
  order between two others that only a chain of the dropped messages kept (A tells the robot,
  which then tells B) is lost with them, so the conflicts it ordered are ordered again
  (:func:`orders_lost`);
* the orders the mission itself requires (``away`` answers, order messages) are kept.

If some conflict cannot be ordered, the new plan is refused and the robot keeps its old one.
It is refused too when the new order makes a robot that is driving wait at a place it reaches
before it can stop (:func:`wait_ahead`): braking past it, the robot would stand where the plans
give the place to another, and creeping back into it, it could box in a robot that waits for it.
:func:`recoordinate_world` does this for a running simulation and installs the new rests in
its robots' executors.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from collections.abc import Set as AbstractSet
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from cosmop.control.safety import own_margin
from cosmop.events import Event, Primitive
from cosmop.planning.plan_types import PlanMessage, RobotPlan, State, Step
from cosmop.planning.primitive_effects import initial_state
from cosmop.planning.realisation import message_links
from cosmop.scene import Scene
from cosmop.sim.realised_times import carry_instants
from cosmop.team.conflicts import Conflict, ConflictSettings, Occupancy, conflicts, is_ordered, occupancies
from cosmop.team.precedence import Precedence
from cosmop.team.safe_plans import TeamSafety, make_team_safe
from cosmop.team.timing import step_durations

if TYPE_CHECKING:
    from cosmop.sim.world import Agent, World

__all__ = [
    "SET_ASIDE_LIMIT",
    "Recoordination",
    "Remaining",
    "message_due_in",
    "order_around_failure",
    "orders_lost",
    "recoordinate",
    "recoordinate_world",
    "reorder_world",
    "unordered_now",
    "wait_ahead",
]

SET_ASIDE_LIMIT = 64
"""The most conflicts an ordering attempt of :func:`recoordinate` (a new plan handed over, or
an order turned round) sets aside before it stops
(:func:`~cosmop.team.safe_plans.make_team_safe`'s `max_set_aside`).  One set aside already
means the attempt fails; the rest of its search only names every conflict it fails on, which
took up to a minute in a crowded fleet (572 set aside).  The re-coordinations captured over the
first six minutes of two 50-robot streams, and the 43 slower than 1.5 s over 1,250 s of a
third, set aside at most 19.  The ordering around a failed robot has no limit."""


@dataclass(frozen=True)
class Remaining:
    """What is left of one robot's plan: its steps from the current one, from `start`.

    Attributes
    ----------
    steps : tuple of Step
    mission : tuple of Event
        The events those steps still realise, messages included, in order.
    start : State
        Where the robot is and how it sees the objects now.
    """

    steps: tuple[Step, ...]
    mission: tuple[Event, ...]
    start: State


@dataclass(frozen=True)
class Recoordination:
    """The result of :func:`recoordinate`: the new rest of every robot's plan, or why not.

    Attributes
    ----------
    accepted : bool
        Whether the new plan could be ordered with the others' rests.
    plans : Mapping[str, RobotPlan]
        Every robot's rest of plan, with the new messages in place (when accepted).
    messages : tuple of PlanMessage
        The messages added.
    dropped : tuple of Event
        The conflict messages of the old plans that the new order replaces.
    reason : str, optional
        Why not, when not accepted.
    """

    accepted: bool
    plans: Mapping[str, RobotPlan]
    messages: tuple[PlanMessage, ...]
    dropped: tuple[Event, ...]
    reason: str | None = None


def _without(rest: Remaining, events: set[Event]) -> RobotPlan:
    """The rest of a plan without the message steps and events in `events`."""
    steps = [
        s for s in rest.steps if not (s.message in events and s.primitive in (Primitive.REQ, Primitive.RES))
    ]
    steps = [
        s
        for s in steps
        if not (s.primitive == Primitive.REQ and s.message is None and _away_of(rest, s) in events)
    ]
    mission = [e for e in rest.mission if e not in events]
    return RobotPlan.from_steps(mission, steps)


def _away_of(rest: Remaining, step: Step) -> Event | None:
    """The away event a ``Req(O)`` step waits for, from the mission."""
    return next((e for e in rest.mission if e.kind == "away" and e.obj == step.object), None)


def recoordinate(
    scene: Scene,
    rests: Mapping[str, Remaining],
    robot: str,
    *,
    sent: Iterable[Event],
    conflict_messages: Iterable[Event],
    used: set[Event],
    positions: Mapping[str, tuple[float, float] | None],
    settings: ConflictSettings | None = None,
    replaced: Remaining | None = None,
) -> Recoordination:
    """Order the rest of every robot's plan again (module docstring).

    Parameters
    ----------
    scene : Scene
    rests : Mapping[str, Remaining]
        Every robot's remaining plan (the stalled robot's new plan among them).
    robot : str
        The robot with the new plan.
    sent : iterable of Event
        Messages already sent (their waits are done).
    conflict_messages : iterable of Event
        The messages that keep plans apart (the others are the mission's own).
    used : set of Event
        Messages already used (new ones avoid them; updated).
    positions : Mapping[str, tuple or None]
        Where every object is now (``None``: carried).
    settings : ConflictSettings, optional
    replaced : Remaining, optional
        The rest of `robot`'s plan that the new one replaces, with its messages (default: its
        entry of `rests`); the orders between the others that passed through it are kept.

    Returns
    -------
    Recoordination
    """
    sent = set(sent)
    pending = {event for event in set(conflict_messages) - sent if robot in event.owners}
    dropped = tuple(sorted(pending, key=lambda e: e.name))  # by name: the order the log shows
    drop = sent | pending
    plans = {r: _without(rest, drop) for r, rest in rests.items()}
    starts = {r: rest.start for r, rest in rests.items()}
    before = {r: _without(rest, sent) for r, rest in {**rests, robot: replaced or rests[robot]}.items()}
    also = orders_lost(scene, before, pending, robot, starts=starts, positions=positions, settings=settings)
    safety = make_team_safe(
        scene,
        plans,
        settings=settings,
        used=used,
        starts=starts,
        positions=positions,
        about=robot,
        also=also,
        max_set_aside=SET_ASIDE_LIMIT,
    )
    if not safety.safe:
        return Recoordination(False, {}, (), dropped, _unresolved(safety))
    return Recoordination(True, safety.plans, safety.messages, dropped)


def orders_lost(
    scene: Scene,
    plans: Mapping[str, RobotPlan],
    dropped: AbstractSet[Event],
    robot: str,
    *,
    starts: Mapping[str, State],
    positions: Mapping[str, tuple[float, float] | None],
    settings: ConflictSettings | None = None,
) -> frozenset[tuple[str, ...]]:
    """The parties of the conflicts between robots other than `robot` that `plans` order only
    through the messages `dropped`.

    The ordering step drops every order that others imply (a transitive reduction), so an
    order between A and B may hold only through `robot`: A sends it a message that it awaits
    before it sends one to B.  Without those messages A and B are no longer ordered.  The
    conflict ``(a, b)`` is lost when one of its occupancies ends before the other starts in
    the order of all the `plans`' messages, and in neither way once the `dropped` ones are
    removed (their ``Req`` steps then wait for nothing, so the steps keep their instants).

    Parameters
    ----------
    scene : Scene
    plans : Mapping[str, RobotPlan]
        Every robot's rest of plan with all its messages still to come (none sent yet),
        `robot`'s old one included.
    dropped : set of Event
        The messages of `robot` that are dropped.
    robot : str
        The robot that replanned (its own conflicts are ordered anyway).
    starts, positions
        The robots' states and the objects' places now (see :func:`recoordinate`).
    settings : ConflictSettings, optional

    Returns
    -------
    frozenset of tuple of str
        :attr:`~cosmop.team.conflicts.Conflict.robots` of every conflict lost.
    """
    settings = settings or ConflictSettings()
    horizons = {r: p.horizon for r, p in plans.items()}
    links = message_links(plans)
    kept = [link for link in links if link.event not in dropped]
    if len(kept) == len(links):
        return frozenset()
    order, without = Precedence(horizons, links), Precedence(horizons, kept)
    if not order.complete:  # `robot`'s old rest is not known: order all that is unordered
        items, _ = occupancies(scene, plans, without, settings, starts, positions)
        found = conflicts(items, settings.clearance)
        return frozenset(c.robots for c in found if robot not in c.robots and not is_ordered(c, without))
    later, earlier = _lost_steps(order, without, robot)
    if not later:
        return frozenset()
    # a conflict lost has one side that starts at a step in `later`, and the other side ends
    # at a step in `earlier` that it no longer always starts after: only those sides are paired,
    # so only the robots with such steps are asked for their own occupancies
    firsts = [order.offsets[r] for r in order.robots]  # the robots' rows, in order
    owners = {order.robots[bisect.bisect_right(firsts, row) - 1] for row in later | earlier}
    items, _ = occupancies(scene, plans, order, settings, starts, positions, robots=owners)
    near = [i for i in items if _may_lose(i, order, later, earlier)]
    return frozenset(
        c.robots
        for c in conflicts(near, settings.clearance)
        if robot not in c.robots and is_ordered(c, order) and not is_ordered(c, without)
    )


def _may_lose(item: Occupancy, order: Precedence, later: AbstractSet[int], earlier: AbstractSet[int]) -> bool:
    """Whether `item` starts at a step of `later` or ends at a step of `earlier` (rows of
    `order`)."""
    return (item.first is not None and order.row(item.first) in later) or (
        item.last is not None and order.row(item.last) in earlier
    )


def _lost_steps(order: Precedence, without: Precedence, robot: str) -> tuple[set[int], set[int]]:
    """The orders lost between the steps of robots other than `robot` once the dropped links
    are gone (`order` -> `without`, the same steps): the rows of the steps that no longer always
    start after some other robot's step (not `robot`'s), and the rows of those other steps.
    Most re-plans lose only orders with `robot` itself, and then both are empty."""
    mine = np.zeros(order.size, dtype=bool)
    mine[order.offsets[robot] : order.offsets[robot] + order.horizons[robot] + 2] = True
    others = np.packbits(~mine, bitorder="little")  # the bit set of the others' steps
    lost = order.begin_bits & ~without.begin_bits & others[: order.begin_bits.shape[1]]
    lost[mine] = 0
    later = np.flatnonzero(lost.any(axis=1))  # steps that lost some order
    earlier = np.flatnonzero(np.unpackbits(np.bitwise_or.reduce(lost, axis=0), bitorder="little"))
    return set(later.tolist()), set(earlier[earlier < order.size].tolist())


# ----------------------------------------------------------------------------------------------
# In a running simulation
# ----------------------------------------------------------------------------------------------


def recoordinate_world(
    world: World, agent: Agent, new: RobotPlan, start: State, settings: ConflictSettings | None = None
) -> tuple[bool, str, list[Event]]:
    """Order the rest of every robot's plan again around `agent`'s `new` plan from `start`.

    When accepted, every robot's executor takes its new rest (``world.conflict_messages``
    gains the messages added).  Returns ``(accepted, why not, messages added)``.  The conflicts
    are found with `settings`, by default the world's (``World.conflict_settings``).

    Parameters
    ----------
    world : World
        The running simulation; its robots' executors take their new rests when accepted.
    agent : Agent
        The robot that replanned.
    new : RobotPlan
        Its new plan.
    start : State
        Where the new plan starts.
    settings : ConflictSettings, optional
        How conflicts are found (default: the world's).
    """
    return _order_again(world, agent, Remaining(new.steps, new.mission, start), settings)


def reorder_world(
    world: World, agent: Agent, settings: ConflictSettings | None = None
) -> tuple[bool, str, list[Event]]:
    """Order `agent`'s conflicts again from now, its plan as it is: who goes first is chosen
    anew by the times expected from here.

    An order is chosen when a plan is handed over, from the times expected then; robots are
    later delayed, wait, or are given new work, and an order may then make a robot stand for
    a long time at a place that another, still far away, will pass only later.  Like a
    *switchable* edge of an action dependency graph, a conflict order between two robots'
    steps that have not begun can be turned round while the team stays safe: the robot's
    unsent conflict messages are dropped and its conflicts ordered again exactly as for a new
    plan (:func:`recoordinate`: the robot expected at a shared place first goes first, the
    orders between the others kept, the team proved free of deadlock), and refused on the same
    terms (a conflict no order resolves, a robot driving now that could not stop for a new
    wait).  Messages already sent stay sent.  Returns ``(accepted, why not, messages added)``.

    Parameters
    ----------
    world : World
        The running simulation; its robots' executors take their new rests when accepted.
    agent : Agent
        The robot whose conflicts are ordered again (typically one standing for a message).
    settings : ConflictSettings, optional
        How conflicts are found (default: the world's).
    """
    return _order_again(world, agent, None, settings)


def message_due_in(world: World, agent: Agent) -> float | None:
    """Expected seconds until the message `agent` waits for at its current step is sent: the
    sender's own steps up to its ``Res``, from where it is now, at the expected times of
    :func:`~cosmop.team.timing.step_durations` (its own waits not counted: a lower bound).
    ``None`` when `agent` waits for no message or its sender's plan no longer sends it.

    Parameters
    ----------
    world : World
        The running simulation.
    agent : Agent
        A robot standing at a ``Req`` step.
    """
    k = agent.step_index
    message = agent.steps[k].message if k < len(agent.steps) else None
    if message is None or message.sender is None:
        return None
    sender = world.agents[world.robot_ids.index(message.sender)]
    rest = sender.steps[sender.step_index :]
    sends = next(
        (n for n, step in enumerate(rest) if step.primitive == Primitive.RES and step.message == message),
        None,
    )
    if sends is None:
        return None
    x, y, h = (float(v) for v in world.pose[sender.index])
    plan = RobotPlan.from_steps((), rest[: sends + 1])
    dynamics = world.scenario.scene.robots[sender.id].dynamics
    return sum(step_durations(plan, (x, y, math.degrees(h)), dynamics))


def order_around_failure(
    world: World,
    failed: Agent,
    replanned: Mapping[str, Remaining],
    settings: ConflictSettings | None = None,
) -> tuple[bool, str, list[Event]]:
    """Order every robot's rest again around a robot that failed, with some robots re-planned.

    The failed robot's plan is emptied: it stands where it is for good, and the messages it
    would have sent or awaited are dropped.  So are the unsent conflict messages of the robots
    in `replanned`, whose rests are replaced by their new plans (planned around it: a route
    through it is ordered by no message).  The conflicts of the whole team are then ordered
    again (:func:`~cosmop.team.safe_plans.make_team_safe` over every rest, the orders already
    kept between the others standing), the team proved free of deadlock, and the result
    installed in the robots' executors, as :func:`recoordinate_world` does for one robot;
    refused, for the same reasons, nothing changes.  Returns ``(accepted, why not, messages
    added)``.

    Parameters
    ----------
    world : World
        The running simulation.
    failed : Agent
        The robot that failed (stopped for good).
    replanned : Mapping[str, Remaining]
        Robots re-planned around it: each one's new plan from where it stands.
    settings : ConflictSettings, optional
        How conflicts are found (default: the world's).
    """
    splits, now = _rests_now(world)
    new = {failed.id: Remaining((), (), now[failed.id].start), **replanned}
    rests = {**now, **new}
    sent = set(world.sent_messages)
    pending = {e for e in set(world.conflict_messages) - sent if set(new) & set(e.owners)}
    drop = sent | pending
    plans = {r: _without(rest, drop) for r, rest in rests.items()}
    safety = make_team_safe(
        world.scenario.scene,
        plans,
        settings=settings or world.conflict_settings,
        used=world.used_messages,
        starts={r: rest.start for r, rest in rests.items()},
        positions=_positions(world),
    )
    if not safety.safe:
        return False, _unresolved(safety), []
    dropped = tuple(sorted(pending, key=lambda e: e.name))
    return _take(world, Recoordination(True, safety.plans, safety.messages, dropped), splits, new)


def _order_again(
    world: World, agent: Agent, new: Remaining | None, settings: ConflictSettings | None
) -> tuple[bool, str, list[Event]]:
    """:func:`recoordinate` every robot's committed rest, now, with `agent`'s replaced by `new`
    (``None``: kept, only re-ordered), and install the result in the robots' executors when
    accepted."""
    splits, now = _rests_now(world)
    rests = {**now, agent.id: new if new is not None else now[agent.id]}
    positions = _positions(world)
    result = recoordinate(
        world.scenario.scene,
        rests,
        agent.id,
        sent=world.sent_messages,
        conflict_messages=world.conflict_messages,
        used=world.used_messages,
        positions=positions,
        settings=settings or world.conflict_settings,
        replaced=now[agent.id],
    )
    if not result.accepted:
        return False, result.reason or "", []
    return _take(world, result, splits, {} if new is None else {agent.id: new})


def _rests_now(world: World) -> tuple[dict[str, tuple[list[Event], list[Event]]], dict[str, Remaining]]:
    """Every robot's mission split into done and to do, and its committed rest from now."""
    splits = {a.id: a.split_mission(world.scenario) for a in world.agents}
    return splits, {a.id: _rest_now(world, a, splits[a.id][1]) for a in world.agents}


def _take(
    world: World,
    result: Recoordination,
    splits: Mapping[str, tuple[list[Event], list[Event]]],
    new: Mapping[str, Remaining],
) -> tuple[bool, str, list[Event]]:
    """Install an accepted re-coordination in the robots' executors (the robots of `new` given
    new plans from where they stood), unless a robot driving now could not stop for a wait it
    adds: ``(accepted, why not, messages added)``."""
    too_late = _too_late_to_stop(world, result)
    if too_late:
        return False, too_late, []
    for other in world.agents:
        _install(other, result.plans[other.id], splits[other.id][0], new=other.id in new)
        if other.id in new:  # its new plan starts where it stood, to the millimetre
            other.replan_start = (other.step_index, new[other.id].start)
    added = [m.event for m in result.messages]
    world.conflict_messages |= set(added)
    return True, "", added


def _unresolved(safety: TeamSafety) -> str:
    """Why a re-coordination is refused: the first conflict no order resolves."""
    return f"the new plans share a place no order resolves: {safety.unresolved[0].describe()}"


def unordered_now(world: World, depth: float = 1.0) -> list[Conflict]:
    """The conflicts between the robots' committed rests that no message orders, now: the
    exact checker's conflict rule on every robot's steps from its current one, from where its
    plan has it now (:func:`_state_now`), with the messages already sent done (an audit of a
    running fleet).

    Only conflicts whose shared space is at least `depth` mm across both ways are returned
    (1 mm by default: a re-planned robot plans from its pose rounded to the millimetre, which
    may make slivers of overlap no plan made).

    Parameters
    ----------
    world : World
        The running simulation.
    depth : float
        The smallest width and height of the shared space counted, mm.

    Returns
    -------
    list of Conflict
        Empty when every conflict is ordered.

    Raises
    ------
    ValueError
        When the committed messages can deadlock (which the ordering proves cannot happen).
    """
    rests = {a.id: _rest_now(world, a, a.split_mission(world.scenario)[1]) for a in world.agents}
    plans = {r: _without(rest, set(world.sent_messages)) for r, rest in rests.items()}
    order = Precedence({r: p.horizon for r, p in plans.items()}, message_links(plans))
    if not order.complete:
        raise ValueError(f"the committed plans can deadlock: {order.stuck}")
    positions = _positions(world)
    settings = world.conflict_settings or ConflictSettings()
    starts = {r: rest.start for r, rest in rests.items()}
    items, _ = occupancies(world.scenario.scene, plans, order, settings, starts, positions)
    out = []
    for conflict in conflicts(items, settings.clearance):
        if not is_ordered(conflict, order):  # (cheap; the shared space is an intersection)
            x0, y0, x1, y1 = conflict.place
            if min(x1 - x0, y1 - y0) >= depth:
                out.append(conflict)
    return out


def wait_ahead(
    start: tuple[float, float], steps: Iterable[Step], waits: Callable[[Step], bool]
) -> float | None:
    """How far (mm, along the drives) a robot at `start` goes through `steps` before the first
    step it waits at; ``None`` if it never waits.

    Parameters
    ----------
    start : tuple of float
        Where the robot is, ``x, y`` mm.
    steps : iterable of Step
        The rest of its plan, from the step it executes now.
    waits : callable
        Whether the robot waits at a step (a ``Req`` whose message has not come).

    Examples
    --------
    >>> new = Event("msg", "R2", responder="R1", tag="c1")
    >>> drive = Step(Primitive.GOTO, None, (300.0, 400.0, 0.0), {})
    >>> wait = Step(Primitive.REQ, None, (300.0, 400.0, 0.0), {}, message=new)
    >>> wait_ahead((0.0, 0.0), [drive, wait], lambda step: step.message == new)
    500.0
    >>> wait_ahead((0.0, 0.0), [drive, wait], lambda step: False) is None
    True
    """
    x, y = start
    gone = 0.0
    for step in steps:
        if step.primitive == Primitive.REQ and waits(step):
            return gone
        if step.primitive == Primitive.GOTO:
            gone += math.hypot(step.robot[0] - x, step.robot[1] - y)
            x, y = step.robot[0], step.robot[1]
    return None


def _too_late_to_stop(world: World, result: Recoordination) -> str | None:
    """Why the new order cannot be kept: a robot driving now would have to wait, sooner than
    its old rest had it wait, at a place it reaches before it can stop (its own stopping
    distance, :func:`~cosmop.control.safety.own_margin`): a new message, or an old one whose
    wait the new cuts of its drive moved closer."""
    for other in world.agents:
        v = float(world.v[other.index])
        if v <= 0.0 or other.id not in result.plans:
            continue

        def waits(step: Step, other: Agent = other) -> bool:
            return step.message is not None and not world.received(other, step)

        xy = (float(world.pose[other.index, 0]), float(world.pose[other.index, 1]))
        ahead = wait_ahead(xy, result.plans[other.id].steps, waits)
        before = wait_ahead(xy, other.steps[other.step_index :], waits)
        stop = float(own_margin(v, world.limits[other.index]))
        if ahead is not None and ahead < stop and (before is None or ahead < before - 1.0):
            return (
                f"{other.id}, driving at {v:.0f} mm/s, would have to wait {ahead:.0f} mm ahead and "
                f"needs {stop:.0f} mm to stop"
            )
    return None


def _install(agent: Agent, plan: RobotPlan, done: list[Event], *, new: bool) -> None:
    """Replace the rest of `agent`'s plan with `plan` (`done`: the mission events done so far).

    The steps of a `new` plan were never planned (no instants); a re-ordered rest keeps the
    instants of the steps it keeps (:func:`~cosmop.sim.realised_times.carry_instants`), and the robot
    goes on with its current step unless that changed.
    """
    k = agent.step_index
    current = agent.steps[k] if k < len(agent.steps) else None
    kept = [] if new else agent.steps[k:]
    agent.plan_instants = agent.plan_instants[:k] + carry_instants(kept, agent.plan_instants[k:], plan.steps)
    agent.steps = agent.steps[:k] + list(plan.steps)
    agent.mission = list(done) + list(plan.mission)
    if new or (k < len(agent.steps) and agent.steps[k] != current):
        agent.restart_step()


def _positions(world: World) -> dict[str, tuple[float, float] | None]:
    """Where every object is now, mm (``None``: carried or shipped)."""
    return {
        oid: None
        if world.carried_by[j] >= 0 or world.shipped[j]
        else (float(world.object_xy[j][0]), float(world.object_xy[j][1]))
        for j, oid in enumerate(world.object_ids)
    }


def _rest_now(world: World, agent: Agent, todo: Iterable[Event]) -> Remaining:
    """What is left of `agent`'s committed plan, from where its plan has the robot now
    (:func:`_state_now`); `todo`: the mission events it has still to do
    (:meth:`~cosmop.sim.world.Agent.split_mission`)."""
    return Remaining(tuple(agent.steps[agent.step_index :]), tuple(todo), _state_now(world, agent))


def _state_now(world: World, agent: Agent) -> State:
    """Where `agent`'s robot is on its plan now (mm, degrees) and the objects as its plan sees them.

    A robot tracks its plan within centimetres (the clearance between robots allows for it), so
    the rest of its plan starts on the plan itself: at the point of the current drive's segment
    nearest the robot (heading as the robot does: a heading never changes a footprint, but it
    times the turns), or where its current step has it stand (a wait a re-ordering put part
    way along a drive stands there, not at the drive's start).  Measured from where the robot
    really is, the rest's first drive would be a line nobody checked: 30 mm beside an aisle
    lined with goods, it cut into them.  Where the robot really is when it has failed (it
    stands there for good) or finished (within its goal tolerance of its plan's end, until it
    is given work).
    """
    k = agent.step_index
    scene = world.scenario.scene
    before = agent.before or initial_state(scene, agent.id, agent.steps, scene.objects)
    x, y, h = (float(v) for v in world.pose[agent.index])
    if agent.done or agent.stopped_until == math.inf:
        return State((x, y, math.degrees(h)), before.objects)
    step = agent.steps[k]
    if step.primitive == Primitive.GOTO:
        x, y = _nearest_on(before.robot[:2], step.robot[:2], (x, y))
        return State((x, y, math.degrees(h)), before.objects)
    return State(step.robot, before.objects)  # a step other than a drive does not move it


def _nearest_on(a: Sequence[float], b: Sequence[float], p: tuple[float, float]) -> tuple[float, float]:
    """The point of segment `a` `b` nearest `p` (mm)."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    length2 = dx * dx + dy * dy
    t = 0.0 if length2 == 0.0 else min(1.0, max(0.0, ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / length2))
    return (a[0] + t * dx, a[1] + t * dy)
