"""Scenarios: the scene (walls, robots, movable objects, workspaces, people) and the mission.

A scenario file (format version 1) is YAML::

    name: warehouse-2x2
    scene:
      obstacles: [[[-2500, -2500], [2500, -2500]], ...]   # wall segments [[x1, y1], [x2, y2]]
      dynamics:   {max_speed: 750, acceleration: 300, braking: 500, turn_rate: 100, cycle: 0.1}
      robots:     {R1: {size: 400, pose: [-2000, -1000, 0]}, ...}   # x, y, heading
      objects:    {O1: {size: 100, position: [2000, -1000]}, O2: {..., sides: [north]}, ...}
      workspaces: {W1: {x: [-1500, -1000], y: [2000, 2500]}, W3: {point: [-4250, 4000]}}
      humans:     {H1: {size: 400, speed: 600, path: [[0, -1500], [0, -2200, 5]]}, ...}
    mission:
      tasks: {R1: [pick O1, drop O1 at W1, return], ...}   # or: dfa: {initial, transitions, ...}

Lengths are millimetres, angles degrees and times seconds (a file with ``units: m`` gives
metres and radians instead, converted at load time: :mod:`cosmop.units`); robots, objects and people are
axis-aligned squares of side ``size``. The optional ``dynamics`` (any subset of its keys) are
the unicycle limits of every robot; a robot may override them field by field with its own
``dynamics`` key, e.g. ``R1: {size: 400, pose: [0, 0, 0], dynamics: {max_speed: 500}}``, but
all robots share one control ``cycle``. The optional ``humans`` are people the robots do not
control: each walks along its ``path`` of points ``[x, y]`` or ``[x, y, dwell]`` (standing
``dwell`` seconds on arriving there) and repeats it, unless ``loop: false``; a person given a
``walk: {x: [lo, hi], y: [lo, hi]}`` area roams there at random once its path ends (at once,
if the path is only its start point).  An object's optional ``sides`` are the sides a robot
may stand on to pick it up or drop it off (``west``, ``south``, ``east``, ``north``; all four
by default).

:func:`load_scenario` reads such a file and :func:`parse_scenario` validates an already-parsed
mapping; both return an immutable :class:`Scenario` or raise
:class:`~cosmop.errors.ScenarioError` naming the file, the field and what was expected.

The file is read by :func:`cosmop.reading.load_yaml`: a YAML dialect close to YAML 1.2's core
schema, in which a key repeated inside one mapping is an error, with bounds on nesting, size
(aliases expanded) and integer length, so a hostile file is answered quickly and clearly.
"""

from __future__ import annotations

import math
import os
import re
from collections import Counter
from collections.abc import Mapping
from dataclasses import dataclass, field, fields, replace
from fractions import Fraction
from pathlib import Path
from types import MappingProxyType, NoneType, UnionType
from typing import Annotated, Any, Literal, NoReturn, Union, get_args, get_origin

from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, ValidationError, field_validator

from cosmop._frozen import reduce_frozen
from cosmop.docking import SIDES
from cosmop.errors import EventSyntaxError, ScenarioError
from cosmop.io import read_text
from cosmop.missions.events import ID_PATTERN, Event, parse_event
from cosmop.reading import FieldPath, Marks, format_path, load_yaml
from cosmop.units import SCENARIO_UNITS, default_dynamics, localize, scene_to_internal, show_length, shown

__all__ = [
    "LENGTH_GRID",
    "MAX_DFA_STATES",
    "MAX_LENGTH",
    "MAX_TASK_EVENTS",
    "SCENARIO_VERSION",
    "Delivery",
    "DfaSpec",
    "Dynamics",
    "Human",
    "Mission",
    "MovableObject",
    "Robot",
    "Scenario",
    "Scene",
    "Wall",
    "Workspace",
    "load_scenario",
    "parse_scenario",
]

LENGTH_GRID = Fraction(1, 1000)
"""Every length the planner uses (walls, poses, positions, sizes, workspaces) is a multiple of
this many millimetres (a micrometre); plans are exact on it."""

MAX_LENGTH = 1e9
"""The largest length or coordinate, in mm (1000 km)."""

MAX_DFA_STATES = 2000
"""Most states an explicit mission DFA may list (its minimisation is quadratic at worst)."""

MAX_TASK_EVENTS = 100
"""Most events one robot's task list may hold (its shortest plan is searched up to 3 per event)."""

SCENARIO_VERSION = 1
"""The scenario file format version this module reads (an optional top-level ``version`` key)."""

Point = tuple[float, float]

# ----------------------------------------------------------------------------------------------
# The loaded scenario: small immutable values
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Dynamics:
    """The unicycle limits of a robot, as used by the simulator and its safety check.

    These are the parameters of the passive-safety condition (the paper's corollary, after
    Mitsch et al.): a robot that brakes at `braking` as soon as it must can always stop before
    reaching anything that moves at most a known speed, given that within one control `cycle`
    it may still accelerate at `acceleration`. The defaults are those of a Pioneer P3-DX-class
    robot used indoors: its spec sheet tops out at 1.2 m/s, and these are moderate indoor
    settings within those limits.

    Parameters
    ----------
    max_speed : float, optional
        Top translational speed, mm/s (> 0; default 750).
    acceleration : float, optional
        Translational acceleration ``A``, mm/s^2 (> 0; default 300).
    braking : float, optional
        Braking deceleration ``b``, mm/s^2 (> 0; default 500).
    turn_rate : float, optional
        Top turning rate ``Omega``, degrees/s (> 0; default 100).
    cycle : float, optional
        Control cycle ``epsilon``: the longest time between two control decisions, s
        (> 0; default 0.1).

    Raises
    ------
    ValueError
        If a field is not a finite positive number.
    """

    max_speed: float = 750.0
    acceleration: float = 300.0
    braking: float = 500.0
    turn_rate: float = 100.0
    cycle: float = 0.1

    def __post_init__(self) -> None:
        for item in fields(self):
            value = getattr(self, item.name)
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise ValueError(f"dynamics: {item.name} must be a number, got {value!r}")
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"dynamics: {item.name} must be a finite positive number, got {value!r}")
            object.__setattr__(self, item.name, float(value))


