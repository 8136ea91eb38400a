"""Re-coordination mid-run: a robot's new plan goes through the same team-safety layer.

When a stalled robot replans (:mod:`cosmop.sim.replan`), its new route may meet the other
robots' routes where its old one did not.  Its new plan is therefore not executed on its own:
the rest of every robot's plan, from where each robot is now, is ordered again by
:func:`cosmop.team.safe_plans.make_team_safe`, exactly as before the run --

* messages already sent stay sent: the steps that wait for them are done;
* the messages that kept the robot's old plan apart from the others and have not been sent yet
  are dropped (they protected places its new plan may no longer share) and its conflicts with
  the others are ordered afresh, proved free of deadlock, with new message names; the others'
  orders among themselves stay as they were;
* the orders the mission itself requires (``away`` answers, order messages) are kept.

If some conflict cannot be ordered, the new plan is refused and the robot keeps its old one.
It is refused too when the new order makes a robot that is driving wait at a place it reaches
before it can stop (:func:`wait_ahead`): braking past it, the robot would stand where the plans
give the place to another, and creeping back into it, it could box in a robot that waits for it.
:func:`recoordinate_world` does this for a running simulation and installs the new rests in
its robots' executors.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

from cosmop.control.safety import own_margin
from cosmop.events import Event, Primitive
from cosmop.planning.plan_types import PlanMessage, RobotPlan, State, Step
from cosmop.planning.primitive_effects import initial_state
from cosmop.scene import Scene
from cosmop.sim.realised_times import carry_instants
from cosmop.team.conflicts import ConflictSettings
from cosmop.team.safe_plans import make_team_safe

if TYPE_CHECKING:
    from cosmop.sim.world import Agent, World

__all__ = ["Recoordination", "Remaining", "recoordinate", "recoordinate_world", "wait_ahead"]


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
    safety = make_team_safe(
        scene, plans, settings=settings, used=used, starts=starts, positions=positions, about=robot
    )
    if not safety.safe:
        return Recoordination(
            False,
            {},
            (),
            dropped,
            f"the new plans share a place no order resolves: {safety.unresolved[0].describe()}",
        )
    return Recoordination(True, safety.plans, safety.messages, dropped)


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
    splits = {a.id: a.split_mission(world.scenario) for a in world.agents}
    rests = {}
    for other in world.agents:
        if other is agent:
            rests[other.id] = Remaining(new.steps, new.mission, start)
        else:
            todo = splits[other.id][1]
            rests[other.id] = Remaining(
                tuple(other.steps[other.step_index :]), tuple(todo), _state_now(world, other)
            )
    positions = {
        oid: None
        if world.carried_by[j] >= 0 or world.shipped[j]
        else (float(world.object_xy[j][0]), float(world.object_xy[j][1]))
        for j, oid in enumerate(world.object_ids)
    }
    result = recoordinate(
        world.scenario.scene,
        rests,
        agent.id,
        sent=world.sent_messages,
        conflict_messages=world.conflict_messages,
        used=world.used_messages,
        positions=positions,
        settings=settings or world.conflict_settings,
    )
    if not result.accepted:
        return False, result.reason or "", []
    too_late = _too_late_to_stop(world, result)
    if too_late:
        return False, too_late, []
    for other in world.agents:
        _install(other, result.plans[other.id], splits[other.id][0], new=other is agent)
        if other is agent:  # its new plan starts where it stood, rounded to the millimetre
            other.replan_start = (other.step_index, start.robot)
    added = [m.event for m in result.messages]
    world.conflict_messages |= set(added)
    return True, "", added


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


def _state_now(world: World, agent: Agent) -> State:
    """Where `agent`'s robot is (mm, degrees) and the objects as its plan sees them now."""
    k = agent.step_index
    scene = world.scenario.scene
    if k > 0:
        objects = agent.steps[k - 1].objects
    else:
        objects = initial_state(scene, agent.id, agent.steps, scene.objects).objects
    x, y, h = world.pose[agent.index]
    return State((float(x), float(y), math.degrees(float(h))), objects)
