"""Docking: the sides of an object a robot handles it from, and the exact poses that touch it.

A robot picks up or drops off an object facing one of its four sides, square on: at heading
0, 90, 180 or 270 degrees, its square touching the object's.  Pure arithmetic on exact unit
vectors (no floating-point sine), shared by the specification, the exact checker and the
simulator's docking.
"""

from __future__ import annotations

from collections.abc import Iterable

__all__ = ["DOCKING_HEADINGS", "SIDES", "docking_pose", "facing", "in_front"]

DOCKING_HEADINGS = (0, 90, 180, 270)
"""Headings (degrees) from which a robot picks up or drops off an object: it faces one of the
object's four sides, square on, and the two squares touch."""

_SLACK = 1e-6  # degrees: the exact checker's tolerance, so a plan it accepts docks here too

_UNITS = {0: (0, 1), 90: (1, 0), 180: (0, -1), 270: (-1, 0)}  # heading -> (sin, cos) exactly

SIDES = {"west": 0, "south": 90, "east": 180, "north": 270}
"""The side of an object a robot stands on, by name, and the heading at which it then faces the
object: on the west side it faces east (+x, heading 0, the paper's only way)."""


def facing(heading: float) -> tuple[int, int]:
    """The exact unit vector ``(cos h, sin h)`` of a docking heading `h` (degrees, modulo 360,
    within 1e-6).

    Parameters
    ----------
    heading : float
        A docking heading, degrees.

    Returns
    -------
    tuple of int
        ``(cos h, sin h)``, each -1, 0 or 1.

    Raises
    ------
    ValueError
        If `heading` is not one of :data:`DOCKING_HEADINGS` (modulo 360).

    Examples
    --------
    >>> facing(90), facing(-90)
    ((0, 1), (0, -1))
    """
    h = round(heading) % 360
    if abs(heading - round(heading)) > _SLACK or h not in _UNITS:
        raise ValueError(f"a robot docks at a heading in {DOCKING_HEADINGS} degrees, not {heading:g}")
    sin, cos = _UNITS[h]
    return cos, sin


def docking_pose(obj: Iterable[float], gap: float, heading: float) -> tuple[float, float]:
    """The robot centre that faces an object at `obj` from `heading`, touching it.

    `gap` is the centre distance :math:`d = (l_r + l_o)/2` (mm) at which the robot's and the
    object's squares touch; the robot stands at :math:`o - d\\,(\\cos h, \\sin h)`.

    Parameters
    ----------
    obj : iterable of float
        The object's centre ``(x, y, ...)``, mm; further items are ignored.
    gap : float
        The centre distance at which the two squares touch, mm.
    heading : float
        The robot's docking heading, degrees (one of :data:`DOCKING_HEADINGS`, modulo 360).

    Returns
    -------
    tuple of float
        The robot's centre ``(x, y)``, mm.

    Examples
    --------
    >>> docking_pose((1000, 0), 250, 0), docking_pose((1000, 0), 250, 270)
    ((750, 0), (1000, 250))
    """
    ox, oy, *_ = obj
    ux, uy = facing(heading)
    return ox - gap * ux, oy - gap * uy


def in_front(robot: Iterable[float], gap: float, heading: float) -> tuple[float, float]:
    """Where an object lies that a robot at `robot` facing `heading` touches: the inverse of
    :func:`docking_pose`, :math:`r + d\\,(\\cos h, \\sin h)` (mm).

    Parameters
    ----------
    robot : iterable of float
        The robot's centre ``(x, y, ...)``, mm; further items (a heading) are ignored.
    gap : float
        The centre distance at which the two squares touch, mm.
    heading : float
        The robot's docking heading, degrees (one of :data:`DOCKING_HEADINGS`, modulo 360).

    Returns
    -------
    tuple of float
        The object's centre ``(x, y)``, mm.
    """
    x, y, *_ = robot
    ux, uy = facing(heading)
    return x + gap * ux, y + gap * uy
