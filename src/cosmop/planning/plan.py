"""Plans: the plan file ``cosmop.plan/1`` and its immutable Python form.

A plan set holds, for every robot, a sequence of motion primitives and the states they lead to
(the paper's trace :math:`q(1), \\dots, q(K)`; instant 0 is the scenario)::

    {
      "format": "cosmop.plan/1",
      "scenario": "warehouse-2x2",
      "feasible": true,
      "robots": {
        "R1": {
          "mission": ["away(O2,R1,R2)", "pick(R1,O1)", "drop(R1,O1,W1)", "return(R1)"],
          "horizon": 7,
          "steps": [
            {"primitive": "Req", "object": "O2", "robot": [-2000, -1000, 0],
             "objects": {"O1": {"position": [2000, -1000], "carried": false, "away": false},
                         "O2": {"position": [1900, -1000], "carried": false, "away": true}}},
            ...
          ]
        }
      },
      "coordination": [{"object": "O2", "requester": "R1", "responder": "R2"}],
      "messages": [{"event": "msg(R2,R1,clear1)", "sender": "R2", "receiver": "R1", "kind": "conflict",
                    "protects": "...", "place": [x_min, y_min, x_max, y_max]}],
      "added": [{"robot": "R1", "object": "C9", "workspace": "aside_C9", "point": [x, y],
                 "why": "..."}]
    }

``steps[k-1]`` is instant *k*: the primitive taken between *k-1* and *k* and the whole state
*after* it, as this robot's model sees it (robot pose ``[x, y, heading]`` in mm and degrees;
every object's centre in mm, whether this robot carries it, and whether it has been moved away
by another robot). ``primitive`` is one of ``GoTo``, ``PickUp``, ``DropOff``, ``Req`` (the
paper's ``?ObjAway``) and ``Res`` (``!ObjAway``); all but ``GoTo`` name their ``object``,
except the ``Req`` and ``Res`` of a message ``msg(S,R,tag)``, which name their ``message``
instead: ``{"primitive": "Res", "object": null, "message": "msg(R2,R1,clear1)", ...}`` is
sent by S right after its previous step, ``Req`` with the same message waits in R's plan
until it has been sent.  ``messages`` lists every such message with what it protects (an order
the mission requires, or a place two robots' plans share: then ``place`` is its bounding box,
mm).  ``added`` lists the tasks the planner added that no mission names: goods that block a
robot and that nobody moves are picked by ``robot`` and set down at ``point`` (mm), which the
plan's events call ``workspace`` (a point workspace that exists only in this plan file).
``start`` and ``end`` (s, on every step or on none) are the step's expected times, the plan
set's :class:`Itinerary`.  An infeasible scenario still has a plan file, with ``"feasible":
false`` and a ``"reason"``.

:func:`load_plan` and :meth:`PlanSet.from_dict` validate the shape of a plan and raise
:class:`PlanError` naming the file, the field (e.g. ``robots.R1.steps[3].primitive``) and what
was expected. Whether a plan is *sound* for a scene (walls, poses, flags, mission) is the
business of :mod:`cosmop.planning.checker`. :func:`initial_state` gives instant 0 of a robot's
plan, and :func:`successor` / :func:`plan_from_actions` build steps by applying the primitives'
nominal effects (handy for hand-made plans and for decoding a solver's model).
"""

from __future__ import annotations

import json
import math
import os
import re
from collections.abc import Collection, Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Any

from cosmop._frozen import reduce_frozen
from cosmop.docking import in_front
from cosmop.errors import CosmopInputError, EventSyntaxError
from cosmop.events import ID_PATTERN, Event, Primitive, parse_event
from cosmop.io import read_text, write_atomic
from cosmop.reading import FieldPath, format_path, json_position, load_json, unprintable
from cosmop.scene import Scenario, Scene, Workspace
from cosmop.units import INTERNAL_UNITS, check_units_field

__all__ = [
    "MAX_STEPS",
    "MESSAGE_PRIMITIVES",
    "MESSAGE_REASONS",
    "OBJECT_PRIMITIVES",
    "PLAN_FORMAT",
    "PRIMITIVES",
    "AddedTask",
    "Coordination",
    "Itinerary",
    "ObjectState",
    "PlanError",
    "PlanMessage",
    "PlanSet",
    "RobotPlan",
    "State",
    "Step",
    "initial_state",
    "load_plan",
    "plan_from_actions",
    "successor",
]

PLAN_FORMAT = "cosmop.plan/1"
"""The value of the ``format`` field of the plan files this module reads and writes."""

MAX_STEPS = 1000
"""Most steps one robot's plan may have (a plan file with more is refused; no horizon goes beyond)."""

PRIMITIVES = tuple(Primitive)
"""The motion primitives, in the paper's order :math:`\\pi^1, \\dots, \\pi^5`."""

OBJECT_PRIMITIVES = frozenset({Primitive.PICKUP, Primitive.DROPOFF, Primitive.REQ, Primitive.RES})
"""The primitives that act on an object (every primitive but ``GoTo``; ``Req`` and ``Res`` of a
``msg`` name a message instead)."""

MESSAGE_PRIMITIVES = frozenset({Primitive.REQ, Primitive.RES})
"""The primitives that can carry a ``msg`` message (wait for it, send it)."""

MESSAGE_REASONS = ("order", "conflict", "mission")
"""Why a planned message exists: an order between robots that the global mission requires, a
place that two robots' plans share (a conflict), or a message the mission itself names."""

_ID_RE = re.compile(rf"{ID_PATTERN}\Z")

Pose = tuple[float, float, float]
Point = tuple[float, float]


class PlanError(CosmopInputError):
    """A plan file (or plan mapping) that cannot be read or does not have the expected shape."""


# ----------------------------------------------------------------------------------------------
# Values
# ----------------------------------------------------------------------------------------------


def _floats(values: Iterable[Any], n: int, what: str) -> tuple[float, ...]:
    result = tuple(float(v) for v in values)
    if len(result) != n:
        raise ValueError(f"{what} needs {n} numbers, got {len(result)}")
    if not all(math.isfinite(v) for v in result):
        raise ValueError(f"{what} must be finite, got {result}")
    return result


def _object_map(objects: Mapping[str, ObjectState]) -> Mapping[str, ObjectState]:
    for name, state in objects.items():
        if not isinstance(state, ObjectState):
            raise TypeError(f"object {name!r}: expected an ObjectState, got {type(state).__name__}")
    if isinstance(objects, MappingProxyType):
        return objects
    return MappingProxyType(dict(objects))


