"""Units: the paper's millimetres and degrees inside, SI (metres, radians) at the edges on request.

cosmop computes in millimetres, degrees and seconds, as the paper does. A scenario file may
instead say ``units: m``: its lengths are then metres, its angles radians and its speeds and
accelerations m/s and m/s^2, as in ROS (REP 103). :func:`scene_to_internal` converts such a
scene once, at load time, so that nothing downstream knows the difference; a file without
``units`` (or with ``units: mm``) means millimetres and degrees, as before.

Every file cosmop writes says its units with a ``units`` key (:data:`INTERNAL_UNITS`);
:func:`check_units_field` reads that key back, and a file without it is an older file in the
same units.

Conversions round to 1e-6 mm and 1e-9 degrees, so that ``2.3`` m is exactly ``2300`` mm and
walls meant to meet still meet.

Nothing downstream knows the difference but the words: the converted scene remembers its file's
units (``Scene.units``), and every message that shows a length, point, pose or speed writes it
with :func:`show_length`, :func:`show_point`, :func:`show_pose` or :func:`show_speed`, so that a
metres file is answered in metres.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import replace
from typing import Any, Literal

from cosmop.scene import Dynamics, Scene

__all__ = [
    "INTERNAL_UNITS",
    "SCENARIO_UNITS",
    "UnitSystem",
    "check_units_field",
    "default_dynamics",
    "length_unit",
    "localize",
    "m_from_mm",
    "mm_from_m",
    "plain",
    "rad_from_deg",
    "scene_to_internal",
    "show_angle",
    "show_length",
    "show_number",
    "show_point",
    "show_pose",
    "show_speed",
    "shown",
]

UnitSystem = Literal["mm", "m"]
"""A scenario's units: ``"mm"`` (millimetres, degrees; the default) or ``"m"`` (metres, radians)."""

SCENARIO_UNITS: tuple[str, ...] = ("mm", "m")
"""The values the scenario key ``units`` accepts."""

INTERNAL_UNITS: Mapping[str, str] = {"length": "mm", "angle": "deg", "time": "s"}
"""The ``units`` key of every JSON file cosmop writes (plans, summaries, traces)."""

_MM_PER_M = 1000.0


def mm_from_m(value: float) -> float:
    """Metres to millimetres, rounded to 1e-6 mm (so that 2.3 m is exactly 2300 mm).

    Parameters
    ----------
    value : float
        A length, m.
    """
    return round(value * _MM_PER_M, 6) + 0.0


def m_from_mm(value: float) -> float:
    """Millimetres to metres.

    Parameters
    ----------
    value : float
        A length, mm.
    """
    return value / _MM_PER_M


def shown(mm: float, units: UnitSystem) -> float:
    """A length of the internal scene (mm) as the file wrote it (mm, or m for ``units: m``).

    Parameters
    ----------
    mm : float
        The length, mm.
    units : {"mm", "m"}
        The file's units.
    """
    return m_from_mm(mm) if units == "m" else mm


def length_unit(units: UnitSystem) -> str:
    """The unit lengths are written in: ``"m"`` or ``"mm"``.

    Parameters
    ----------
    units : {"mm", "m"}
        The file's units.
    """
    return "m" if units == "m" else "mm"


def show_number(mm: float, units: UnitSystem) -> str:
    """A length or coordinate of the internal scene (mm) as the file would write it, without a unit.

    Whole numbers without a point and in full (``800000``, never ``8e+05``), others exactly in
    mm and to 1e-9 m (a micrometre's thousandth, below the planner's grid) in metres.

    Parameters
    ----------
    mm : float
        The length or coordinate, mm.
    units : {"mm", "m"}
        The file's units.

    Examples
    --------
    >>> show_number(800000.0, "m"), show_number(1433.5, "mm"), show_number(-2000.0, "mm")
    ('800', '1433.5', '-2000')
    """
    value = round(float(mm) / _MM_PER_M, 9) if units == "m" else float(mm)
    if not math.isfinite(value):
        return str(value)
    if value.is_integer():
        return str(int(value))
    return repr(value + 0.0)