@dataclass(frozen=True)
class Robot:
    """A mobile robot: an axis-aligned square.

    Parameters
    ----------
    id : str
        The robot's id, e.g. ``"R1"``.
    size : float
        Side of the square footprint, mm (> 0).
    pose : tuple of float
        Initial pose ``(x, y, heading)``: centre in mm, heading in degrees.
    dynamics : Dynamics, optional
        The robot's limits (speeds in mm/s, degrees/s; accelerations in mm/s^2; cycle in s);
        by default :class:`Dynamics`' defaults. A loaded scenario gives every robot the
        defaults, overridden by ``scene.dynamics``, overridden by the robot's own ``dynamics``.
    """

    id: str
    size: float
    pose: tuple[float, float, float]
    dynamics: Dynamics = Dynamics()


@dataclass(frozen=True)
class MovableObject:
    """An object the robots can pick up and drop off: an axis-aligned square.

    Parameters
    ----------
    id : str
        The object's id, e.g. ``"O1"``.
    size : float
        Side of the square, mm (> 0).
    position : tuple of float
        Initial centre ``(x, y)``, mm.
    sides : tuple of str, optional
        The sides a robot may stand on to pick it up or drop it off (``"west"``, ``"south"``,
        ``"east"``, ``"north"``; default all four), kept once each in the order of their
        headings.  Goods on a shelf that opens to the north say ``("north",)``; the paper's
        robots use the west side only.
    """

    id: str
    size: float
    position: Point
    sides: tuple[str, ...] = tuple(SIDES)

    def __post_init__(self) -> None:
        unknown = [s for s in self.sides if s not in SIDES]
        if unknown or not self.sides:
            raise ValueError(f"object {self.id}: sides must be a non-empty subset of {list(SIDES)}")
        object.__setattr__(self, "sides", tuple(sorted(set(self.sides), key=SIDES.__getitem__)))

    @property
    def headings(self) -> tuple[int, ...]:
        """The docking headings (degrees) from which it is handled, one per side, in order."""
        return tuple(SIDES[s] for s in self.sides)


@dataclass(frozen=True)
class Workspace:
    """A place where objects are dropped off: an axis-aligned rectangle or a single point.

    Parameters
    ----------
    id : str
        The workspace's id, e.g. ``"W1"``.
    x, y : tuple of float, optional
        The rectangle ``x[0] <= x <= x[1]``, ``y[0] <= y <= y[1]`` (mm); both or neither.
    point : tuple of float, optional
        The point ``(x, y)`` (mm), instead of a rectangle.
    """

    id: str
    x: Point | None = None
    y: Point | None = None
    point: Point | None = None

    def __post_init__(self) -> None:
        rectangle = self.x is not None and self.y is not None
        if rectangle == (self.point is not None) or (self.x is None) != (self.y is None):
            raise ValueError(f"workspace {self.id}: give either x and y ranges, or a point")
        if rectangle and (self.x[0] > self.x[1] or self.y[0] > self.y[1]):
            raise ValueError(f"workspace {self.id}: ranges must be [lo, hi] with lo <= hi")

    @property
    def is_point(self) -> bool:
        """Whether the workspace is a single point."""
        return self.point is not None

    @property
    def center(self) -> Point:
        """The centre of the rectangle, or the point (mm)."""
        if self.point is not None:
            return self.point
        return ((self.x[0] + self.x[1]) / 2.0, (self.y[0] + self.y[1]) / 2.0)

    @property
    def ranges(self) -> tuple[Point, Point]:
        """``(x range, y range)`` (mm); a point workspace gives ranges of zero width."""
        if self.point is not None:
            return (self.point[0], self.point[0]), (self.point[1], self.point[1])
        return self.x, self.y

    def centres(self, size: float) -> Workspace:
        """Where the centre of a square of side `size` (mm) lies when the whole square is inside.

        A rectangle shrinks by ``size / 2`` on every side; a point workspace is its own answer
        (it names the object's position exactly).

        Raises
        ------
        ValueError
            If the rectangle is narrower or shallower than `size`: it cannot hold the square.

        Examples
        --------
        >>> Workspace("W", x=(0, 500), y=(0, 300)).centres(100)
        Workspace(id='W', x=(50.0, 450.0), y=(50.0, 250.0), point=None)
        """
        if self.point is not None:
            return self
        half = size / 2.0
        x, y = (self.x[0] + half, self.x[1] - half), (self.y[0] + half, self.y[1] - half)
        if x[0] > x[1] or y[0] > y[1]:
            raise ValueError(f"workspace {self.id} cannot hold a square of side {size:g} mm")
        return Workspace(self.id, x=x, y=y)

    def holds(self, x: float, y: float, size: float, tol: float = 0.0) -> bool:
        """Whether a square of side `size` (mm) centred at ``(x, y)`` lies wholly inside, within
        `tol` mm (a point workspace: the centre is the point): :meth:`centres` contains it.

        >>> Workspace("W", x=(0, 500), y=(0, 300)).holds(460, 100, 100)
        False
        """
        return self.centres(size).contains(x, y, tol)

    def contains(self, x: float, y: float, tol: float = 0.0) -> bool:
        """Whether the position ``(x, y)`` lies in the workspace (boundary included).

        Parameters
        ----------
        x, y : float
            The position, mm.
        tol : float, optional
            Slack in mm added on every side (default 0: exact; a point workspace then
            contains only that point).

        Returns
        -------
        bool
        """
        if self.point is not None:
            return abs(x - self.point[0]) <= tol and abs(y - self.point[1]) <= tol
        return self.x[0] - tol <= x <= self.x[1] + tol and self.y[0] - tol <= y <= self.y[1] + tol


