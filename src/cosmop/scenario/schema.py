"""The scenario file's structure: pydantic models of format version 1, and what each field
expects, in words, for the error messages of :mod:`cosmop.scenario.build`."""

from __future__ import annotations

from typing import Annotated, Any, Literal, cast

from pydantic import AfterValidator, BaseModel, BeforeValidator, ConfigDict, Field, field_validator
from pydantic_core import PydanticCustomError

from cosmop.docking import SIDES
from cosmop.reading import UNPRINTABLE, unprintable
from cosmop.units import SCENARIO_UNITS

MAX_DFA_STATES = 2000
"""Most states an explicit mission DFA may list (its minimisation is quadratic at worst)."""

SCENARIO_VERSION = 1
"""The scenario file format version this module reads (an optional top-level ``version`` key)."""


Point = tuple[float, float]


def _none_to(empty: Any) -> BeforeValidator:
    """``objects:`` with nothing under it (null) means an empty collection."""
    return BeforeValidator(lambda value: type(empty)() if value is None else value)


def _int_state_to_str(value: Any) -> Any:
    return str(value) if isinstance(value, int) and not isinstance(value, bool) else value


def _printable(value: str) -> str:
    """Names, ids, states and events are shown on terminals and written into files: a YAML
    escape such as ``"\\e[31m"`` must not smuggle a control sequence through them."""
    if (problem := unprintable(value)) is not None:
        raise PydanticCustomError(UNPRINTABLE, problem)
    return value


_Number = Annotated[float, Field(strict=True, allow_inf_nan=False)]
_Positive = Annotated[float, Field(strict=True, allow_inf_nan=False, gt=0)]
_Text = Annotated[str, Field(strict=True), AfterValidator(_printable)]
_StateName = Annotated[
    str, BeforeValidator(_int_state_to_str), Field(strict=True, min_length=1), AfterValidator(_printable)
]
_Pair = tuple[_Number, _Number]


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class _DynamicsModel(_Model):
    """Any subset of the :class:`~cosmop.scene.Dynamics` fields; an absent field is inherited."""

    max_speed: _Positive | None = None
    acceleration: _Positive | None = None
    braking: _Positive | None = None
    turn_rate: _Positive | None = None
    cycle: _Positive | None = None

    @field_validator("*", mode="before")
    @classmethod
    def _given_means_a_number(cls, value: Any) -> Any:
        if value is None:  # "cycle: null" is a mistake, not "inherit"
            raise ValueError("expected a number, got null")
        return value

    def overrides(self) -> dict[str, float]:
        """The fields given, by name."""
        return self.model_dump(exclude_none=True)


class _RobotModel(_Model):
    size: _Positive
    pose: tuple[_Number, _Number, _Number]
    dynamics: _DynamicsModel | None = None


_Side = Literal["west", "south", "east", "north"]


class _ObjectModel(_Model):
    size: _Positive
    position: _Pair
    # by default all four: SIDES's keys, which are exactly the names of _Side
    sides: Annotated[list[_Side], Field(min_length=1, max_length=4)] = cast(list[_Side], list(SIDES))


class WorkspaceModel(_Model):
    x: _Pair | None = None
    y: _Pair | None = None
    point: _Pair | None = None


class _AreaModel(_Model):
    x: _Pair
    y: _Pair


class HumanModel(_Model):
    size: _Positive
    speed: _Positive
    path: Annotated[list[Annotated[list[_Number], Field(min_length=2, max_length=3)]], Field(min_length=1)]
    loop: Annotated[bool, Field(strict=True)] = True
    walk: _AreaModel | None = None


class SceneModel(_Model):
    obstacles: Annotated[list[tuple[_Pair, _Pair]], _none_to([])] = []
    robots: Annotated[dict[_Text, _RobotModel], Field(min_length=1)]
    objects: Annotated[dict[_Text, _ObjectModel], _none_to({})] = {}
    workspaces: Annotated[dict[_Text, WorkspaceModel], _none_to({})] = {}
    humans: Annotated[dict[_Text, HumanModel], _none_to({})] = {}
    dynamics: _DynamicsModel | None = None


