"""CoSMoP: one robot's safe motion primitives and local mission as CLTLB(D) formulas.

Section IV of the paper.  The state at instant ``k`` (Section IV-C) is the robot's pose
:math:`q_r = (x, y, \\alpha)`, every object's :math:`q_b^j = (x, y, p, a)` (position, carried,
away) and the primitive :math:`\\pi` taken between ``k-1`` and ``k`` (``NONE`` at instant 0).
Positions are integers in mm, headings integers in degrees, as in the paper, unless the scene
needs finer poses (an odd side, a half-millimetre coordinate): then positions are exact
rationals (:func:`position_sort`); so is the heading when a given heading is not whole degrees
(:func:`heading_sort`).

Each primitive is a small object with a name and an ``effect``: the constraint relating
:math:`q` and :math:`\\bigcirc q` when :math:`\\bigcirc\\pi` is that primitive.  The
specification is :math:`\\Box(\\bigcirc(\\pi = \\text{prim}) \\rightarrow \\text{effect})` for
every primitive and object it applies to.  Adding a primitive means adding such an object;
the solver does not change.  GoTo uses the sound region constraints of
:mod:`cosmop.planning.regions` (never a wall or resting object overlapped, touching allowed).

The local mission, a sequence of events :math:`e_1 \\dots e_m`, is the nested until
:math:`a_1 \\mathbf{U} (g_1 \\wedge \\bigcirc(a_2 \\mathbf{U} (g_2 \\wedge \\cdots
\\bigcirc(a_m \\mathbf{U} (g_m \\wedge \\neg\\bigcirc true)))))`.  Here :math:`g_i` is the
event's goal (e.g. :math:`\\pi = \\text{PickUp}_j`) and :math:`a_i` the primitives allowed
before it (GoTo, and requests for objects the robot neither carries, places nor must pick).
This is the paper's encoding with its typo fixed (pick ends with PickUp, not DropOff), and it
ends the trace at the last event.

A local mission that branches is a DFA :math:`(Q, \\Sigma, \\delta, q_0, F)` over the
robot's events instead (:func:`automaton_parts`): an integer :math:`q` holds its state per
instant and an integer :math:`\\epsilon` the mission event the step performs (0: none).  A step
that performs :math:`e` satisfies :math:`e`'s goal (the same goals as the until chain) and
moves :math:`q` along :math:`\\delta(\\cdot, e)`; a step that performs none is GoTo or Req and
keeps :math:`q`; PickUp, DropOff and Res happen only as mission events; the last instant has
:math:`q \\in F`.  A sequence's DFA (a chain) gives the same plans as its until chain.

The paper's :math:`\\phi_{carry}` (an object's position changes only when it is dropped) is
part of every primitive's frame condition: GoTo, PickUp, Req and Res keep every position,
and DropOff moves only the object it drops.

The specification is a list of *named parts* (the initial state, each primitive, each wall
and object constraint of GoTo and DropOff, the mission), so an unsat core names what blocks a
mission.
"""

from __future__ import annotations

import copy
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from fractions import Fraction
from functools import cached_property, lru_cache
from types import MappingProxyType
from typing import Any

import shapely
from shapely.geometry.base import BaseGeometry

from cosmop.automata import DFA
from cosmop.docking import facing
from cosmop.events import Event, Primitive, realising_step
from cosmop.logic import (
    FALSE,
    TRUE,
    Always,
    Expr,
    Formula,
    Implies,
    Next,
    Not,
    Until,
    Var,
    conj,
    disj,
    eq,
    to_fraction,
)
from cosmop.planning.plan_types import State
from cosmop.planning.regions import HalfPlane, square_sides, wall_regions
from cosmop.scene import Scene, Wall, Workspace
from cosmop.squares import docking_places

NONE = 0

_Term = Expr | Fraction
"""An arithmetic term of the specification: a solver variable's expression, or an exact number."""


def _num(value: float) -> Fraction:
    return to_fraction(value)  # exact: a scenario's lengths lie on a micrometre grid


def position_sort(scene: Scene, start: State | None = None, spots: Iterable[tuple[float, float]] = ()) -> str:
    """The sort of the position variables: ``"int"`` (whole mm, the paper's) or ``"real"``.

    Walls and rectangular workspaces only bound positions (inequalities), so they never force
    a fractional pose; the poses a primitive forces are the start and home poses, the pick and
    drop poses (an object's position minus the two half-sides), point workspaces and, given a
    `start` state, where the robot and the objects are in it, and the `spots` drops are pinned
    to.  When all of those are whole millimetres, integers lose no plan; otherwise (an object
    of side 101 mm, a good at x = 0.5 mm) positions are exact rationals, so that no plan is lost to rounding.

    Parameters
    ----------
    scene : Scene
        The scene (robots, objects, workspaces; mm).
    start : State, optional
        Instant 0 when it is not the scenario.
    spots : iterable of (float, float)
        The centres (mm) drops are pinned to.
    """
    numbers = [v for r in scene.robots.values() for v in (r.size / 2, *r.pose[:2])]
    numbers += [v for o in scene.objects.values() for v in (o.size / 2, *o.position)]
    numbers += [v for w in scene.workspaces.values() if w.point is not None for v in w.point]
    if start is not None:  # a plan from a given state (mid-run) starts exactly there
        numbers += [*start.robot[:2], *(v for o in start.objects.values() for v in o.position)]
    numbers += [v for spot in spots for v in spot]
    return "int" if all(_whole(v) for v in numbers) else "real"


def _whole(value: float) -> bool:
    """Whether `value` is a whole number (mm), as :func:`_num` reads it; a float is tested
    directly (a warehouse's thousands of goods would otherwise each make three fractions)."""
    if isinstance(value, float):
        return value.is_integer()
    return _num(value).denominator == 1


def heading_sort(scene: Scene, robot: str, start: State | None = None) -> str:
    """The sort of the robot's heading variable: ``"int"`` (whole degrees, the paper's) or ``"real"``.

    A GoTo leaves the heading free (it ends turned to any heading), every other primitive keeps
    it, and only three kinds of constraint fix it to a value: the heading at instant 0 (the
    scenario's pose or, given a `start` state, the heading there), the home heading that
    ``return`` comes back to (the scenario's pose), and the docking headings of picks and drops
    (0, 90, 180 or 270 degrees).  When the robot's given headings are whole degrees, integers
    lose no plan; otherwise (a ROS file's -1.5708 rad, which is -90.000210459 degrees, or
    45.5 degrees) the heading is an exact rational, so that the plan starts and ends exactly
    at the given headings.  Other robots' headings never enter this robot's problem.

    Parameters
    ----------
    scene : Scene
        The scene (the robot's pose, degrees).
    robot : str
        The robot's id.
    start : State, optional
        Instant 0 when it is not the scenario.
    """
    headings = [scene.robots[robot].pose[2], *([start.robot[2]] if start is not None else [])]
    return "int" if all(_num(h).denominator == 1 for h in headings) else "real"


MOTION_MARGIN = Fraction(20)
"""mm a straight motion keeps from walls and resting objects, except where it starts or ends.

The plan may let a robot touch a wall or an object (a docking pose touches its object, a home
may touch a wall), but a controller cannot drive a robot *along* a face it touches: it stops a
cycle's braking distance short, a few millimetres off, and every move along the face then cuts
into it.  A motion therefore either stays this far from every obstacle, or approaches a
touching pose from this far away, or leaves one to this far away; sliding along a face within
the margin is not a plan."""