@dataclass(frozen=True)
class Human:
    """A person: an uncontrolled mover, an axis-aligned square.

    The person starts at the first point of `path` and walks straight from each point to the
    next at `speed`, standing still ``dwell`` seconds on arriving at a point (for the first
    point, also at the start). After the last point the person walks back to the first and
    repeats the path if `loop`, or stays at the last point otherwise. If `walk` is given, a
    person whose path ends (``loop`` false, or a path of only the start point) then roams
    forever to random points of that rectangle, drawn by the simulation from its seed; with
    `walk`, the path may be just the start point.

    Parameters
    ----------
    id : str
        The person's id, e.g. ``"H1"``.
    size : float
        Side of the square footprint, mm (> 0).
    speed : float
        Walking speed, mm/s (> 0): the most the person ever moves.
    path : tuple of (float, float, float)
        Waypoints ``(x, y, dwell)``: position in mm, dwell in seconds (>= 0). Points given as
        ``(x, y)`` get dwell 0. At least two points unless `walk` is given.
    loop : bool, optional
        Whether to repeat the path (default true).
    walk : tuple of (float, float), optional
        The roaming area ``((xlo, xhi), (ylo, yhi))``, mm, with ``lo <= hi``.

    Raises
    ------
    ValueError
        If a size, speed, dwell or range is out of bounds, or the path is too short.
    """

    id: str
    size: float
    speed: float
    path: tuple[tuple[float, float, float], ...]
    loop: bool = True
    walk: tuple[Point, Point] | None = None

    def __post_init__(self) -> None:
        if not (self.size > 0 and self.speed > 0):
            raise ValueError(f"human {self.id}: size and speed must be positive")
        if any(len(point) not in (2, 3) for point in self.path):
            raise ValueError(f"human {self.id}: path points are (x, y) or (x, y, dwell)")
        path = tuple(
            (float(point[0]), float(point[1]), float(point[2]) if len(point) > 2 else 0.0)
            for point in self.path
        )
        if any(dwell < 0 for _, _, dwell in path):
            raise ValueError(f"human {self.id}: dwell times must be >= 0")
        if len(path) < (1 if self.walk is not None else 2):
            raise ValueError(f"human {self.id}: a path needs two points, or one point and a walk area")
        object.__setattr__(self, "path", path)
        if self.walk is not None:
            (xlo, xhi), (ylo, yhi) = self.walk
            if xlo > xhi or ylo > yhi:
                raise ValueError(f"human {self.id}: walk ranges must be [lo, hi] with lo <= hi")
            object.__setattr__(self, "walk", ((float(xlo), float(xhi)), (float(ylo), float(yhi))))

    @property
    def start(self) -> Point:
        """Where the person starts: the first point of the path ``(x, y)``, mm."""
        return self.path[0][:2]


@dataclass(frozen=True)
class Wall:
    """A wall: the straight segment from `start` to `end` (mm; the end points differ)."""

    start: Point
    end: Point

    @property
    def length(self) -> float:
        """Length of the segment, mm."""
        return math.dist(self.start, self.end)


def _frozen_mapping(mapping: Mapping[str, Any]) -> Mapping[str, Any]:
    if isinstance(mapping, MappingProxyType):
        return mapping
    return MappingProxyType(dict(mapping))


@dataclass(frozen=True)
class Scene:
    """The physical scene: walls, robots, movable objects, workspaces and people.

    The mappings are read-only and keep the order of the scenario file.

    Parameters
    ----------
    obstacles : tuple of Wall
        Wall segments.
    robots : Mapping[str, Robot]
        Robots by id.
    objects : Mapping[str, MovableObject]
        Movable objects by id.
    workspaces : Mapping[str, Workspace]
        Workspaces by id.
    humans : Mapping[str, Human]
        People (uncontrolled movers) by id; by default none.
    dynamics : Dynamics, optional
        The scene-wide robot limits as given in the file (:class:`Dynamics`' defaults
        overridden by ``scene.dynamics``); each robot's own are in ``Robot.dynamics``.
    """

    __reduce__ = reduce_frozen  # picklable for worker processes

    obstacles: tuple[Wall, ...]
    robots: Mapping[str, Robot]
    objects: Mapping[str, MovableObject] = field(default_factory=dict)
    workspaces: Mapping[str, Workspace] = field(default_factory=dict)
    humans: Mapping[str, Human] = field(default_factory=dict)
    dynamics: Dynamics = Dynamics()

    def __post_init__(self) -> None:
        object.__setattr__(self, "obstacles", tuple(self.obstacles))
        for name in ("robots", "objects", "workspaces", "humans"):
            object.__setattr__(self, name, _frozen_mapping(getattr(self, name)))

    def blocked(
        self, half: float, slack: float = 0.5, within: tuple[float, float, float, float] | None = None
    ):
        """Where the centre of an axis-aligned square of half-side `half` (mm) overlaps a wall.

        Each wall grown by the square exactly (the convex hull of the square at both ends),
        less `slack` mm: touching stays free, and so does a gap exactly as wide as the square
        (the walls are shrunk one by one, so that gap is not closed by their union).  A shapely
        geometry (empty without walls).  Given ``within = (xmin, ymin, xmax, ymax)``, only the
        walls whose grown shape can meet that box are taken (the answer is the same inside it).
        """
        import shapely

        from cosmop.squares import swept_square

        walls = self.obstacles
        if within is not None:
            x0, y0, x1, y1 = within
            walls = tuple(
                w
                for w in walls
                if min(w.start[0], w.end[0]) - half <= x1
                and max(w.start[0], w.end[0]) + half >= x0
                and min(w.start[1], w.end[1]) - half <= y1
                and max(w.start[1], w.end[1]) + half >= y0
            )
        side = 2.0 * (half - slack)
        return shapely.unary_union([swept_square(w.start, w.end, side) for w in walls])


@dataclass(frozen=True)
class DfaSpec:
    """An explicit mission automaton, as written in a scenario file.

    Parameters
    ----------
    states : tuple of str
        All states, in the file's order (``states:`` if given, else order of appearance).
    initial : str
        The initial state.
    marked : tuple of str
        The marked (accepting) states; by default all states, i.e. a prefix-closed mission.
    transitions : tuple of (str, Event, str)
        Deterministic transitions ``(source, event, target)``.
    marked_given : bool
        Whether the file listed ``marked``.  Then the mission is complete exactly in the marked
        states; otherwise in the states without an outgoing transition.
    """

    states: tuple[str, ...]
    initial: str
    marked: tuple[str, ...]
    transitions: tuple[tuple[str, Event, str], ...]
    marked_given: bool = False

    @property
    def complete_states(self) -> tuple[str, ...]:
        """The states in which the mission is complete (file order)."""
        if self.marked_given:
            return self.marked
        busy = {source for source, _, _ in self.transitions}
        return tuple(q for q in self.states if q not in busy)

    @property
    def alphabet(self) -> tuple[Event, ...]:
        """The distinct events on the transitions, sorted."""
        return tuple(sorted({event for _, event, _ in self.transitions}))