@dataclass(frozen=True)
class ObjectState:
    """The state of one movable object at one instant, as a robot's plan sees it.

    Parameters
    ----------
    position : tuple of float
        Centre ``(x, y)`` of the object's square, mm. A carried object keeps the position where
        it was picked up until it is dropped off (the paper's :math:`\\phi_{carry}`).
    carried : bool
        Whether this robot carries the object (the paper's :math:`q_b.p`).
    away : bool
        Whether another robot has moved the object away on request (the paper's :math:`q_b.a`).
    """

    position: Point
    carried: bool = False
    away: bool = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "position", _floats(self.position, 2, "an object position"))
        object.__setattr__(self, "carried", bool(self.carried))
        object.__setattr__(self, "away", bool(self.away))

    def to_dict(self) -> dict[str, Any]:
        """The JSON form: ``{"position": [x, y], "carried": bool, "away": bool}``."""
        return {"position": [_num(v) for v in self.position], "carried": self.carried, "away": self.away}


@dataclass(frozen=True)
class State:
    """The state of a robot's model at one instant: its pose and every object's state.

    Parameters
    ----------
    robot : tuple of float
        The robot's pose ``(x, y, heading)``: centre in mm, heading in degrees.
    objects : Mapping[str, ObjectState]
        Every object of the scene, by id (read-only).
    """

    __reduce__ = reduce_frozen  # picklable for worker processes

    robot: Pose
    objects: Mapping[str, ObjectState]

    def __post_init__(self) -> None:
        object.__setattr__(self, "robot", _floats(self.robot, 3, "a robot pose"))
        object.__setattr__(self, "objects", _object_map(self.objects))


def initial_state(
    scene: Scene,
    robot_id: str,
    plan: RobotPlan | Sequence[Step] | None = None,
    moved: Collection[str] | None = None,
) -> State:
    """Instant 0 of a robot's plan: the scenario, with goods that robots move as the plan knows them.

    Each robot is planned alone, against the objects as it knows them: goods another robot
    hands over to it lie where the other puts them down, goods others drop in a dock it shares
    lie in their slots (:mod:`cosmop.missions.handover`, :func:`cosmop.planning.aside.dock_slots`).
    Its plan lists that model at every step; instant 0 is the model before the first step.

    Parameters
    ----------
    scene : Scene
        The scene the plan is for.
    robot_id : str
        The robot whose plan it is.
    plan : RobotPlan or sequence of Step, optional
        The plan (or its steps).
    moved : collection of str, optional
        The goods whose place at instant 0 is the plan's own (as its first step lists them,
        before that step's effect): goods the team moves, whose real places the team's checker
        verifies (:mod:`cosmop.planning.joint`).  By default the goods the plan picks up.

    Returns
    -------
    State
        The robot at its initial pose (mm, degrees); every object at its scenario position
        (or, the `moved` ones, as the plan lists them), not carried and not away.

    Raises
    ------
    KeyError
        If the scene has no robot `robot_id`.
    """
    robot = scene.robots[robot_id]
    objects = {o: ObjectState(obj.position, carried=False, away=False) for o, obj in scene.objects.items()}
    steps = plan.steps if isinstance(plan, RobotPlan) else tuple(plan or ())
    if steps:
        if moved is None:
            moved = {s.object for s in steps if s.primitive == Primitive.PICKUP}
        first = steps[0].objects
        for oid in moved:
            if oid in objects and oid in first:
                objects[oid] = ObjectState(first[oid].position, carried=False, away=False)
    return State(robot=robot.pose, objects=objects)


Action = tuple[str, Any] | tuple[str]
"""A primitive to apply: ``("GoTo", (x, y, heading))``, ``("PickUp", "O1")``, ... (see :func:`successor`)."""


def successor(
    scene: Scene,
    robot_id: str,
    state: State,
    primitive: str,
    obj: str | None = None,
    to: tuple[float, float, float] | None = None,
) -> Step:
    """The step that applies a primitive's nominal effect to `state` (no rule is checked).

    ``GoTo`` moves the robot to `to`; ``PickUp(O)`` marks O carried; ``DropOff(O)`` puts O at
    :math:`(x, y) + d\\,(\\cos h, \\sin h)` in front of the robot facing :math:`h` (a docking
    heading: 0, 90, 180 or 270 degrees), :math:`d = (l + b)/2`, and marks it not carried;
    ``Req(O)`` marks O away; ``Res(O)`` changes nothing. Whether the step is allowed is the
    business of :func:`cosmop.planning.checker.check_robot_plan`.

    Parameters
    ----------
    scene : Scene
        The scene (for the sizes).
    robot_id : str
        The robot taking the step.
    state : State
        The state before the step.
    primitive : {"GoTo", "PickUp", "DropOff", "Req", "Res"}
        The primitive.
    obj : str, optional
        The object, for every primitive but ``GoTo``.
    to : tuple of float, optional
        The target pose ``(x, y, heading)`` (mm, degrees), for ``GoTo`` only.

    Returns
    -------
    Step
    """
    robot = state.robot
    objects = dict(state.objects)
    if primitive == Primitive.GOTO:
        if to is None:
            raise ValueError("GoTo needs a target pose `to`")
        robot = to
    elif to is not None:
        raise ValueError(f"{primitive} does not move the robot; give no target pose")
    elif primitive == Primitive.PICKUP:
        objects[obj] = ObjectState(objects[obj].position, carried=True, away=objects[obj].away)
    elif primitive == Primitive.DROPOFF:
        gap = (scene.robots[robot_id].size + scene.objects[obj].size) / 2.0
        objects[obj] = ObjectState(_ahead(robot, gap), carried=False, away=objects[obj].away)
    elif primitive == Primitive.REQ:
        objects[obj] = ObjectState(objects[obj].position, carried=objects[obj].carried, away=True)
    return Step(primitive, obj, robot, objects)


def _ahead(pose: Pose, gap: float) -> tuple[float, float]:
    """The point `gap` mm ahead of `pose`: exact at a docking heading, in floats at any other
    (a plan written by hand may drop at 45 degrees; the checker names that, not this)."""
    try:
        return in_front(pose, gap, pose[2])
    except ValueError:
        turn = math.radians(pose[2])
        return pose[0] + gap * math.cos(turn), pose[1] + gap * math.sin(turn)


