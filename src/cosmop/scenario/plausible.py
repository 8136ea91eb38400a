"""Bounds on a scenario's numbers: ranges outside which a value is refused, and narrower ones
outside which it is probably a mistake.

Two kinds of bound, both given once per quantity (:data:`QUANTITIES`) in the internal units
(mm, degrees, seconds):

* *valid*: outside it the simulator or the planner cannot work (a control cycle of a
  nanosecond never ends a run; a top speed of 1e-300 mm/s gives a finishing time of 300
  digits).  The loader refuses such a value, naming the field and the range.
* *plausible*: outside it the value loads but is probably a slip, most often of units (a robot
  400 m wide in a metres file was meant in millimetres).  The loader returns a warning record
  (:class:`~cosmop.errors.InputWarning`), one per quantity, and the command line prints it.

The checks read the scene as the file wrote it (before :func:`cosmop.units.scene_to_internal`),
so that every message shows the user's own numbers and units, and so that a huge value in a
metres file is refused before converting it to millimetres could overflow.  When the value
would be plausible had the file been written in the other units (metres for millimetres,
radians for degrees, and back), the message says so.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass, fields
from typing import Literal

from cosmop.reading import FieldPath
from cosmop.scene import Dynamics, Scene
from cosmop.units import UnitSystem, plain

__all__ = ["QUANTITIES", "Quantity", "implausible", "out_of_range"]

Kind = Literal["length", "speed", "acceleration", "turn rate", "angle", "time"]

_UNIT = {
    "length": ("mm", "m"),
    "speed": ("mm/s", "m/s"),
    "acceleration": ("mm/s^2", "m/s^2"),
    "turn rate": ("degrees/s", "rad/s"),
    "angle": ("degrees", "radians"),
    "time": ("s", "s"),
}
_ANGULAR = ("turn rate", "angle")
_SLIP = {  # (angular, the file's units): the likely slip
    (False, "m"): "it looks like millimetres in a metres file",
    (False, "mm"): "it looks like metres in a millimetre file (add units: m, or write millimetres)",
    (True, "m"): "it looks like degrees in a file in radians (units: m)",
    (True, "mm"): "it looks like radians in a file in degrees (add units: m, or write degrees)",
}


@dataclass(frozen=True)
class Quantity:
    """What one kind of number of a scenario may be.

    Parameters
    ----------
    what : str
        The quantity in words, as it starts a message: ``"a robot's side"``.
    kind : {"length", "speed", "acceleration", "turn rate", "angle", "time"}
        Its dimension, which says its unit in either file units and how a slip of units scales it.
    plausible : tuple of float
        ``(lo, hi)`` in mm, degrees and seconds: outside, the value is probably a mistake.
    valid : tuple of float, optional
        ``(lo, hi)``: outside, the value is refused; ``None`` when other checks bound it.
    magnitude : bool, optional
        Whether the bounds are on the value's magnitude (coordinates, headings), ``lo`` then 0.
    """

    what: str
    kind: Kind
    plausible: tuple[float, float]
    valid: tuple[float, float] | None = None
    magnitude: bool = False

    def unit(self, units: UnitSystem) -> str:
        """The quantity's unit in a file in `units`: ``"m/s"``.

        Parameters
        ----------
        units : {"mm", "m"}
            The file's units.
        """
        return _UNIT[self.kind][units == "m"]

    def internal(self, value: float, units: UnitSystem) -> float:
        """`value`, as written in a file in `units`, in mm, degrees and seconds.

        Parameters
        ----------
        value : float
            The value as the file wrote it (in `units`).
        units : {"mm", "m"}
            The file's units.
        """
        if units != "m" or self.kind == "time":
            return value
        return math.degrees(value) if self.kind in _ANGULAR else value * 1000.0

    def in_file(self, value: float, units: UnitSystem) -> float:
        """`value` in mm, degrees or seconds as a file in `units` writes it.

        Parameters
        ----------
        value : float
            The value in mm, degrees or seconds.
        units : {"mm", "m"}
            The file's units.
        """
        if units != "m" or self.kind == "time":
            return value
        return math.radians(value) if self.kind in _ANGULAR else value / 1000.0

    def within(self, value: float, bounds: tuple[float, float], units: UnitSystem) -> bool:
        """Whether `value`, as written in a file in `units`, lies within `bounds` (internal units).

        Parameters
        ----------
        value : float
            The value as the file wrote it (in `units`).
        bounds : tuple of float
            ``(lo, hi)`` in mm, degrees and seconds.
        units : {"mm", "m"}
            The file's units.
        """
        inside = self.internal(value, units)  # a metres file's 1e308 is inf here, out of every range
        lo, hi = bounds
        return lo <= (abs(inside) if self.magnitude else inside) <= hi

    def expected(self, bounds: tuple[float, float], units: UnitSystem) -> str:
        """The range `bounds` in words in the file's units: ``between 0.05 and 5 m``.

        Parameters
        ----------
        bounds : tuple of float
            ``(lo, hi)`` in mm, degrees and seconds.
        units : {"mm", "m"}
            The file's units.
        """
        lo, hi = (plain(self.in_file(bound, units)) for bound in bounds)
        unit = self.unit(units)
        return f"at most {hi} {unit} either way" if self.magnitude else f"between {lo} and {hi} {unit}"

    def slip(self, value: float, units: UnitSystem) -> str | None:
        """The likely slip of units when `value` would be plausible in the other units, else None.

        Parameters
        ----------
        value : float
            The value as the file wrote it (in `units`).
        units : {"mm", "m"}
            The file's units.
        """
        if self.kind == "time":
            return None
        other: UnitSystem = "mm" if units == "m" else "m"
        return _SLIP[(self.kind in _ANGULAR, units)] if self.within(value, self.plausible, other) else None


_SIDE_OF_ROBOT = Quantity("a robot's side", "length", (50.0, 5000.0))
_SIDE_OF_OBJECT = Quantity("an object's side", "length", (10.0, 5000.0))
_SIDE_OF_PERSON = Quantity("a person's side", "length", (100.0, 3000.0))
_COORDINATE = Quantity("a coordinate", "length", (0.0, 1e7), magnitude=True)
_HEADING = Quantity("a heading", "angle", (0.0, 360.0), magnitude=True)
_WALKING = Quantity("a walking speed", "speed", (20.0, 5000.0), valid=(1.0, 1e5))
_DYNAMICS = {
    "max_speed": Quantity("a top speed", "speed", (20.0, 10_000.0), valid=(1.0, 1e5)),
    "acceleration": Quantity("an acceleration", "acceleration", (10.0, 20_000.0), valid=(1.0, 1e5)),
    "braking": Quantity("a braking deceleration", "acceleration", (10.0, 20_000.0), valid=(1.0, 1e5)),
    "turn_rate": Quantity("a turning rate", "turn rate", (5.0, 1000.0), valid=(1.0, 3600.0)),
    "cycle": Quantity("a control cycle", "time", (0.001, 1.0), valid=(0.001, 1.0)),
}
QUANTITIES: tuple[Quantity, ...] = (
    _SIDE_OF_ROBOT,
    _SIDE_OF_OBJECT,
    _SIDE_OF_PERSON,
    _COORDINATE,
    _HEADING,
    _WALKING,
    *_DYNAMICS.values(),
)
"""Every quantity checked, with its bounds (the robots' dynamics: :class:`~cosmop.scene.Dynamics`)."""


def _numbers(scene: Scene) -> Iterator[tuple[FieldPath, Quantity, float]]:
    """``(field path, quantity, value)`` of every number of `scene` that has bounds, in file order."""
    for i, wall in enumerate(scene.obstacles):
        for j, point in enumerate((wall.start, wall.end)):
            for k in (0, 1):
                yield ("scene", "obstacles", i, j, k), _COORDINATE, point[k]
    yield from _dynamics(("scene", "dynamics"), scene.dynamics, None)
    for rid, robot in scene.robots.items():
        yield ("scene", "robots", rid, "size"), _SIDE_OF_ROBOT, robot.size
        for k in (0, 1):
            yield ("scene", "robots", rid, "pose", k), _COORDINATE, robot.pose[k]
        yield ("scene", "robots", rid, "pose", 2), _HEADING, robot.pose[2]
        yield from _dynamics(("scene", "robots", rid, "dynamics"), robot.dynamics, scene.dynamics)
    for oid, obj in scene.objects.items():
        yield ("scene", "objects", oid, "size"), _SIDE_OF_OBJECT, obj.size
        for k in (0, 1):
            yield ("scene", "objects", oid, "position", k), _COORDINATE, obj.position[k]
    for wid, ws in scene.workspaces.items():
        for key in ("x", "y", "point"):
            for k, value in enumerate(getattr(ws, key) or ()):
                yield ("scene", "workspaces", wid, key, k), _COORDINATE, value
    for hid, human in scene.humans.items():
        path = ("scene", "humans", hid)
        yield (*path, "size"), _SIDE_OF_PERSON, human.size
        yield (*path, "speed"), _WALKING, human.speed
        for n, waypoint in enumerate(human.path):
            for k in (0, 1):
                yield (*path, "path", n, k), _COORDINATE, waypoint[k]
        for axis, bounds in zip("xy", human.walk or (), strict=False):
            for k, value in enumerate(bounds):
                yield (*path, "walk", axis, k), _COORDINATE, value


def _dynamics(
    path: FieldPath, dynamics: Dynamics, inherited: Dynamics | None
) -> Iterator[tuple[FieldPath, Quantity, float]]:
    """A robot's limits where they differ from the scene's (`inherited`), which name their own field."""
    for item in fields(dynamics):
        value = getattr(dynamics, item.name)
        if inherited is None or value != getattr(inherited, item.name):
            yield (*path, item.name), _DYNAMICS[item.name], value


def out_of_range(scene: Scene, units: UnitSystem) -> tuple[FieldPath, str] | None:
    """The first number of `scene` (as its file wrote it, in `units`) outside its valid range.

    Parameters
    ----------
    scene : Scene
        The scene as the file wrote it (before :func:`cosmop.units.scene_to_internal`).
    units : {"mm", "m"}
        The file's units.

    Returns
    -------
    tuple or None
        ``(field path, what was expected)``, or ``None`` when every number is in range.
    """
    for path, quantity, value in _numbers(scene):
        if quantity.valid is not None and not quantity.within(value, quantity.valid, units):
            slip = quantity.slip(value, units)
            return path, (
                f"expected {quantity.what} {quantity.expected(quantity.valid, units)}, got {plain(value)}"
                + (f"; {slip}" if slip else "")
            )
    return None


def implausible(scene: Scene, units: UnitSystem) -> list[tuple[FieldPath, str]]:
    """Warnings on the numbers of `scene` (as its file wrote it) outside their plausible range.

    One per quantity: the first such field, with how many more there are.

    Parameters
    ----------
    scene : Scene
        The scene as the file wrote it (before :func:`cosmop.units.scene_to_internal`).
    units : {"mm", "m"}
        The file's units.

    Returns
    -------
    list of (field path, problem)
        In the order of :data:`QUANTITIES`' first findings in the file.
    """
    found: dict[Quantity, list[tuple[FieldPath, float]]] = {}
    for path, quantity, value in _numbers(scene):
        if not quantity.within(value, quantity.plausible, units):
            found.setdefault(quantity, []).append((path, value))
    out = []
    for quantity, places in found.items():
        path, value = places[0]
        text = (
            f"{quantity.what} of {plain(value)} {quantity.unit(units)} is implausible (expected "
            f"{quantity.expected(quantity.plausible, units)})"
        )
        if (slip := quantity.slip(value, units)) is not None:
            text += f"; {slip}"
        if len(places) > 1:
            text += f" ({len(places) - 1} more such value{'s' if len(places) > 2 else ''} in the file)"
        out.append((path, text))
    return out