class DfaModel(_Model):
    initial: _StateName
    transitions: list[tuple[_StateName, _Text, _StateName]]
    states: list[_StateName] | None = None
    marked: list[_StateName] | None = None


def _one_to_list(value: Any) -> Any:
    """``to: W1`` is ``to: [W1]``."""
    return [value] if isinstance(value, str) else value


class DeliveryModel(_Model):
    object: _Text
    to: Annotated[list[_Text], BeforeValidator(_one_to_list), Field(min_length=1)]
    by: Annotated[list[_Text], BeforeValidator(_one_to_list), Field(min_length=1)] | None = None


class MissionModel(_Model):
    tasks: dict[_Text, Annotated[list[_Text], _none_to([])]] | None = None
    dfa: DfaModel | None = None
    deliveries: Annotated[list[DeliveryModel], Field(min_length=1)] | None = None
    returns: Annotated[bool | None, Field(strict=True, alias="return")] = None


class OrderModel(_Model):
    at: Annotated[float, Field(strict=True, allow_inf_nan=False, ge=0)]
    object: _Text
    to: Annotated[list[_Text], BeforeValidator(_one_to_list), Field(min_length=1)]
    by: Annotated[list[_Text], BeforeValidator(_one_to_list), Field(min_length=1)] | None = None


class ScenarioModel(_Model):
    version: Annotated[int, Field(strict=True)] | None = None
    name: Annotated[str, Field(strict=True, min_length=1), AfterValidator(_printable)]
    scene: SceneModel
    mission: MissionModel | None = None
    orders: Annotated[list[OrderModel], Field(min_length=1)] | None = None
    units: Literal[SCENARIO_UNITS] | None = None  # type: ignore[valid-type]


class OrdersFileModel(_Model):
    """An order stream in a file of its own (``cosmop run --orders FILE``): its fields are the
    scenario's ``orders`` (so that errors name the same paths)."""

    orders: Annotated[list[OrderModel], Field(min_length=1)]