@dataclass(frozen=True)
class ObjectVars:
    """CLTLB(D) terms of one object: position (mm, :func:`position_sort`), carried, away (bool).

    A field no primitive of the robot can change is its value instead of a variable: a
    number for a position, :data:`~cosmop.logic.TRUE` or :data:`~cosmop.logic.FALSE` for a
    flag (:meth:`RobotProblem.obj`).  Substituting the value of a variable that the initial
    state fixes and every step keeps changes no plan, and removes the variable at every instant.
    """

    x: Var | Fraction
    y: Var | Fraction
    carried: Var | Formula
    away: Var | Formula

    @classmethod
    def named(cls, obj: str, sort: str = "int") -> ObjectVars:
        """Fresh variables for every field of `obj`.

        Parameters
        ----------
        obj : str
            The object's id (the variables are ``obj.x``, ``obj.y``, ``obj.p``, ``obj.a``).
        sort : {"int", "real"}
            The sort of the position variables (:func:`position_sort`).
        """
        return cls(
            Var(f"{obj}.x", sort), Var(f"{obj}.y", sort), Var(f"{obj}.p", "bool"), Var(f"{obj}.a", "bool")
        )

    @property
    def varies(self) -> bool:
        """Whether some field is a variable (some primitive of the robot can change it)."""
        return any(isinstance(t, Var) for t in (self.x, self.y, self.carried, self.away))

    @property
    def resting(self) -> Formula:
        """:math:`\\neg p \\wedge \\neg a`: the object lies where it is (an obstacle)."""
        return _negated(self.carried) & _negated(self.away)

    def read(self, state: Mapping[str, Any]) -> tuple[Any, Any, bool, bool]:
        """``(x, y, carried, away)`` in a state of the trace (values for the fixed fields).

        Parameters
        ----------
        state : Mapping[str, Any]
            One instant of a trace: each variable's value, by name.
        """
        values: list[Any] = [
            state[v.name] if isinstance(v, Var) else (v if isinstance(v, Fraction) else v == TRUE)
            for v in (self.x, self.y, self.carried, self.away)
        ]
        x, y, carried, away = values
        return x, y, carried, away


def _negated(flag: Var | Formula) -> Formula:
    """:math:`\\neg` `flag`, folded when it is a constant."""
    return FALSE if flag == TRUE else TRUE if flag == FALSE else ~flag


def _flag(value: bool) -> Formula:
    """A fixed flag as a formula."""
    return TRUE if value else FALSE


def _later(term: Any) -> Any:
    """:math:`\\bigcirc` `term`; a fixed value is its own successor."""
    return term.next() if isinstance(term, Var) else term


def _released(carried: Var | Formula) -> Formula:
    """:math:`\\neg\\bigcirc p`: not carried at the next instant."""
    return _negated(_later(carried))


@dataclass(frozen=True)
class ObstacleKey:
    """One obstacle as the specification's parts keep clear of it: a wall (by its index in the
    scene) or a resting object, with what the parts concern.

    A wall is two obstacles, one to drives and one to picks and drops (`handling`: the gripper,
    the good set down); an object is one.  A wall to drives or an object also has a stronger
    GoTo part (`past_ends`, :func:`corner_clearance_key`).  :attr:`text` is the obstacle's name
    in words, ``"wall 3"``, ``"wall 3 while handling"``, ``"object O2"``, ``"wall 3 past its
    ends"``.

    Parameters
    ----------
    wall : int, optional
        The wall's index in the scene's obstacles (a wall).
    obj : str, optional
        The object's id (an object); exactly one of `wall` and `obj` is given.
    handling : bool
        The wall to picks and drops, not to drives (walls only).
    past_ends : bool
        The stronger GoTo part: departures from past the obstacle's ends pass them clear (not
        with `handling`).

    Raises
    ------
    ValueError
        If not exactly one of `wall` and `obj` is given, or `handling` is given for an object
        or together with `past_ends`.
    """

    wall: int | None = None
    obj: str | None = None
    handling: bool = False
    past_ends: bool = False
    _hash: int = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if (self.wall is None) == (self.obj is None):
            raise ValueError("an obstacle is a wall or an object: give exactly one of them")
        if self.handling and (self.wall is None or self.past_ends):
            raise ValueError("only a wall has parts for picks and drops, and they have no stronger one")
        # keys index the constraints of every synthesis: hash them once
        object.__setattr__(self, "_hash", hash((self.wall, self.obj, self.handling, self.past_ends)))

    def __hash__(self) -> int:
        return self._hash

    def __reduce__(self) -> tuple[Any, tuple[int | None, str | None, bool, bool]]:
        # rebuilt where it is unpickled: a text's hash differs between processes
        return (_key, (self.wall, self.obj, self.handling, self.past_ends))

    @property
    def text(self) -> str:
        """The obstacle in words: ``"wall 3"``, ``"wall 3 while handling"``, ``"object O2"``,
        ``"wall 3 past its ends"``."""
        name = f"wall {self.wall}" if self.wall is not None else f"object {self.obj}"
        if self.handling:
            name += " while handling"
        return f"{name} past its ends" if self.past_ends else name

    @property
    def base(self) -> ObstacleKey:
        """The obstacle whose GoTo part this one strengthens, or the key itself."""
        return _key(self.wall, self.obj, self.handling, False) if self.past_ends else self

    def __str__(self) -> str:
        return self.text


@dataclass(frozen=True)
class ObstaclePart:
    """The name of a part of the specification that keeps the robot, or its goods, clear of one
    obstacle: the obstacle and the words that name the part.

    The part's name in words, :attr:`text`, is `before` + `ref` + `after`, e.g. ``"gripper
    clear of "`` + ``"wall 3"``, ``"room from "`` + ``"O2"`` + ``" while handling O1"``, or
    ``"wall 3"`` + ``" [[0, 0], [1, 0]]"`` (the wall's ends).

    Parameters
    ----------
    obstacle : ObstacleKey
        The obstacle the part keeps clear of.
    ref : str
        The words that name the obstacle in the part's name.
    before, after : str
        The words before and after them.
    """

    obstacle: ObstacleKey
    ref: str
    before: str = ""
    after: str = ""

    @property
    def text(self) -> str:
        """The part's name in words (as the explanations of an infeasible mission write it)."""
        return f"{self.before}{self.ref}{self.after}"

    def labelled(self, label: str) -> str:
        """The name with the wall called `label` (what it keeps the robot out of) instead of
        its number, and without its ends.

        Parameters
        ----------
        label : str
            The wall's label.
        """
        return f"{self.before}{label}{' past its ends' if self.obstacle.past_ends else ''}"

    def __str__(self) -> str:
        return self.text


PartName = str | ObstaclePart
"""The name of a part of the specification: words, or an obstacle part's name."""


@lru_cache(maxsize=1 << 16)
def _key(wall: int | None, obj: str | None, handling: bool, past_ends: bool) -> ObstacleKey:
    """One key per obstacle: equal keys are the same object, so dicts find them by identity
    (hundreds of thousands of lookups in one team's syntheses)."""
    return ObstacleKey(wall, obj, handling, past_ends)


def wall_key(i: int, handling: bool = False) -> ObstacleKey:
    """Wall `i` (its index in the scene) as an obstacle: to drives (``"wall 3"``), or to picks
    and drops (``"wall 3 while handling"``: the gripper, the good set down).

    Parameters
    ----------
    i : int
        The wall's index in the scene's obstacles.
    handling : bool
        The wall to picks and drops, not to drives.
    """
    return _key(i, None, handling, False)


