"""The plan file ``cosmop.plan/1``: reading it into a :class:`~cosmop.planning.plan_types.PlanSet`
and writing one.

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
set's :class:`~cosmop.planning.plan_types.Itinerary`.  ``units`` (absent in older files) is
:data:`cosmop.units.INTERNAL_UNITS`.  An infeasible scenario still has a plan file, with
``"feasible": false`` and a ``"reason"``.

:func:`load_plan` and :func:`read_plan` check the file's structure (the pydantic
models below, :data:`STRUCTURE`), then its consistency (events, horizons, objects, times), and
raise :class:`PlanError` as one line naming the file, the field and what was expected and
found (``plan.json: robots.R1.steps[3].primitive: expected one of GoTo, PickUp, DropOff, Req,
Res, got 'Fly' (line 40, column 24)``).

Whether a plan is *sound* for a scene (walls, poses, flags, mission) is the business of
:mod:`cosmop.planning.checker`.  :meth:`PlanSet.save
<cosmop.planning.plan_types.PlanSet.save>` writes the file.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from typing import Annotated, Any, Literal, NoReturn

from pydantic import AfterValidator, BaseModel, BeforeValidator, ConfigDict, Field, with_config
from typing_extensions import TypedDict

from cosmop.errors import CosmopInputError, EventSyntaxError
from cosmop.events import ID_PATTERN, Event, Primitive, parse_event
from cosmop.io import read_text
from cosmop.planning.plan_types import (
    MAX_STEPS,
    MESSAGE_PRIMITIVES,
    PLAN_FORMAT,
    AddedTask,
    Coordination,
    Itinerary,
    ObjectState,
    PlanMessage,
    PlanSet,
    RobotPlan,
    Step,
)
from cosmop.reading import FieldPath, Structure, load_json, printable, show
from cosmop.units import check_units_field

__all__ = [
    "STRUCTURE",
    "AddedTaskModel",
    "CoordinationModel",
    "MessageModel",
    "ObjectStateModel",
    "PlanError",
    "PlanFileModel",
    "RobotPlanModel",
    "StepModel",
    "load_plan",
    "read_plan",
]


class PlanError(CosmopInputError):
    """A plan file (or plan mapping) that cannot be read or does not have the expected shape."""


# ----------------------------------------------------------------------------------------------
# The structure
# ----------------------------------------------------------------------------------------------


def _refuse_null(value: Any) -> Any:
    """A key given means a value: ``"start": null`` is a mistake, not "no time"."""
    if value is None:
        raise ValueError("null where a value was expected")
    return value


_Number = Annotated[float, Field(strict=True, allow_inf_nan=False)]
_Text = Annotated[str, Field(strict=True), AfterValidator(printable)]
_Id = Annotated[str, Field(strict=True, pattern=f"^(?:{ID_PATTERN})$")]
_Flag = Annotated[bool, Field(strict=True)]
_Time = Annotated[_Number | None, BeforeValidator(_refuse_null)]
_Robot = Annotated[_Id | None, BeforeValidator(_refuse_null)]
_PrimitiveName = Literal["GoTo", "PickUp", "DropOff", "Req", "Res"]  # PRIMITIVES, in their order
_MessageKind = Literal["order", "conflict", "mission"]  # MESSAGE_REASONS


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


@with_config(ConfigDict(extra="forbid"))
class ObjectStateModel(TypedDict):
    """An object's state in a step: ``{"position": [x, y], "carried": bool, "away": bool}``.

    A TypedDict, not a model: a plan file holds one per object per step, and a dict is validated
    in less than half the time of a model instance.
    """

    position: tuple[_Number, _Number]
    carried: _Flag
    away: _Flag


class StepModel(_Model):
    """A step: its primitive, what it acts on, its times, and the state after it."""

    primitive: _PrimitiveName
    object: _Id | None = None
    message: _Text | None = None
    start: _Time = None
    end: _Time = None
    robot: tuple[_Number, _Number, _Number]
    objects: dict[_Id, ObjectStateModel]


class RobotPlanModel(_Model):
    """One robot's plan: ``{"mission": [...], "horizon": K, "steps": [...]}``."""

    mission: list[_Text]
    horizon: Annotated[int, Field(strict=True, ge=0)]
    steps: Annotated[list[StepModel], Field(max_length=MAX_STEPS)]