def plan_from_actions(
    scene: Scene, robot_id: str, mission: Iterable[str | Event], actions: Iterable[Action]
) -> RobotPlan:
    """A robot plan from a list of primitives, each applied with :func:`successor`.

    Parameters
    ----------
    scene : Scene
        The scene; instant 0 is :func:`initial_state`.
    robot_id : str
        The robot.
    mission : iterable of str or Event
        The mission the plan is meant to realise.
    actions : iterable of tuple
        ``("GoTo", (x, y, heading))`` or ``(primitive, object)`` for the others.

    Returns
    -------
    RobotPlan

    Examples
    --------
    >>> plan = plan_from_actions(scene, "R2", ["pick(R2,O2)"],
    ...                          [("GoTo", (1650, -1000, 0)), ("PickUp", "O2")])  # doctest: +SKIP
    """
    state = initial_state(scene, robot_id)
    steps = []
    for action in actions:
        primitive, *rest = action
        arg = rest[0] if rest else None
        if primitive == Primitive.GOTO:
            step = successor(scene, robot_id, state, primitive, to=arg)
        else:
            step = successor(scene, robot_id, state, primitive, obj=arg)
        steps.append(step)
        state = step.state
    return RobotPlan.from_steps(mission, steps)


@dataclass(frozen=True)
class Step:
    """Instant *k* of a robot's plan: the primitive taken between *k-1* and *k*, and the state after it.

    Parameters
    ----------
    primitive : Primitive or {"GoTo", "PickUp", "DropOff", "Req", "Res"}
        The motion primitive (a name is turned into its :class:`~cosmop.events.Primitive`).
    object : str or None
        The object the primitive acts on; ``None`` for ``GoTo`` and for the ``Req``/``Res`` of
        a message.
    robot : tuple of float
        The robot's pose after the step, ``(x, y, heading)`` in mm and degrees.
    objects : Mapping[str, ObjectState]
        Every object's state after the step, by id (read-only).
    message : str, optional
        For ``Req`` (wait) and ``Res`` (send) of a message: its event ``msg(S,R,tag)``.

    Raises
    ------
    ValueError
        If the primitive is unknown, or `object` is missing (or given, for ``GoTo``), or a
        message is given to a primitive other than ``Req``/``Res`` or together with an object.
    """

    __reduce__ = reduce_frozen  # picklable for worker processes

    primitive: Primitive
    object: str | None
    robot: Pose
    objects: Mapping[str, ObjectState]
    message: str | None = None

    def __post_init__(self) -> None:
        if self.primitive not in PRIMITIVES:
            raise ValueError(f"unknown primitive {self.primitive!r}; expected one of {', '.join(PRIMITIVES)}")
        object.__setattr__(self, "primitive", Primitive(self.primitive))
        if self.message is not None:
            if self.primitive not in MESSAGE_PRIMITIVES or self.object is not None:
                raise ValueError(f"only Req and Res without an object carry a message, not {self.primitive}")
            event = parse_event(self.message)
            if event.kind != "msg":
                raise ValueError(f"a step's message is a msg(S,R,tag) event, got {self.message!r}")
            object.__setattr__(self, "message", event.name)
        elif self.primitive in OBJECT_PRIMITIVES and not self.object:
            raise ValueError(f"{self.primitive} needs the object it acts on")
        if self.primitive == Primitive.GOTO and self.object is not None:
            raise ValueError(f"GoTo acts on no object, got {self.object!r}")
        object.__setattr__(self, "robot", _floats(self.robot, 3, "a robot pose"))
        object.__setattr__(self, "objects", _object_map(self.objects))

    @property
    def label(self) -> str:
        """The primitive with its object or message: ``PickUp(O1)``, ``Req(msg(R2,R1,t))``, ``GoTo``."""
        what = self.object if self.object is not None else self.message
        return self.primitive if what is None else f"{self.primitive}({what})"

    @property
    def state(self) -> State:
        """The state after the step (pose and objects, without the primitive)."""
        return State(self.robot, self.objects)

    def to_dict(self) -> dict[str, Any]:
        """The JSON form of the step (``object`` is ``null`` for ``GoTo``; ``message`` only when set)."""
        data: dict[str, Any] = {"primitive": self.primitive, "object": self.object}
        if self.message is not None:
            data["message"] = self.message
        data["robot"] = [_num(v) for v in self.robot]
        data["objects"] = {oid: state.to_dict() for oid, state in self.objects.items()}
        return data

    def to_text(self) -> str:
        """The step as one line: primitive, robot pose, and what is carried, dropped or away."""
        x, y, heading = self.robot
        notes = []
        carried = [oid for oid, s in self.objects.items() if s.carried]
        if carried:
            notes.append("carrying " + ", ".join(carried))
        if self.primitive == Primitive.DROPOFF and self.object in self.objects:
            notes.append(f"{self.object} at {_point(self.objects[self.object].position)}")
        away = [oid for oid, s in self.objects.items() if s.away]
        if away:
            notes.append("away: " + ", ".join(away))
        text = f"{self.label:<12} robot ({_fmt(x)}, {_fmt(y)}, {_fmt(heading)}°)"
        return f"{text}  {'; '.join(notes)}" if notes else text