def object_key(obj: str) -> ObstacleKey:
    """Object `obj` as an obstacle: ``"object O2"``.

    Parameters
    ----------
    obj : str
        The object's id.
    """
    return _key(None, obj, False, False)


def corner_clearance_key(key: ObstacleKey) -> ObstacleKey:
    """The stronger GoTo part for obstacle `key` (a wall to drives or an object): departures
    from past its ends pass them clear (:data:`PAST_AN_END`), ``"wall 3 past its ends"``.

    Its *corner clearance*: the ends of a wall, the corners of an object, are the corners of
    the obstacle grown by the robot's square (its configuration-space obstacle), and a motion
    that leaves the line of one side from beyond such a corner keeps :data:`PASSING` from it.

    It implies the obstacle's own GoTo part, and costs the solver more: lazy geometry
    (:mod:`cosmop.planning.obstacles`) adds it only for the obstacles a plan passes too close.

    Parameters
    ----------
    key : ObstacleKey
        The obstacle (:func:`wall_key` to drives, or :func:`object_key`).
    """
    return _key(key.wall, key.obj, False, True)


@dataclass(frozen=True)
class Action:
    """A primitive applied to an object (``None`` for GoTo), with its code in :math:`\\pi`."""

    primitive: Primitive
    obj: str | None
    code: int