class CoordinationModel(_Model):
    """A request/response pair: ``{"object", "requester", "responder"}``."""

    object: _Id
    requester: _Id
    responder: _Id


class MessageModel(_Model):
    """A planned message: ``{"event", "sender", "receiver", "kind", "protects"[, "place"]}``."""

    event: _Text
    sender: _Robot = None
    receiver: _Robot = None
    kind: _MessageKind
    protects: _Text
    place: tuple[_Number, _Number, _Number, _Number] | None = None


class AddedTaskModel(_Model):
    """A task the planner added: ``{"robot", "object", "workspace", "point", "why"}``."""

    robot: _Id
    object: _Id
    workspace: _Id
    point: tuple[_Number, _Number]
    why: _Text


class PlanFileModel(_Model):
    """The whole plan file."""

    format: Literal["cosmop.plan/1"]  # PLAN_FORMAT
    scenario: _Text
    feasible: _Flag
    units: Any = None  # cosmop.units.check_units_field says what it must be
    reason: _Text | None = None
    robots: dict[_Id, RobotPlanModel]
    coordination: list[CoordinationModel] = []
    messages: list[MessageModel] = []
    allocation: dict[str, _Id] = {}
    added: list[AddedTaskModel] = []


_ROBOT_ID = f"a robot id ({ID_PATTERN})"
_OBJECT_ID = f"an object id ({ID_PATTERN})"
_STEP = ("robots", "*", "steps", "#")
_STATE = (*_STEP, "objects", "*")

EXPECTED: dict[tuple[str, ...], str] = {
    (): f"a JSON object with keys format, scenario, feasible, robots (a {PLAN_FORMAT} file)",
    ("format",): f"{PLAN_FORMAT!r}, the plan file format",
    ("scenario",): "the scenario's name (text)",
    ("feasible",): "true or false (whether a plan was found)",
    ("reason",): "why no plan exists (text), or null",
    ("robots",): "a mapping from robot ids to plans {mission, horizon, steps}",
    ("robots", "*", "[key]"): _ROBOT_ID,
    ("robots", "*"): "a plan {mission, horizon, steps}",
    ("robots", "*", "mission"): "a list of events such as 'pick(R1,O1)'",
    ("robots", "*", "mission", "#"): "an event such as 'pick(R1,O1)' (text)",
    ("robots", "*", "horizon"): "the number of steps, an integer >= 0",
    ("robots", "*", "steps"): f"a list of at most {MAX_STEPS:,} steps",
    _STEP: "a step {primitive, object, robot, objects}",
    (*_STEP, "primitive"): "one of GoTo, PickUp, DropOff, Req, Res",
    (*_STEP, "object"): f"{_OBJECT_ID}, or null",
    (*_STEP, "message"): "a message such as 'msg(R1,R2,t1)', or null",
    (*_STEP, "start"): "a time in seconds (the step's expected start)",
    (*_STEP, "end"): "a time in seconds (the step's expected end)",
    (*_STEP, "robot"): "a list [x, y, heading] (mm, mm, degrees)",
    (*_STEP, "robot", "#"): "a finite number",
    (*_STEP, "objects"): "a mapping from object ids to states {position, carried, away}",
    (*_STATE, "[key]"): _OBJECT_ID,
    _STATE: "an object state {position, carried, away}",
    (*_STATE, "position"): "a list [x, y] (mm)",
    (*_STATE, "position", "#"): "a finite number (mm)",
    (*_STATE, "carried"): "true or false (whether this robot carries it)",
    (*_STATE, "away"): "true or false (whether another robot has moved it away)",
    ("coordination",): "a list of pairs {object, requester, responder}",
    ("coordination", "#"): "a pair {object, requester, responder}",
    ("coordination", "#", "object"): _OBJECT_ID,
    ("coordination", "#", "requester"): _ROBOT_ID,
    ("coordination", "#", "responder"): _ROBOT_ID,
    ("messages",): "a list of messages {event, kind, protects}",
    ("messages", "#"): "a message {event, sender, receiver, kind, protects, place}",
    ("messages", "#", "event"): "a message such as 'msg(R1,R2,t1)'",
    ("messages", "#", "sender"): _ROBOT_ID,
    ("messages", "#", "receiver"): _ROBOT_ID,
    ("messages", "#", "kind"): "one of order, conflict, mission",
    ("messages", "#", "protects"): "what the message protects, in words (text)",
    ("messages", "#", "place"): "a box [x_min, y_min, x_max, y_max] (mm), or null",
    ("messages", "#", "place", "#"): "a finite number (mm)",
    ("allocation",): "a mapping from tasks to robot ids",
    ("allocation", "*"): _ROBOT_ID,
    ("added",): "a list of added tasks {robot, object, workspace, point, why}",
    ("added", "#"): "an added task {robot, object, workspace, point, why}",
    ("added", "#", "robot"): _ROBOT_ID,
    ("added", "#", "object"): _OBJECT_ID,
    ("added", "#", "workspace"): f"a workspace id ({ID_PATTERN})",
    ("added", "#", "point"): "a point [x, y] (mm)",
    ("added", "#", "point", "#"): "a finite number (mm)",
    ("added", "#", "why"): "the reason, in words (text)",
}
"""What each field of a plan file expects, in words (patterns as :class:`cosmop.reading.Structure`'s)."""