@dataclass(frozen=True)
class RobotPlan:
    """One robot's plan: the mission it realises and its steps, instants 1 to K.

    Parameters
    ----------
    mission : tuple of str
        The events the plan realises, in order, as canonical names (``pick(R1,O1)``,
        ``drop(R1,O1,W1)``, ``return(R1)``, ``away(O2,R1,R2)``). :class:`~cosmop.events.Event`
        values and the paper's compact names are accepted and stored canonically.
    horizon : int
        K, the number of steps.
    steps : tuple of Step
        ``steps[k-1]`` is instant *k*.

    Raises
    ------
    ValueError
        If `horizon` differs from the number of steps or a mission event cannot be parsed.
    """

    mission: tuple[str, ...]
    horizon: int
    steps: tuple[Step, ...]

    def __post_init__(self) -> None:
        names = []
        for item in self.mission:
            if isinstance(item, Event):
                names.append(item.name)
            else:
                try:
                    names.append(parse_event(item).name)
                except EventSyntaxError as err:
                    raise ValueError(str(err)) from None
        object.__setattr__(self, "mission", tuple(names))
        object.__setattr__(self, "steps", tuple(self.steps))
        if isinstance(self.horizon, bool) or not isinstance(self.horizon, int):
            raise ValueError(f"the horizon must be an integer, got {self.horizon!r}")
        if self.horizon != len(self.steps):
            raise ValueError(f"the horizon {self.horizon} differs from the number of steps {len(self.steps)}")

    @classmethod
    def from_steps(cls, mission: Iterable[str | Event], steps: Iterable[Step]) -> RobotPlan:
        """A plan whose horizon is the number of `steps`."""
        steps = tuple(steps)
        return cls(tuple(mission), len(steps), steps)

    @property
    def events(self) -> tuple[Event, ...]:
        """The mission as :class:`~cosmop.events.Event` values."""
        return tuple(parse_event(name) for name in self.mission)

    def state(self, k: int, initial: State | None = None) -> State:
        """The state at instant `k`.

        Parameters
        ----------
        k : int
            The instant, ``0 <= k <= horizon``.
        initial : State, optional
            Instant 0 (see :func:`initial_state`); required only for ``k == 0``.

        Returns
        -------
        State
            `initial` for ``k == 0``, else the state after ``steps[k-1]``.

        Raises
        ------
        IndexError
            If `k` is out of range.
        ValueError
            If ``k == 0`` and `initial` is not given.
        """
        if not 0 <= k <= self.horizon:
            raise IndexError(f"instant {k} is outside 0..{self.horizon}")
        if k == 0:
            if initial is None:
                raise ValueError("instant 0 is the scenario: pass initial=initial_state(scene, robot_id)")
            return initial
        return self.steps[k - 1].state

    def to_dict(self) -> dict[str, Any]:
        """The JSON form: ``{"mission": [...], "horizon": K, "steps": [...]}``."""
        return {
            "mission": list(self.mission),
            "horizon": self.horizon,
            "steps": [step.to_dict() for step in self.steps],
        }

    def to_text(self, times: Iterable[tuple[float, float]] | None = None) -> str:
        """The plan for people: one line per step, ``k  primitive  robot (x, y, heading°)  notes``,
        with the step's expected ``start-end`` seconds after `k` when `times` are given."""
        width = len(str(self.horizon))
        slots = [f"{a:7.1f}-{b:<7.1f}s  " for a, b in times] if times is not None else [""] * self.horizon
        return "\n".join(
            f"{k:>{width}}  {slot}{step.to_text()}"
            for k, (step, slot) in enumerate(zip(self.steps, slots, strict=True), 1)
        )


@dataclass(frozen=True)
class Coordination:
    """A request/response pair: `responder` moves `object` away for `requester`.

    The pair is the shared event ``away(object, requester, responder)``: the requester's
    ``Req(object)`` (the paper's ``?O Away``) and the responder's ``Res(object)`` (``!O Away``).
    """

    object: str
    requester: str
    responder: str

    @property
    def event(self) -> Event:
        """The shared mission event ``away(O,A,B)``."""
        return Event("away", self.requester, self.object, responder=self.responder)

    def to_dict(self) -> dict[str, str]:
        """The JSON form: ``{"object": ..., "requester": ..., "responder": ...}``."""
        return {"object": self.object, "requester": self.requester, "responder": self.responder}


@dataclass(frozen=True)
class PlanMessage:
    """A message the plans rely on: what it is, between whom, and what it protects.

    Parameters
    ----------
    event : str
        The message event ``msg(S,R,tag)`` (canonical text).
    kind : {"order", "conflict", "mission"}
        Why it exists (:data:`MESSAGE_REASONS`).
    protects : str
        In words: which step of the receiver waits for which step of the sender, and why.
    place : tuple of float, optional
        For a conflict: the bounding box ``(x_min, y_min, x_max, y_max)`` (mm) of the space
        the two robots share.
    """

    event: str
    kind: str
    protects: str
    place: tuple[float, float, float, float] | None = None

    def __post_init__(self) -> None:
        event = parse_event(self.event)
        if event.kind != "msg":
            raise ValueError(f"a planned message is a msg(S,R,tag) event, got {self.event!r}")
        if self.kind not in MESSAGE_REASONS:
            raise ValueError(f"a message's kind is one of {', '.join(MESSAGE_REASONS)}, got {self.kind!r}")
        object.__setattr__(self, "event", event.name)
        if self.place is not None:
            object.__setattr__(self, "place", _floats(self.place, 4, "a place"))

    @property
    def sender(self) -> str:
        """The robot that sends the message."""
        return parse_event(self.event).sender

    @property
    def receiver(self) -> str:
        """The robot that waits for it."""
        return parse_event(self.event).receiver

    def to_dict(self) -> dict[str, Any]:
        """The JSON form: ``{"event", "sender", "receiver", "kind", "protects"[, "place"]}``."""
        data: dict[str, Any] = {
            "event": self.event,
            "sender": self.sender,
            "receiver": self.receiver,
            "kind": self.kind,
            "protects": self.protects,
        }
        if self.place is not None:
            data["place"] = [_num(v) for v in self.place]
        return data


@dataclass(frozen=True)
class AddedTask:
    """A task no mission names, added by the planner: goods moved out of a robot's way.

    Parameters
    ----------
    robot : str
        The robot that moves them (its mission gains ``pick(robot,object)`` and
        ``drop(robot,object,workspace)``).
    object : str
        The goods that block.
    workspace : str
        The id of the place they are set down at, a point workspace of this plan file only.
    point : tuple of float
        That place, ``(x, y)`` mm: the goods' centre after the drop.
    why : str
        In words: whose way they block and why this robot moves them.
    """

    __reduce__ = reduce_frozen  # picklable for worker processes

    robot: str
    object: str
    workspace: str
    point: tuple[float, float]
    why: str

    def __post_init__(self) -> None:
        object.__setattr__(self, "point", _floats(self.point, 2, "a point"))

    @property
    def events(self) -> tuple[Event, Event]:
        """The two mission events the task adds to its robot's mission."""
        return (
            Event("pick", self.robot, self.object),
            Event("drop", self.robot, self.object, workspace=self.workspace),
        )

    def to_dict(self) -> dict[str, Any]:
        """The JSON form: ``{"robot", "object", "workspace", "point", "why"}``."""
        return {
            "robot": self.robot,
            "object": self.object,
            "workspace": self.workspace,
            "point": [_num(v) for v in self.point],
            "why": self.why,
        }


