"""Where a plan realises its mission events: the one mapping from events to steps.

A plan's ``mission`` is realised in order: there are instants :math:`0 \\le i_1 < i_2 < \\dots`
with event *m* holding at :math:`i_m` (a ``return``, a pose rather than a step, may hold at the
same instant as the event before it) --

* ``pick(R,O)``: step *i* is ``PickUp(O)``;
* ``drop(R,O,W)``: step *i* is ``DropOff(O)`` and O's square after it lies wholly in W;
* ``return(R)``: the pose at instant *i* is the robot's initial pose in the scenario;
* ``away(O,A,B)``: step *i* is ``Req(O)`` for the requester A, ``Res(O)`` for the responder B;
* ``msg(S,R,tag)``: step *i* is ``Res`` carrying the message for the sender S, ``Req`` carrying
  it for the receiver R.

:func:`event_instants` finds the earliest such instants (greedily, which finds a realisation
whenever one exists, since each event is matched at its first chance after the previous one).
The checker, the coordination layer and the simulator all use it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from cosmop.events import Event, Link, Primitive, realising_step
from cosmop.planning.plan_types import RobotPlan, State, Step
from cosmop.planning.primitive_effects import initial_state
from cosmop.scene import Scene

__all__ = [
    "TOLERANCE",
    "angles_equal",
    "at_pose",
    "event_instants",
    "holds_at",
    "message_links",
    "unanswered_requests",
]

TOLERANCE = 1e-6
"""Tolerance of numeric equality, mm or degrees."""


def angles_equal(a: float, b: float) -> bool:
    """Whether two headings (degrees) agree within :data:`TOLERANCE`, modulo 360.

    Parameters
    ----------
    a, b : float
        The headings (degrees).
    """
    diff = (a - b) % 360.0
    return min(diff, 360.0 - diff) <= TOLERANCE


def at_pose(pose: Sequence[float], home: Sequence[float]) -> bool:
    """Whether two poses ``(x, y, heading)`` agree within :data:`TOLERANCE`.

    Parameters
    ----------
    pose, home : sequence of float
        The poses ``(x, y, heading)`` (mm, degrees).
    """
    return (
        abs(pose[0] - home[0]) <= TOLERANCE
        and abs(pose[1] - home[1]) <= TOLERANCE
        and angles_equal(pose[2], home[2])
    )


def holds_at(
    event: Event, robot: str, plan: RobotPlan, states: Sequence[State], scene: Scene, i: int
) -> bool:
    """Whether `event` holds at instant `i` of `robot`'s `plan` (`states` are instants 0..K).

    Parameters
    ----------
    event : Event
        The mission event.
    robot : str
        The robot whose plan it is.
    plan : RobotPlan
        The plan.
    states : sequence of State
        The plan's states at instants 0..K.
    scene : Scene
        The scene (initial poses, object sizes, workspaces).
    i : int
        The instant, ``0 <= i <= K``.
    """
    if event.kind == "return":
        return at_pose(states[i].robot, scene.robots[robot].pose)
    if i == 0:
        return False
    step = plan.steps[i - 1]
    wanted = realising_step(event, robot)
    if wanted is None or (step.primitive, step.object, step.message) != wanted:
        return False
    if event.kind == "drop":
        assert event.obj is not None and event.workspace is not None  # a drop names both
        obj = step.objects.get(event.obj)
        size = scene.objects[event.obj].size
        return obj is not None and scene.workspaces[event.workspace].holds(*obj.position, size, TOLERANCE)
    return True


def event_instants(
    plan: RobotPlan,
    robot: str,
    scene: Scene,
    events: Sequence[Event] | None = None,
    start: State | None = None,
) -> list[int | None]:
    """The instant at which each mission event is realised, in order.

    Parameters
    ----------
    plan : RobotPlan
        The plan.
    robot : str
        The robot whose plan it is.
    scene : Scene
        The scene (initial poses, object sizes, workspaces).
    events : sequence of Event, optional
        The events to realise (default: the plan's mission).
    start : State, optional
        Instant 0 when it is not the scenario.

    Returns
    -------
    list of (int or None)
        One entry per event: its instant, or ``None`` for the first event that cannot be
        realised after the previous one and every event after it.
    """
    events = plan.mission if events is None else tuple(events)
    states = [start or initial_state(scene, robot, plan, scene.objects), *(s.state for s in plan.steps)]
    out: list[int | None] = []
    last: int | None = None
    for event in events:
        after = 0 if last is None else last + (0 if event.kind == "return" else 1)
        found = next(
            (i for i in range(after, plan.horizon + 1) if holds_at(event, robot, plan, states, scene, i)),
            None,
        )
        if found is None:
            return out + [None] * (len(events) - len(out))
        out.append(found)
        last = found
    return out


def _message_steps(robot: str, plan: RobotPlan) -> list[tuple[int, Step, Event | None]]:
    """The plan's Req and Res steps (instant after each) with the message each sends or awaits.

    A step that names its ``message`` is that message; a ``Req(O)`` or ``Res(O)`` is the next
    ``away`` event of O in the mission with the robot in that role (``None`` when none is left).
    """
    pending = [e for e in plan.mission if e.kind == "away"]
    out: list[tuple[int, Step, Event | None]] = []
    for k, step in enumerate(plan.steps, 1):
        if step.primitive not in (Primitive.REQ, Primitive.RES):
            continue
        if step.message is not None:
            out.append((k, step, step.message))
            continue
        role = "receiver" if step.primitive == Primitive.REQ else "sender"
        event = next((e for e in pending if e.obj == step.object and getattr(e, role) == robot), None)
        if event is not None:
            pending.remove(event)
        out.append((k, step, event))
    return out


def unanswered_requests(plans: Mapping[str, RobotPlan]) -> list[tuple[str, int, str]]:
    """``(robot, instant, object)`` of every ``Req(O)`` whose mission has no ``away`` left for it.

    No robot's plan answers such a request (an answer is an ``away`` event of both missions),
    so in joint execution the robot would wait there for ever.

    Parameters
    ----------
    plans : Mapping[str, RobotPlan]
        Every robot's plan, by robot id.
    """
    return [
        (robot, k, str(step.object))
        for robot, plan in plans.items()
        for k, step, event in _message_steps(robot, plan)
        if event is None and step.primitive == Primitive.REQ
    ]


def unsent_answers(plans: Mapping[str, RobotPlan]) -> list[tuple[str, int, str]]:
    """``(robot, instant, object)`` of every ``Res(O)`` whose mission has no ``away`` left for it.

    Such an answer tells nobody anything: every request it could answer is answered already
    (messages match one to one), so the plan does something its mission does not ask for.

    Parameters
    ----------
    plans : Mapping[str, RobotPlan]
        Every robot's plan, by robot id.
    """
    return [
        (robot, k, str(step.object))
        for robot, plan in plans.items()
        for k, step, event in _message_steps(robot, plan)
        if event is None and step.primitive == Primitive.RES
    ]


def repeated_messages(plans: Mapping[str, RobotPlan]) -> list[tuple[str, int, Event, int]]:
    """``(robot, instant, message, first instant)`` of every ``Req`` or ``Res`` step that awaits
    or sends a ``msg`` an earlier step of the same plan already awaits or sends.

    A message is sent once and awaited once; :func:`message_links` matches the first of each.

    Parameters
    ----------
    plans : Mapping[str, RobotPlan]
        Every robot's plan, by robot id.
    """
    out = []
    for robot, plan in plans.items():
        first: dict[tuple[Event, Primitive], int] = {}
        for k, step, event in _message_steps(robot, plan):
            if event is None or step.message is None:
                continue  # an away: a second Req(O) or Res(O) finds no away left (above)
            key = (event, step.primitive)
            if key in first:
                out.append((robot, k, event, first[key]))
            first.setdefault(key, k)
    return out


def message_links(plans: Mapping[str, RobotPlan]) -> list[Link]:
    """Every message of the plans with the steps that send and await it.

    A ``msg`` is matched through the ``message`` of its ``Req`` and ``Res`` steps.  An
    ``away(O,A,B)`` is awaited by A's ``Req(O)`` and sent by B's ``Res(O)``: the *k*-th
    ``Res(O)`` of B's plan sends the *k*-th ``away(O,*,B)`` of B's mission.

    Parameters
    ----------
    plans : Mapping[str, RobotPlan]
        Every robot's plan, by robot id.
    """
    sends: dict[Event, tuple[str, int]] = {}
    waits: dict[Event, tuple[str, int]] = {}
    for robot, plan in plans.items():
        for k, step, event in _message_steps(robot, plan):
            if event is not None:
                table = waits if step.primitive == Primitive.REQ else sends
                table.setdefault(event, (robot, k))
    out = []
    for event in sorted(set(sends) | set(waits), key=lambda e: e.name):
        sender, receiver = event.sender, event.receiver
        assert sender is not None and receiver is not None  # a message has both
        send, wait = sends.get(event), waits.get(event)
        out.append(
            Link(
                event,
                sender,
                send[1] if send is not None and send[0] == sender else None,
                receiver,
                wait[1] if wait is not None and wait[0] == receiver else None,
            )
        )
    return out


def request_phases(
    plan: RobotPlan, robot: str, scene: Scene, events: Sequence[Event]
) -> list[tuple[str, int]]:
    """Each ``Req(O)`` step of `plan` with the index in `events` of the first event realised at
    or after it (``len(events)`` if none is): the event the request prepares.

    These are the requests :func:`cosmop.team.coordination_events.coordinate` turns into
    request/response pairs.

    Parameters
    ----------
    plan : RobotPlan
        The plan.
    robot : str
        The robot whose plan it is.
    scene : Scene
        The scene (initial poses, object sizes, workspaces).
    events : sequence of Event
        The mission events, in order.
    """
    instants = event_instants(plan, robot, scene, events)
    out = []
    for k, step in enumerate(plan.steps, 1):
        if step.primitive == Primitive.REQ and step.object is not None:
            index = next((n for n, t in enumerate(instants) if t is not None and t >= k), len(events))
            out.append((step.object, index))
    return out
