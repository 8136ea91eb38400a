"""The value types of a scenario: the scene (walls, robots, movable objects, workspaces,
people) and the mission, as small immutable values.

This module sits near the bottom of the house: every layer (missions, planning, control, simulation,
viz) speaks of a scenario in these types, and none of them need the file format.  The
scenario file is read and checked by :mod:`cosmop.scenario`, which builds these values.

Lengths are millimetres, angles degrees and times seconds; robots, objects and people are
axis-aligned squares of side ``size``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from fractions import Fraction
from pathlib import Path
from types import MappingProxyType
from typing import Any, Literal

from cosmop._frozen import reduce_frozen
from cosmop.docking import SIDES
from cosmop.errors import InputWarning
from cosmop.events import Event

__all__ = [
    "LENGTH_GRID",
    "MAX_LENGTH",
    "MAX_TASK_EVENTS",
    "Delivery",
    "DfaSpec",
    "Dynamics",
    "Human",
    "Mission",
    "MovableObject",
    "Order",
    "Robot",
    "Scenario",
    "Scene",
    "Wall",
    "Workspace",
]

LENGTH_GRID = Fraction(1, 1000)
"""Every length the planner uses (walls, poses, positions, sizes, workspaces) is a multiple of
this many millimetres (a micrometre); plans are exact on it."""

MAX_LENGTH = 1e9
"""The largest length or coordinate, in mm (1000 km)."""

MAX_TASK_EVENTS = 100
"""Most tasks (pick, drop and return events) one robot's mission may hold; its shortest plan is
searched up to 3 steps per event.  Messages (``msg``, ``away``) do not count: the planner adds
them itself when it coordinates the team, and the scenario and the planner count the same."""


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
        if rectangle:
            x, y = self._box()
            if x[0] > x[1] or y[0] > y[1]:
                raise ValueError(f"workspace {self.id}: ranges must be [lo, hi] with lo <= hi")

    def _box(self) -> tuple[Point, Point]:
        # The x and y ranges of a rectangle workspace (both given: __post_init__ checks it).
        assert self.x is not None and self.y is not None
        return self.x, self.y

    @property
    def is_point(self) -> bool:
        """Whether the workspace is a single point."""
        return self.point is not None

    @property
    def center(self) -> Point:
        """The centre of the rectangle, or the point (mm)."""
        if self.point is not None:
            return self.point
        x, y = self._box()
        return ((x[0] + x[1]) / 2.0, (y[0] + y[1]) / 2.0)

    @property
    def ranges(self) -> tuple[Point, Point]:
        """``(x range, y range)`` (mm); a point workspace gives ranges of zero width."""
        if self.point is not None:
            return (self.point[0], self.point[0]), (self.point[1], self.point[1])
        return self._box()

    def centres(self, size: float) -> Workspace:
        """Where the centre of a square of side `size` (mm) lies when the whole square is inside.

        A rectangle shrinks by ``size / 2`` on every side; a point workspace is its own answer
        (it names the object's position exactly).

        Parameters
        ----------
        size : float
            Side of the square, mm.

        Returns
        -------
        Workspace
            The workspace of allowed centres (same id).

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
        box_x, box_y = self._box()
        x, y = (box_x[0] + half, box_x[1] - half), (box_y[0] + half, box_y[1] - half)
        if x[0] > x[1] or y[0] > y[1]:
            raise ValueError(f"workspace {self.id} cannot hold a square of side {size:g} mm")
        return Workspace(self.id, x=x, y=y)

    def holds(self, x: float, y: float, size: float, tol: float = 0.0) -> bool:
        """Whether a square of side `size` (mm) centred at ``(x, y)`` lies wholly inside, within
        `tol` mm (a point workspace: the centre is the point): :meth:`centres` contains it.

        Parameters
        ----------
        x, y : float
            The square's centre, mm.
        size : float
            Side of the square, mm.
        tol : float, optional
            Slack in mm on every side (default 0: exact).

        Returns
        -------
        bool

        Examples
        --------
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
        box_x, box_y = self._box()
        return box_x[0] - tol <= x <= box_x[1] + tol and box_y[0] - tol <= y <= box_y[1] + tol


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
    """A wall: the straight segment from `start` to `end` (mm; the end points differ).

    `label` names a wall the planner adds itself (around another robot's space, say), so that
    a reason never names an internal piece as if the user had drawn it; a wall of the file has
    none and is named by its index there.  It takes no part in comparisons.
    """

    start: Point
    end: Point
    label: str | None = field(default=None, compare=False)

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
    units : {"mm", "m"}, optional
        The units the scenario file was written in (``"mm"``: millimetres and degrees, the
        default; ``"m"``: metres and radians).  Every number of the scene is in millimetres and
        degrees either way; this only says how messages show lengths, speeds and angles to the
        person who wrote the file (:mod:`cosmop.units`), so two scenes that differ only here
        are equal.
    """

    __reduce__ = reduce_frozen  # picklable for worker processes

    obstacles: tuple[Wall, ...]
    robots: Mapping[str, Robot]
    objects: Mapping[str, MovableObject] = field(default_factory=dict)
    workspaces: Mapping[str, Workspace] = field(default_factory=dict)
    humans: Mapping[str, Human] = field(default_factory=dict)
    dynamics: Dynamics = Dynamics()
    units: Literal["mm", "m"] = field(default="mm", compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "obstacles", tuple(self.obstacles))
        for name in ("robots", "objects", "workspaces", "humans"):
            object.__setattr__(self, name, _frozen_mapping(getattr(self, name)))

    def blocked(
        self, half: float, slack: float = 0.5, within: tuple[float, float, float, float] | None = None
    ) -> Any:
        """Where the centre of an axis-aligned square of half-side `half` (mm) overlaps a wall.

        Each wall grown by the square exactly (the convex hull of the square at both ends),
        less `slack` mm: touching stays free, and so does a gap exactly as wide as the square
        (the walls are shrunk one by one, so that gap is not closed by their union).  A shapely
        geometry (empty without walls).  Given ``within = (xmin, ymin, xmax, ymax)``, only the
        walls whose grown shape can meet that box are taken (the answer is the same inside it).

        Parameters
        ----------
        half : float
            Half the side of the square, mm.
        slack : float, optional
            How much less than the square each wall is grown by, mm (default 0.5).
        within : tuple of float, optional
            A box ``(xmin, ymin, xmax, ymax)``, mm, to which the answer may be limited.

        Returns
        -------
        shapely.Geometry
            The blocked region of centres.
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
        assert self.deliveries is not None  # exactly one of the three forms is given
        out: set[Event] = set()
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
class Order:
    """An order of a lifelong run: at time `at` an object becomes due at one of some workspaces.

    The goods exist from the start, where the scene puts them; the order makes them due.  It is
    a delivery (:class:`Delivery`) with a release time.

    Parameters
    ----------
    at : float
        When the order is released, s from the start of the run (>= 0).
    object : str
        The object to deliver.
    to : tuple of str
        The workspaces it may go to (any one of them).
    by : tuple of str
        The robots that may deliver it (all the scene's robots when the file does not say).
    """

    __reduce__ = reduce_frozen

    at: float
    object: str
    to: tuple[str, ...]
    by: tuple[str, ...]


@dataclass(frozen=True)
class Scenario:
    """A validated scenario.

    Parameters
    ----------
    name : str
        The scenario's name.
    scene : Scene
        Walls, robots, objects, workspaces and people.
    mission : Mission or None
        The global mission; None for a scenario that holds only an order stream.
    source : pathlib.Path, optional
        The file it was loaded from, as given to :func:`cosmop.scenario.load_scenario`.
    warnings : tuple of InputWarning, optional
        What the loader found implausible but not wrong (a robot 400 m wide in a metres
        file, ...), one record per finding; the library never prints them.  They describe the
        file, not the scenario, so two scenarios that differ only here are equal.
    orders : tuple of Order, optional
        The orders released over time, for a lifelong run (``cosmop run``), by release time.
    """

    name: str
    scene: Scene
    mission: Mission | None
    source: Path | None = None
    warnings: tuple[InputWarning, ...] = field(default=(), compare=False)
    orders: tuple[Order, ...] = ()

    @property
    def units(self) -> Literal["mm", "m"]:
        """The units the file was written in, which messages show lengths in (``Scene.units``)."""
        return self.scene.units
