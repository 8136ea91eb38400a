"""Receding-horizon replanning: a stalled robot plans its remaining mission from where it is.

The paper (end of Section IV): when the environment is not fair and a robot cannot go on, it
stays safe, and "we can update the scene description and search for new plans at the current
state in a receding horizon strategy".  :func:`replan` builds that scene -- the scenario's
walls plus every sensed obstacle as a rectangle of four walls -- and solves the robot's remaining
mission events with :func:`cosmop.planning.synthesis.synthesize` from the robot's current state
(integer mm and degrees), without new requests (a new request would need the top-down layer to
re-verify the team).  The new plan must pass the exact plan checker, like every plan the tool
returns.  :func:`replan_stalled` does this for a robot of a running simulation that makes no
progress, and hands its new plan to the team-safety layer (:mod:`cosmop.sim.recoordinate`).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from collections.abc import Set as AbstractSet
from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from cosmop.control.geometry import box_gaps
from cosmop.events import Event, Primitive
from cosmop.planning.checker import check_robot_plan
from cosmop.planning.plan_types import ObjectState, RobotPlan, State
from cosmop.planning.primitive_effects import initial_state
from cosmop.planning.report import Violation
from cosmop.scene import Scene, Wall
from cosmop.sim.recoordinate import recoordinate_world
from cosmop.team.conflicts import ConflictSettings

if TYPE_CHECKING:
    from cosmop.planning.synthesis import Synthesis
    from cosmop.sim.world import Agent, World

__all__ = [
    "Rectangle",
    "grown",
    "mission_left",
    "replan",
    "replan_stalled",
    "rest_collisions",
    "robot_room",
    "route",
    "sensed_scene",
    "start_state",
    "why_no_plan",
]

_PERSON_ROOM = 10.0  # mm added around a sensed person (a robot gets the standoff)


Rectangle = tuple[float, float, float, float]
"""An axis-aligned rectangle ``x0, y0, x1, y1`` (mm)."""


def sensed_scene(scene: Scene, rectangles: Iterable[Rectangle], labels: Sequence[str] = ()) -> Scene:
    """The scene with each sensed rectangle ``(x0, y0, x1, y1)`` (mm) added as four walls.

    Parameters
    ----------
    scene : Scene
        The scene as planned.
    rectangles : iterable of (float, float, float, float)
        The sensed obstacles, grown by the room to keep (:func:`grown`), mm.
    labels : sequence of str
        What each rectangle is, in words ("R1, failed at 150.0 s"), so that a reason names it
        (:attr:`cosmop.scene.Wall.label`); unnamed ones are "a sensed obstacle".
    """
    walls = list(scene.obstacles)
    for k, (x0, y0, x1, y1) in enumerate(rectangles):
        corners = [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
        label = labels[k] if k < len(labels) else "a sensed obstacle"
        walls += [Wall(corners[i], corners[(i + 1) % 4], label) for i in range(4)]
    return replace(scene, obstacles=tuple(walls))


def grown(box: Sequence[float], room: float, goods: NDArray[np.float64]) -> Rectangle:
    """The square `box` ``(x, y, half side)`` grown by `room` on each side, except where that
    would cover resting goods: a side stops 1 mm short of the goods beyond it (of a good off a
    corner, both sides do).

    A robot that stands (or failed) beside goods, say where it was about to pick them, would
    otherwise have them inside its grown square, as walls through them, and nobody could pick
    them.  Plans are still held to the clearance between robots by the exact checks; the room
    only steers the new route clear of them where it can.

    Parameters
    ----------
    box : sequence of float
        The sensed square ``x, y, half side``, mm.
    room : float
        The room to keep around it, mm (>= 0).
    goods : ndarray, shape (m, 3)
        The resting goods as boxes ``x, y, half side``, mm.

    Returns
    -------
    tuple of float
        ``x0, y0, x1, y1``, mm.

    Examples
    --------
    >>> grown((0.0, 0.0, 200.0), 100.0, np.array([[250.0, 0.0, 50.0]]))
    (-300.0, -300.0, 200.0, 300.0)
    """
    x, y, h = (float(v) for v in box)
    # the growth of each side: west, south, east, north
    grow = [room] * 4
    near = (  # the goods within `room` of the square
        goods[box_gaps(goods[:, :2], goods[:, 2:3], np.array([[x, y, h]]))[:, 0] < room]
        if len(goods)
        else goods
    )
    for gx, gy, gh in near:
        # how far the good lies beyond each side of the square (negative: not beyond it); a good
        # that overlaps the square itself (beyond no side) cannot be kept out
        beyond = [(x - h) - (gx + gh), (y - h) - (gy + gh), (gx - gh) - (x + h), (gy - gh) - (y + h)]
        for side, gap in enumerate(beyond):
            # every side it lies beyond, not only the farthest: a good off a corner would
            # otherwise have the other side's growth run along its face, a wall between it and
            # a robot picking it from beside that face
            if gap >= 0.0:
                grow[side] = min(grow[side], max(gap - 1.0, 0.0))
    return (x - h - grow[0], y - h - grow[1], x + h + grow[2], y + h + grow[3])


def replan(
    scene: Scene,
    robot: str,
    events: Sequence[Event],
    start: State,
    sensed: Iterable[Rectangle] = (),
    *,
    labels: Sequence[str] = (),
    max_horizon: int = 12,
    rlimit: int = 50_000_000,
) -> RobotPlan | None:
    """The shortest plan of `events` from `start` among the walls and the sensed obstacles,
    its route made shorter among those (:data:`~cosmop.planning.synthesis.ROUTE_ROUNDS`: a
    robot among others that move drives the shortest way it finds, measured in lifelong runs).
    Found by the quick search (:func:`~cosmop.planning.synthesis.synthesize`'s ``copies``,
    ``from_bound`` and ``near_lines``): as short as the batch planner's, not necessarily the
    same plan.

    Parameters
    ----------
    scene : Scene
        The scenario's scene (its robot pose stays the ``return`` target).
    robot : str
    events : sequence of Event
        The mission events not done yet, in order.
    start : State
        The robot's pose and the objects as it knows them now, in integers (mm, degrees).
    sensed : iterable of (float, float, float, float)
        Obstacles sensed around the robot, as rectangles ``x0, y0, x1, y1`` (mm), grown by
        the room to keep (:func:`grown`).
    labels : sequence of str
        What each sensed rectangle is, in words (:func:`sensed_scene`).
    max_horizon, rlimit : int
        Bounds of the solver (see :func:`~cosmop.planning.synthesis.synthesize`).

    Returns
    -------
    RobotPlan or None
        A plan that passes :func:`~cosmop.planning.checker.check_robot_plan` from `start`, or
        ``None`` when there is none within the bound (:func:`why_no_plan` says why).
    """
    world = sensed_scene(scene, sensed, labels)
    result = _synthesize(world, robot, events, start, max_horizon, rlimit, explain=False)
    if not result.feasible or result.plan is None:
        return None
    if check_robot_plan(world, robot, result.plan, start=start):
        return None  # unsound plans are never executed
    return result.plan


def why_no_plan(
    scene: Scene,
    robot: str,
    events: Sequence[Event],
    start: State,
    sensed: Iterable[Rectangle] = (),
    *,
    labels: Sequence[str] = (),
    max_horizon: int = 12,
    rlimit: int = 50_000_000,
) -> str:
    """Why :func:`replan` found no plan, in the user's words: the first event out of reach and
    what blocks it (the scenario's walls and goods, the sensed obstacles by their `labels`).

    It searches again and explains (unsatisfiable cores: dearer than the plan), so a caller
    asks once per refusal it reports.  The parameters are :func:`replan`'s.

    Parameters
    ----------
    scene : Scene
    robot : str
    events : sequence of Event
    start : State
    sensed : iterable of (float, float, float, float)
    labels : sequence of str
    max_horizon, rlimit : int
    """
    world = sensed_scene(scene, sensed, labels)
    result = _synthesize(world, robot, events, start, max_horizon, rlimit, explain=True)
    if result.feasible:  # a plan the exact checker refused (never seen): say so plainly
        return f"{robot}'s plan from where it stands failed the exact checker"
    return result.reason or f"{robot} has no plan within {max_horizon} steps from where it stands"


def _synthesize(
    world: Scene,
    robot: str,
    events: Sequence[Event],
    start: State,
    max_horizon: int,
    rlimit: int,
    *,
    explain: bool,
) -> Synthesis:
    """The robot's events from `start` in the sensed `world`, without new requests (a new
    request would need the top-down layer); a plan's route made shorter, a refusal explained."""
    # the solver (and Z3) load only when a robot replans: most runs never do
    from cosmop.planning.synthesis import ROUTE_ROUNDS, synthesize

    return synthesize(
        world,
        robot,
        tuple(events),
        requests=False,
        max_horizon=max_horizon,
        rlimit=rlimit,
        start=start,
        explain=explain,
        route_rounds=0 if explain else ROUTE_ROUNDS,
        # found faster: any of the shortest plans will do, its route is made shorter anyway
        copies=True,
        from_bound=True,
        near_lines=True,
    )