STRUCTURE = Structure(PlanFileModel, EXPECTED, PlanError)
"""The plan file's structure: its model, its words, and :class:`PlanError`."""


# ----------------------------------------------------------------------------------------------
# Reading
# ----------------------------------------------------------------------------------------------


class _PlanReader:
    """Builds a PlanSet from parsed JSON: the structure first, then what the structure cannot say
    (events, horizons, objects, times); every error names the file and the field (and its line
    and column, given the file's `text`)."""

    def __init__(self, file: str | None, text: str | None = None) -> None:
        self.file = file
        self.text = text

    def fail(self, path: FieldPath, problem: str) -> NoReturn:
        raise STRUCTURE.fail(path, problem, self.file, self.text)

    def plan_set(self, data: Any) -> PlanSet:
        if isinstance(data, Mapping) and "format" in data and data["format"] != PLAN_FORMAT:
            # another format (version) first: its other fields may legitimately differ
            self.fail(("format",), f"expected {EXPECTED[('format',)]}, got {show(data['format'])}")
        model: PlanFileModel = STRUCTURE.validate(data, self.file, self.text)
        if (problem := check_units_field(model.units)) is not None:
            self.fail(("units",), problem)
        if not model.feasible and not model.reason:
            got = show(model.reason) if "reason" in model.model_fields_set else "nothing"
            self.fail(
                ("reason",), f"expected a reason a person can act on (the plan is infeasible), got {got}"
            )
        robots, times = {}, {}
        for robot, plan in model.robots.items():
            robots[robot] = self.robot_plan(plan, ("robots", robot), robot)
            times[robot] = self.slots(plan.steps, ("robots", robot, "steps"))
        itinerary = self.itinerary(times)
        pairs = tuple(
            self.coordination(pair, ("coordination", i)) for i, pair in enumerate(model.coordination)
        )
        messages = tuple(self.message(item, ("messages", i)) for i, item in enumerate(model.messages))
        added = tuple(
            AddedTask(task.robot, task.object, task.workspace, task.point, task.why) for task in model.added
        )
        return PlanSet(
            model.scenario,
            model.feasible,
            robots,
            pairs,
            model.reason,
            messages,
            dict(model.allocation),
            added,
            itinerary,
        )

    def robot_plan(self, plan: RobotPlanModel, path: FieldPath, robot: str) -> RobotPlan:
        mission = []
        for i, text in enumerate(plan.mission):
            try:
                mission.append(parse_event(text, robot=robot))
            except EventSyntaxError as err:
                self.fail((*path, "mission", i), str(err))
        if plan.horizon != len(plan.steps):
            self.fail(
                (*path, "horizon"), f"expected the number of steps, {len(plan.steps)}, got {plan.horizon}"
            )
        steps = tuple(self.step(step, (*path, "steps", i)) for i, step in enumerate(plan.steps))
        return RobotPlan(tuple(mission), plan.horizon, steps)

    def step(self, step: StepModel, path: FieldPath) -> Step:
        primitive = Primitive(step.primitive)
        message = self.step_message(step, path, primitive)
        obj = step.object
        if primitive == Primitive.GOTO or message is not None:
            if obj is not None:
                what = (
                    "GoTo acts on no object"
                    if message is None
                    else f"{primitive} of a message names no object"
                )
                self.fail((*path, "object"), f"expected null ({what}), got {show(obj)}")
        elif obj is None:
            got = show(None) if "object" in step.model_fields_set else "nothing"
            self.fail((*path, "object"), f"expected the id of the object {primitive} acts on, got {got}")
        objects = {
            oid: ObjectState(s["position"], s["carried"], s["away"]) for oid, s in step.objects.items()
        }
        if obj is not None and obj not in objects:
            listed = ", ".join(objects) or "none"
            self.fail((*path, "object"), f"expected one of the step's objects ({listed}), got {obj!r}")
        return Step(primitive, obj, step.robot, objects, message)

    def step_message(self, step: StepModel, path: FieldPath, primitive: Primitive) -> Event | None:
        """The step's ``message`` (a msg event of a Req or Res), or None."""
        if step.message is None:
            return None
        if primitive not in MESSAGE_PRIMITIVES:
            self.fail(
                (*path, "message"),
                f"expected no message (only Req and Res carry one), got {show(step.message)}",
            )
        return self.msg_event(step.message, (*path, "message"))

    def msg_event(self, text: str, path: FieldPath) -> Event:
        """The message event `text` (``msg(S,R,tag)``)."""
        try:
            event = parse_event(text)
        except EventSyntaxError as err:
            self.fail(path, str(err))
        if event.kind != "msg":
            self.fail(path, f"expected a msg(SENDER,RECEIVER,TAG) event, got {event.name}")
        return event

    def slots(self, steps: list[StepModel], path: FieldPath) -> tuple[tuple[float, float], ...] | None:
        """The steps' ``start`` and ``end`` (s), checked in order; None when no step has them."""
        if not steps:
            return ()
        if all(step.start is None and step.end is None for step in steps):
            return None
        out, previous = [], 0.0
        for i, step in enumerate(steps):
            start, end = step.start, step.end
            if start is None or end is None:
                self.fail(
                    (*path, i, "start" if start is None else "end"),
                    f"missing required key {'start' if start is None else 'end'!r}: expected a time (s); "
                    "timed steps all have 'start' and 'end'",
                )
            if start < previous:
                self.fail(
                    (*path, i, "start"),
                    f"expected a time (s) >= {previous:g}, when the step before ends (or 0), got {start:g}",
                )
            if end < start:
                self.fail(
                    (*path, i, "end"), f"expected a time (s) >= the step's start {start:g}, got {end:g}"
                )
            out.append((start, end))
            previous = end
        return tuple(out)

    def itinerary(self, times: Mapping[str, tuple[tuple[float, float], ...] | None]) -> Itinerary | None:
        """The plan set's itinerary: every robot's steps timed, or none of them."""
        if not any(times.values()):  # nothing timed (a robot without steps has no times either way)
            return None
        missing = next((r for r, slots in times.items() if slots is None), None)
        if missing is not None:
            self.fail(
                ("robots", missing, "steps"),
                "expected 'start' and 'end' (s) on every step, as the other robots' steps have them, "
                "got steps without them",
            )
        return Itinerary({robot: slots or () for robot, slots in times.items()})

    def coordination(self, pair: CoordinationModel, path: FieldPath) -> Coordination:
        if pair.requester == pair.responder:
            self.fail(
                (*path, "responder"),
                f"expected a robot other than the requester {pair.requester!r}, got {pair.responder!r}",
            )
        return Coordination(pair.object, pair.requester, pair.responder)

    def message(self, item: MessageModel, path: FieldPath) -> PlanMessage:
        event = self.msg_event(item.event, (*path, "event"))
        for key, robot, given in (
            ("sender", event.sender, item.sender),
            ("receiver", event.receiver, item.receiver),
        ):
            if given is not None and given != robot:
                self.fail((*path, key), f"expected {robot!r} (from {event.name}), got {show(given)}")
        return PlanMessage(event, item.kind, item.protects, item.place)


def read_plan(data: Any, file: str | os.PathLike[str] | None = None) -> PlanSet:
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
        If the content does not have the shape of a ``cosmop.plan/1`` file; the error names the
        file, the field and what was expected there.
    """
    return _PlanReader(None if file is None else os.fspath(file)).plan_set(data)


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
    return _PlanReader(file, text).plan_set(data)  # the text: errors say the field's line