def plain(value: float) -> str:
    """A number as people write it: whole ones in full (``800000``, never ``8e+05``), others to
    six significant digits; huge and tiny ones in exponent form (``1e+300``).

    Parameters
    ----------
    value : float
        The number.
    """
    if math.isfinite(value) and float(value).is_integer() and abs(value) < 1e15:
        return str(int(value))
    return f"{value:.6g}"


def show_length(mm: float, units: UnitSystem) -> str:
    """A length of the internal scene (mm) in the file's units, with the unit (``"0.4 m"``).

    Parameters
    ----------
    mm : float
        The length, mm.
    units : {"mm", "m"}
        The file's units.
    """
    return f"{show_number(mm, units)} {length_unit(units)}"


def show_point(point: Iterable[float], units: UnitSystem) -> str:
    """A point of the internal scene (mm) in the file's units: ``(0.8, 1)`` for ``(800, 1000)`` in m.

    Parameters
    ----------
    point : iterable of float
        The coordinates, mm.
    units : {"mm", "m"}
        The file's units.
    """
    return "(" + ", ".join(show_number(v, units) for v in point) + ")"


def show_angle(degrees: float, units: UnitSystem) -> str:
    """A heading of the internal scene (degrees) in the file's units: ``90°`` or ``1.5708 rad``.

    Parameters
    ----------
    degrees : float
        The heading, degrees.
    units : {"mm", "m"}
        The file's units (``"m"``: radians).
    """
    if units == "m":
        return f"{math.radians(degrees):.6g} rad"
    return f"{show_number(degrees, 'mm')}°"


def show_pose(pose: Sequence[float], units: UnitSystem) -> str:
    """A pose ``(x, y, heading)`` of the internal scene in the file's units: ``(0.8, 1, 1.5708 rad)``.

    Parameters
    ----------
    pose : sequence of float
        ``(x, y, heading)``: position in mm, heading in degrees.
    units : {"mm", "m"}
        The file's units.
    """
    x, y, heading = pose
    return f"({show_number(x, units)}, {show_number(y, units)}, {show_angle(heading, units)})"


def show_speed(mm_per_s: float, units: UnitSystem) -> str:
    """A speed of the internal scene (mm/s) in the file's units, with the unit (``"0.75 m/s"``).

    Parameters
    ----------
    mm_per_s : float
        The speed, mm/s.
    units : {"mm", "m"}
        The file's units.
    """
    return f"{show_number(mm_per_s, units)} {length_unit(units)}/s"


def _deg_from_rad(value: float) -> float:
    return round(math.degrees(value), 9) + 0.0


def rad_from_deg(value: float) -> float:
    """Degrees to radians.

    Parameters
    ----------
    value : float
        An angle, degrees.
    """
    return math.radians(value)


def _point(point: tuple[float, float]) -> tuple[float, float]:
    x, y = point
    return mm_from_m(x), mm_from_m(y)


def _dynamics(d: Dynamics) -> Dynamics:
    return replace(
        d,
        max_speed=mm_from_m(d.max_speed),
        acceleration=mm_from_m(d.acceleration),
        braking=mm_from_m(d.braking),
        turn_rate=_deg_from_rad(d.turn_rate),
    )


def default_dynamics(units: UnitSystem) -> Dynamics:
    """:class:`~cosmop.scene.Dynamics`' defaults expressed in `units` (m/s, rad/s, ... for ``"m"``).

    A scene read in metres starts from these, so that :func:`scene_to_internal` turns them
    back into exactly the millimetre defaults.

    Parameters
    ----------
    units : {"mm", "m"}
        The units to express them in.
    """
    d = Dynamics()
    if units == "mm":
        return d
    return replace(
        d,
        max_speed=m_from_mm(d.max_speed),
        acceleration=m_from_mm(d.acceleration),
        braking=m_from_mm(d.braking),
        turn_rate=rad_from_deg(d.turn_rate),
    )