# ----------------------------------------------------------------------------------------------
# In a running simulation
# ----------------------------------------------------------------------------------------------


def replan_stalled(world: World, agent: Agent) -> None:
    """Receding horizon: replan `agent`'s remaining mission with the robots and people it senses.

    Does nothing when the settings turn replanning off.  Every attempt goes to
    ``world.replan_log``; a new plan is taken only if the team-safety layer orders it with
    the others' rests (:func:`cosmop.sim.recoordinate.recoordinate_world`).

    Parameters
    ----------
    world : World
        The running simulation.
    agent : Agent
        The stalled robot.
    """
    s = world.settings
    if not s.replan:
        return
    world.replan_attempts += 1
    remaining, start = mission_left(world, agent)
    # A replan should not be much longer than what is left of the plan: bound the search there
    # (an infeasible replan -- a blocked doorway -- would otherwise search every horizon).
    horizon = min(s.max_horizon, len(agent.steps) - agent.step_index + 4)
    plan = replan(
        world.scenario.scene,
        agent.id,
        remaining,
        start,
        _sensed(world, agent),
        max_horizon=horizon,
        rlimit=s.rlimit,
    )
    if plan is None:
        world.replan_log.append(
            {"t": round(world.t, 6), "robot": agent.id, "accepted": False, "why": "no plan"}
        )
        return
    accepted, why, added = recoordinate_world(world, agent, plan, start)
    world.replan_log.append(
        {
            "t": round(world.t, 6),
            "robot": agent.id,
            "accepted": accepted,
            "why": why or None,
            "messages": [event.name for event in added],
        }
    )
    if accepted:
        world.replans += 1
        world.replan_log[-1]["route"] = route(agent, start.robot)


