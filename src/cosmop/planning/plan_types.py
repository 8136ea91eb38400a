"""Plans as values: every robot's steps and the states they lead to, and the plan set of a team.

A plan set (:class:`PlanSet`, the content of a plan file ``cosmop.plan/1``,
:mod:`cosmop.planning.plan_file`) holds, for every robot, a :class:`RobotPlan`: a sequence of
motion primitives, each a :class:`Step` with the state after it (the paper's trace
:math:`q(1), \\dots, q(K)`; instant 0 is the scenario,
:func:`~cosmop.planning.primitive_effects.initial_state`).
A :class:`State` is the robot's pose ``(x, y, heading)`` (mm, degrees) and every object's
:class:`ObjectState`: its centre (mm), whether this robot carries it, and whether another robot
has moved it away.  Besides the plans: the request/response pairs (:class:`Coordination`), the
messages the plans send and wait for (:class:`PlanMessage`), the tasks the planner added
(:class:`AddedTask`) and when each step is expected to start and end (:class:`Itinerary`).

The values are immutable and check their own consistency (a step's primitive and object, a
plan's horizon); whether a plan is *sound* for a scene (walls, poses, flags, mission) is the
business of :mod:`cosmop.planning.checker`.  What the primitives do to a state is in
:mod:`cosmop.planning.primitive_effects`.
"""

from __future__ import annotations

import math
import os
from collections.abc import ItemsView, Iterable, Iterator, KeysView, Mapping, ValuesView
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Any

from cosmop._frozen import reduce_frozen
from cosmop.events import Event, Primitive
from cosmop.io import compact_json, write_atomic
from cosmop.scene import Scenario, Workspace
from cosmop.units import INTERNAL_UNITS

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
    "ObjectStates",
    "PlanMessage",
    "PlanSet",
    "Point",
    "Pose",
    "RobotPlan",
    "State",
    "Step",
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

Pose = tuple[float, float, float]
"""A robot's pose ``(x, y, heading)``: mm, mm, degrees."""

Point = tuple[float, float]
"""A point ``(x, y)``, mm."""


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


