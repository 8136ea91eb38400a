"""Messages in plans: the ``Req`` and ``Res`` steps that wait for and send ``msg`` events.

A message does not move anything, so it is placed after synthesis instead of by the solver:

* :func:`place_mission_messages` puts the messages a robot's local mission names (orders
  between robots, written by the user or added by :mod:`cosmop.missions.ordering`) into its
  plan: a send right after the step that realises the event before it, a wait right before the
  step that realises the event after it;
* :func:`place_edges` turns start edges ("B may start step *j* once A has completed step *i*",
  from :mod:`cosmop.team.conflicts`) into messages: ``Res`` right after A's step *i*,
  ``Req`` right before B's step *j*.

Both go through :func:`insert_steps`, which keeps the plan's mission list in the order its
steps realise it.  A sent message comes before a wait placed at the same point.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace
from typing import Any

from cosmop.events import Event, Node, Primitive, message
from cosmop.planning.checker import check_robot_plan
from cosmop.planning.plan_types import RobotPlan, State, Step
from cosmop.planning.primitive_effects import initial_state, plan_from_actions
from cosmop.planning.realisation import event_instants
from cosmop.scene import Scene

__all__ = [
    "answer_early",
    "insert_steps",
    "merge_drives",
    "place_edges",
    "place_mission_messages",
    "split_drives",
    "strip_messages",
    "wait_early",
]

Insert = tuple[int, int, Event]
"""``(after instant p, 0 for a send / 1 for a wait, message event)``."""


def strip_messages(mission: Sequence[Event]) -> tuple[Event, ...]:
    """The mission without its ``msg`` events (what the solver plans; ``away`` stays).

    Parameters
    ----------
    mission : sequence of Event
        A robot's mission.
    """
    return tuple(e for e in mission if e.kind != "msg")


def answer_early(plan: RobotPlan) -> RobotPlan:
    """`plan` with every answer ``Res(O)`` moved right after the ``PickUp(O)`` it follows.

    An answer changes nothing but tells another robot that O is out of the way; the solver may
    put it after some drives, which keeps the requester waiting (and can close a wait cycle
    with robots those drives must pass).  Moved forward it takes the pose and objects of the
    step it now follows; the order of the plan's mission events is unchanged.

    Parameters
    ----------
    plan : RobotPlan
        The robot's plan.
    """
    out: list[Step] = []
    for step in plan.steps:
        if step.primitive == Primitive.RES and step.message is None:
            pick = max(
                (n for n, s in enumerate(out) if s.primitive == Primitive.PICKUP and s.object == step.object),
                default=None,
            )
            if pick is not None:
                at = pick + 1
                while at < len(out) and out[at].primitive == Primitive.RES and out[at].message is None:
                    at += 1
                before = out[at - 1]
                out.insert(at, replace(step, robot=before.robot, objects=before.objects))
                continue
        out.append(step)
    return RobotPlan.from_steps(plan.mission, out)


def wait_early(scene: Scene, robot: str, plan: RobotPlan) -> RobotPlan:
    """`plan` with every run of requests issued before the drives that lead to it.

    A plan may drive somewhere and then wait there for another robot's answer (``GoTo``,
    ``Req``).  Where a robot waits does not matter to its mission, but a robot parked next to
    the goods stands in the way of the very robot it waits for.  Requests are moved before the
    drive when the reordered plan still passes the exact checker (the drive then meets fewer
    objects: the requested ones are away); otherwise the plan is kept.

    Parameters
    ----------
    scene : Scene
        The scene the plan is checked in.
    robot : str
        The robot's id.
    plan : RobotPlan
        The robot's plan.
    """
    actions: list[tuple[str, Any]] = [
        (Primitive.GOTO, st.robot) if st.primitive == Primitive.GOTO else (st.primitive, st.object)
        for st in plan.steps
    ]
    k, changed = 0, False
    while k < len(actions):
        if actions[k][0] == Primitive.REQ and k > 0 and actions[k - 1][0] == Primitive.GOTO:
            b = k - 1
            while b > 0 and actions[b - 1][0] == Primitive.GOTO:
                b -= 1
            e = k
            while e + 1 < len(actions) and actions[e + 1][0] == Primitive.REQ:
                e += 1
            actions = actions[:b] + actions[k : e + 1] + actions[b:k] + actions[e + 1 :]
            changed = True
            k = e + 1
        else:
            k += 1
    if not changed:
        return plan
    reordered = plan_from_actions(scene, robot, plan.mission, actions)
    return reordered if not check_robot_plan(scene, robot, reordered) else plan


def split_drives(
    plan: RobotPlan,
    start: Sequence[float],
    max_length: float,
    roomy: Callable[[float, float], bool] | None = None,
) -> RobotPlan:
    """`plan` (from pose `start`) with every drive longer than `max_length` (mm) cut into pieces.

    A piece sweeps part of what the whole drive sweeps, so the plan stays sound; the pieces let
    another robot wait only until this one has passed the place they share, not until the whole
    drive is over.  Drives are halved until short enough, so the new waypoints are exact
    (dyadic fractions of integer coordinates).  A cut is made only where ``roomy(x, y)`` (a
    robot may have to wait there for a message: not in a narrow passage).

    Parameters
    ----------
    plan : RobotPlan
        The robot's plan.
    start : sequence of float
        The robot's pose at instant 0, ``(x, y, heading)`` (mm, degrees).
    max_length : float
        The longest drive kept whole (mm).
    roomy : callable, optional
        ``roomy(x, y)``: whether a robot centred at ``(x, y)`` (mm) may wait there; by default
        everywhere.
    """
    out: list[Step] = []
    pose = tuple(start)
    for step in plan.steps:
        start, pose = pose, step.robot
        if step.primitive != Primitive.GOTO:
            out.append(step)
            continue
        length = ((pose[0] - start[0]) ** 2 + (pose[1] - start[1]) ** 2) ** 0.5
        pieces = 1
        while length / pieces > max_length and pieces < 64:
            pieces *= 2
        for j in range(1, pieces):
            t = j / pieces
            point = (
                start[0] + (pose[0] - start[0]) * t,
                start[1] + (pose[1] - start[1]) * t,
                _travel(start, pose),
            )
            if roomy is None or roomy(point[0], point[1]):
                out.append(replace(step, robot=point))
        out.append(step)
    return RobotPlan.from_steps(plan.mission, out)


def cut_drives(
    plan: RobotPlan,
    start: Sequence[float],
    cuts: Mapping[int, Sequence[float]],
    roomy: Callable[[float, float], bool] | None = None,
) -> RobotPlan:
    """`plan` (from pose `start`) with its GoTo step *k* cut at the fractions ``cuts[k]`` of its way.

    A piece sweeps part of what the whole drive sweeps, so the plan stays sound; at a cut the
    robot faces the way it goes (no turn between pieces).  Each cut is
    rounded to a multiple of :data:`CUT_GRAIN` of the way (an exact point of the segment for
    coordinates on the micrometre grid), and a cut is made only where ``roomy(x, y)`` (a robot
    may wait there for a message: not in a narrow passage).

    Parameters
    ----------
    plan : RobotPlan
        The robot's plan.
    start : sequence of float
        The robot's pose at instant 0, ``(x, y, heading)`` (mm, degrees).
    cuts : Mapping[int, sequence of float]
        The fractions of its way (between 0 and 1) at which GoTo step *k* is cut, by *k*.
    roomy : callable, optional
        ``roomy(x, y)``: whether a robot centred at ``(x, y)`` (mm) may wait there; by default
        everywhere.
    """
    out: list[Step] = []
    pose = tuple(start)
    for k, step in enumerate(plan.steps, 1):
        begin, pose = pose, step.robot
        if step.primitive == Primitive.GOTO:
            for t in sorted({round(t * CUT_GRAIN) / CUT_GRAIN for t in cuts.get(k, ())}):
                if 0.0 < t < 1.0:
                    x, y = begin[0] + (pose[0] - begin[0]) * t, begin[1] + (pose[1] - begin[1]) * t
                    point = (x, y, _travel(begin, pose))
                    if roomy is None or roomy(point[0], point[1]):
                        out.append(replace(step, robot=point))
        out.append(step)
    return RobotPlan.from_steps(plan.mission, out)


def _travel(start: Sequence[float], end: Sequence[float]) -> float:
    """The heading (degrees) of the way from `start` to `end`: a robot at a cut of the drive
    faces where it goes, so it turns nowhere between the pieces."""
    return round(math.degrees(math.atan2(end[1] - start[1], end[0] - start[0])), 9)


CUT_GRAIN = 1024
"""Cuts of a drive fall on multiples of ``1 / CUT_GRAIN`` of its way (dyadic: exact points)."""


def merge_drives(plan: RobotPlan, waypoints: set[tuple[float, float]]) -> RobotPlan:
    """Undo :func:`split_drives` where no message came between the pieces.

    Two consecutive GoTo steps are joined when the point between them is not one of
    `waypoints` (the plan's own, before splitting): the joined drive sweeps exactly what the two
    pieces swept, and nothing waits or is sent between them, so every order between robots
    stays as it was.

    Parameters
    ----------
    plan : RobotPlan
        The robot's plan.
    waypoints : set of (float, float)
        The points ``(x, y)`` (mm) the plan's drives ended at before splitting.
    """
    out: list[Step] = []
    for step in plan.steps:
        if (
            step.primitive == Primitive.GOTO
            and out
            and out[-1].primitive == Primitive.GOTO
            and (out[-1].robot[0], out[-1].robot[1]) not in waypoints
        ):
            out[-1] = step
            continue
        out.append(step)
    return RobotPlan.from_steps(plan.mission, out)


def insert_steps(
    scene: Scene,
    robot: str,
    plan: RobotPlan,
    inserts: Sequence[Insert],
    start: State | None = None,
    mission: Sequence[Event] | None = None,
) -> tuple[RobotPlan, dict[int, int]]:
    """`plan` with a ``Res`` (send) or ``Req`` (wait) step of each message inserted.

    Parameters
    ----------
    scene : Scene
        The scene (the robot's initial state when `start` is not given).
    robot : str
        The robot's id.
    plan : RobotPlan
        The robot's plan.
    inserts : sequence of Insert
        Where each message goes: after instant *p* (0 = before the first step).
    start : State, optional
        Instant 0 when it is not the scenario.
    mission : sequence of Event, optional
        The new plan's mission list, when the caller knows it; by default the old mission with
        each message placed where its step is.

    Returns
    -------
    RobotPlan, dict
        The new plan, and the new instant of every old instant.
    """
    if mission is None:
        instants = event_instants(plan, robot, scene, start=start)
        # ties are broken by the events' names (their order as text)
        keyed = [
            ((float(t) if t is not None else float(plan.horizon), 0, 0), event.name, event)
            for t, event in zip(instants, plan.mission, strict=True)
        ]
        ordered = sorted(inserts, key=lambda item: (item[0], item[1], item[2].name))
        keyed += [((p + 0.5, rank, n), event.name, event) for n, (p, rank, event) in enumerate(ordered)]
        mission = [event for *_, event in sorted(keyed, key=lambda item: item[:2])]
    # messages after one instant go in the mission's order (a wait the mission puts before a
    # send stays before it, even when the event between them needs no step)
    order = {event: i for i, event in enumerate(mission)}
    at: dict[int, list[tuple[int, int, str, Event]]] = {}
    for p, rank, event in inserts:
        at.setdefault(p, []).append((order.get(event, len(order)), rank, event.name, event))
    state = start or initial_state(scene, robot, plan, scene.objects)
    steps: list[Step] = []
    moved: dict[int, int] = {0: 0}
    for k in range(plan.horizon + 1):
        if k > 0:
            step = plan.steps[k - 1]
            steps.append(step)
            state = step.state
            moved[k] = len(steps)
        for _, rank, _, event in sorted(at.get(k, ()), key=lambda item: item[:3]):
            primitive = Primitive.RES if rank == 0 else Primitive.REQ
            steps.append(Step(primitive, None, state.robot, state.objects, event))
    return RobotPlan.from_steps(mission, steps), moved


def place_mission_messages(
    scene: Scene, robot: str, plan: RobotPlan, mission: Sequence[Event], start: State | None = None
) -> RobotPlan:
    """Put the ``msg`` events of `mission` into `plan`, which realises the rest of it.

    A message the robot sends goes right after the step that realises the mission event before
    it (at the start if there is none); a message it waits for goes right before the step that
    realises the event after it (at the end if there is none).

    Parameters
    ----------
    scene : Scene
        The scene (the robot's initial state when `start` is not given).
    robot : str
        The robot's id.
    plan : RobotPlan
        The robot's plan.
    mission : sequence of Event
        The robot's mission, its ``msg`` events included, in order.
    start : State, optional
        Instant 0 when it is not the scenario.
    """
    if not any(e.kind == "msg" for e in mission):
        return plan
    planned = [e for e in mission if e.kind != "msg"]
    instants = event_instants(plan, robot, scene, planned, start)
    inserts: list[Insert] = []
    seen = 0  # events of `planned` before the current message
    for event in mission:
        if event.kind != "msg":
            seen += 1
            continue
        if event.sender == robot:
            p = 0 if seen == 0 else (instants[seen - 1] or 0)
            inserts.append((p, 0, event))
        else:
            nxt = instants[seen] if seen < len(instants) else None
            p = plan.horizon if nxt is None else max(nxt - 1, 0)
            before = instants[seen - 1] if seen > 0 else None
            if before is not None:
                p = max(p, before)
            inserts.append((p, 1, event))
    new, _ = insert_steps(scene, robot, plan, inserts, start, mission)
    return new


def place_edges(
    scene: Scene,
    plans: Mapping[str, RobotPlan],
    edges: Sequence[tuple[Node, Node]],
    tag: str = "clear",
    used: set[Event] | None = None,
    starts: Mapping[str, State] | None = None,
) -> tuple[dict[str, RobotPlan], list[tuple[Event, tuple[Node, Node], tuple[Node, Node]]]]:
    """One message per start edge ``((A, i), (B, j))``: A sends after step *i*, B waits before *j*.

    Returns the new plans and, per message, ``(event, old edge, edge in new instants)``;
    the new edge ``((A, i'), (B, j'))`` names A's ``Res`` and B's ``Req`` steps.

    Parameters
    ----------
    scene : Scene
        The scene (the robots' initial states when `starts` does not give them).
    plans : Mapping[str, RobotPlan]
        Every robot's plan, by id.
    edges : sequence of (Node, Node)
        The start edges ``((A, i), (B, j))``: B may start step *j* once A has completed step *i*.
    tag : str
        The messages' tags are this followed by a number.
    used : set of Event, optional
        Messages already taken; the new ones are added to it.
    starts : Mapping[str, State], optional
        The robots' states at instant 0, by id, when it is not the scenario.
    """
    used = set() if used is None else used
    inserts: dict[str, list[Insert]] = {r: [] for r in plans}
    events = []
    for n, ((a, i), (b, j)) in enumerate(edges, 1):
        number = n
        event = message(a, b, f"{tag}{number}")
        while event in used:
            number += len(edges)
            event = message(a, b, f"{tag}{number}")
        used.add(event)
        inserts[a].append((i, 0, event))
        inserts[b].append((j - 1, 1, event))
        events.append(event)
    out: dict[str, RobotPlan] = {}
    moved: dict[str, dict[int, int]] = {}
    for robot, plan in plans.items():
        start = (starts or {}).get(robot)
        out[robot], moved[robot] = insert_steps(scene, robot, plan, inserts[robot], start)
    placed: list[tuple[Event, tuple[Node, Node], tuple[Node, Node]]] = []
    for event, edge in zip(events, edges, strict=True):
        sender, receiver = event.sender, event.receiver
        assert sender is not None and receiver is not None  # a message has both
        send = next(k for k, s in enumerate(out[sender].steps, 1) if s.message == event)
        wait = next(k for k, s in enumerate(out[receiver].steps, 1) if s.message == event)
        placed.append((event, edge, ((sender, send), (receiver, wait))))
    return out, placed