_WALL = "a wall [[x1, y1], [x2, y2]]: two points of two numbers each (mm)"
RANGE = "a range [lo, hi] of two numbers with lo <= hi (mm)"
_STATE = "a state name"
_DYNAMICS = "a mapping with any of the keys max_speed, acceleration, braking, turn_rate, cycle"
_DYNAMICS_FIELDS = {
    "max_speed": "a positive number (top translational speed, mm/s)",
    "acceleration": "a positive number (translational acceleration, mm/s^2)",
    "braking": "a positive number (braking deceleration, mm/s^2)",
    "turn_rate": "a positive number (top turning rate, degrees/s)",
    "cycle": "a positive number (control cycle, s)",
}
_WAYPOINT = "a point [x, y] or [x, y, dwell]: two or three numbers (mm, mm, seconds)"
# What is expected at a field; "*" stands for any id, "#" for any list index.
EXPECTED: dict[tuple[str, ...], str] = {
    ("version",): f"{SCENARIO_VERSION}, the scenario format version",
    ("name",): "a non-empty name (text)",
    ("units",): "mm (millimetres and degrees, the default) or m (metres and radians, SI)",
    ("scene", "obstacles"): "a list of walls [[x1, y1], [x2, y2]]",
    ("scene", "obstacles", "#"): _WALL,
    ("scene", "robots"): "a non-empty mapping from robot ids to {size, pose}",
    ("scene", "robots", "*", "size"): "a positive number (side of the square robot, mm)",
    ("scene", "robots", "*", "pose"): "a pose [x, y, heading]: three numbers (mm, mm, degrees)",
    ("scene", "objects"): "a mapping from object ids to {size, position, sides (optional)}",
    ("scene", "objects", "*", "size"): "a positive number (side of the square object, mm)",
    ("scene", "objects", "*", "position"): "a position [x, y]: two numbers (mm)",
    ("scene", "objects", "*", "sides"): (
        "a non-empty list of the sides a robot may handle it from: west, south, east, north"
    ),
    ("scene", "objects", "*", "sides", "#"): "one of west, south, east, north",
    ("scene", "workspaces"): "a mapping from workspace ids to {x: [lo, hi], y: [lo, hi]} or {point: [x, y]}",
    ("scene", "workspaces", "*"): "{x: [lo, hi], y: [lo, hi]} or {point: [x, y]}",
    ("scene", "workspaces", "*", "x"): RANGE,
    ("scene", "workspaces", "*", "y"): RANGE,
    ("scene", "workspaces", "*", "point"): "a point [x, y]: two numbers (mm)",
    ("scene", "humans"): "a mapping from human ids to {size, speed, path}",
    ("scene", "humans", "*", "size"): "a positive number (side of the square person, mm)",
    ("scene", "humans", "*", "speed"): "a positive number (walking speed, mm/s)",
    ("scene", "humans", "*", "path"): f"a non-empty list of waypoints, each {_WAYPOINT}",
    ("scene", "humans", "*", "path", "#"): _WAYPOINT,
    ("scene", "humans", "*", "loop"): "true or false (whether to repeat the path)",
    ("scene", "humans", "*", "walk"): "an area {x: [lo, hi], y: [lo, hi]} (mm) to roam in",
    ("scene", "humans", "*", "walk", "x"): RANGE,
    ("scene", "humans", "*", "walk", "y"): RANGE,
    ("scene", "dynamics"): _DYNAMICS,
    ("scene", "robots", "*", "dynamics"): _DYNAMICS,
    **{("scene", "dynamics", key): text for key, text in _DYNAMICS_FIELDS.items()},
    **{("scene", "robots", "*", "dynamics", key): text for key, text in _DYNAMICS_FIELDS.items()},
    ("mission",): (
        "exactly one of tasks: {robot: [steps]}, dfa: {initial, transitions} or deliveries: [{object, to}]"
    ),
    ("mission", "deliveries"): "a non-empty list of deliveries {object, to, by}",
    ("mission", "deliveries", "#"): "a delivery {object: O1, to: W1 or [W1, W2], by: [R1, R2] (optional)}",
    ("mission", "deliveries", "#", "object"): "an object id",
    ("mission", "deliveries", "#", "to"): "a workspace id or a non-empty list of them",
    ("mission", "deliveries", "#", "to", "#"): "a workspace id",
    ("mission", "deliveries", "#", "by"): "a robot id or a non-empty list of them",
    ("mission", "deliveries", "#", "by", "#"): "a robot id",
    ("mission", "return"): "true or false (deliveries: robots that moved something end at home)",
    ("orders",): "a non-empty list of orders {at, object, to, by (optional)}",
    ("orders", "#"): "an order {at: 35.5, object: O1, to: W1 or [W1, W2], by: [R1, R2] (optional)}",
    ("orders", "#", "at"): "a release time in seconds, a number >= 0",
    ("orders", "#", "object"): "an object id",
    ("orders", "#", "to"): "a workspace id or a non-empty list of them",
    ("orders", "#", "to", "#"): "a workspace id",
    ("orders", "#", "by"): "a robot id or a non-empty list of them",
    ("orders", "#", "by", "#"): "a robot id",
    ("mission", "tasks"): "a mapping from robot ids to lists of task steps",
    ("mission", "tasks", "*"): "a list of task steps such as [pick O1, drop O1 at W1, return]",
    ("mission", "tasks", "*", "#"): "a task step (text) such as 'pick O1', 'drop O1 at W1' or 'return'",
    ("mission", "dfa", "initial"): _STATE,
    ("mission", "dfa", "states"): "a list of state names",
    ("mission", "dfa", "states", "#"): _STATE,
    ("mission", "dfa", "marked"): "a list of state names",
    ("mission", "dfa", "marked", "#"): _STATE,
    ("mission", "dfa", "transitions"): "a list of transitions [state, event, state]",
    (
        "mission",
        "dfa",
        "transitions",
        "#",
    ): 'a transition [state, event, state], e.g. [q0, "pick(R1,O1)", q1]',
}


def show_points(*points: Point) -> str:
    """Points as a message shows them: ``[[0, 0], [1, 2.5]]``.

    Parameters
    ----------
    *points : tuple of float
        The points ``(x, y)``, as the file wrote them.
    """
    return "[" + ", ".join(f"[{x:g}, {y:g}]" for x, y in points) + "]"