@dataclass(frozen=True)
class Itinerary:
    """When every step of a plan set is expected to start and end: the plans as a schedule.

    Times are seconds from the moment the whole team starts (every robot at instant 0 at time
    0).  A step starts when its robot's previous step ends; a ``Req`` ends when its message has
    been sent, so the waiting shows as the ``Req``'s length.  The estimates come from
    :func:`cosmop.planning.timing.itinerary`; a plan file shares them per step (``"start"``,
    ``"end"``) so that other systems can reserve space and time, as fleet traffic schedules do.

    Parameters
    ----------
    times : Mapping[str, sequence of (float, float)]
        Per robot, ``(start, end)`` of its steps, instants 1 to K in order (s).

    Raises
    ------
    ValueError
        If a time is negative or not finite, a step ends before it starts, or starts before
        its robot's previous step ends.

    Examples
    --------
    >>> it = Itinerary({"R1": [(0.0, 2.5), (2.5, 4.0)], "R2": [(0.0, 1.0)]})
    >>> it.slot("R1", 2), it.end("R1"), it.makespan
    ((2.5, 4.0), 4.0, 4.0)
    """

    __reduce__ = reduce_frozen  # picklable for worker processes

    times: Mapping[str, tuple[tuple[float, float], ...]]

    def __post_init__(self) -> None:
        times = {}
        for robot, slots in self.times.items():
            slots = tuple((float(a), float(b)) for a, b in slots)
            previous = 0.0
            for k, (a, b) in enumerate(slots, 1):
                if not (math.isfinite(a) and math.isfinite(b)) or a < 0.0:
                    raise ValueError(f"{robot}, instant {k}: times are finite seconds >= 0, got ({a}, {b})")
                if b < a or a < previous:
                    raise ValueError(
                        f"{robot}, instant {k}: a step starts after its robot's previous step ends "
                        f"({previous:g} s) and ends after it starts, got ({a:g}, {b:g})"
                    )
                previous = b
            times[robot] = slots
        object.__setattr__(self, "times", MappingProxyType(times))

    def slot(self, robot: str, k: int) -> tuple[float, float]:
        """``(start, end)`` of `robot`'s instant `k` (1..K), s."""
        if not 1 <= k <= len(self.times[robot]):
            raise IndexError(f"{robot} has no instant {k}")
        return self.times[robot][k - 1]

    def end(self, robot: str) -> float:
        """When `robot` is expected to have done its whole plan, s (0 for an empty plan)."""
        slots = self.times[robot]
        return slots[-1][1] if slots else 0.0

    @property
    def makespan(self) -> float:
        """When the whole team is expected to be done, s."""
        return max((self.end(r) for r in self.times), default=0.0)


@dataclass(frozen=True)
class PlanSet:
    """The plans of all robots for one scenario (the content of a ``cosmop.plan/1`` file).

    Parameters
    ----------
    scenario : str
        The scenario's name.
    feasible : bool
        Whether a plan was found; an infeasible plan set says why in `reason`.
    robots : Mapping[str, RobotPlan]
        Plans by robot id (read-only, in the order given).
    coordination : tuple of Coordination
        The request/response pairs the plans rely on.
    reason : str, optional
        Why no plan exists, in words a person can act on (required when not `feasible`).
    messages : tuple of PlanMessage
        The messages (``msg`` events) the plans send and wait for, with what each protects.
    allocation : Mapping[str, str], optional
        When the mission let the planner choose: the chosen robot by object (or task).
    added : tuple of AddedTask
        Tasks the planner added that no mission names (goods moved out of a robot's way).
    itinerary : Itinerary, optional
        When each step is expected to start and end (s); in the file, each step's ``start``
        and ``end``.

    Raises
    ------
    ValueError
        If `feasible` is false and no `reason` is given, or the itinerary's robots or numbers
        of steps differ from the plans'.
    """

    __reduce__ = reduce_frozen  # picklable for worker processes

    scenario: str
    feasible: bool
    robots: Mapping[str, RobotPlan] = field(default_factory=dict)
    coordination: tuple[Coordination, ...] = ()
    reason: str | None = None
    messages: tuple[PlanMessage, ...] = ()
    allocation: Mapping[str, str] = field(default_factory=dict)
    added: tuple[AddedTask, ...] = ()
    itinerary: Itinerary | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "added", tuple(self.added))
        if self.itinerary is not None:
            sizes = {r: len(slots) for r, slots in self.itinerary.times.items()}
            if sizes != {r: p.horizon for r, p in self.robots.items()}:
                raise ValueError("the itinerary must time every step of every plan, and nothing else")
        if not isinstance(self.robots, MappingProxyType):
            object.__setattr__(self, "robots", MappingProxyType(dict(self.robots)))
        object.__setattr__(self, "coordination", tuple(self.coordination))
        object.__setattr__(self, "messages", tuple(self.messages))
        object.__setattr__(self, "allocation", MappingProxyType(dict(self.allocation)))
        if not self.feasible and not self.reason:
            raise ValueError("an infeasible plan set needs a reason")

    @property
    def horizon(self) -> int:
        """The total number of steps over all robots."""
        return sum(plan.horizon for plan in self.robots.values())

    def to_dict(self) -> dict[str, Any]:
        """The JSON form of the plan file (``reason`` only when there is one)."""
        data: dict[str, Any] = {
            "format": PLAN_FORMAT,
            "scenario": self.scenario,
            "feasible": self.feasible,
            "units": dict(INTERNAL_UNITS),
        }
        if self.reason is not None:
            data["reason"] = self.reason
        data["robots"] = {robot: plan.to_dict() for robot, plan in self.robots.items()}
        if self.itinerary is not None:  # each step says when it is expected: an itinerary
            for robot, plan in data["robots"].items():
                plan["steps"] = [
                    _timed(step, slot)
                    for step, slot in zip(plan["steps"], self.itinerary.times[robot], strict=True)
                ]
        data["coordination"] = [pair.to_dict() for pair in self.coordination]
        data["messages"] = [message.to_dict() for message in self.messages]
        if self.allocation:
            data["allocation"] = dict(self.allocation)
        if self.added:
            data["added"] = [task.to_dict() for task in self.added]
        return data

    def extend(self, scenario: Scenario) -> Scenario:
        """`scenario` with the places of the added tasks as point workspaces.

        A place whose id the scenario already has is left out: the checker names that clash.
        """
        scene = scenario.scene
        new = {t.workspace: Workspace(t.workspace, point=t.point) for t in self.added}
        new = {wid: ws for wid, ws in new.items() if wid not in scene.workspaces}
        if not new:
            return scenario
        return replace(scenario, scene=replace(scene, workspaces={**scene.workspaces, **new}))

    @classmethod
    def from_dict(cls, data: Any, file: str | os.PathLike[str] | None = None) -> PlanSet:
        """Validate a plan file's content (parsed JSON) and build the plan set.

        Parameters
        ----------
        data : Any
            The parsed JSON.
        file : str or os.PathLike, optional
            The file it came from, for error messages.

        Returns
        -------
        PlanSet

        Raises
        ------
        PlanError
            If the content does not have the shape of a ``cosmop.plan/1`` file; the error
            names the file, the field and what was expected.
        """
        return _Reader(None if file is None else os.fspath(file)).plan_set(data)

    def save(self, path: str | os.PathLike[str]) -> None:
        """Write the plan file (JSON, UTF-8), atomically.

        The JSON is indented, with every list or object that fits on one line kept on one
        line (a step with few objects is one line).

        Parameters
        ----------
        path : str or os.PathLike
            The destination; its directory must exist.
        """
        write_atomic(path, _pretty(self.to_dict()) + "\n")

    def to_text(self) -> str:
        """The plan set for people: per robot a header line and one line per step."""
        lines = [f"plan for {self.scenario}: {'feasible' if self.feasible else 'infeasible'}"]
        if self.reason:
            lines.append(f"reason: {self.reason}")
        for robot, plan in self.robots.items():
            lines.append(f"{robot} ({plan.horizon} steps): {', '.join(plan.mission) or 'no mission'}")
            times = self.itinerary.times[robot] if self.itinerary is not None else None
            lines.extend("  " + line for line in plan.to_text(times).splitlines())
        for pair in self.coordination:
            lines.append(f"coordination: {pair.responder} moves {pair.object} away for {pair.requester}")
        for message in self.messages:
            lines.append(f"message {message.event} ({message.kind}): {message.protects}")
        for task in self.added:
            x, y = task.point
            lines.append(f"added: {task.robot} sets {task.object} down at ({x:g}, {y:g}): {task.why}")
        return "\n".join(lines)