def route(agent: Agent, start: Sequence[float]) -> dict[str, Any]:
    """What `agent` does from now on, for the pictures: where it starts (mm, mm, degrees) and
    each step left with its pose, primitive and what it is about (an object or a message).

    Parameters
    ----------
    agent : Agent
        The robot, with its new plan.
    start : sequence of float
        Where it starts, ``x, y`` mm and heading in degrees.
    """
    steps = agent.steps[agent.step_index :]
    return {
        "from": [round(float(v), 3) for v in start],
        "steps": [
            {
                "pose": [round(float(v), 3) for v in s.robot],
                "primitive": str(s.primitive),
                "about": s.object or (s.message.name if s.message is not None else None),
            }
            for s in steps
        ],
    }


def _sensed(world: World, agent: Agent) -> list[Rectangle]:
    """The robots and people `agent` senses, as rectangles grown by the room to keep
    (:func:`grown`): robots the clearance the team-safety layer checks (:func:`robot_room`),
    people a little.  A robot that has finished stays where it is for good: sensed however far."""
    s = world.settings
    i = agent.index
    sensed = world.obstacles()
    boxes, names = sensed.boxes, list(sensed.names)
    gaps = box_gaps(world.pose[i, :2], world.robot_half[i], boxes)
    finished = {a.id for a in world.agents if a.done}
    goods = world.resting_boxes()
    return [
        grown(b, robot_room(g) if n in world.robot_ids else _PERSON_ROOM, goods)
        for b, n, g in zip(boxes, names, gaps, strict=True)
        if n != agent.id and n not in world.object_ids and (g < s.sense_range or n in finished)
    ]


