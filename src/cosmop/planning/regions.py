"""Sound region constraints for GoTo: where a square robot may move in a straight line.

The paper's GoTo specification (Section IV-B) keeps both ends of each straight motion in one
region "below, above, left or right" of every wall segment.  Its formulas have sign typos and
a ``(1 + m)`` factor that is wrong for a square footprint: a square of half-side :math:`h`
reaches :math:`h(|n_x| + |n_y|)` along a wall's normal :math:`n`, not :math:`h(1 + m)` for the
slope :math:`m`.  This module states the intent exactly and soundly.

For a wall from :math:`p` to :math:`q`, direction :math:`w = q - p` and normal
:math:`n = (-w_y, w_x)`, and a robot whose footprint is the axis-aligned square of half-side
:math:`h` centred at :math:`c`, the four regions are the closed half-planes

.. math::

   n \\cdot (c - p) \\ge h(|n_x| + |n_y|), \\quad
   n \\cdot (c - p) \\le -h(|n_x| + |n_y|), \\quad
   w \\cdot (c - p) \\le -h(|w_x| + |w_y|), \\quad
   w \\cdot (c - q) \\ge h(|w_x| + |w_y|).

:math:`h(|v_x| + |v_y|)` is the support of the square in direction :math:`v`, so each region
holds exactly the squares lying in a closed half-plane that meets the wall at most on its
boundary.  A half-plane is convex, so if both end squares of a motion lie in it, the whole
swept area (the convex hull of the two squares) does too.  The motion then never overlaps the
wall; touching it is allowed.  The coefficients are not normalised: with integer wall
coordinates and an integer side every coefficient is an integer or a half-integer, so an SMT
encoding over the rationals is exact.

Objects are axis-aligned squares too.  Their four regions are the paper's
left/right/below/above with clearance :math:`d = (l_b + l_r)/2`, which is exact for
touching.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from functools import lru_cache
from typing import Any


@dataclass(frozen=True)
class HalfPlane:
    """The closed half-plane :math:`a x + b y \\ge c` of robot centres (mm).

    Attributes
    ----------
    a, b, c : Fraction
        Exact coefficients.
    label : str
        Which side it is (``"left of wall 3"``, ...), for explanations.
    """

    a: Fraction
    b: Fraction
    c: Fraction
    label: str = ""

    def contains(self, x: float, y: float) -> bool:
        """Whether the centre ``(x, y)`` lies in the half-plane (exact for rational input).

        Parameters
        ----------
        x, y : float
            The robot centre (mm).
        """
        return Fraction(x) * self.a + Fraction(y) * self.b >= self.c


def _support(vx: Fraction, vy: Fraction, half: Fraction) -> Fraction:
    """Support of the axis-aligned square of half-side ``half`` in direction ``v``."""
    return half * (abs(vx) + abs(vy))


@lru_cache(maxsize=1 << 16)  # exact arithmetic, asked again for every wall at every synthesis
def wall_regions(
    start: tuple[float, float], end: tuple[float, float], side: float | Fraction, name: str = "wall"
) -> tuple[HalfPlane, HalfPlane, HalfPlane, HalfPlane]:
    """The four regions around a wall segment for a square robot of side ``side``.

    Parameters
    ----------
    start, end : (float, float)
        The wall's end points :math:`p \\ne q` (mm).
    side : float or Fraction
        The robot's side length (mm).
    name : str
        Used in the labels.

    Returns
    -------
    tuple of HalfPlane
        ``(one side, other side, before start, after end)``: a straight motion whose two end
        centres lie in one of them never overlaps the wall.
    """
    px, py = Fraction(start[0]), Fraction(start[1])
    qx, qy = Fraction(end[0]), Fraction(end[1])
    wx, wy = qx - px, qy - py
    if wx == 0 and wy == 0:
        raise ValueError("a wall needs two distinct end points")
    nx, ny = -wy, wx
    half = Fraction(side) / 2
    sn, sw = _support(nx, ny, half), _support(wx, wy, half)
    return (
        HalfPlane(nx, ny, nx * px + ny * py + sn, f"left of {name}"),
        HalfPlane(-nx, -ny, -(nx * px + ny * py) + sn, f"right of {name}"),
        HalfPlane(-wx, -wy, -(wx * px + wy * py) + sw, f"before the start of {name}"),
        HalfPlane(wx, wy, wx * qx + wy * qy + sw, f"past the end of {name}"),
    )


_Side = tuple[Fraction, Fraction, Any]
"""One side ``(a, b, c)`` of :func:`square_sides`: ``a``, ``b`` exact, ``c`` a number or a solver term."""


def square_sides(ox: Any, oy: Any, d: Any) -> tuple[_Side, _Side, _Side, _Side]:
    """The four sides of an axis-aligned square obstacle at centre distance `d`, as ``(a, b, c)``.

    ``a x + b y >= c`` holds for centres ``(x, y)`` at least `d` left of, right of, below or
    above the centre ``(ox, oy)``: ``(left, right, below, above)``.  The coefficients are
    exact (``Fraction``); `ox`, `oy` and `d` may be numbers or solver terms, so the
    specification (where an object's position is a variable) and :func:`object_regions` build
    the same half-planes.

    Parameters
    ----------
    ox, oy : Fraction, float or z3 arithmetic term
        The obstacle's centre (mm).
    d : Fraction, float or z3 arithmetic term
        The least distance of a robot centre from it along either axis (mm).

    Returns
    -------
    tuple of (Fraction, Fraction, term)
        ``(left, right, below, above)``.
    """
    one, zero = Fraction(1), Fraction(0)
    return ((-one, zero, d - ox), (one, zero, ox + d), (zero, -one, d - oy), (zero, one, oy + d))


def object_regions(
    position: tuple[float, float], object_side: float, robot_side: float, name: str = "object"
) -> tuple[HalfPlane, HalfPlane, HalfPlane, HalfPlane]:
    """The four regions around a resting square object for a square robot.

    ``(left, right, below, above)`` of the object with clearance
    :math:`d = (l_b + l_r)/2`: e.g. left is :math:`x \\le o_x - d`.  A straight motion whose
    two end centres lie in one of them never overlaps the object (touching allowed).

    Parameters
    ----------
    position : (float, float)
        The object's centre (mm).
    object_side, robot_side : float
        The object's and the robot's side lengths (mm).
    name : str
        Used in the labels.

    Returns
    -------
    tuple of HalfPlane
        ``(left, right, below, above)``.
    """
    ox, oy = Fraction(position[0]), Fraction(position[1])
    d = (Fraction(object_side) + Fraction(robot_side)) / 2
    labels = (f"left of {name}", f"right of {name}", f"below {name}", f"above {name}")
    left, right, below, above = (
        HalfPlane(a, b, c, label) for (a, b, c), label in zip(square_sides(ox, oy, d), labels, strict=True)
    )
    return left, right, below, above