@dataclass(frozen=True)
class Mission:
    """The global mission: per-robot task sequences, an explicit DFA, or deliveries (one of them).

    Parameters
    ----------
    tasks : Mapping[str, tuple of Event], optional
        One event sequence per robot; the global mission is their parallel composition.
    dfa : DfaSpec, optional
        The global mission automaton.
    deliveries : tuple of Delivery, optional
        Goods to move, without saying which robot moves them (the planner chooses).
    returns : bool
        Deliveries only: every robot that moved something ends at its start pose.
    """

    __reduce__ = reduce_frozen  # picklable for worker processes

    tasks: Mapping[str, tuple[Event, ...]] | None = None
    dfa: DfaSpec | None = None
    deliveries: tuple[Delivery, ...] | None = None
    returns: bool = False

    def __post_init__(self) -> None:
        if sum(x is not None for x in (self.tasks, self.dfa, self.deliveries)) != 1:
            raise ValueError("a mission has exactly one of tasks, dfa or deliveries")
        if self.tasks is not None:
            object.__setattr__(
                self, "tasks", MappingProxyType({robot: tuple(seq) for robot, seq in self.tasks.items()})
            )
        if self.deliveries is not None:
            object.__setattr__(self, "deliveries", tuple(self.deliveries))

    @property
    def form(self) -> Literal["tasks", "dfa", "deliveries"]:
        """``"tasks"``, ``"dfa"`` or ``"deliveries"``: how the mission was given."""
        if self.tasks is not None:
            return "tasks"
        return "dfa" if self.dfa is not None else "deliveries"

    @property
    def events(self) -> frozenset[Event]:
        """Every event the mission mentions (its alphabet)."""
        if self.tasks is not None:
            return frozenset(event for sequence in self.tasks.values() for event in sequence)
        if self.dfa is not None:
            return frozenset(self.dfa.alphabet)
        out = set()
        for d in self.deliveries:
            out.update(d.events())
            if self.returns:
                out.update(Event("return", r) for r in d.by)
        return frozenset(out)


@dataclass(frozen=True)
class Delivery:
    """One delivery of a deliveries mission: an object to one of some workspaces.

    Parameters
    ----------
    object : str
        The object to move.
    to : tuple of str
        The workspaces it may go to (any one of them).
    by : tuple of str
        The robots that may move it (all the scene's robots when the file does not say).
    """

    object: str
    to: tuple[str, ...]
    by: tuple[str, ...]

    def events(self) -> list[Event]:
        """Every pick and drop event that can realise the delivery."""
        out = []
        for robot in self.by:
            out.append(Event("pick", robot, obj=self.object))
            out.extend(Event("drop", robot, obj=self.object, workspace=w) for w in self.to)
        return out


@dataclass(frozen=True)
class Scenario:
    """A validated scenario.

    Parameters
    ----------
    name : str
        The scenario's name.
    scene : Scene
        Walls, robots, objects, workspaces and people.
    mission : Mission
        The global mission.
    source : pathlib.Path, optional
        The file it was loaded from, as given to :func:`load_scenario`.
    """

    name: str
    scene: Scene
    mission: Mission
    source: Path | None = None


# ----------------------------------------------------------------------------------------------
# Structure: pydantic models of the file format
# ----------------------------------------------------------------------------------------------


def _none_to(empty: Any) -> BeforeValidator:
    """``objects:`` with nothing under it (null) means an empty collection."""
    return BeforeValidator(lambda value: type(empty)() if value is None else value)


def _int_state_to_str(value: Any) -> Any:
    return str(value) if isinstance(value, int) and not isinstance(value, bool) else value


_Number = Annotated[float, Field(strict=True, allow_inf_nan=False)]
_Positive = Annotated[float, Field(strict=True, allow_inf_nan=False, gt=0)]
_Text = Annotated[str, Field(strict=True)]
_StateName = Annotated[str, BeforeValidator(_int_state_to_str), Field(strict=True, min_length=1)]
_Pair = tuple[_Number, _Number]


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class _DynamicsModel(_Model):
    """Any subset of the :class:`Dynamics` fields; an absent field is inherited."""

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


class _ObjectModel(_Model):
    size: _Positive
    position: _Pair
    sides: Annotated[list[Literal["west", "south", "east", "north"]], Field(min_length=1, max_length=4)] = (
        list(SIDES)
    )


class _WorkspaceModel(_Model):
    x: _Pair | None = None
    y: _Pair | None = None
    point: _Pair | None = None


class _AreaModel(_Model):
    x: _Pair
    y: _Pair


class _HumanModel(_Model):
    size: _Positive
    speed: _Positive
    path: Annotated[list[Annotated[list[_Number], Field(min_length=2, max_length=3)]], Field(min_length=1)]
    loop: Annotated[bool, Field(strict=True)] = True
    walk: _AreaModel | None = None


class _SceneModel(_Model):
    obstacles: Annotated[list[tuple[_Pair, _Pair]], _none_to([])] = []
    robots: Annotated[dict[_Text, _RobotModel], Field(min_length=1)]
    objects: Annotated[dict[_Text, _ObjectModel], _none_to({})] = {}
    workspaces: Annotated[dict[_Text, _WorkspaceModel], _none_to({})] = {}
    humans: Annotated[dict[_Text, _HumanModel], _none_to({})] = {}
    dynamics: _DynamicsModel | None = None


class _DfaModel(_Model):
    initial: _StateName
    transitions: list[tuple[_StateName, _Text, _StateName]]
    states: list[_StateName] | None = None
    marked: list[_StateName] | None = None


def _one_to_list(value: Any) -> Any:
    """``to: W1`` is ``to: [W1]``."""
    return [value] if isinstance(value, str) else value


class _DeliveryModel(_Model):
    object: _Text
    to: Annotated[list[_Text], BeforeValidator(_one_to_list), Field(min_length=1)]
    by: Annotated[list[_Text], BeforeValidator(_one_to_list), Field(min_length=1)] | None = None


class _MissionModel(_Model):
    tasks: dict[_Text, Annotated[list[_Text], _none_to([])]] | None = None
    dfa: _DfaModel | None = None
    deliveries: Annotated[list[_DeliveryModel], Field(min_length=1)] | None = None
    returns: Annotated[bool | None, Field(strict=True, alias="return")] = None


class _ScenarioModel(_Model):
    version: Annotated[int, Field(strict=True)] | None = None
    name: Annotated[str, Field(strict=True, min_length=1)]
    scene: _SceneModel
    mission: _MissionModel
    units: Literal[SCENARIO_UNITS] | None = None  # type: ignore[valid-type]