def robot_room(gap: float) -> float:
    """The room (mm) a re-plan keeps around another robot whose square is `gap` mm (L-infinity)
    from the re-planning robot's: the clearance the team-safety layer checks, or less where
    the two already stand closer (robots parked touching may leave each other, as the plans
    allow, :mod:`cosmop.team.conflicts`), 1 mm short of touching so that the start, rounded to
    the millimetre, is never inside it.

    Parameters
    ----------
    gap : float
        The gap between the two robots' squares now, mm.
    """
    return float(min(ConflictSettings().clearance, max(gap - 1.0, 0.0)))


def mission_left(world: World, agent: Agent) -> tuple[list[Event], State]:
    """What a re-plan of `agent` plans, and from where: the mission events it has still to do
    with the mission's own messages (the messages that kept plans apart are dropped, to be
    ordered afresh with the new plan), and its state now (:func:`start_state`).

    Parameters
    ----------
    world : World
        The running simulation.
    agent : Agent
        The robot re-planned.
    """
    _, todo = agent.split_mission(world.scenario)
    remaining = [e for e in todo if e not in world.conflict_messages and e not in world.sent_messages]
    return remaining, start_state(world, agent, {e.obj for e in remaining if e.kind == "pick"})


def start_state(world: World, agent: Agent, picks: AbstractSet[str | None] = frozenset()) -> State:
    """Where `agent` replans from: its pose and every object, rounded to integer mm and degrees.

    An object another robot carries, or one it has asked to be moved away (a ``Req`` step done),
    is away: not in its way.  Goods it still has to pick (`picks`) and does not carry are where
    its plan expects them: a robot that another hands them over to waits for them where the
    other puts them down (:mod:`cosmop.team.handover`), wherever they are now.

    Parameters
    ----------
    world : World
        The running simulation.
    agent : Agent
        The robot that replans.
    picks : set of str, optional
        The objects it still has to pick up.
    """
    i = agent.index
    k = agent.step_index
    done_steps = agent.steps[:k]
    before = agent.before  # a replan's first step: the objects as the replan saw them
    expected = (
        before.objects
        if before is not None
        else initial_state(world.scenario.scene, agent.id, agent.steps, world.object_ids).objects
    )
    requested = {st.object for st in done_steps if st.primitive == Primitive.REQ}
    objects = {}
    for j, oid in enumerate(world.object_ids):
        carried = world.carried_by[j] == i
        if oid in picks and not carried and oid in expected and not expected[oid].carried:
            objects[oid] = ObjectState(expected[oid].position, carried=False, away=False)
            continue
        away = (world.carried_by[j] >= 0 and not carried) or bool(world.shipped[j])  # not in its way
        away = away or oid in requested
        pos = world.object_xy[j]
        objects[oid] = ObjectState(
            (round(float(pos[0])), round(float(pos[1]))), carried=bool(carried), away=away
        )
    x, y, h = world.pose[i]
    return State((round(float(x)), round(float(y)), round(math.degrees(float(h)))), objects)


def rest_collisions(world: World) -> list[Violation]:
    """Where the robots' committed rests run into walls or resting goods, now: every robot's
    steps from its current one, checked by the exact single-robot checker from the start of
    that step on its plan (:attr:`~cosmop.sim.world.Agent.before`), with the goods where they
    are now as its plan sees them (:func:`start_state`).  An audit of a running fleet, beside
    :func:`~cosmop.sim.recoordinate.unordered_now`: a rest cut on a line nobody checked fails it.

    Parameters
    ----------
    world : World
        The running simulation.

    Returns
    -------
    list of Violation
        The ``wall`` and ``object-collision`` violations, robot by robot; empty when none.
    """
    out = []
    for agent in world.agents:
        if agent.before is None or agent.done:  # not yet started, or nothing left
            continue
        picks = {e.obj for e in agent.split_mission(world.scenario)[1] if e.kind == "pick"}
        start = State(agent.before.robot, start_state(world, agent, picks).objects)
        plan = RobotPlan.from_steps([], agent.steps[agent.step_index :])
        found = check_robot_plan(world.scenario.scene, agent.id, plan, start=start)
        out += [v for v in found if v.rule in ("wall", "object-collision")]
    return out