@dataclass(frozen=True)
class RobotProblem:
    """Everything one robot's plan is about: scene, robot, local mission, allowed actions.

    Parameters
    ----------
    scene : Scene
        The scene (walls, robots, objects, workspaces; mm).
    robot : str
        The robot's id.
    mission : tuple of Event
        The local mission as a sequence of events (pick, drop, return, away).
    requests : bool
        Whether the robot may ask for objects to be moved away (Req).
    primitives : Mapping[Primitive, Encoding], optional
        The primitive library (default :data:`ENCODINGS`); each primitive says which objects
        it applies to (:meth:`Encoding.targets`), and the actions are all such pairs.
    start : State, optional
        Instant 0 when it is not the scenario: a robot that replans mid-mission starts where it
        is (exact numbers: the sorts follow them), with the objects as it knows them; ``return``
        still means the scenario's initial pose.
    unrequestable : frozenset of str
        Objects the robot may not ask for (nobody can move them, or asking deadlocks the team).
    automaton : DFA, optional
        A branching local mission: `mission` is then its alphabet (as events) and a plan may
        perform any word of its marked language (:func:`automaton_parts`).
    margin : Fraction
        mm a GoTo keeps from walls and resting objects between its ends (default
        :data:`MOTION_MARGIN`; 0 lets a motion slide along what it touches).
    obstacles : frozenset of ObstacleKey, optional
        Write the parts of only these obstacles (:func:`wall_key`, :func:`object_key`; a wall
        is two, one to drives and one to picks and drops; :func:`corner_clearance_key` of either names
        the stronger GoTo part); every wall and object by default.
        Lazy geometry (:mod:`cosmop.planning.obstacles`) writes the parts it needs only.
    spots : tuple of (Event, (float, float))
        Drops pinned to one spot: the object's centre (mm) where the drop event must put it,
        inside the event's workspace.  A robot that hands goods over to another drops them
        where the receiver was planned to pick them (:mod:`cosmop.team.handover`).

    Attributes
    ----------
    actions : tuple of Action
        Every (primitive, object) the robot may take, with its code in :math:`\\pi`.
    sort : str
        The sort of positions (:func:`position_sort`).
    heading_sort : str
        The sort of the heading (:func:`heading_sort`).
    objects : Mapping[str, ObjectVars]
        Each object's terms: variables, or values for the fields no action changes.

    Notes
    -----
    With the default library PickUp and DropOff apply to the objects the mission picks, Req to
    every other object (never one the robot carries, has placed or must pick: asking another
    robot to move goods the robot itself handles would make it wait on itself), Res
    to the objects of the ``away`` events the robot answers.
    """

    scene: Scene
    robot: str
    mission: tuple[Event, ...]
    requests: bool = True
    primitives: Mapping[Primitive, Encoding] | None = None
    start: State | None = None
    unrequestable: frozenset[str] = frozenset()
    automaton: DFA | None = None
    margin: Fraction = MOTION_MARGIN
    obstacles: frozenset[ObstacleKey] | None = None
    spots: tuple[tuple[Event, tuple[float, float]], ...] = ()
    actions: tuple[Action, ...] = field(init=False)
    sort: str = field(init=False)
    heading_sort: str = field(init=False)
    objects: Mapping[str, ObjectVars] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "mission", tuple(self.mission))
        primitives = ENCODINGS if self.primitives is None else self.primitives
        object.__setattr__(self, "primitives", MappingProxyType(dict(primitives)))
        acts = [(prim.name, obj) for prim in primitives.values() for obj in prim.targets(self)]
        object.__setattr__(self, "actions", tuple(Action(name, o, i + 1) for i, (name, o) in enumerate(acts)))
        object.__setattr__(self, "sort", position_sort(self.scene, self.start, (s for _, s in self.spots)))
        object.__setattr__(self, "heading_sort", heading_sort(self.scene, self.robot, self.start))
        object.__setattr__(self, "objects", MappingProxyType(self._object_terms()))

    def _object_terms(self) -> dict[str, ObjectVars]:
        """Each object's terms: variables for what some action changes, values for the rest.

        Only DropOff moves an object and only PickUp and DropOff change ``carried``, both for
        the objects the mission handles (:attr:`own_objects`); only Req changes ``away``, for
        its targets.  Every other field keeps its value at instant 0 (the scenario, or
        `start`) at every step (each primitive's frame condition), so it is that value.
        """
        handled = set(self.own_objects)
        asked = {a.obj for a in self.actions if a.primitive == Primitive.REQ}
        out: dict[str, ObjectVars] = {}
        for o in self.scene.objects:
            position, carried, away = self.at_start(o)
            if o not in handled and o not in asked:  # nothing varies: values only
                out[o] = ObjectVars(_num(position[0]), _num(position[1]), _flag(carried), _flag(away))
                continue
            v = ObjectVars.named(o, self.sort)
            out[o] = ObjectVars(
                v.x if o in handled else _num(position[0]),
                v.y if o in handled else _num(position[1]),
                v.carried if o in handled else _flag(carried),
                v.away if o in asked else _flag(away),
            )
        return out

    @cached_property
    def varying_objects(self) -> tuple[str, ...]:
        """The objects with a field that varies (:attr:`objects`: a variable), in the scene's
        order.  Every frame condition and flag over the objects needs only these, and
        :attr:`carried_elsewhere`: the others' fields are values that keep themselves."""
        return tuple(o for o, v in self.objects.items() if v.varies)

    @cached_property
    def carried_elsewhere(self) -> bool:
        """Whether an object's carried flag is a fixed true (another robot carries it, as
        `start` knows it): then this robot can never pick or drop, as it would hold two."""
        return any(v.carried == TRUE for v in self.objects.values())

    # asked for every object of every part: worked out once (a warehouse holds thousands of goods)
    @cached_property
    def own_objects(self) -> tuple[str, ...]:
        """Objects the mission picks or drops (never requested: the robot handles them), in the
        scene's order."""
        handled = {e.obj for e in self.mission if e.kind in ("pick", "drop")}
        return tuple(o for o in self.scene.objects if o in handled)

    @cached_property
    def answered_objects(self) -> tuple[str, ...]:
        """Objects of the ``away`` events this robot answers, in the scene's order."""
        answered = {e.obj for e in self.mission if e.kind == "away" and e.responder == self.robot}
        return tuple(o for o in self.scene.objects if o in answered)

    def with_obstacles(self, keys: frozenset[ObstacleKey]) -> RobotProblem:
        """The same problem writing the parts of only the obstacles `keys` (:attr:`obstacles`).

        ``dataclasses.replace`` would work out the actions, sorts and terms again; they do not
        depend on which obstacles are written.

        Parameters
        ----------
        keys : frozenset of ObstacleKey
            The obstacles whose parts are written.
        """
        out = copy.copy(self)
        object.__setattr__(out, "obstacles", frozenset(keys))
        return out

    # -- variables -----------------------------------------------------------------------------
    @property
    def x(self) -> Var:
        return Var("x", self.sort)

    @property
    def y(self) -> Var:
        return Var("y", self.sort)

    @property
    def h(self) -> Var:
        return Var("heading", self.heading_sort)

    @property
    def pi(self) -> Var:
        return Var("pi", "int")

    @property
    def state(self) -> Var:
        """:math:`q`, the state of the mission automaton (branching missions only)."""
        return Var("q", "int")

    @property
    def performed(self) -> Var:
        """:math:`\\epsilon`, the mission event the step performs: 1 + its index in `mission`, 0 none."""
        return Var("event", "int")

    def written(self, key: ObstacleKey) -> bool:
        """Whether the parts of obstacle `key` are written (:attr:`obstacles`).

        Parameters
        ----------
        key : ObstacleKey
            An obstacle (:func:`wall_key`, :func:`object_key`, :func:`corner_clearance_key`).
        """
        return self.obstacles is None or key in self.obstacles

    def walls(self, handling: bool = False) -> list[tuple[int, Wall]]:
        """``(index, wall)`` of the walls whose parts for drives (or for picks and drops, when
        `handling`) are written (:attr:`obstacles`).

        Parameters
        ----------
        handling : bool
            The walls to picks and drops, not to drives.
        """
        return [(i, self.scene.obstacles[i]) for i in self._written_walls(handling, past_ends=False)]

    def obstacle_objects(self) -> list[str]:
        """The objects whose parts as obstacles are written (:attr:`obstacles`)."""
        return self._written_objects(past_ends=False)

    def _written_walls(self, handling: bool, past_ends: bool | None) -> list[int]:
        """Indices of the walls with a written key of that `handling` and `past_ends` (``None``:
        either), ascending.  From the keys, not the scene: a warehouse has thousands of walls
        and a lazy problem writes a few."""
        if self.obstacles is None:
            return list(range(len(self.scene.obstacles)))
        return sorted(
            {
                k.wall
                for k in self.obstacles
                if k.wall is not None and k.handling == handling and past_ends in (None, k.past_ends)
            }
        )

    def _written_objects(self, past_ends: bool | None) -> list[str]:
        """The objects with a written key of that `past_ends` (``None``: either), in the scene's order."""
        if self.obstacles is None:
            return list(self.scene.objects)
        written = {k.obj for k in self.obstacles if k.obj is not None and past_ends in (None, k.past_ends)}
        return [o for o in self.scene.objects if o in written] if written else []

    def drive_obstacles(self) -> tuple[list[int], list[str]]:
        """The walls (indices) and objects with a GoTo part written (their own or the stronger,
        :func:`corner_clearance_key`)."""
        return self._written_walls(False, past_ends=None), self._written_objects(past_ends=None)

    def at_start(self, obj: str) -> tuple[tuple[float, float], bool, bool]:
        """``(position, carried, away)`` of `obj` at instant 0: in `start`, else the scenario's.

        Parameters
        ----------
        obj : str
            The object's id.
        """
        known = self.start.objects.get(obj) if self.start is not None else None
        if known is None:
            return self.scene.objects[obj].position, False, False
        return known.position, known.carried, known.away

    def drop_centres(self, event: Event) -> Workspace:
        """Where the drop `event` may put its object's centre: the workspace's
        :meth:`~cosmop.scene.Workspace.centres`, or the one spot it is pinned to (:attr:`spots`).

        Parameters
        ----------
        event : Event
            A drop event of the mission.
        """
        assert event.obj is not None and event.workspace is not None  # a drop names both
        for pinned, spot in self.spots:
            if pinned == event:
                return Workspace(event.workspace, point=spot)
        return self.scene.workspaces[event.workspace].centres(self.scene.objects[event.obj].size)

    def obj(self, obj: str) -> ObjectVars:
        """The terms of `obj` (:class:`ObjectVars`; fixed fields are values).

        Parameters
        ----------
        obj : str
            The object's id.
        """
        return self.objects[obj]

    @property
    def side(self) -> Fraction:
        return _num(self.scene.robots[self.robot].size)

    def code(self, primitive: str, obj: str | None = None) -> int | None:
        """Code of an action in :math:`\\pi`, or ``None`` if the robot may not take it.

        Parameters
        ----------
        primitive : str
            The primitive (a :class:`~cosmop.events.Primitive`).
        obj : str, optional
            The object it acts on (``None`` for GoTo).
        """
        for a in self.actions:
            if a.primitive == primitive and a.obj == obj:
                return a.code
        return None

    def is_action(self, primitive: str, obj: str | None = None) -> Formula:
        """:math:`\\pi` is the action, or false if the robot may not take it.

        Parameters
        ----------
        primitive : str
            The primitive (a :class:`~cosmop.events.Primitive`).
        obj : str, optional
            The object it acts on (``None`` for GoTo).
        """
        code = self.code(primitive, obj)
        return self.pi.eq(code) if code is not None else FALSE

    def requests_except(self, obj: str | None) -> Formula:
        """:math:`\\pi` is GoTo or a request for an object other than ``obj``.

        Parameters
        ----------
        obj : str or None
            The object not to request (``None``: every request is allowed).
        """
        return disj(
            [
                self.pi.eq(a.code)
                for a in self.actions
                if a.primitive == Primitive.GOTO or (a.primitive == Primitive.REQ and a.obj != obj)
            ]
        )

    def clearance(self, obj: str) -> Fraction:
        """:math:`d = (l_b + l_r)/2`, the centre distance when robot and object touch.

        Parameters
        ----------
        obj : str
            The object's id.
        """
        return (_num(self.scene.objects[obj].size) + self.side) / 2


def _less(term: _Term, amount: Fraction) -> _Term:
    """``term - amount``, leaving `term` as it is when `amount` is zero (a smaller formula)."""
    return term if amount == 0 else term - amount


def _docking_poses(
    p: RobotProblem, obj: str, ox: _Term, oy: _Term, d: Fraction
) -> list[tuple[int, _Term, _Term]]:
    """``(h, x, y)``: the robot centre that faces `obj` at ``(ox, oy)`` from heading ``h``, touching
    it, :math:`(o_x, o_y) - d\\,(\\cos h, \\sin h)`, for each of the object's docking headings
    (:attr:`~cosmop.scene.MovableObject.headings`); exact terms."""
    out: list[tuple[int, _Term, _Term]] = []
    for heading in p.scene.objects[obj].headings:
        ux, uy = facing(heading)
        out.append((heading, _less(ox, d * ux), _less(oy, d * uy)))
    return out