_WALL = "a wall [[x1, y1], [x2, y2]]: two points of two numbers each (mm)"
_RANGE = "a range [lo, hi] of two numbers with lo <= hi (mm)"
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
_EXPECTED: dict[tuple[str, ...], str] = {
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
    ("scene", "workspaces", "*", "x"): _RANGE,
    ("scene", "workspaces", "*", "y"): _RANGE,
    ("scene", "workspaces", "*", "point"): "a point [x, y]: two numbers (mm)",
    ("scene", "humans"): "a mapping from human ids to {size, speed, path}",
    ("scene", "humans", "*", "size"): "a positive number (side of the square person, mm)",
    ("scene", "humans", "*", "speed"): "a positive number (walking speed, mm/s)",
    ("scene", "humans", "*", "path"): f"a non-empty list of waypoints, each {_WAYPOINT}",
    ("scene", "humans", "*", "path", "#"): _WAYPOINT,
    ("scene", "humans", "*", "loop"): "true or false (whether to repeat the path)",
    ("scene", "humans", "*", "walk"): "an area {x: [lo, hi], y: [lo, hi]} (mm) to roam in",
    ("scene", "humans", "*", "walk", "x"): _RANGE,
    ("scene", "humans", "*", "walk", "y"): _RANGE,
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


def _unwrap(annotation: Any) -> Any:
    while True:
        origin = get_origin(annotation)
        if origin is Annotated:
            annotation = get_args(annotation)[0]
        elif origin in (Union, UnionType):
            members = [arg for arg in get_args(annotation) if arg is not NoneType]
            if len(members) != 1:
                return annotation
            annotation = members[0]
        else:
            return annotation


def _model_at(path: FieldPath) -> type[BaseModel] | None:
    """The pydantic model describing the mapping at `path`, if that position is a model."""
    annotation: Any = _ScenarioModel
    for part in path:
        annotation = _unwrap(annotation)
        if isinstance(annotation, type) and issubclass(annotation, BaseModel):
            if part not in annotation.model_fields:
                return None
            annotation = annotation.model_fields[part].annotation
        elif get_origin(annotation) is dict:
            annotation = get_args(annotation)[1]
        elif get_origin(annotation) is list:
            annotation = get_args(annotation)[0]
        else:
            return None
    annotation = _unwrap(annotation)
    return annotation if isinstance(annotation, type) and issubclass(annotation, BaseModel) else None


def _describe_keys(model: type[BaseModel]) -> str:
    keys = [name if info.is_required() else f"{name} (optional)" for name, info in model.model_fields.items()]
    return "a mapping with keys " + ", ".join(keys)


def _expected_at(loc: FieldPath) -> tuple[FieldPath, str | None]:
    """The field to report for an error at `loc`, and what is expected there."""
    for length in range(len(loc), -1, -1):
        prefix = loc[:length]
        for pattern, text in _EXPECTED.items():
            if len(pattern) == length and all(
                _matches(p, part) for p, part in zip(pattern, prefix, strict=True)
            ):
                return prefix, text
        model = _model_at(prefix)
        if model is not None:
            return prefix, _describe_keys(model)
    return loc, None


def _matches(pattern: str, part: str | int) -> bool:
    if pattern == "#":
        return isinstance(part, int)
    return pattern == "*" or pattern == part


def _lookup(data: Any, path: FieldPath) -> tuple[bool, Any]:
    for part in path:
        if isinstance(data, Mapping):
            if part not in data:
                return False, None
        elif not (isinstance(data, list) and isinstance(part, int) and 0 <= part < len(data)):
            return False, None
        data = data[part]
    return True, data


def _show_points(*points: Point) -> str:
    return "[" + ", ".join(f"[{x:g}, {y:g}]" for x, y in points) + "]"


def _show(value: Any) -> str:
    if value is None:
        return "nothing (null)"
    if isinstance(value, bool):
        return "true" if value else "false"
    text = repr(value)
    return text if len(text) <= 80 else text[:77] + "..."


# ----------------------------------------------------------------------------------------------
# Building and checking the scenario
# ----------------------------------------------------------------------------------------------


class _Builder:
    """Validates one scenario mapping and builds the :class:`Scenario`."""

    def __init__(self, data: Any, file: str | None, marks: Marks | None) -> None:
        self.data = data
        self.file = file
        self.marks = marks or {}
        units = data.get("units") if isinstance(data, Mapping) else None
        self.units = units if units in SCENARIO_UNITS else "mm"  # the words of its messages

    def fail(self, path: FieldPath, expected: str) -> NoReturn:
        line = column = None
        for length in range(len(path), 0, -1):
            if path[:length] in self.marks:
                line, column = self.marks[path[:length]]
                break
        raise ScenarioError(
            localize(expected, self.units),
            file=self.file,
            field=format_path(path) if path else None,
            line=line,
            column=column,
        )

    # -- structure ----------------------------------------------------------------------------

    def validate_structure(self) -> _ScenarioModel:
        if not isinstance(self.data, Mapping):
            what = (
                "the file is empty"
                if self.data is None
                else f"got {type(self.data).__name__} {_show(self.data)}"
            )
            self.fail((), f"expected a mapping with keys name, scene, mission at the top level; {what}")
        try:
            return _ScenarioModel.model_validate(self.data)
        except ValidationError as exc:
            errors = exc.errors(include_url=False)
            first = min(
                enumerate(errors),
                key=lambda item: (self._line_of(tuple(item[1]["loc"])), item[0]),
            )[1]
            self._structure_error(first)

    def _line_of(self, loc: FieldPath) -> float:
        for length in range(len(loc), 0, -1):
            if loc[:length] in self.marks:
                return self.marks[loc[:length]][0]
        return math.inf

    def _structure_error(self, error: Mapping[str, Any]) -> NoReturn:
        loc: FieldPath = tuple(error["loc"])
        kind = error["type"]
        if "[key]" in loc:
            cut = loc.index("[key]")
            key = loc[cut - 1]
            self.fail(loc[: cut - 1], f"keys here must be ids (text), got {_show(key)}")
        if kind == "extra_forbidden":
            model = _model_at(loc[:-1])
            keys = model.model_fields.items() if model is not None else ()
            allowed = ", ".join(f.alias or name for name, f in keys) or "none"
            self.fail(loc, f"unknown key {loc[-1]!r}; expected one of: {allowed}")
        if kind == "missing" and isinstance(loc[-1], str):
            path, text = _expected_at(loc)
            detail = f": expected {text}" if text is not None and path == loc else ""
            self.fail(loc, f"missing required key {loc[-1]!r}{detail}")
        path, text = _expected_at(loc)
        if text is None:
            self.fail(loc, str(error["msg"]))
        found, value = _lookup(self.data, path)
        shown = _show(value) if found else "nothing"
        self.fail(path, f"expected {text}, got {shown}")

    # -- semantics ----------------------------------------------------------------------------

    def build(self, source: Path | None) -> Scenario:
        model = self.validate_structure()
        if model.version is not None and model.version != SCENARIO_VERSION:
            self.fail(("version",), f"expected {_EXPECTED[('version',)]}, got {model.version}")
        scene = scene_to_internal(self.build_scene(model.scene), model.units or "mm")
        self.check_precision(scene)
        self.check_bodies(scene)
        mission = self.build_mission(model.mission, scene)
        return Scenario(name=model.name, scene=scene, mission=mission, source=source)

    def build_scene(self, model: _SceneModel) -> Scene:
        owner_of_id: dict[str, FieldPath] = {}
        kinds = {
            "robots": "a robot",
            "objects": "an object",
            "workspaces": "a workspace",
            "humans": "a human",
        }
        for group in kinds:
            for ident in getattr(model, group):
                path = ("scene", group, ident)
                if not re.fullmatch(ID_PATTERN, ident):
                    self.fail(path, f"expected an id matching {ID_PATTERN}, got {ident!r}")
                if ident in owner_of_id:
                    other = owner_of_id[ident]
                    self.fail(
                        path,
                        f"id {ident!r} is already used by {kinds[other[1]]} ({format_path(other)}); "
                        "ids must be unique across robots, objects, workspaces and humans",
                    )
                owner_of_id[ident] = path

        walls = []
        for index, (start, end) in enumerate(model.obstacles):
            if start == end:
                self.fail(
                    ("scene", "obstacles", index),
                    f"expected a wall with two distinct end points, got {_show_points(start, end)}",
                )
            walls.append(Wall(start, end))

        base = default_dynamics(self.units)  # the defaults in the file's units
        dynamics = base if model.dynamics is None else replace(base, **model.dynamics.overrides())
        robots = {
            ident: Robot(
                ident,
                r.size,
                r.pose,
                dynamics if r.dynamics is None else replace(dynamics, **r.dynamics.overrides()),
            )
            for ident, r in model.robots.items()
        }
        self.check_cycles(robots, dynamics)
        objects = {
            ident: MovableObject(ident, o.size, o.position, tuple(o.sides))
            for ident, o in model.objects.items()
        }
        workspaces = {ident: self.build_workspace(ident, w) for ident, w in model.workspaces.items()}
        humans = {ident: self.build_human(ident, h) for ident, h in model.humans.items()}
        return Scene(
            obstacles=tuple(walls),
            robots=robots,
            objects=objects,
            workspaces=workspaces,
            humans=humans,
            dynamics=dynamics,
        )

    def check_precision(self, scene: Scene) -> None:
        """Every length the planner uses lies on the :data:`LENGTH_GRID` and within :data:`MAX_LENGTH`."""
        grid = f"{shown(float(LENGTH_GRID), self.units):f}".rstrip("0") + (
            " m" if self.units == "m" else " mm"
        )
        for path, value in _planned_lengths(scene):
            if abs(value) > MAX_LENGTH:
                self.fail(
                    path, f"expected a length of at most {show_length(MAX_LENGTH, self.units)}, got {value:g}"
                )
            if (Fraction(repr(float(value))) / LENGTH_GRID).denominator != 1:
                shown_value = f"{shown(value, self.units):.12g}"
                self.fail(
                    path,
                    f"expected a multiple of {grid} (plans are exact to a micrometre), got {shown_value}",
                )

    def check_bodies(self, scene: Scene) -> None:
        """A physically possible scene: no body overlaps a wall or another body at the start."""
        from cosmop.physics import overlaps

        found = overlaps(scene, units=self.units)
        if found:
            self.fail(found[0].field, found[0].describe())

    def check_cycles(self, robots: Mapping[str, Robot], default: Dynamics) -> None:
        """All robots share one control cycle: report the first robot off the most common one."""
        counts = Counter(robot.dynamics.cycle for robot in robots.values())
        if len(counts) <= 1:
            return
        # the cycle most robots use; on a tie the scene-wide one, else the first in file order
        common = max(counts, key=lambda cycle: (counts[cycle], cycle == default.cycle))
        odd = next(robot for robot in robots.values() if robot.dynamics.cycle != common)
        users = [robot.id for robot in robots.values() if robot.dynamics.cycle == common]
        if len(users) == len(robots) - 1:
            others = "the others use"
        elif len(users) == 1:
            others = f"{users[0]} uses"
        else:
            shown = ", ".join(users[:3]) + (f" and {len(users) - 3} more" if len(users) > 3 else "")
            others = f"{shown} use"
        self.fail(
            ("scene", "robots", odd.id, "dynamics", "cycle"),
            "every robot must share one control cycle (the simulation steps all robots with one "
            f"clock); this robot's is {odd.dynamics.cycle:g} s, {others} {common:g} s",
        )

    def build_human(self, ident: str, model: _HumanModel) -> Human:
        path = ("scene", "humans", ident)
        for index, point in enumerate(model.path):
            if len(point) == 3 and point[2] < 0:
                self.fail(
                    (*path, "path", index, 2), f"expected a dwell time >= 0 (seconds), got {point[2]:g}"
                )
        if len(model.path) < 2 and model.walk is None:
            self.fail(
                (*path, "path"),
                "expected at least two waypoints to walk between, or a walk area "
                "{x: [lo, hi], y: [lo, hi]} to roam in from the start point; got one point",
            )
        walk = None
        if model.walk is not None:
            for axis in ("x", "y"):
                lo, hi = getattr(model.walk, axis)
                if lo > hi:
                    self.fail((*path, "walk", axis), f"expected {_RANGE}, got lo = {lo:g} > hi = {hi:g}")
            walk = (model.walk.x, model.walk.y)
        points = tuple((p[0], p[1], p[2] if len(p) == 3 else 0.0) for p in model.path)
        return Human(ident, model.size, model.speed, points, loop=model.loop, walk=walk)

    def build_workspace(self, ident: str, model: _WorkspaceModel) -> Workspace:
        path = ("scene", "workspaces", ident)
        if model.point is not None:
            if model.x is not None or model.y is not None:
                self.fail(path, "expected either {x: [lo, hi], y: [lo, hi]} or {point: [x, y]}, not both")
            return Workspace(ident, point=model.point)
        if model.x is None and model.y is None:
            self.fail(path, "expected {x: [lo, hi], y: [lo, hi]} or {point: [x, y]}, got neither")
        for axis in ("x", "y"):
            bounds = getattr(model, axis)
            if bounds is None:
                self.fail((*path, axis), f"missing required key {axis!r}: expected {_RANGE}")
            if bounds[0] > bounds[1]:
                self.fail((*path, axis), f"expected {_RANGE}, got lo = {bounds[0]:g} > hi = {bounds[1]:g}")
        return Workspace(ident, x=model.x, y=model.y)

    def build_mission(self, model: _MissionModel, scene: Scene) -> Mission:
        given = [k for k in ("tasks", "dfa", "deliveries") if getattr(model, k) is not None]
        if len(given) != 1:
            got = " and ".join(given) if given else "none"
            expected = "expected exactly one of 'tasks', 'dfa' or 'deliveries'"
            self.fail(("mission",), f"{expected}, got {got}")
        if model.returns is not None and model.deliveries is None:
            self.fail(
                ("mission", "return"), "'return' goes with 'deliveries' (tasks and DFAs say it by events)"
            )
        if model.tasks is not None:
            return Mission(tasks=self.build_tasks(model.tasks, scene))
        if model.dfa is not None:
            return Mission(dfa=self.build_dfa(model.dfa, scene))
        return Mission(deliveries=self.build_deliveries(model.deliveries, scene), returns=bool(model.returns))

    def build_deliveries(self, models: list[_DeliveryModel], scene: Scene) -> tuple[Delivery, ...]:
        out, first = [], {}
        for index, model in enumerate(models):
            path = ("mission", "deliveries", index)
            obj = model.object
            if obj not in scene.objects:
                self.fail((*path, "object"), f"unknown object {obj!r}; {_known('objects', scene.objects)}")
            if obj in first:
                self.fail((*path, "object"), f"{obj} is already delivered by deliveries[{first[obj]}]")
            first[obj] = index
            for k, ws in enumerate(model.to):
                if ws not in scene.workspaces:
                    known = _known("workspaces", scene.workspaces)
                    self.fail((*path, "to", k), f"unknown workspace {ws!r}; {known}")
                self.check_holds((*path, "to", k), scene.objects[obj], ws, scene)
            by = tuple(model.by) if model.by is not None else tuple(scene.robots)
            for k, robot in enumerate(by):
                if robot not in scene.robots:
                    self.fail((*path, "by", k), f"unknown robot {robot!r}; {_known('robots', scene.robots)}")
            out.append(Delivery(model.object, tuple(dict.fromkeys(model.to)), tuple(dict.fromkeys(by))))
        return tuple(out)

    def build_tasks(self, tasks: Mapping[str, list[str]], scene: Scene) -> dict[str, tuple[Event, ...]]:
        if not tasks:
            self.fail(("mission", "tasks"), "expected a task list for at least one robot, got none")
        result = {}
        mover: dict[str, FieldPath] = {}  # the first task that moves each object
        for robot, steps in tasks.items():
            if robot not in scene.robots:
                self.fail(
                    ("mission", "tasks", robot), f"unknown robot {robot!r}; {_known('robots', scene.robots)}"
                )
            if len(steps) > MAX_TASK_EVENTS:
                self.fail(
                    ("mission", "tasks", robot),
                    f"a task list of {len(steps)} events; at most {MAX_TASK_EVENTS} per robot are planned "
                    "(split the mission into several runs)",
                )
            events = []
            for index, text in enumerate(steps):
                path = ("mission", "tasks", robot, index)
                event = self.parse(path, text, robot)
                if robot not in event.owners:
                    owners = " and ".join(sorted(event.owners))
                    self.fail(
                        path,
                        f"expected an event of robot {robot}, got {event.name}, which belongs to {owners}",
                    )
                self.check_references(path, event, scene)
                if event.kind in ("pick", "drop"):
                    first = mover.setdefault(event.obj, path)
                    if first[2] != robot:
                        self.fail(
                            path,
                            f"{event.obj} is already moved by {first[2]} ({format_path(first)}); one robot "
                            "moves each object in a task list (a relay between robots needs an order: "
                            "write the mission as a dfa)",
                        )
                events.append(event)
            result[robot] = tuple(events)
        return result

    def build_dfa(self, model: _DfaModel, scene: Scene) -> DfaSpec:
        base = ("mission", "dfa")
        listed = self.unique_states((*base, "states"), model.states) if model.states is not None else None

        def known(path: FieldPath, state: str, role: str) -> None:
            if listed is not None and state not in listed:
                self.fail(path, f"unknown {role} state {state!r}; it is not in mission.dfa.states")

        known((*base, "initial"), model.initial, "initial")
        order: dict[str, None] = dict.fromkeys(listed if listed is not None else [model.initial])
        first_transition: dict[tuple[str, Event], tuple[int, str]] = {}
        transitions = []
        for index, (source, text, target) in enumerate(model.transitions):
            path = (*base, "transitions", index)
            known((*path, 0), source, "source")
            known((*path, 2), target, "target")
            event = self.parse((*path, 1), text, None)
            self.check_references((*path, 1), event, scene)
            if (source, event) in first_transition:
                other, other_target = first_transition[(source, event)]
                if other_target == target:
                    problem = f"repeats transitions[{other}] ({source} --{event.name}--> {target})"
                else:
                    problem = (
                        f"nondeterministic: from state {source!r}, event {event.name} leads to "
                        f"{other_target!r} (transitions[{other}]) and to {target!r}"
                    )
                self.fail(path, f"{problem}; expected at most one transition per state and event")
            first_transition[(source, event)] = (index, target)
            order.setdefault(source)
            order.setdefault(target)
            transitions.append((source, event, target))
        states = tuple(order)
        if len(states) > MAX_DFA_STATES:
            self.fail(
                base,
                f"a DFA of {len(states):,} states; at most {MAX_DFA_STATES:,} are read "
                "(write a large mission as tasks or deliveries: they are composed, not listed)",
            )

        if model.marked is None:
            marked = states
        else:
            marked = self.unique_states((*base, "marked"), model.marked)
            for index, state in enumerate(marked):
                if state not in order:
                    where = "mission.dfa.states" if listed is not None else "the transitions or initial"
                    self.fail(
                        (*base, "marked", index), f"unknown marked state {state!r}; it is not in {where}"
                    )
        spec = DfaSpec(
            states=states,
            initial=model.initial,
            marked=tuple(marked),
            transitions=tuple(transitions),
            marked_given=model.marked is not None,
        )
        reachable = _reachable(model.initial, transitions)
        if not any(q in reachable for q in spec.complete_states):
            where = "marked" if spec.marked_given else "without an outgoing transition"
            listed_states = ", ".join(spec.complete_states) or "none"
            self.fail(
                base,
                f"the mission can never be complete: no complete state ({where}: {listed_states}) "
                f"can be reached from the initial state {model.initial!r}; expected at least one",
            )
        return spec

    def unique_states(self, path: FieldPath, states: list[str]) -> tuple[str, ...]:
        seen: dict[str, int] = {}
        for index, state in enumerate(states):
            if state in seen:
                self.fail((*path, index), f"duplicate state {state!r} (already at index {seen[state]})")
            seen[state] = index
        return tuple(states)

    def parse(self, path: FieldPath, text: str, robot: str | None) -> Event:
        try:
            return parse_event(text, robot=robot)
        except EventSyntaxError as err:
            self.fail(path, str(err))

    def check_references(self, path: FieldPath, event: Event, scene: Scene) -> None:
        for robot in sorted(event.owners):
            if robot not in scene.robots:
                self.fail(path, f"unknown robot {robot!r} in {event.name}; {_known('robots', scene.robots)}")
        if event.obj is not None and event.obj not in scene.objects:
            self.fail(
                path, f"unknown object {event.obj!r} in {event.name}; {_known('objects', scene.objects)}"
            )
        if event.workspace is not None and event.workspace not in scene.workspaces:
            self.fail(
                path,
                f"unknown workspace {event.workspace!r} in {event.name}; "
                f"{_known('workspaces', scene.workspaces)}",
            )
        if event.kind == "drop":
            self.check_holds(path, scene.objects[event.obj], event.workspace, scene)

    def check_holds(self, path: FieldPath, obj: MovableObject, workspace: str, scene: Scene) -> None:
        """A drop's workspace can hold the object: as wide and as deep, with a place clear of walls."""
        ws, size = scene.workspaces[workspace], show_length(obj.size, self.units)
        if not ws.is_point and min(ws.x[1] - ws.x[0], ws.y[1] - ws.y[0]) < obj.size:
            width, depth = (show_length(hi - lo, self.units) for lo, hi in (ws.x, ws.y))
            self.fail(
                path,
                f"workspace {workspace} ({width} x {depth}) cannot hold {obj.id} (a {size} square); "
                "expected a workspace at least as wide and deep as its goods",
            )
        if not _fits(scene, obj, ws):
            self.fail(
                path,
                f"workspace {workspace} is too small for {obj.id} ({size}): no drop position "
                "in it keeps the object clear of the walls",
            )


def _known(group: str, ids: Mapping[str, Any]) -> str:
    if not ids:
        return f"the scene has no {group}"
    return f"the scene's {group} are " + ", ".join(ids)


# ----------------------------------------------------------------------------------------------
# Public entry points
# ----------------------------------------------------------------------------------------------


def _planned_lengths(scene: Scene):
    """``(field path, length in mm)`` of every coordinate and size the planner encodes."""
    for i, wall in enumerate(scene.obstacles):
        for j, point in enumerate((wall.start, wall.end)):
            for k in (0, 1):
                yield ("scene", "obstacles", i, j, k), point[k]
    for rid, robot in scene.robots.items():
        yield ("scene", "robots", rid, "size"), robot.size
        for k in (0, 1):
            yield ("scene", "robots", rid, "pose", k), robot.pose[k]
    for oid, obj in scene.objects.items():
        yield ("scene", "objects", oid, "size"), obj.size
        for k in (0, 1):
            yield ("scene", "objects", oid, "position", k), obj.position[k]
    for wid, ws in scene.workspaces.items():
        for key in ("x", "y", "point"):
            for k, value in enumerate(getattr(ws, key) or ()):
                yield ("scene", "workspaces", wid, key, k), value


def _fits(scene: Scene, obj: MovableObject, workspace: Workspace) -> bool:
    """Whether some position in `workspace` holds `obj`'s square clear of every wall (touching allowed)."""
    from cosmop.squares import rectangle  # shapely: loaded only when a drop is checked

    places = rectangle(*workspace.centres(obj.size).ranges)
    return not places.difference(scene.blocked(obj.size / 2.0, within=places.bounds)).is_empty


def _reachable(initial: str, transitions) -> set[str]:
    """The states reachable from `initial` along `transitions` ``(source, event, target)``."""
    successors: dict[str, list[str]] = {}
    for source, _, target in transitions:
        successors.setdefault(source, []).append(target)
    seen, todo = {initial}, [initial]
    while todo:
        for nxt in successors.get(todo.pop(), ()):
            if nxt not in seen:
                seen.add(nxt)
                todo.append(nxt)
    return seen


def parse_scenario(data: Mapping[str, Any], source: str | os.PathLike[str] | None = None) -> Scenario:
    """Validate a scenario given as a mapping (e.g. already-parsed YAML or JSON).

    Parameters
    ----------
    data : Mapping
        The scenario, with the structure of a version-1 scenario file.
    source : str or os.PathLike, optional
        Where the data came from; used in error messages and kept as ``Scenario.source``.

    Returns
    -------
    Scenario
        The validated scenario.

    Raises
    ------
    ScenarioError
        If the data are not a valid scenario; the error names the field and what was expected.
    """
    file = None if source is None else os.fspath(source)
    return _Builder(data, file, None).build(None if source is None else Path(source))


def load_scenario(path: str | os.PathLike[str]) -> Scenario:
    """Load and validate a scenario file (YAML, format version 1).

    Parameters
    ----------
    path : str or os.PathLike
        The scenario file.

    Returns
    -------
    Scenario
        The validated scenario; ``source`` is `path`.

    Raises
    ------
    ScenarioError
        If the file cannot be read, is not valid YAML (the line is given), repeats a key, or is
        not a valid scenario; the error names the file, the field and what was expected.
    """
    file = os.fspath(path)
    text = read_text(path, ScenarioError, "a scenario file")
    data, marks = load_yaml(text, file, ScenarioError)
    return _Builder(data, file, marks).build(Path(path))