def scene_to_internal(scene: Scene, units: UnitSystem) -> Scene:
    """The scene in millimetres and degrees, from a scene read in `units`.

    Parameters
    ----------
    scene : Scene
        A scene whose numbers are in `units`: with ``"m"``, lengths in m, headings in rad,
        speeds in m/s (turn rates rad/s), accelerations in m/s^2; times are seconds either way.
    units : {"mm", "m"}
        The scene's units; ``"mm"`` returns `scene` unchanged.

    Returns
    -------
    Scene
        The same scene in mm, degrees, mm/s, degrees/s, mm/s^2 and s.
    """
    if units == "mm":
        return scene
    if units != "m":
        raise ValueError(f"unknown units {units!r}; expected one of {SCENARIO_UNITS}")
    robots = {
        rid: replace(
            r,
            size=mm_from_m(r.size),
            pose=(mm_from_m(r.pose[0]), mm_from_m(r.pose[1]), _deg_from_rad(r.pose[2])),
            dynamics=_dynamics(r.dynamics),
        )
        for rid, r in scene.robots.items()
    }
    objects = {
        oid: replace(o, size=mm_from_m(o.size), position=_point(o.position))
        for oid, o in scene.objects.items()
    }
    workspaces = {
        wid: replace(
            w,
            x=None if w.x is None else _point(w.x),
            y=None if w.y is None else _point(w.y),
            point=None if w.point is None else _point(w.point),
        )
        for wid, w in scene.workspaces.items()
    }
    humans = {
        hid: replace(
            h,
            size=mm_from_m(h.size),
            speed=mm_from_m(h.speed),
            path=tuple((mm_from_m(x), mm_from_m(y), dwell) for x, y, dwell in h.path),
            walk=None if h.walk is None else (_point(h.walk[0]), _point(h.walk[1])),
        )
        for hid, h in scene.humans.items()
    }
    walls = tuple(replace(w, start=_point(w.start), end=_point(w.end)) for w in scene.obstacles)
    return replace(
        scene,
        obstacles=walls,
        robots=robots,
        objects=objects,
        workspaces=workspaces,
        humans=humans,
        dynamics=_dynamics(scene.dynamics),
        units="m",  # messages show its lengths in metres again
    )


_WORDS_SI = (
    ("mm/s^2", "m/s^2"),
    ("mm/s", "m/s"),
    ("degrees/s", "rad/s"),
    ("(mm)", "(m)"),
    ("mm,", "m,"),
    (" mm", " m"),
    ("degrees", "radians"),
)


def localize(message: str, units: UnitSystem) -> str:
    """A message about a scenario field with its unit words in the file's `units`.

    The scenario's messages name units the internal way ("a positive number (side of the
    square robot, mm)"); for a file in metres they should say "m" and "radians".

    Parameters
    ----------
    message : str
        The message, with its units named the internal way.
    units : {"mm", "m"}
        The file's units.
    """
    if units != "m":
        return message
    for old, new in _WORDS_SI:
        message = message.replace(old, new)
    return message


def check_units_field(value: Any) -> str | None:
    """Why a file's ``units`` value is not :data:`INTERNAL_UNITS`, or None when it is (or is absent).

    Parameters
    ----------
    value : Any
        The parsed value of the ``units`` key; ``None`` when the key is absent (older files).

    Returns
    -------
    str or None
        An "expected ..., got ..." message, or None when the value is acceptable.
    """
    if value is None or (isinstance(value, Mapping) and dict(value) == dict(INTERNAL_UNITS)):
        return None
    return f"expected {dict(INTERNAL_UNITS)} (cosmop writes mm, degrees and seconds), got {value!r}"