def _docked(p: RobotProblem, obj: str, ox: _Term, oy: _Term, d: Fraction) -> Formula:
    """The robot faces `obj` at ``(ox, oy)`` square on, from one of its sides, touching it:
    :math:`\\bigvee_h \\alpha = h \\wedge (x, y)` is the pose of :func:`_docking_poses`."""
    return disj(p.h.eq(h) & p.x.eq(x) & p.y.eq(y) for h, x, y in _docking_poses(p, obj, ox, oy, d))


def _static(*terms: Any) -> Formula:
    """Every variable among `terms` keeps its value (fixed values always do)."""
    return conj(v.next().eq(v) if v.sort != "bool" else eq(v.next(), v) for v in terms if isinstance(v, Var))


def _half_plane(h: HalfPlane, x: Expr, y: Expr) -> Formula:
    return h.a * x + h.b * y >= h.c


class Encoding:
    """A safe motion primitive: its name and the constraint between :math:`q` and :math:`\\bigcirc q`.

    Subclasses set ``name`` and implement :meth:`targets` (the objects it applies to, ``None``
    for a primitive without object) and :meth:`parts` (named formulas that hold whenever
    :math:`\\bigcirc \\pi` is this primitive applied to ``obj``).  A new primitive is a new
    subclass added to the library passed to :class:`RobotProblem`; the solver does not change
    (the plan format and the simulator need a :class:`~cosmop.events.Primitive` member and an
    executor too).
    """

    name: Primitive

    def targets(self, p: RobotProblem) -> tuple[str | None, ...]:
        """The objects the primitive applies to in `p` (``(None,)`` for one without object).

        Parameters
        ----------
        p : RobotProblem
            The robot's planning problem.
        """
        raise NotImplementedError

    def parts(self, p: RobotProblem, obj: str | None) -> list[tuple[PartName, Formula]]:
        """Named formulas that hold whenever :math:`\\bigcirc \\pi` is this primitive on `obj`.

        Parameters
        ----------
        p : RobotProblem
            The robot's planning problem.
        obj : str or None
            The object it acts on, one of :meth:`targets` (``None`` for one without object).
        """
        raise NotImplementedError


def _gripper_clear(p: RobotProblem, obj: str, ox: Expr, oy: Expr) -> list[tuple[PartName, Formula]]:
    """Robot and object squares in one region of every wall: no wall between them (the gripper).

    The regions of one wall computed for the two sizes are the same half-planes shifted by each
    square's support, so both squares in the i-th of them put their union on one side.
    """
    side = _num(p.scene.objects[obj].size)
    out: list[tuple[PartName, Formula]] = []
    for i, wall in p.walls(handling=True):
        pairs = zip(
            wall_regions(wall.start, wall.end, p.side), wall_regions(wall.start, wall.end, side), strict=True
        )
        out.append(
            (
                ObstaclePart(wall_key(i, handling=True), wall_key(i).text, "gripper clear of "),
                disj(_half_plane(a, p.x, p.y) & _half_plane(b, ox, oy) for a, b in pairs),
            )
        )
    return out


HANDLING_CLEARANCE = Fraction(1)
"""mm a robot keeps from every *other* resting object while it picks up or drops off.

Touching is allowed everywhere else, but a robot that stands touching one resting object
and puts another down on its other side (or picks one up there) is wedged: every way out
slides along a face it touches.  A millimetre of room lets it leave without touching."""


def _handling_room(
    p: RobotProblem, obj: str, places: list[BaseGeometry] | None
) -> list[tuple[PartName, Formula]]:
    """The robot keeps :data:`HANDLING_CLEARANCE` from every resting object but `obj`.

    `places` are where the robot's centre can be while handling `obj` (shapely geometries;
    ``None``: anywhere).  An object this robot never moves rests where it started: when it is
    far from every such place its constraint always holds, and is left out (a smaller formula).
    """
    out: list[tuple[PartName, Formula]] = []
    for o in p.obstacle_objects():
        if o == obj:
            continue
        size = _num(p.scene.objects[o].size)
        gap = (p.side + size) / 2 + HANDLING_CLEARANCE
        if o not in p.own_objects and places is not None:
            at = _resting(p, o)
            if at is not None:
                near = shapely.box(
                    at[0] - float(gap), at[1] - float(gap), at[0] + float(gap), at[1] + float(gap)
                )
                if not any(place.intersects(near) for place in places):
                    continue
        w = p.obj(o)
        apart = disj([p.x <= w.x - gap, p.x >= w.x + gap, p.y <= w.y - gap, p.y >= w.y + gap])
        name = ObstaclePart(object_key(o), o, "room from ", f" while handling {obj}")
        out.append((name, Implies(w.resting, apart)))
    return out


def _resting(p: RobotProblem, o: str) -> tuple[float, float] | None:
    """Where an object this robot never moves rests (``None``: carried at the start)."""
    if p.start is not None:
        state = p.start.objects.get(o)
        return None if state is None or state.carried else state.position
    return p.scene.objects[o].position


def _drop_places(p: RobotProblem, obj: str) -> list[BaseGeometry] | None:
    """Robot centres that drop `obj` in one of the mission's workspaces for it (``None``: any)."""
    d = float(p.clearance(obj))
    places: list[BaseGeometry] = []
    for e in p.mission:
        if e.kind == "drop" and e.obj == obj:
            ws = p.drop_centres(e)
            places += docking_places(*ws.ranges, d, p.scene.objects[obj].headings)
    return places or None


def _pick_places(p: RobotProblem, obj: str) -> list[BaseGeometry] | None:
    """Robot centres that pick `obj` up: facing where it starts or is dropped, from any side."""
    at = _resting(p, obj)
    if at is None:
        return None
    d = float(p.clearance(obj))
    here = docking_places((at[0], at[0]), (at[1], at[1]), d, p.scene.objects[obj].headings)
    return [*here, *(_drop_places(p, obj) or [])]


def _robot_static(p: RobotProblem) -> Formula:
    return _static(p.x, p.y, p.h)


def _objects_static(p: RobotProblem, *, carried: bool = True, skip: str | None = None) -> Formula:
    """Every object but `skip` keeps its position (and carried flag).  ``away`` flags have one
    frame axiom each instead (:func:`away_frames`): only a request changes one."""
    out: list[Var | Fraction | Formula] = []
    for o in p.varying_objects:  # the others' fields are values: they keep themselves
        if o == skip:
            continue
        v = p.obj(o)
        out += [v.x, v.y, *([v.carried] if carried else [])]
    return _static(*out)


def away_frames(p: RobotProblem) -> list[tuple[PartName, Formula]]:
    """:math:`\\Box(\\bigcirc\\top \\rightarrow (\\bigcirc a_o \\leftrightarrow a_o) \\vee
    \\bigcirc(\\pi = \\mathrm{Req}_o))` for each good the robot may request: only its request
    moves it away.

    The same as every other primitive keeping :math:`a_o` in its effect, written once per good
    instead of once per primitive and good (with N goods to request, N squared terms per
    instant).

    Parameters
    ----------
    p : RobotProblem
        The robot's planning problem.
    """
    out: list[tuple[PartName, Formula]] = []
    for a in p.actions:
        if a.primitive != Primitive.REQ or a.obj is None:
            continue
        flag = p.obj(a.obj).away
        if isinstance(flag, Var):
            kept = Always(Implies(Next(TRUE), eq(flag.next(), flag) | Next(p.pi.eq(a.code))))
            out.append((f"{a.obj} goes away only on request", kept))
    return out