class ObjectStates(Mapping[str, "ObjectState"]):
    """Every object's :class:`ObjectState` at one instant, by id: read-only, checked once.

    Each step of a plan lists every object of the scene (a warehouse holds thousands of goods),
    and most steps change none: a step or state given an ``ObjectStates`` keeps it as it is
    instead of copying and checking it again.

    Parameters
    ----------
    states : Mapping[str, ObjectState] or iterable of (str, ObjectState)
        The objects' states.

    Raises
    ------
    TypeError
        If a value is not an :class:`ObjectState`.
    """

    __slots__ = ("_states",)

    def __init__(self, states: Mapping[str, ObjectState] | Iterable[tuple[str, ObjectState]] = ()) -> None:
        table = dict(states)
        for name, state in table.items():
            if not isinstance(state, ObjectState):
                raise TypeError(f"object {name!r}: expected an ObjectState, got {type(state).__name__}")
        self._states = table

    @classmethod
    def of(cls, states: Mapping[str, ObjectState]) -> ObjectStates:
        """`states` as an ``ObjectStates``: itself when it is one (already checked), else checked.

        Parameters
        ----------
        states : Mapping[str, ObjectState]
            The objects' states.
        """
        return states if isinstance(states, ObjectStates) else cls(states)

    def updated(self, changes: Mapping[str, ObjectState]) -> ObjectStates:
        """These states with `changes` (only they are checked again).

        Parameters
        ----------
        changes : Mapping[str, ObjectState]
            New states of some objects.
        """
        if not changes:
            return self
        out = ObjectStates(changes)
        out._states = {**self._states, **out._states}
        return out

    def __getitem__(self, name: str) -> ObjectState:
        return self._states[name]

    # the dictionary's own views and lookups: thousands of objects are read at a time
    def get(self, name: str, default: Any = None) -> Any:
        """The state of object `name`, or `default` when the map has none.

        Parameters
        ----------
        name : str
            The object's id.
        default : object, optional
            What to answer for an unknown id.
        """
        return self._states.get(name, default)

    def keys(self) -> KeysView[str]:
        return self._states.keys()

    def values(self) -> ValuesView[ObjectState]:
        return self._states.values()

    def items(self) -> ItemsView[str, ObjectState]:
        return self._states.items()

    def __iter__(self) -> Iterator[str]:
        return iter(self._states)

    def __len__(self) -> int:
        return len(self._states)

    def __contains__(self, name: object) -> bool:
        return name in self._states

    def __eq__(self, other: object) -> bool:
        if isinstance(other, ObjectStates):
            return self is other or self._states == other._states
        if not isinstance(other, Mapping):
            return NotImplemented
        return self._states == dict(other)

    __hash__ = None  # type: ignore[assignment]  # like a dict: equal by content, not hashable

    def __repr__(self) -> str:
        return f"ObjectStates({self._states!r})"

    def __reduce__(self) -> tuple[Any, ...]:
        return (ObjectStates, (self._states,))


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
        object.__setattr__(self, "objects", ObjectStates.of(self.objects))


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
    message : Event, optional
        For ``Req`` (wait) and ``Res`` (send) of a message: its event ``msg(S,R,tag)``.

    Raises
    ------
    ValueError
        If the primitive is unknown, or `object` is missing (or given, for ``GoTo``), or a
        message is given to a primitive other than ``Req``/``Res`` or together with an object,
        or is not a ``msg`` event.
    TypeError
        If the message is not an :class:`~cosmop.events.Event` (text is parsed where it is
        read, with :func:`~cosmop.events.parse_event`).
    """

    __reduce__ = reduce_frozen  # picklable for worker processes

    primitive: Primitive
    object: str | None
    robot: Pose
    objects: Mapping[str, ObjectState]
    message: Event | None = None

    def __post_init__(self) -> None:
        if self.primitive not in PRIMITIVES:
            raise ValueError(f"unknown primitive {self.primitive!r}; expected one of {', '.join(PRIMITIVES)}")
        object.__setattr__(self, "primitive", Primitive(self.primitive))
        if self.message is not None:
            if self.primitive not in MESSAGE_PRIMITIVES or self.object is not None:
                raise ValueError(f"only Req and Res without an object carry a message, not {self.primitive}")
            if not isinstance(self.message, Event):
                raise TypeError(f"a step's message is an Event, got {self.message!r}")
            if self.message.kind != "msg":
                raise ValueError(f"a step's message is a msg(S,R,tag) event, got {self.message.name}")
        elif self.primitive in OBJECT_PRIMITIVES and not self.object:
            raise ValueError(f"{self.primitive} needs the object it acts on")
        if self.primitive == Primitive.GOTO and self.object is not None:
            raise ValueError(f"GoTo acts on no object, got {self.object!r}")
        object.__setattr__(self, "robot", _floats(self.robot, 3, "a robot pose"))
        object.__setattr__(self, "objects", ObjectStates.of(self.objects))

    @property
    def label(self) -> str:
        """The primitive with its object or message: ``PickUp(O1)``, ``Req(msg(R2,R1,t))``, ``GoTo``."""
        what = self.object if self.message is None else self.message.name
        return self.primitive if what is None else f"{self.primitive}({what})"

    @property
    def state(self) -> State:
        """The state after the step (pose and objects, without the primitive)."""
        return State(self.robot, self.objects)

    def to_dict(self) -> dict[str, Any]:
        """The JSON form of the step (``object`` is ``null`` for ``GoTo``; ``message`` only when set)."""
        data: dict[str, Any] = {"primitive": self.primitive, "object": self.object}
        if self.message is not None:
            data["message"] = self.message.name
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
        if self.primitive == Primitive.DROPOFF and self.object is not None and self.object in self.objects:
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
    mission : tuple of Event
        The events the plan realises, in order (in a plan file: their canonical names,
        ``pick(R1,O1)``, ``drop(R1,O1,W1)``, ``return(R1)``, ``away(O2,R1,R2)``).
    horizon : int
        K, the number of steps.
    steps : tuple of Step
        ``steps[k-1]`` is instant *k*.

    Raises
    ------
    ValueError
        If `horizon` differs from the number of steps.
    TypeError
        If a mission item is not an :class:`~cosmop.events.Event` (text is parsed where it is
        read, with :func:`~cosmop.events.parse_event`).
    """

    mission: tuple[Event, ...]
    horizon: int
    steps: tuple[Step, ...]

    def __post_init__(self) -> None:
        object.__setattr__(self, "mission", tuple(self.mission))
        for item in self.mission:
            if not isinstance(item, Event):
                raise TypeError(f"a plan's mission holds Event values, got {item!r}")
        object.__setattr__(self, "steps", tuple(self.steps))
        if isinstance(self.horizon, bool) or not isinstance(self.horizon, int):
            raise ValueError(f"the horizon must be an integer, got {self.horizon!r}")
        if self.horizon != len(self.steps):
            raise ValueError(f"the horizon {self.horizon} differs from the number of steps {len(self.steps)}")

    @classmethod
    def from_steps(cls, mission: Iterable[Event], steps: Iterable[Step]) -> RobotPlan:
        """A plan whose horizon is the number of `steps`.

        Parameters
        ----------
        mission : iterable of Event
            The events the plan realises.
        steps : iterable of Step
            Instants 1 to K.
        """
        steps = tuple(steps)
        return cls(tuple(mission), len(steps), steps)

    @property
    def word(self) -> tuple[str, ...]:
        """The mission as the top-down layer's automata read it: the events' names (their
        letters)."""
        return tuple(event.name for event in self.mission)

    def state(self, k: int, initial: State | None = None) -> State:
        """The state at instant `k`.

        Parameters
        ----------
        k : int
            The instant, ``0 <= k <= horizon``.
        initial : State, optional
            Instant 0 (see :func:`~cosmop.planning.primitive_effects.initial_state`); required only
            for ``k == 0``.

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
            "mission": [event.name for event in self.mission],
            "horizon": self.horizon,
            "steps": [step.to_dict() for step in self.steps],
        }

    def to_text(self, times: Iterable[tuple[float, float]] | None = None) -> str:
        """The plan for people: one line per step, ``k  primitive  robot (x, y, heading°)  notes``,
        with the step's expected ``start-end`` seconds after `k` when `times` are given.

        Parameters
        ----------
        times : iterable of (float, float), optional
            Each step's expected ``(start, end)``, s (:attr:`Itinerary.times`).
        """
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
    event : Event
        The message event ``msg(S,R,tag)``.
    kind : {"order", "conflict", "mission"}
        Why it exists (:data:`MESSAGE_REASONS`).
    protects : str
        In words: which step of the receiver waits for which step of the sender, and why.
    place : tuple of float, optional
        For a conflict: the bounding box ``(x_min, y_min, x_max, y_max)`` (mm) of the space
        the two robots share.
    """

    event: Event
    kind: str
    protects: str
    place: tuple[float, float, float, float] | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.event, Event):
            raise TypeError(f"a planned message's event is an Event, got {self.event!r}")
        if self.event.kind != "msg":
            raise ValueError(f"a planned message is a msg(S,R,tag) event, got {self.event.name}")
        if self.kind not in MESSAGE_REASONS:
            raise ValueError(f"a message's kind is one of {', '.join(MESSAGE_REASONS)}, got {self.kind!r}")
        if self.place is not None:
            object.__setattr__(self, "place", _floats(self.place, 4, "a place"))

    @property
    def sender(self) -> str:
        """The robot that sends the message."""
        sender = self.event.sender
        assert sender is not None  # a msg event names its sender
        return sender

    @property
    def receiver(self) -> str:
        """The robot that waits for it."""
        receiver = self.event.receiver
        assert receiver is not None  # a msg event names its receiver
        return receiver

    def to_dict(self) -> dict[str, Any]:
        """The JSON form: ``{"event", "sender", "receiver", "kind", "protects"[, "place"]}``."""
        data: dict[str, Any] = {
            "event": self.event.name,
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
    :func:`cosmop.team.timing.itinerary`; a plan file shares them per step (``"start"``,
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
        """``(start, end)`` of `robot`'s instant `k` (1..K), s.

        Parameters
        ----------
        robot : str
            The robot's id.
        k : int
            The instant, 1 to K.
        """
        if not 1 <= k <= len(self.times[robot]):
            raise IndexError(f"{robot} has no instant {k}")
        return self.times[robot][k - 1]

    def end(self, robot: str) -> float:
        """When `robot` is expected to have done its whole plan, s (0 for an empty plan).

        Parameters
        ----------
        robot : str
            The robot's id.
        """
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

        Parameters
        ----------
        scenario : Scenario
            The scenario the plans are for.
        """
        scene = scenario.scene
        new = {t.workspace: Workspace(t.workspace, point=t.point) for t in self.added}
        new = {wid: ws for wid, ws in new.items() if wid not in scene.workspaces}
        if not new:
            return scenario
        return replace(scenario, scene=replace(scene, workspaces={**scene.workspaces, **new}))

    def save(self, path: str | os.PathLike[str]) -> None:
        """Write the plan file (JSON, UTF-8), atomically.

        The JSON is indented, with every list or object that fits on one line kept on one
        line (a step with few objects is one line).

        Parameters
        ----------
        path : str or os.PathLike
            The destination; its directory must exist.
        """
        write_atomic(path, compact_json(self.to_dict()) + "\n")

    def to_text(self) -> str:
        """The plan set for people: per robot a header line and one line per step."""
        lines = [f"plan for {self.scenario}: {'feasible' if self.feasible else 'infeasible'}"]
        if self.reason:
            lines.append(f"reason: {self.reason}")
        for robot, plan in self.robots.items():
            lines.append(
                f"{robot} ({plan.horizon} steps): {', '.join(e.name for e in plan.mission) or 'no mission'}"
            )
            times = self.itinerary.times[robot] if self.itinerary is not None else None
            lines.extend("  " + line for line in plan.to_text(times).splitlines())
        for pair in self.coordination:
            lines.append(f"coordination: {pair.responder} moves {pair.object} away for {pair.requester}")
        for message in self.messages:
            lines.append(f"message {message.event.name} ({message.kind}): {message.protects}")
        for task in self.added:
            x, y = task.point
            lines.append(f"added: {task.robot} sets {task.object} down at ({x:g}, {y:g}): {task.why}")
        return "\n".join(lines)


# ----------------------------------------------------------------------------------------------
# Formatting
# ----------------------------------------------------------------------------------------------


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
