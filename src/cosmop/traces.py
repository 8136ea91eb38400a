"""Simulation traces (``cosmop.trace/1``): the :class:`Trace` of a run, and its JSON file.

A :class:`Trace` holds a run frame by frame as numpy arrays over the frames and the ids of the
robots, people and objects.  The simulator makes it (:meth:`cosmop.sim.SimResult.trace`); the
animations and the web viewer (:mod:`cosmop.viz`) and the ROS 2 bag export
(:mod:`cosmop.export`) read it.  Units: mm, degrees and seconds
(:data:`cosmop.units.INTERNAL_UNITS`).

Its file (:meth:`Trace.to_json`, :meth:`Trace.save`, :func:`load_trace`) is JSON: ``format``
(:data:`TRACE_FORMAT`), ``scenario``, ``units`` (absent in older files: mm, degrees, s), ``dt``
(s), ``frames`` (each with ``t`` in s, ``robots`` ``{id: {"pose": [x, y, heading], "v", "w",
"carrying", "primitive", "waiting", "delayed", "awaits", "yields_to"}}``, ``humans`` and ``objects``
``{id: [x, y]}``), ``messages`` (each a mapping with at least ``t``, ``from`` and ``to``; other
keys are kept as they are, so new kinds of message pass through) and ``replans`` (absent when
none: each accepted replan's ``t``, ``robot`` and ``route``, where the robot went on from and
the steps it had left).  A robot state leaves out ``awaits`` (the message it waits for) and
``yields_to`` (the robot or person it gives way to) when they are null.  :func:`check_trace`
checks that shape (the TypedDicts below, :data:`STRUCTURE`) and names, in one line, the file,
the first field that is wrong, what was expected there and what it is::

    run.json: frames[3].robots.R1.v: expected a speed (mm/s), got 'fast' (line 1, column 512)
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Annotated, Any, Literal, NotRequired, cast, overload

import numpy as np
from pydantic import Field
from typing_extensions import TypedDict

from cosmop.errors import CosmopInputError, EventSyntaxError
from cosmop.events import Event, parse_event
from cosmop.io import atomic_path, collector_paused, read_text
from cosmop.reading import Structure, load_json, show
from cosmop.units import INTERNAL_UNITS, check_units_field

__all__ = [
    "STRUCTURE",
    "TRACE_FORMAT",
    "FrameModel",
    "MessageModel",
    "ReplanModel",
    "RobotState",
    "RobotStateModel",
    "RouteModel",
    "RouteStepModel",
    "Trace",
    "TraceError",
    "TraceFileModel",
    "as_trace",
    "check_trace",
    "load_trace",
    "message_label",
]

TRACE_FORMAT = "cosmop.trace/1"
"""The ``format`` of a trace file: what :meth:`Trace.to_json` writes and :func:`load_trace` reads."""

_LENGTH_DIGITS = 3  # a file's lengths (mm), angles (degrees) and speeds: to 0.001
_TIME_DIGITS = 6  # a file's times (s): to 1 µs


class TraceError(CosmopInputError, ValueError):
    """A trace that cannot be read or does not have the ``cosmop.trace/1`` shape.

    It is a :class:`ValueError` too: a malformed trace handed to a function is a bad value.
    """


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


# ----------------------------------------------------------------------------------------------
# The file's structure
# ----------------------------------------------------------------------------------------------
# TypedDicts, not models: a long run has millions of robot states, and pydantic validates a dict
# in less than half the time of a model instance.  Keys a mapping has beyond these are let
# through (a trace written by a newer or another tool may say more).

_Number = Annotated[float, Field(strict=True, allow_inf_nan=False)]
_Text = Annotated[str, Field(strict=True)]
_Flag = Annotated[bool, Field(strict=True)]
_Pose = tuple[_Number, _Number, _Number]
_Point = tuple[_Number, _Number]


class RobotStateModel(TypedDict):
    """A robot in a frame: its pose, and what the trace says about it besides."""

    pose: _Pose
    v: NotRequired[_Number]
    w: NotRequired[_Number]
    carrying: NotRequired[_Text | None]
    primitive: NotRequired[_Text | None]
    waiting: NotRequired[_Flag]
    delayed: NotRequired[_Flag]
    awaits: NotRequired[_Text | None]
    yields_to: NotRequired[_Text | None]


class FrameModel(TypedDict):
    """A frame: its time (s), and where the robots, people and objects are."""

    t: _Number
    robots: NotRequired[dict[str, RobotStateModel]]
    humans: NotRequired[dict[str, _Point]]
    objects: NotRequired[dict[str, _Point]]


MessageModel = TypedDict("MessageModel", {"t": _Number, "from": _Text, "to": _Text})
"""A message: its time (s), sender and receiver (other keys pass through as they are)."""


class RouteStepModel(TypedDict):
    """A step of a replanned route."""

    pose: _Pose
    primitive: _Text
    about: NotRequired[_Text | None]


RouteModel = TypedDict("RouteModel", {"from": _Pose, "steps": list[RouteStepModel]})
"""A replanned route: the pose the robot went on from, and the steps it had left."""


class ReplanModel(TypedDict):
    """An accepted replan: its time (s), the robot and its route."""

    t: _Number
    robot: _Text
    route: RouteModel


class TraceFileModel(TypedDict):
    """The whole trace file."""

    format: Literal["cosmop.trace/1"]  # TRACE_FORMAT
    scenario: NotRequired[_Text | None]
    units: NotRequired[Any]  # cosmop.units.check_units_field says what it must be
    dt: NotRequired[Annotated[float, Field(strict=True, allow_inf_nan=False, gt=0)]]
    frames: Annotated[list[FrameModel], Field(min_length=1)]
    messages: NotRequired[list[MessageModel]]
    replans: NotRequired[list[ReplanModel]]


_POSE = "[x, y, heading] (mm, mm, degrees)"
_ROBOT = ("frames", "#", "robots", "*")
_STEP = ("replans", "#", "route", "steps", "#")

EXPECTED: dict[tuple[str, ...], str] = {
    (): f"a JSON object with keys format, frames (a {TRACE_FORMAT} file)",
    ("format",): f"{TRACE_FORMAT!r}, the trace file format",
    ("scenario",): "the scenario's name (text), or null",
    ("dt",): "the cycle in seconds (a positive number)",
    ("frames",): "a non-empty list of frames",
    ("frames", "#"): "a frame {t, robots, humans, objects}",
    ("frames", "#", "t"): "the frame's time t (s), a finite number",
    ("frames", "#", "robots"): "a mapping of robot states by id",
    _ROBOT: "a robot state {pose, v, w, carrying, primitive, waiting, delayed, awaits, yields_to}",
    (*_ROBOT, "pose"): _POSE,
    (*_ROBOT, "pose", "#"): "a finite number",
    (*_ROBOT, "v"): "a speed (mm/s)",
    (*_ROBOT, "w"): "a turning rate (deg/s)",
    (*_ROBOT, "carrying"): "the id of the object carried, or null",
    (*_ROBOT, "primitive"): "the name of a primitive, or null",
    (*_ROBOT, "waiting"): "true or false",
    (*_ROBOT, "delayed"): "true or false",
    (*_ROBOT, "awaits"): "the name of the message the robot waits for, or null",
    (*_ROBOT, "yields_to"): "the id of the robot or person the robot gives way to, or null",
    **{("frames", "#", group): "a mapping of positions [x, y] (mm) by id" for group in ("humans", "objects")},
    **{("frames", "#", group, "*"): "a position [x, y] (mm)" for group in ("humans", "objects")},
    **{("frames", "#", group, "*", "#"): "a finite number (mm)" for group in ("humans", "objects")},
    ("messages",): "a list of messages",
    ("messages", "#"): "a message {t, from, to, ...}",
    ("messages", "#", "t"): "the message's time t (s), a finite number",
    ("messages", "#", "from"): "the id of the robot that sent it",
    ("messages", "#", "to"): "the id of the robot it was sent to",
    ("replans",): "a list of replans",
    ("replans", "#"): "a replan {t, robot, route}",
    ("replans", "#", "t"): "the replan's time t (s), a finite number",
    ("replans", "#", "robot"): "the id of the robot replanned",
    ("replans", "#", "route"): "a route {from, steps}",
    ("replans", "#", "route", "from"): _POSE,
    ("replans", "#", "route", "from", "#"): "a finite number",
    ("replans", "#", "route", "steps"): "a list of steps",
    _STEP: "a step {pose, primitive, about}",
    (*_STEP, "pose"): _POSE,
    (*_STEP, "pose", "#"): "a finite number",
    (*_STEP, "primitive"): "the name of a primitive",
    (*_STEP, "about"): "the object or message the step is about, or null",
}
"""What each field of a trace file expects, in words (patterns as :class:`cosmop.reading.Structure`'s)."""

STRUCTURE = Structure(TraceFileModel, EXPECTED, TraceError)
"""The trace file's structure: its TypedDicts, its words, and :class:`TraceError`."""

_STATE_KEYS = frozenset(RobotStateModel.__annotations__) - {"pose"}  # all but the pose: optional
_SPARSE_KEYS = ("awaits", "yields_to")  # written only where not null: most robots wait for nothing


def _check(data: Any, file: str | None, text: str | None) -> dict[str, Any]:
    """`data` as a dict once its shape is checked (the file's `text`, if given, for the line)."""
    if isinstance(data, Mapping) and "format" in data and data["format"] != TRACE_FORMAT:
        problem = f"expected {EXPECTED[('format',)]}, got {show(data['format'])}"
        raise STRUCTURE.fail(("format",), problem, file, text)
    STRUCTURE.validate(data, file, text)
    if (units_problem := check_units_field(data.get("units"))) is not None:
        raise STRUCTURE.fail(("units",), units_problem, file, text)
    return dict(data)


def check_trace(data: Any, file: str | os.PathLike[str] | None = None) -> dict[str, Any]:
    """Check the shape of a parsed trace and return it.

    Parameters
    ----------
    data : Any
        The parsed ``cosmop.trace/1`` JSON.
    file : str or os.PathLike, optional
        The file it came from, for the error.

    Returns
    -------
    dict
        `data` (a shallow copy), its values as they are.

    Raises
    ------
    TraceError
        In one line: the file, the first wrong field, what was expected there and what it is.
    """
    return _check(data, None if file is None else os.fspath(file), None)


@dataclass(frozen=True)
class RobotState:
    """One robot in one frame of a :class:`Trace` (:meth:`Trace.robots_at`).

    Attributes
    ----------
    pose : tuple of float
        ``(x, y, heading)``: mm, mm, degrees.
    carrying : str or None
        The id of the object the robot carries.
    waiting : bool
        Whether the robot waits for an answer (a ``Req``).
    """

    pose: tuple[float, float, float]
    carrying: str | None = None
    waiting: bool = False


_ARRAYS = {  # every array of a Trace: its dtype, the ids along its second axis, its last axis
    "t": (float, None, ()),
    "poses": (float, "robot_ids", (3,)),
    "v": (float, "robot_ids", ()),
    "w": (float, "robot_ids", ()),
    "carrying": (int, "robot_ids", ()),
    "primitive": (int, "robot_ids", ()),
    "waiting": (bool, "robot_ids", ()),
    "delayed": (bool, "robot_ids", ()),
    "awaits": (object, "robot_ids", ()),
    "yields_to": (object, "robot_ids", ()),
    "humans": (float, "human_ids", (2,)),
    "objects": (float, "object_ids", (2,)),
}


# Arrays have no single truth value, so a trace equals only itself (eq=False).
@dataclass(frozen=True, eq=False)
class Trace:
    """A run frame by frame: numpy arrays over the frames, and the ids they follow.

    The arrays are read-only.  A thing a frame does not show is NaN there: a trace written by
    another tool may name different robots, people or objects in different frames.

    Attributes
    ----------
    t : ndarray, shape (n,)
        Time of each frame, s.
    robot_ids : tuple of str
        The robots, in the order of the robot arrays' second axis.
    poses : ndarray, shape (n, R, 3)
        Each robot's pose ``(x, y, heading)`` in mm, mm and degrees; NaN where a frame lacks it.
    v, w : ndarray, shape (n, R), optional
        Speed (mm/s) and turning rate (deg/s) of each robot; None when the trace has none.
    carrying : ndarray of int, shape (n, R), optional
        Index into `object_ids` of the object each robot carries, -1 for none.
    primitive : ndarray of int, shape (n, R), optional
        Index into `primitive_names` of what each robot executes.
    primitive_names : tuple of (str or None)
        What the `primitive` indices stand for (the simulator's 0 is None: finished).
    waiting : ndarray of bool, shape (n, R), optional
        Whether each robot waits for an answer (a ``Req``).
    delayed : ndarray of bool, shape (n, R), optional
        Whether a delay has stopped each robot (:mod:`cosmop.sim.delays`); None: a run without
        delays (older files have none either).
    awaits : ndarray of object, shape (n, R), optional
        The name of the message each robot stands waiting for (``msg(...)`` or ``away(...)``),
        None where it waits for none; None: the trace does not say.
    yields_to : ndarray of object, shape (n, R), optional
        The id of the robot or person each robot gives way to (it stands although its step
        would have it move, :data:`cosmop.sim.recording.YIELD_AFTER_S`), None where none.
    human_ids, object_ids : tuple of str
        The people and objects, in the order of their arrays' second axis.
    humans, objects : ndarray, shape (n, H, 2) and (n, O, 2)
        Positions, mm; NaN where a frame lacks them.  None (the default): none.
    messages : tuple of Mapping
        The messages, as given: ``t`` (s), ``from``, ``to`` and any other keys.
    replans : tuple of Mapping
        The accepted replans in time order: ``t`` (s), ``robot`` and ``route`` (``from``: the
        pose it went on from; ``steps``: each step left, ``pose``, ``primitive`` and ``about``,
        the object or message it is about).
    scenario : str or None
        The scenario's name.
    dt : float or None
        The control cycle, s.
    units : Mapping[str, str]
        The file's ``units`` (:data:`cosmop.units.INTERNAL_UNITS`: mm, degrees, seconds).

    Examples
    --------
    >>> trace = Trace(t=np.array([0.0, 0.1]), robot_ids=("R1",), poses=[[[0, 0, 0]], [[10.0004, 0, 90]]])
    >>> trace.to_json()["frames"][1]
    {'t': 0.1, 'robots': {'R1': {'pose': [10.0, 0.0, 90.0]}}, 'humans': {}, 'objects': {}}
    >>> Trace.from_json(trace.to_json()).poses[1].tolist()
    [[10.0, 0.0, 90.0]]
    """

    t: np.ndarray
    robot_ids: tuple[str, ...]
    poses: np.ndarray
    v: np.ndarray | None = None
    w: np.ndarray | None = None
    carrying: np.ndarray | None = None
    primitive: np.ndarray | None = None
    primitive_names: tuple[str | None, ...] = ()
    waiting: np.ndarray | None = None
    delayed: np.ndarray | None = None
    awaits: np.ndarray | None = None
    yields_to: np.ndarray | None = None
    human_ids: tuple[str, ...] = ()
    humans: np.ndarray | None = None
    object_ids: tuple[str, ...] = ()
    objects: np.ndarray | None = None
    messages: tuple[Mapping[str, Any], ...] = ()
    replans: tuple[Mapping[str, Any], ...] = ()
    scenario: str | None = None
    dt: float | None = None
    units: Mapping[str, str] = field(default_factory=lambda: MappingProxyType(dict(INTERNAL_UNITS)))

    def __post_init__(self) -> None:
        for name in ("robot_ids", "primitive_names", "human_ids", "object_ids", "messages", "replans"):
            object.__setattr__(self, name, tuple(getattr(self, name)))
        object.__setattr__(self, "units", MappingProxyType(dict(self.units)))
        t = np.asarray(self.t, dtype=float)
        if t.ndim != 1:
            raise ValueError(f"Trace.t must have the shape (n,), got {t.shape}")
        for name, (dtype, ids, tail) in _ARRAYS.items():
            value = getattr(self, name)
            if value is None and name in ("humans", "objects"):
                value = np.empty((len(t), 0, 2))
            if value is None:
                continue
            # A read-only view: the trace cannot change its arrays, and the caller's stay as they are.
            array: np.ndarray = np.asarray(value, dtype=dtype).view()
            shape = (len(t),) if ids is None else (len(t), len(getattr(self, ids)), *tail)
            if array.shape != shape:
                raise ValueError(f"Trace.{name} must have the shape {shape}, got {array.shape}")
            array.flags.writeable = False
            object.__setattr__(self, name, array)
        if self.dt is not None and not (_is_number(self.dt) and self.dt > 0):
            raise ValueError(f"Trace.dt must be a positive number of seconds, got {self.dt!r}")

    # -- reading -----------------------------------------------------------------------------

    def ids(self, group: str) -> tuple[str, ...]:
        """The ids of ``"robots"``, ``"humans"`` or ``"objects"``, in the order of their arrays.

        Parameters
        ----------
        group : {"robots", "humans", "objects"}
            Which things.
        """
        return {"robots": self.robot_ids, "humans": self.human_ids, "objects": self.object_ids}[group]

    def positions(self, group: str) -> np.ndarray:
        """Positions ``(x, y)`` (mm) of ``"robots"``, ``"humans"`` or ``"objects"``: shape (n, N, 2).

        Parameters
        ----------
        group : {"robots", "humans", "objects"}
            Which things.
        """
        return self.poses[:, :, :2] if group == "robots" else cast(np.ndarray, getattr(self, group))

    def seen(self, group: str, every: int = 1) -> np.ndarray:
        """Every position (mm) of `group` that a frame shows, every `every`-th frame: shape (m, 2).

        Parameters
        ----------
        group : {"robots", "humans", "objects"}
            Which things.
        every : int
            Take every `every`-th frame (1: all).
        """
        points = self.positions(group)[::every].reshape(-1, 2)
        shown: np.ndarray = points[~np.isnan(points[:, 0])]  # numpy types a masked index as Any
        return shown

    def robots_at(self, k: int) -> dict[str, RobotState]:
        """The robots frame `k` shows, in the order of :attr:`robot_ids`.

        Parameters
        ----------
        k : int
            The frame's index.
        """
        poses = self.poses[k].tolist()
        carrying = self.carrying[k].tolist() if self.carrying is not None else [-1] * len(poses)
        waiting = self.waiting[k].tolist() if self.waiting is not None else [False] * len(poses)
        return {
            rid: RobotState(tuple(pose), self.object_ids[c] if c >= 0 else None, w)
            for rid, pose, c, w in zip(self.robot_ids, poses, carrying, waiting, strict=True)
            if not math.isnan(pose[0])
        }

    def points_at(self, group: str, k: int) -> dict[str, tuple[float, float]]:
        """Where frame `k` shows the ``"humans"`` or the ``"objects"`` (mm), by id.

        Parameters
        ----------
        group : {"humans", "objects"}
            Which things.
        k : int
            The frame's index.
        """
        points = self.positions(group)[k].tolist()
        return {pid: (x, y) for pid, (x, y) in zip(self.ids(group), points, strict=True) if not math.isnan(x)}

    def carried_at(self, k: int) -> dict[str, str]:
        """The objects carried in frame `k`: the carrier's id by object id.

        Parameters
        ----------
        k : int
            The frame's index.
        """
        return {s.carrying: rid for rid, s in self.robots_at(k).items() if s.carrying is not None}

    # -- the file -----------------------------------------------------------------------------

    def rounded(self) -> Trace:
        """This trace at the precision of its file: lengths, degrees and speeds to 0.001, times to 1 µs."""
        return replace(
            self,
            t=_rounded(self.t, _TIME_DIGITS),
            poses=_rounded(self.poses, _LENGTH_DIGITS),
            v=_rounded(self.v, _LENGTH_DIGITS),
            w=_rounded(self.w, _LENGTH_DIGITS),
            humans=_rounded(self.humans, _LENGTH_DIGITS),
            objects=_rounded(self.objects, _LENGTH_DIGITS),
        )

    def to_json(self) -> dict[str, Any]:
        """The ``cosmop.trace/1`` file as a JSON-ready dict: one frame per entry of :attr:`t`.

        Lengths, degrees and speeds are rounded to 0.001, times to 1 µs (:meth:`rounded`); what
        a frame does not show (NaN) and the keys the trace has no array for are left out.
        """
        return {
            **self._json_head(),
            "frames": self.rounded()._json_frames(slice(None)),
            "messages": [dict(m) for m in self.messages],
            **({"replans": [dict(r) for r in self.replans]} if self.replans else {}),
        }

    def _json_head(self) -> dict[str, Any]:
        """The file's fields before its frames."""
        data: dict[str, Any] = {"format": TRACE_FORMAT}
        if self.scenario is not None:
            data["scenario"] = self.scenario
        data["units"] = dict(self.units)
        if self.dt is not None:
            data["dt"] = self.dt
        return data

    def _json_frames(self, rows: slice) -> list[dict[str, Any]]:
        """The frames `rows` as the file writes them (this trace already :meth:`rounded`)."""
        robots = self._json_robots(rows)
        humans, objects = (_json_points(self.ids(g), self.positions(g)[rows]) for g in ("humans", "objects"))
        return [
            {"t": t, "robots": robots[k], "humans": humans[k], "objects": objects[k]}
            for k, t in enumerate(self.t[rows].tolist())
        ]

    def _json_robots(self, rows: slice) -> list[dict[str, dict[str, Any]]]:
        """The robot states of the frames `rows` as the file writes them (this trace already
        :meth:`rounded`)."""
        objects, names = [*self.object_ids, None], self.primitive_names  # carrying -1: objects[-1], None
        poses, v, w, carrying, primitive, waiting, delayed, awaits, yields_to = (
            None if a is None else a[rows]
            for a in (
                self.poses, self.v, self.w, self.carrying, self.primitive, self.waiting, self.delayed,
                self.awaits, self.yields_to,
            )
        )  # fmt: skip
        assert poses is not None  # every trace has poses
        columns = {"pose": poses.tolist()}
        for key, array, to_json in (
            ("v", v, None),
            ("w", w, None),
            ("carrying", carrying, objects.__getitem__),
            ("primitive", primitive, names.__getitem__),
            ("waiting", waiting, None),
            ("delayed", delayed, None),
            ("awaits", awaits, None),
            ("yields_to", yields_to, None),
        ):
            if array is not None:
                values = array.tolist()
                columns[key] = values if to_json is None else [list(map(to_json, row)) for row in values]
        # NaN (not shown) is looked for value by value only in the arrays that have one
        holes = any(np.isnan(a).any() for a in (poses, v, w) if a is not None and a.dtype.kind == "f")
        frames = []
        for k in range(len(poses)):
            robots = {}
            for i, rid in enumerate(self.robot_ids):
                if not holes:
                    state = {key: values[k][i] for key, values in columns.items()}
                elif not math.isnan(columns["pose"][k][i][0]):  # else: this frame does not show it
                    state = {key: values[k][i] for key, values in columns.items()}
                    state = {n: x for n, x in state.items() if not (isinstance(x, float) and x != x)}
                else:
                    continue
                for key in _SPARSE_KEYS:
                    if key in state and state[key] is None:
                        del state[key]
                robots[rid] = state
            frames.append(robots)
        return frames

    @classmethod
    def from_json(cls, data: Any, file: str | os.PathLike[str] | None = None) -> Trace:
        """The trace of a parsed ``cosmop.trace/1`` file, once :func:`check_trace` has checked it.

        The ids of each kind are taken in the order the frames first name them (objects that
        are only ever carried come last); a frame that does not name one is NaN there.  Keys no
        robot state has (``v``, ``w``, ``carrying``, ``primitive``, ``waiting``, ``delayed``,
        ``awaits``, ``yields_to``) give None.

        Parameters
        ----------
        data : Any
            The parsed JSON.
        file : str or os.PathLike, optional
            The file it came from, for the error.

        Returns
        -------
        Trace

        Raises
        ------
        TraceError
            Naming `file`, the first wrong field, what was expected there and what it is.
        """
        return cls._from_checked(check_trace(data, file))

    @classmethod
    def _from_checked(cls, checked: Mapping[str, Any]) -> Trace:
        """The trace of a parsed file whose shape is checked."""
        frames = checked["frames"]
        robot_ids = _first_seen(frames, "robots")
        columns = _robot_columns(frames, robot_ids)
        carried = [oid for row in columns.get("carrying", ()) for oid in row if oid is not None]
        object_ids = tuple(dict.fromkeys([*_first_seen(frames, "objects"), *carried]))
        names: tuple[str | None, ...] = ()
        if "carrying" in columns:
            index = {oid: j for j, oid in enumerate(object_ids)} | {None: -1}
            columns["carrying"] = _indices(columns["carrying"], index, len(robot_ids))
        if "primitive" in columns:
            named = [p for row in columns["primitive"] for p in row if p is not None]
            names = (None, *dict.fromkeys(named))  # 0: none, as the simulator numbers them
            index = {name: k for k, name in enumerate(names)}
            columns["primitive"] = _indices(columns["primitive"], index, len(robot_ids))
        human_ids = _first_seen(frames, "humans")
        return cls(
            t=np.array([float(frame["t"]) for frame in frames], dtype=float),
            robot_ids=robot_ids,
            primitive_names=names,
            human_ids=human_ids,
            humans=_point_columns(frames, "humans", human_ids),
            object_ids=object_ids,
            objects=_point_columns(frames, "objects", object_ids),
            messages=tuple(checked.get("messages", [])),
            replans=tuple(checked.get("replans", [])),
            scenario=checked.get("scenario"),
            dt=checked.get("dt"),
            units=checked.get("units") or INTERNAL_UNITS,
            **columns,
        )

    def save(self, path: str | os.PathLike[str]) -> None:
        """Write :meth:`to_json` to `path` as compact JSON, atomically (:func:`cosmop.io.atomic_path`).

        The frames are turned into JSON a block at a time, so that a long run is never all in
        memory as Python objects (a 50-robot run's 11,000 frames took some 500 MiB that way);
        the file's bytes are those of ``json.dumps(to_json())``.

        Parameters
        ----------
        path : str or os.PathLike
            The destination; its directory must exist.
        """
        exact = self.rounded()
        with (
            collector_paused(),
            atomic_path(path) as tmp,
            open(tmp, "w", encoding="utf-8", newline="") as out,
        ):
            out.write(_compact(self._json_head())[:-1] + ',"frames":[')  # the head, still open
            for start in range(0, len(exact.t), _FRAMES_PER_BLOCK):
                block = _compact(exact._json_frames(slice(start, start + _FRAMES_PER_BLOCK)))
                out.write(("," if start else "") + block[1:-1])  # the frames without their brackets
            out.write('],"messages":' + _compact([dict(m) for m in self.messages]))
            if self.replans:
                out.write(',"replans":' + _compact([dict(r) for r in self.replans]))
            out.write("}\n")


_FRAMES_PER_BLOCK = 500  # frames made into JSON at a time by Trace.save


def _compact(value: Any) -> str:
    """`value` as compact JSON (the trace file's separators)."""
    return json.dumps(value, separators=(",", ":"))


@overload
def _rounded(values: np.ndarray, digits: int) -> np.ndarray: ...
@overload
def _rounded(values: None, digits: int) -> None: ...
@overload
def _rounded(values: np.ndarray | None, digits: int) -> np.ndarray | None: ...
def _rounded(values: np.ndarray | None, digits: int) -> np.ndarray | None:
    """`values` rounded to `digits` decimals exactly as Python's :func:`round` rounds each float.

    ``np.round`` scales by ``10**digits`` first, which can tip a value to the other side of a
    tie; the files keep the bytes they always had, so every value goes through ``round``.
    Values ``np.round`` leaves unchanged are already the doubles nearest to `digits`-decimal
    numbers, far from any tie, and ``round`` leaves them unchanged too: a trace already
    rounded (:meth:`cosmop.sim.SimResult.trace`) is not rounded again value by value.
    """
    if values is None:
        return None
    if np.array_equal(np.round(values, digits), values, equal_nan=True):
        return values
    # k / 10**d with k the integer nearest to x 10**d is the double ``round`` returns, unless
    # the product was rounded across a tie: only the values within a hair of one go through
    # ``round`` (the hair: the product's rounding error, with a wide margin)
    scaled = values * 10.0**digits
    out = np.rint(scaled) / 10.0**digits
    hair = 1e-6 + 1e-14 * np.abs(scaled)
    with np.errstate(invalid="ignore"):
        close = np.abs(np.abs(scaled - np.floor(scaled)) - 0.5) <= hair
    out[close] = [round(x, digits) for x in values[close].tolist()]
    return out


def _json_points(ids: Sequence[str], positions: np.ndarray) -> list[dict[str, list[float]]]:
    """Each frame's ``{id: [x, y]}`` (mm), leaving out what the frame does not show (NaN)."""
    return [
        {pid: point for pid, point in zip(ids, row, strict=True) if not math.isnan(point[0])}
        for row in positions.tolist()
    ]


def _first_seen(frames: Sequence[Mapping[str, Any]], group: str) -> tuple[str, ...]:
    """The ids the frames name under `group`, in the order they first appear."""
    return tuple(dict.fromkeys(pid for frame in frames for pid in frame.get(group, {})))


def _robot_columns(frames: Sequence[Mapping[str, Any]], robot_ids: Sequence[str]) -> dict[str, Any]:
    """``poses`` (n, R, 3) and every optional key some robot state has, frame by frame.

    ``v`` and ``w`` are arrays (NaN where not given), ``waiting`` and ``delayed`` boolean arrays, ``carrying``
    and ``primitive`` lists of rows of names (None where not given), still to be numbered.
    """
    n, index = len(frames), {rid: i for i, rid in enumerate(robot_ids)}
    columns: dict[str, Any] = {"poses": np.full((n, len(robot_ids), 3), np.nan)}
    given: set[str] = set()
    for key, empty in (("v", np.nan), ("w", np.nan), ("waiting", False), ("delayed", False)):
        columns[key] = np.full((n, len(robot_ids)), empty)
    for key in ("carrying", "primitive"):
        columns[key] = [[None] * len(robot_ids) for _ in range(n)]
    for key in _SPARSE_KEYS:
        columns[key] = np.full((n, len(robot_ids)), None, dtype=object)
    for k, frame in enumerate(frames):
        for rid, state in frame.get("robots", {}).items():
            i = index[rid]
            columns["poses"][k, i] = state["pose"]
            for key in _STATE_KEYS & state.keys():
                columns[key][k][i] = state[key]
                given.add(key)
    return {key: value for key, value in columns.items() if key == "poses" or key in given}


def _indices(rows: list[list[str | None]], index: Mapping[str | None, int], width: int) -> np.ndarray:
    """Rows of names (None included) as their numbers in `index`: shape (n, width)."""
    return np.array([[index[name] for name in row] for row in rows], dtype=int).reshape(-1, width)


def _point_columns(frames: Sequence[Mapping[str, Any]], group: str, ids: Sequence[str]) -> np.ndarray:
    """Positions (mm) of the `group` ids in every frame, shape (n, N, 2); NaN where not shown."""
    index = {pid: j for j, pid in enumerate(ids)}
    out = np.full((len(frames), len(ids), 2), np.nan)
    for k, frame in enumerate(frames):
        for pid, point in frame.get(group, {}).items():
            out[k, index[pid]] = point
    return out


def as_trace(trace: Trace | Mapping[str, Any]) -> Trace:
    """`trace` itself, or the :class:`Trace` of a parsed ``cosmop.trace/1`` mapping.

    What the public functions that read traces call first, so that they take either.

    Parameters
    ----------
    trace : Trace or Mapping
        A trace, or a parsed trace file.

    Returns
    -------
    Trace

    Raises
    ------
    TraceError
        If a mapping does not have the ``cosmop.trace/1`` shape (:func:`check_trace`).
    """
    return trace if isinstance(trace, Trace) else Trace.from_json(trace)


def load_trace(path: str | os.PathLike[str]) -> Trace:
    """Read a ``cosmop.trace/1`` file as a :class:`Trace` (checked by :func:`check_trace`).

    Parameters
    ----------
    path : str or os.PathLike
        The trace file.

    Returns
    -------
    Trace

    Raises
    ------
    TraceError
        If the file cannot be read or parsed, naming it, or does not have the trace's shape,
        naming it, the first wrong field (and its line and column), what was expected there and
        what it is.
    """
    file = os.fspath(path)
    text = read_text(path, TraceError, "a trace file")
    return Trace._from_checked(_check(load_json(text, file, TraceError), file, text))


def message_label(message: Mapping[str, Any]) -> str:
    """A short text for a message of any kind: its object, else its event (a ``msg``'s tag), kind or
    type, else "message".

    Parameters
    ----------
    message : Mapping
        A message of a trace (:attr:`Trace.messages`).
    """
    for key in ("object", "event", "kind", "type"):
        value = message.get(key)
        if isinstance(value, str):
            if key == "event" and (event := _event_or_none(value)) is not None and event.tag is not None:
                return event.tag  # a msg event's tag says what it is about
            return value
    return "message"


def _event_or_none(text: str) -> Event | None:
    """The event a trace's text names, or None for text of another kind (kept as it is)."""
    try:
        return parse_event(text)
    except EventSyntaxError:
        return None