STEEPNESS = 4
"""A motion that ends touching a face comes 1 mm closer to it per at most this many mm along it
(it meets the face at 14 degrees or more).  A shallow approach would hold the robot within a
millimetre or two of the face for a long way, which a controller cannot follow any better than
a slide.  A departure abreast of what it leaves needs no such bound: the executor first creeps
straight out from the exact pose it stands on, and the motion then gains the margin from there
(one from past an obstacle's end passes the end clear: :data:`PAST_AN_END`)."""


@dataclass(frozen=True)
class _Face:
    """The closed half-plane :math:`a x + b y \\ge c` of robot centres on one side of an obstacle.

    ``c`` is a number, or a term in a resting object's position.  :meth:`away` and
    :meth:`along` measure a displacement across and along the boundary, in the same scale.
    """

    a: Fraction
    b: Fraction
    c: _Term

    def holds(self, x: Expr, y: Expr) -> Formula:
        return self.a * x + self.b * y >= self.c

    def away(self, dx: Expr, dy: Expr) -> Expr:
        return self.a * dx + self.b * dy

    def along(self, dx: Expr, dy: Expr) -> Expr:
        return self.a * dy - self.b * dx


PASSING = Fraction(1, 10)
"""A motion that leaves a side of an obstacle from past the obstacle's end passes that end at
least this share of the margin away (2 mm), unless it leaves steeply (:data:`PAST_AN_END`).

A square robot that passes an end closer cannot correct its heading without its corner
touching the end: the controller stops there.  Abreast of the obstacle the question does not
arise (the gap only grows), and the solver, which puts points on the boundaries of what it is
allowed, would otherwise start such motions exactly on the side's line, right past the end."""

PAST_AN_END = ((STEEPNESS, 0), (49, 5), (499, 50))
"""``(r, k)``: ways to leave a side of an obstacle from past its end, less than
:data:`PASSING` margins from both: at least 1 mm away from the side per `r` mm towards the end,
from at least `k` margins past it.

The two gaps meet, as the motion passes the end, at a mean of the gap past the end and the
side's, weighted by the rates they change at: at least ``k / (r + 1)`` margins, which is
:data:`PASSING`; any slope as steep as an approach may start right at the end (it passes it
briefly, and the executor first creeps out of a start that close)."""


def _level(face: _Face, far: _Face, x: Expr, y: Expr, share: Fraction | int) -> Formula:
    """The robot centre :math:`(x, y)` is at least `share` margins inside `face` (`far` at one)."""
    return face.a * x + face.b * y >= (1 - share) * face.c + share * far.c


def _past_an_end(
    side: tuple[_Face, _Face], end: tuple[_Face, _Face], x: Expr, y: Expr, dx: Expr, dy: Expr, gain: Expr
) -> Formula:
    """The departure from `side` at :math:`(x, y)` by :math:`(dx, dy)`, gaining `gain` on it,
    passes the neighbouring side `end` (each: touching and at the margin) clear (:data:`PASSING`)."""
    towards = -end[0].away(dx, dy)  # how much nearer the end the motion comes
    out: list[Formula] = [
        end[0].a * x + end[0].b * y <= end[0].c
    ]  # abreast of the obstacle, or beyond this end
    out.append(_level(*side, x, y, PASSING) & _level(*end, x, y, PASSING))
    for rate, margins in PAST_AN_END:
        slope = towards <= rate * gain
        out.append(slope & _level(*end, x, y, margins) if margins else slope)
    return disj(out)


@lru_cache(maxsize=16384)  # robots of one size share their walls' formulas (pure, hashable)
def _apart(x: Var, y: Var, faces: tuple[tuple[_Face, _Face], ...], ends: bool = False) -> Formula:
    """A straight motion from :math:`(x, y)` to :math:`\\bigcirc(x, y)` clear of one obstacle.

    `faces` pairs each side on which a square touching the obstacle may lie with the same side
    moved away by the margin (which lies inside it); sides 0 and 1 are opposite, as are 2 and
    3.  Both ends lie on one side (then so does the swept hull: it is convex), and the motion
    either keeps the margin, or starts there and approaches the side's boundary at least
    :data:`STEEPNESS` steep, or departs from the side's boundary to the margin.  Abreast of the
    obstacle (not strictly inside either neighbouring side) the nearest part of the obstacle is
    the side itself, so a departure's gap only grows.  With `ends`, a departure from past an
    end must also pass that end clear (:func:`_past_an_end`); this formula implies the one
    without, and is what :func:`corner_clearance_key` names.  The gap is never held near zero.
    """
    nx, ny = x.next(), y.next()
    dx, dy = nx - x, ny - y
    out: list[Formula] = []
    for k, (touch, far) in enumerate(faces):
        if far is touch:
            out.append(touch.holds(x, y) & touch.holds(nx, ny))
            continue
        gain, along = touch.away(dx, dy), touch.along(dx, dy)
        steep = (along <= -STEEPNESS * gain) & (-along <= -STEEPNESS * gain)
        leaves = touch.holds(x, y) & far.holds(nx, ny)  # keeps the margin, or departs
        if ends:
            ends_of = faces[2:] if k < 2 else faces[:2]
            passed = [_past_an_end((touch, far), e, x, y, dx, dy, gain) for e in ends_of]
            leaves = leaves & (far.holds(x, y) | conj(passed))
        out.append(leaves | (far.holds(x, y) & touch.holds(nx, ny) & steep))
    return disj(out)


def _wall_sides(p: RobotProblem, wall: Wall, name: str) -> tuple[tuple[_Face, _Face], ...]:
    """The four sides of a wall for the robot's square, touching and at the margin."""
    touching = [_Face(h.a, h.b, h.c) for h in wall_regions(wall.start, wall.end, p.side, name)]
    if not p.margin:
        return tuple(zip(touching, touching, strict=True))
    grown = [_Face(h.a, h.b, h.c) for h in wall_regions(wall.start, wall.end, p.side + 2 * p.margin, name)]
    return tuple(zip(touching, grown, strict=True))


def _object_sides(v: ObjectVars, d: Fraction, m: Fraction) -> tuple[tuple[_Face, _Face], ...]:
    """Left, right, below and above an object at centre distance `d` (touching) and `d + m`."""
    touching = [_Face(*side) for side in square_sides(v.x, v.y, d)]
    far = [_Face(*side) for side in square_sides(v.x, v.y, d + m)] if m else touching
    return tuple(zip(touching, far, strict=True))


class GoTo(Encoding):
    """Move in a straight line; never overlap a wall or a resting object, never slide along one.

    Touching is allowed at either end of the motion; otherwise it keeps
    :attr:`RobotProblem.margin`, departs from touching to it, or approaches from it steeply
    (:data:`MOTION_MARGIN`, :data:`STEEPNESS`, :func:`_apart`).  The part named
    :func:`corner_clearance_key` also passes the obstacle's ends clear (:data:`PAST_AN_END`).
    """

    name = Primitive.GOTO

    def targets(self, p: RobotProblem) -> tuple[str | None, ...]:
        return (None,)

    def parts(self, p: RobotProblem, obj: str | None) -> list[tuple[PartName, Formula]]:
        x, y = p.x, p.y
        out: list[tuple[PartName, Formula]] = [("GoTo keeps the objects", _objects_static(p))]
        walls, objects = p.drive_obstacles()
        for i in walls:
            wall = p.scene.obstacles[i]
            if written := _goto_parts(p, wall_key(i)):
                sides = _wall_sides(p, wall, wall_key(i).text)
                coordinates = f" {[list(wall.start), list(wall.end)]}"
                out += [
                    (ObstaclePart(key, key.text, after=coordinates), _apart(x, y, sides, ends=key.past_ends))
                    for key in written
                ]
        for o in objects:
            if written := _goto_parts(p, object_key(o)):
                v = p.obj(o)
                sides = _object_sides(v, p.clearance(o), p.margin)
                out += [
                    (ObstaclePart(key, key.text), Implies(v.resting, _apart(x, y, sides, ends=key.past_ends)))
                    for key in written
                ]
        return out