def load_plan(path: str | os.PathLike[str]) -> PlanSet:
    """Read and validate a plan file (``cosmop.plan/1``, JSON).

    Parameters
    ----------
    path : str or os.PathLike
        The plan file.

    Returns
    -------
    PlanSet

    Raises
    ------
    PlanError
        If the file cannot be read, is not JSON (the line and column are given) or does not
        have the shape of a plan file; the error names the file, the field and what was expected.
    """
    file = os.fspath(path)
    text = read_text(path, PlanError, "a plan file")
    if not text.strip():
        raise PlanError("the file is empty; expected a cosmop.plan/1 JSON object", file=file)
    data = load_json(text, file, PlanError, unique_keys=True)
    return _Reader(file, text).plan_set(data)  # the text: errors say the field's line


# ----------------------------------------------------------------------------------------------
# Reading: shape validation with field paths
# ----------------------------------------------------------------------------------------------


def _describe(value: Any) -> str:
    names = {dict: "an object", list: "a list", str: "a string", bool: "a boolean", type(None): "null"}
    if type(value) in names:
        text = names[type(value)]
        return f"{text} {value!r}" if isinstance(value, str | bool) else text
    if isinstance(value, int | float):
        return f"the number {value!r}"
    return type(value).__name__


class _Reader:
    """Builds a PlanSet from parsed JSON, raising PlanError with the file and field path (and
    its line and column, given the file's `text`)."""

    def __init__(self, file: str | None, text: str | None = None) -> None:
        self.file = file
        self.text = text

    def fail(self, path: FieldPath, expected: str) -> PlanError:
        found = json_position(self.text, path) if self.text is not None and path else None
        line, column = found or (None, None)  # the whole file (path ()) has no line of its own
        return PlanError(expected, file=self.file, field=format_path(path), line=line, column=column)

    def mapping(self, value: Any, path: FieldPath, required: tuple[str, ...], optional: tuple[str, ...] = ()):
        if not isinstance(value, dict):
            raise self.fail(path, f"expected a JSON object, got {_describe(value)}")
        for key in required:
            if key not in value:
                raise self.fail(path, f"missing field {key!r}")
        allowed = required + optional
        for key in value:
            if key not in allowed:
                raise self.fail(
                    (*path, key), f"unknown field {key!r}; expected {', '.join(repr(k) for k in allowed)}"
                )
        return value

    def string(self, value: Any, path: FieldPath, what: str = "text") -> str:
        if not isinstance(value, str):
            raise self.fail(path, f"expected {what}, got {_describe(value)}")
        if (problem := unprintable(value)) is not None:  # it is printed and written on
            raise self.fail(path, problem)
        return value

    def ident(self, value: Any, path: FieldPath, what: str) -> str:
        text = self.string(value, path, f"{what} id")
        if not _ID_RE.match(text):
            raise self.fail(path, f"{text!r} is not a valid {what} id (expected {ID_PATTERN})")
        return text

    def boolean(self, value: Any, path: FieldPath) -> bool:
        if not isinstance(value, bool):
            raise self.fail(path, f"expected true or false, got {_describe(value)}")
        return value

    def number(self, value: Any, path: FieldPath) -> float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.fail(path, f"expected a number, got {_describe(value)}")
        if not math.isfinite(value):
            raise self.fail(path, f"expected a finite number, got {value!r}")
        return float(value)

    def numbers(self, value: Any, path: FieldPath, names: tuple[str, ...], units: str) -> tuple[float, ...]:
        wanted = f"a list [{', '.join(names)}] ({units})"
        if not isinstance(value, list):
            raise self.fail(path, f"expected {wanted}, got {_describe(value)}")
        if len(value) != len(names):
            raise self.fail(path, f"expected {wanted}, got {len(value)} number(s)")
        return tuple(self.number(item, (*path, i)) for i, item in enumerate(value))

    def plan_set(self, data: Any) -> PlanSet:
        if isinstance(data, dict) and "format" in data and data["format"] != PLAN_FORMAT:
            # another format (version) first: its other fields may legitimately differ
            raise self.fail(("format",), f"unknown format {data['format']!r}; expected {PLAN_FORMAT!r}")
        root = self.mapping(
            data,
            (),
            ("format", "scenario", "feasible", "robots"),
            ("coordination", "reason", "messages", "allocation", "units", "added"),
        )
        if (problem := check_units_field(root.get("units"))) is not None:
            raise self.fail(("units",), problem)
        scenario = self.string(root["scenario"], ("scenario",), "the scenario's name as text")
        feasible = self.boolean(root["feasible"], ("feasible",))
        reason = root.get("reason")
        if reason is not None:
            reason = self.string(reason, ("reason",), "text or null")
        if not feasible and not reason:
            raise self.fail(("reason",), "an infeasible plan needs a reason a person can act on")
        robots_data = root["robots"]
        if not isinstance(robots_data, dict):
            raise self.fail(
                ("robots",), f"expected a JSON object of plans by robot id, got {_describe(robots_data)}"
            )
        robots, times = {}, {}
        for robot, plan in robots_data.items():
            self.ident(robot, ("robots", robot), "robot")
            robots[robot] = self.robot_plan(plan, ("robots", robot), robot)
            times[robot] = self.slots(plan["steps"], ("robots", robot, "steps"))
        itinerary = self.itinerary(times)
        pairs_data = root.get("coordination", [])
        if not isinstance(pairs_data, list):
            raise self.fail(("coordination",), f"expected a list, got {_describe(pairs_data)}")
        pairs = tuple(self.coordination(item, ("coordination", i)) for i, item in enumerate(pairs_data))
        messages_data = root.get("messages", [])
        if not isinstance(messages_data, list):
            raise self.fail(("messages",), f"expected a list, got {_describe(messages_data)}")
        messages = tuple(self.message(item, ("messages", i)) for i, item in enumerate(messages_data))
        allocation_data = root.get("allocation", {})
        if not isinstance(allocation_data, dict):
            raise self.fail(
                ("allocation",), f"expected an object of robots by task, got {_describe(allocation_data)}"
            )
        allocation = {
            key: self.ident(value, ("allocation", key), "robot") for key, value in allocation_data.items()
        }
        added_data = root.get("added", [])
        if not isinstance(added_data, list):
            raise self.fail(("added",), f"expected a list, got {_describe(added_data)}")
        added = tuple(self.added_task(item, ("added", i)) for i, item in enumerate(added_data))
        return PlanSet(scenario, feasible, robots, pairs, reason, messages, allocation, added, itinerary)

    def slots(self, steps: list, path: FieldPath) -> tuple[tuple[float, float], ...] | None:
        """The steps' ``start`` and ``end`` (s), checked in order; None when no step has them."""
        if not steps:
            return ()
        if not any(isinstance(step, dict) and ("start" in step or "end" in step) for step in steps):
            return None
        out, previous = [], 0.0
        for i, step in enumerate(steps):
            for key in ("start", "end"):
                if key not in step:
                    raise self.fail(
                        (*path, i), f"missing field {key!r}; timed steps all have 'start' and 'end' (s)"
                    )
            start = self.number(step["start"], (*path, i, "start"))
            end = self.number(step["end"], (*path, i, "end"))
            if start < previous:
                raise self.fail(
                    (*path, i, "start"),
                    f"expected a time (s) >= {previous:g}, when the step before ends (or 0), got {start:g}",
                )
            if end < start:
                raise self.fail(
                    (*path, i, "end"), f"expected a time (s) >= the step's start {start:g}, got {end:g}"
                )
            out.append((start, end))
            previous = end
        return tuple(out)

    def itinerary(self, times: Mapping[str, tuple | None]) -> Itinerary | None:
        """The plan set's itinerary: every robot's steps timed, or none of them."""
        if not any(times.values()):  # nothing timed (a robot without steps has no times either way)
            return None
        missing = next((r for r, slots in times.items() if slots is None), None)
        if missing is not None:
            raise self.fail(
                ("robots", missing, "steps"),
                "expected 'start' and 'end' (s) on every step, as the other robots' steps have them",
            )
        return Itinerary(times)

    def added_task(self, value: Any, path: FieldPath) -> AddedTask:
        item = self.mapping(value, path, ("robot", "object", "workspace", "point", "why"))
        return AddedTask(
            self.ident(item["robot"], (*path, "robot"), "robot"),
            self.ident(item["object"], (*path, "object"), "object"),
            self.ident(item["workspace"], (*path, "workspace"), "workspace"),
            self.numbers(item["point"], (*path, "point"), ("x", "y"), "mm"),
            self.string(item["why"], (*path, "why"), "the reason, as text"),
        )

    def message(self, value: Any, path: FieldPath) -> PlanMessage:
        item = self.mapping(value, path, ("event", "kind", "protects"), ("sender", "receiver", "place"))
        text = self.string(item["event"], (*path, "event"), "a message such as 'msg(R1,R2,t1)'")
        try:
            event = parse_event(text)
        except EventSyntaxError as err:
            raise self.fail((*path, "event"), str(err)) from None
        if event.kind != "msg":
            raise self.fail((*path, "event"), f"expected a msg(SENDER,RECEIVER,TAG) event, got {event.name}")
        for key, robot in (("sender", event.sender), ("receiver", event.receiver)):
            if key in item and item[key] != robot:
                raise self.fail(
                    (*path, key), f"expected {robot!r} (from {event.name}), got {_describe(item[key])}"
                )
        kind = self.string(item["kind"], (*path, "kind"))
        if kind not in MESSAGE_REASONS:
            raise self.fail((*path, "kind"), f"expected one of {', '.join(MESSAGE_REASONS)}, got {kind!r}")
        protects = self.string(item["protects"], (*path, "protects"))
        place = item.get("place")
        if place is not None:
            place = self.numbers(place, (*path, "place"), ("x_min", "y_min", "x_max", "y_max"), "mm")
        return PlanMessage(event.name, kind, protects, place)

    def coordination(self, value: Any, path: FieldPath) -> Coordination:
        item = self.mapping(value, path, ("object", "requester", "responder"))
        obj = self.ident(item["object"], (*path, "object"), "object")
        requester = self.ident(item["requester"], (*path, "requester"), "robot")
        responder = self.ident(item["responder"], (*path, "responder"), "robot")
        if requester == responder:
            raise self.fail(
                (*path, "responder"), f"the responder must differ from the requester {requester!r}"
            )
        return Coordination(obj, requester, responder)

    def robot_plan(self, value: Any, path: FieldPath, robot: str) -> RobotPlan:
        item = self.mapping(value, path, ("mission", "horizon", "steps"))
        mission_data = item["mission"]
        if not isinstance(mission_data, list):
            raise self.fail((*path, "mission"), f"expected a list of events, got {_describe(mission_data)}")
        mission = []
        for i, text in enumerate(mission_data):
            event_path = (*path, "mission", i)
            self.string(text, event_path, "an event such as 'pick(R1,O1)'")
            try:
                mission.append(parse_event(text, robot=robot).name)
            except EventSyntaxError as err:
                raise self.fail(event_path, str(err)) from None
        horizon = item["horizon"]
        if isinstance(horizon, bool) or not isinstance(horizon, int) or horizon < 0:
            raise self.fail((*path, "horizon"), f"expected a non-negative integer, got {_describe(horizon)}")
        steps_data = item["steps"]
        if not isinstance(steps_data, list):
            raise self.fail((*path, "steps"), f"expected a list of steps, got {_describe(steps_data)}")
        if len(steps_data) > MAX_STEPS:
            raise self.fail((*path, "steps"), f"{len(steps_data)} steps; a plan has at most {MAX_STEPS:,}")
        if horizon != len(steps_data):
            raise self.fail(
                (*path, "horizon"),
                f"the horizon is {horizon} but there are {len(steps_data)} steps; they must be equal",
            )
        steps = tuple(self.step(s, (*path, "steps", i)) for i, s in enumerate(steps_data))
        return RobotPlan(tuple(mission), horizon, steps)

    def step(self, value: Any, path: FieldPath) -> Step:
        item = self.mapping(
            value, path, ("primitive", "robot", "objects"), ("object", "message", "start", "end")
        )
        primitive = item["primitive"]
        if primitive not in PRIMITIVES:
            raise self.fail(
                (*path, "primitive"),
                f"unknown primitive {_describe(primitive)}; expected one of {', '.join(PRIMITIVES)}",
            )
        obj = item.get("object")
        message = self.step_message(item, path, primitive)
        if primitive == Primitive.GOTO or message is not None:
            if obj is not None:
                what = (
                    "GoTo acts on no object"
                    if message is None
                    else f"{primitive} of a message names no object"
                )
                raise self.fail((*path, "object"), f"{what}; expected null, got {_describe(obj)}")
        else:
            if obj is None:
                raise self.fail((*path, "object"), f"{primitive} needs the id of the object it acts on")
            self.ident(obj, (*path, "object"), "object")
        robot = self.numbers(item["robot"], (*path, "robot"), ("x", "y", "heading"), "mm, mm, degrees")
        objects_data = item["objects"]
        if not isinstance(objects_data, dict):
            raise self.fail(
                (*path, "objects"),
                f"expected a JSON object of object states by id, got {_describe(objects_data)}",
            )
        objects = {}
        for oid, state in objects_data.items():
            state_path = (*path, "objects", oid)
            self.ident(oid, state_path, "object")
            fields = self.mapping(state, state_path, ("position", "carried", "away"))
            objects[oid] = ObjectState(
                self.numbers(fields["position"], (*state_path, "position"), ("x", "y"), "mm"),
                self.boolean(fields["carried"], (*state_path, "carried")),
                self.boolean(fields["away"], (*state_path, "away")),
            )
        if obj is not None and obj not in objects:
            listed = ", ".join(objects) or "none"
            raise self.fail((*path, "object"), f"{obj!r} is not among the step's objects ({listed})")
        return Step(primitive, obj, robot, objects, message)

    def step_message(self, item: dict, path: FieldPath, primitive: str) -> str | None:
        """The step's ``message`` (a msg event of a Req or Res), or None."""
        message = item.get("message")
        if message is None:
            return None
        if primitive not in MESSAGE_PRIMITIVES:
            raise self.fail((*path, "message"), f"only Req and Res carry a message, not {primitive}")
        text = self.string(message, (*path, "message"), "a message such as 'msg(R1,R2,t1)'")
        try:
            event = parse_event(text)
        except EventSyntaxError as err:
            raise self.fail((*path, "message"), str(err)) from None
        if event.kind != "msg":
            raise self.fail(
                (*path, "message"), f"expected a msg(SENDER,RECEIVER,TAG) event, got {event.name}"
            )
        return event.name