def _goto_parts(p: RobotProblem, key: ObstacleKey) -> list[ObstacleKey]:
    """The obstacles of the GoTo parts written for obstacle `key`: its stronger one
    (:func:`corner_clearance_key`, which passes the ends clear), its own, or both, in that order
    (an unsat core shrunk by deleting parts in order then keeps the obstacle's own part where
    that alone blocks)."""
    return [k for k in (corner_clearance_key(key), key) if p.written(k)]


class PickUp(Encoding):
    """Pick ``obj`` up carrying nothing, facing one of its sides and touching it (:func:`_docked`)."""

    name = Primitive.PICKUP

    def targets(self, p: RobotProblem) -> tuple[str | None, ...]:
        return p.own_objects

    def parts(self, p: RobotProblem, obj: str | None) -> list[tuple[PartName, Formula]]:
        assert obj is not None  # PickUp acts on an object
        v, d = p.obj(obj), p.clearance(obj)
        assert isinstance(v.x, Var) and isinstance(v.y, Var)  # its own goods: their position varies
        # the robot's hands are empty now, hold `obj` next; the fixed flags: none is carried
        now = [_negated(p.obj(o).carried) for o in p.varying_objects]
        later = [(_later if o == obj else _released)(p.obj(o).carried) for o in p.varying_objects]
        carry = conj([_flag(not p.carried_elsewhere), *now, *later])
        pose = _docked(p, obj, v.x, v.y, d) & ~v.away
        out = [(f"PickUp {obj}", _robot_static(p) & carry & pose & _objects_static(p, carried=False))]
        return out + _gripper_clear(p, obj, v.x, v.y) + _handling_room(p, obj, _pick_places(p, obj))


class DropOff(Encoding):
    """Leave the carried ``obj`` in front of the robot (any docking heading, :func:`_docked`), never
    onto a wall or another object."""

    name = Primitive.DROPOFF

    def targets(self, p: RobotProblem) -> tuple[str | None, ...]:
        return p.own_objects

    def parts(self, p: RobotProblem, obj: str | None) -> list[tuple[PartName, Formula]]:
        assert obj is not None  # DropOff acts on an object
        v, d = p.obj(obj), p.clearance(obj)
        assert isinstance(v.x, Var) and isinstance(v.y, Var)  # its own goods: their position varies
        # only `obj` is held now, nothing next; the fixed flags: none is carried
        fixed = _flag(not p.carried_elsewhere)
        flags = {o: p.obj(o).carried for o in p.varying_objects}
        held = conj([fixed, *(flag if o == obj else _negated(flag) for o, flag in flags.items())])
        released = conj([fixed, *(_released(p.obj(o).carried) for o in p.varying_objects)])
        place = _docked(p, obj, v.x.next(), v.y.next(), d)
        rest = _objects_static(p, carried=False, skip=obj)
        out: list[tuple[PartName, Formula]] = [
            (f"DropOff {obj}", _robot_static(p) & held & released & place & rest)
        ]
        out += _gripper_clear(p, obj, v.x.next(), v.y.next()) + _handling_room(p, obj, _drop_places(p, obj))
        side = _num(p.scene.objects[obj].size)
        for i, wall in p.walls(handling=True):
            regions = wall_regions(wall.start, wall.end, side, wall_key(i).text)
            out.append(
                (
                    ObstaclePart(wall_key(i, handling=True), wall_key(i).text, f"{obj} dropped clear of "),
                    disj(_half_plane(h, v.x.next(), v.y.next()) for h in regions),
                )
            )
        for o in p.obstacle_objects():
            if o == obj:
                continue
            w = p.obj(o)
            gap = (side + _num(p.scene.objects[o].size)) / 2
            apart = disj(
                [
                    v.x.next() <= w.x - gap,
                    v.x.next() >= w.x + gap,
                    v.y.next() <= w.y - gap,
                    v.y.next() >= w.y + gap,
                ]
            )
            out.append(
                (ObstaclePart(object_key(o), o, f"{obj} dropped clear of "), Implies(w.resting, apart))
            )
        return out


class Req(Encoding):
    """Ask for ``obj`` to be moved away and wait, clear of every pose that picks it (each side)."""

    name = Primitive.REQ

    def targets(self, p: RobotProblem) -> tuple[str | None, ...]:
        if not p.requests:
            return ()
        return tuple(o for o in p.scene.objects if o not in p.own_objects and o not in p.unrequestable)

    def parts(self, p: RobotProblem, obj: str | None) -> list[tuple[PartName, Formula]]:
        assert obj is not None  # Req acts on an object
        v, d, side = p.obj(obj), p.clearance(obj), p.side
        assert isinstance(v.away, Var)  # a good it may request: its away flag varies
        flags = ~v.away & v.away.next() & _objects_static(p)
        room = [  # clear of every pose that picks it: the helper picks from a side of its choosing
            disj([p.x <= px - side, p.x >= px + side, p.y <= py - side, p.y >= py + side])
            for _, px, py in _docking_poses(p, obj, v.x, v.y, d)
        ]
        return [(f"Req {obj}", _robot_static(p) & flags & conj(room))]


class Res(Encoding):
    """Answer that ``obj`` (carried) has been moved away."""

    name = Primitive.RES

    def targets(self, p: RobotProblem) -> tuple[str | None, ...]:
        return p.answered_objects

    def parts(self, p: RobotProblem, obj: str | None) -> list[tuple[PartName, Formula]]:
        assert obj is not None  # Res acts on an object
        return [(f"Res {obj}", _robot_static(p) & _objects_static(p) & p.obj(obj).carried)]


ENCODINGS: Mapping[Primitive, Encoding] = MappingProxyType(
    {c.name: c() for c in (GoTo, PickUp, DropOff, Req, Res)}
)
"""The primitive library: each primitive's encoding, in the order of :class:`~cosmop.events.Primitive`."""


def _goal(p: RobotProblem, event: Event) -> tuple[Formula, Formula]:
    """(allowed primitives before the event, the event's goal at its instant)."""
    if event.kind == "return":
        x0, y0, h0 = p.scene.robots[p.robot].pose
        home = p.x.eq(_num(x0)) & p.y.eq(_num(y0)) & p.h.eq(_num(h0))
        return p.requests_except(None), home & (p.requests_except(None) | p.pi.eq(NONE))
    if event.kind not in ("pick", "drop", "away"):
        raise ValueError(f"unknown event kind {event.kind!r}")
    realised = realising_step(event, p.robot)
    assert realised is not None  # a pick, drop or away is realised by a step
    primitive, obj, _ = realised
    goal = p.is_action(primitive, obj)
    if event.kind == "drop":  # and the object inside the workspace
        assert event.obj is not None  # a drop names its object
        v = p.obj(event.obj)
        ws = p.drop_centres(event)
        if ws.point is not None:
            assert isinstance(v.x, Var) and isinstance(v.y, Var)  # its own goods: their position varies
            inside = v.x.eq(_num(ws.point[0])) & v.y.eq(_num(ws.point[1]))
        else:
            assert ws.x is not None and ws.y is not None  # a rectangle
            inside = conj(
                [v.x >= _num(ws.x[0]), v.x <= _num(ws.x[1]), v.y >= _num(ws.y[0]), v.y <= _num(ws.y[1])]
            )
        goal = goal & inside
    return p.requests_except(obj), goal


def mission_formula(p: RobotProblem, events: Sequence[Event] | None = None) -> Formula:
    """The local mission as nested until, ending the trace at its last event.

    Parameters
    ----------
    p : RobotProblem
        The robot's planning problem.
    events : sequence of Event, optional
        The events, in order (default the problem's mission).
    """
    events = p.mission if events is None else tuple(events)
    if not events:
        return Not(Next(TRUE))
    tail: Formula = Not(Next(TRUE))  # after the last event the trace ends
    phase: Formula = tail
    for event in reversed(events):
        allowed, goal = _goal(p, event)
        phase = Until(allowed | p.pi.eq(NONE), goal & tail)
        tail = Next(phase)
    return phase


def automaton_parts(p: RobotProblem) -> list[tuple[PartName, Formula]]:
    """The branching local mission ``p.automaton`` over the instants (see the module docstring).

    With :math:`g_e` the goal of event :math:`e` (:func:`_goal`), the parts are, for every
    instant :math:`k` (and :math:`k + 1` when it exists)

    * :math:`\\epsilon_0 = 0 \\wedge q_0 = q_0^{K}` or, for an event :math:`e` defined at
      :math:`q_0^{K}`, :math:`\\epsilon_0 = e \\wedge g_e \\wedge q_0 = \\delta(q_0^{K}, e)`;
    * :math:`\\epsilon_{k+1} = e \\rightarrow g_e(k+1) \\wedge \\bigvee_{s} (q_k = s \\wedge
      q_{k+1} = \\delta(s, e))` over the states where :math:`e` is defined;
    * :math:`\\epsilon_{k+1} = 0 \\rightarrow q_{k+1} = q_k \\wedge \\pi_{k+1} \\in
      \\{GoTo, Req\\}`;
    * at the last instant :math:`q_K \\in F`.

    So the events the plan performs, in order, form a word that takes the automaton to a
    marked state; no other PickUp, DropOff or Res is possible (they are mission events only).

    Parameters
    ----------
    p : RobotProblem
        The robot's planning problem.
    """
    dfa = p.automaton
    assert dfa is not None
    q, ev = p.state, p.performed
    columns = dfa.event_index()
    moves = []
    for i, event in enumerate(p.mission):
        j = columns[event.name]
        edges = [(s, int(dfa.delta[s, j])) for s in range(dfa.n_states) if dfa.delta[s, j] >= 0]
        goal = _goal(p, event)[1]
        along = disj(q.eq(s) & q.next().eq(t) for s, t in edges)
        moves.append(Implies(Next(ev.eq(i + 1)), Next(goal) & along))
    idle = Implies(Next(ev.eq(0)), q.next().eq(q) & Next(p.requests_except(None)))
    some = Next(disj(ev.eq(c) for c in range(len(p.mission) + 1)))
    first = [ev.eq(0) & q.eq(dfa.initial)]
    for i, event in enumerate(p.mission):
        target = int(dfa.delta[dfa.initial, columns[event.name]])
        if target >= 0:
            first.append(ev.eq(i + 1) & _goal(p, event)[1] & q.eq(target))
    final = disj(q.eq(int(f)) for f in range(dfa.n_states) if dfa.marked[f])
    return [
        ("mission: first instant", disj(first)),
        ("mission: steps", Always(Implies(Next(TRUE), conj([*moves, idle, some])))),
        ("mission: complete at the end", Always(Implies(Not(Next(TRUE)), final))),
    ]


def initial_state(p: RobotProblem) -> Formula:
    """Instant 0: the scenario's poses and positions, nothing carried or away, no primitive.

    With ``p.start`` (a replan mid-mission) instant 0 is that state instead.  Fields that are
    fixed values (:meth:`RobotProblem.obj`) already hold them and need no constraint.

    Parameters
    ----------
    p : RobotProblem
        The robot's planning problem.
    """
    x0, y0, h0 = p.start.robot if p.start is not None else p.scene.robots[p.robot].pose
    parts = [p.x.eq(_num(x0)), p.y.eq(_num(y0)), p.h.eq(_num(h0)), p.pi.eq(NONE)]
    for o in p.varying_objects:  # the others' values already hold
        position, carried, away = p.at_start(o)
        v = p.obj(o)
        for term, value in ((v.x, position[0]), (v.y, position[1])):
            if isinstance(term, Var):
                parts.append(term.eq(_num(value)))
        for flag, value in ((v.carried, carried), (v.away, away)):
            if isinstance(flag, Var):
                parts.append(flag if value else ~flag)
    return conj(parts)


def specification(p: RobotProblem, events: Sequence[Event] | None = None) -> list[tuple[PartName, Formula]]:
    """The named parts of :math:`\\phi_{\\mathcal{P}}(\\mathcal{M}) \\wedge \\phi_{K}` for one robot.

    Every part holds at instant 0 of a plan; their conjunction is the whole specification.

    Parameters
    ----------
    p : RobotProblem
        The robot's planning problem.
    events : sequence of Event, optional
        The events to plan, in order (default the problem's mission, or its automaton).
    """
    codes = [a.code for a in p.actions]
    primitives = p.primitives
    assert primitives is not None  # set by RobotProblem
    parts: list[tuple[PartName, Formula]] = [
        ("initial state", initial_state(p)),
        ("one primitive per step", Always(Implies(Next(TRUE), Next(disj(p.pi.eq(c) for c in codes))))),
    ]
    for action in p.actions:
        # one guard object for all the action's parts: the evaluator and the encoder look
        # formulas up by structure, and an equal but distinct guard costs a deep comparison
        guard = Next(p.pi.eq(action.code))
        for name, effect in primitives[action.primitive].parts(p, action.obj):
            parts.append((name, Always(Implies(guard, effect))))
    parts += away_frames(p)
    if p.automaton is not None and events is None:
        return parts + automaton_parts(p)
    parts.append(("mission", mission_formula(p, events)))
    return parts


def request_codes(p: RobotProblem) -> dict[int, str]:
    """Codes of the Req actions, with their objects.

    Parameters
    ----------
    p : RobotProblem
        The robot's planning problem.
    """
    return {a.code: a.obj for a in p.actions if a.primitive == Primitive.REQ and a.obj is not None}


def decode(p: RobotProblem, code: int) -> Action:
    """The action whose code in :math:`\\pi` is `code`.

    Parameters
    ----------
    p : RobotProblem
        The robot's planning problem.
    code : int
        A value of :math:`\\pi` (not :data:`NONE`).

    Raises
    ------
    ValueError
        If no action of `p` has that code.
    """
    for a in p.actions:
        if a.code == code:
            return a
    raise ValueError(f"no action has code {code}")


def events_of(mission: Iterable[Event | str]) -> tuple[Event, ...]:
    """`mission` as events (names are parsed).

    Parameters
    ----------
    mission : iterable of Event or str
        Events, or their names (``pick(R1,O1)``, ...).
    """
    from cosmop.events import parse_event

    return tuple(e if isinstance(e, Event) else parse_event(e) for e in mission)