# ----------------------------------------------------------------------------------------------
# Formatting
# ----------------------------------------------------------------------------------------------


def _pretty(value: Any, level: int = 0, width: int = 100) -> str:
    """JSON indented by two spaces, with every value that fits in `width` columns on one line."""
    compact = json.dumps(value, ensure_ascii=False, separators=(", ", ": "))
    if not isinstance(value, dict | list) or not value or len(compact) + 2 * level <= width:
        return compact
    pad, end = "  " * (level + 1), "  " * level
    if isinstance(value, dict):
        items = [
            f"{pad}{json.dumps(key, ensure_ascii=False)}: {_pretty(item, level + 1, width)}"
            for key, item in value.items()
        ]
        return "{\n" + ",\n".join(items) + "\n" + end + "}"
    items = [pad + _pretty(item, level + 1, width) for item in value]
    return "[\n" + ",\n".join(items) + "\n" + end + "]"


def _timed(step: dict[str, Any], slot: tuple[float, float]) -> dict[str, Any]:
    """A step's JSON form with its expected ``start`` and ``end`` (s) after what it does."""
    head = {key: step[key] for key in ("primitive", "object", "message") if key in step}
    return {**head, "start": _num(slot[0]), "end": _num(slot[1]), **step}


def _num(value: float) -> int | float:
    """A JSON number: integral values as integers (``-2000``, not ``-2000.0``)."""
    if float(value).is_integer() and abs(value) < 2**53:
        return int(value)
    return float(value)


def _fmt(value: float) -> str:
    """A coordinate for people: ``-2000``, ``12.5`` (integers without a point, others exactly)."""
    value = float(value)
    if value.is_integer():
        return str(int(value))
    return repr(value)


def _point(point: Iterable[float]) -> str:
    return "(" + ", ".join(_fmt(v) for v in point) + ")"
