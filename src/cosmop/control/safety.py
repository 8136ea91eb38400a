"""Passive safety of the extended Dynamic Window Approach (the paper's ``safe`` and Corollary).

A robot with translational speed :math:`v \\ge 0`, acceleration at most :math:`A`, braking
:math:`b` and control cycle :math:`\\varepsilon` may start a new arc only when, for every
obstacle :math:`o` that moves at most :math:`V_o` fast,

.. math::

    \\lVert p_r - p_o \\rVert_\\infty > \\Big(\\frac{A}{b} + 1\\Big)\\Big(\\frac{A}{2}\\varepsilon^2
    + \\varepsilon v\\Big) + \\frac{v^2}{2b} + V_o\\Big(\\varepsilon + \\frac{v + A\\varepsilon}{b}\\Big);

otherwise it brakes with :math:`-b` (Mitsch et al., Theorem 2 of the journal version; the
paper's ``safe``).  Then the robot is never moving when it touches an obstacle: it can always
stop before the gap closes, even if the obstacle runs towards it at :math:`V_o`.  Solving the
condition for :math:`v` gives the paper's Corollary,

.. math::

    v_{max} = b\\sqrt{\\Big(\\frac{A}{b} + 1\\Big)\\varepsilon^2 + \\Big(\\frac{V}{b}\\Big)^2 +
    \\frac{2\\lVert p_r - p_o \\rVert_\\infty}{b}} - b\\,\\varepsilon\\Big(\\frac{A}{b} + 1\\Big) - V,

and ``safe`` holds exactly when :math:`v < v_{max}`.  The paper uses one :math:`V` for all
obstacles; the condition holds obstacle by obstacle, so walls and resting objects use
:math:`V_o = 0` and people their top speed.

In the condition :math:`V_o` only bounds how far the obstacle can come during the robot's
stopping horizon :math:`T = \\varepsilon + (v + A\\varepsilon)/b`: the term is
:math:`V_o T`.  Another robot of the team shares its speed :math:`v_o` and acceleration
limit :math:`A_o` (the robots talk over the message bus), so within :math:`T` it moves at most
:math:`v_o T + A_o T^2/2`; :func:`obstacle_speed` gives the matching
:math:`V_o = \\min(v^{top}_o, v_o + A_o T/2)`, which is still a sound bound and lets two
robots that stand close start again (with the top speed alone they could block each other
for ever).  Units: mm, mm/s, mm/s², s.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TypeAlias

import numpy as np
from numpy.typing import NDArray

from cosmop.scene import Dynamics

__all__ = [
    "Limits",
    "admissible_speed",
    "cycle_distance",
    "is_safe",
    "obstacle_speed",
    "own_margin",
    "stopping_horizon",
    "stopping_margin",
]


_Real: TypeAlias = float | NDArray[np.float64]
"""A quantity given for one robot or obstacle (float) or for a batch of them (float array)."""


@dataclass(frozen=True)
class Limits:
    """The unicycle limits of a batch of robots, one array entry per robot.

    The arrays of :class:`~cosmop.scene.Dynamics`, so that every function here that takes
    `dynamics` takes a batch too (with :meth:`column`, against many obstacles at once).

    Attributes
    ----------
    max_speed : ndarray
        Top translational speed, mm/s.
    acceleration, braking : ndarray
        :math:`A` and :math:`b`, mm/s².
    turn_rate : ndarray
        :math:`\\Omega`, rad/s (a scenario gives degrees/s).
    cycle : ndarray
        :math:`\\varepsilon`, s.
    """

    max_speed: NDArray[np.float64]
    acceleration: NDArray[np.float64]
    braking: NDArray[np.float64]
    turn_rate: NDArray[np.float64]
    cycle: NDArray[np.float64]

    @classmethod
    def of(cls, dynamics: Sequence[Dynamics]) -> Limits:
        """The limits of robots with these `dynamics`, in order.

        Parameters
        ----------
        dynamics : sequence of Dynamics
            One per robot.

        Examples
        --------

        >>> Limits.of([Dynamics(), Dynamics(max_speed=500)]).max_speed
        array([750., 500.])
        """
        return cls(
            max_speed=np.array([d.max_speed for d in dynamics], dtype=float),
            acceleration=np.array([d.acceleration for d in dynamics], dtype=float),
            braking=np.array([d.braking for d in dynamics], dtype=float),
            turn_rate=np.array([math.radians(d.turn_rate) for d in dynamics], dtype=float),
            cycle=np.array([d.cycle for d in dynamics], dtype=float),
        )

    def __getitem__(self, rows: int | slice | NDArray[np.intp] | NDArray[np.bool_]) -> Limits:
        """The limits of the robots `rows` (an index array, a mask or a slice; one robot's index
        gives scalar entries, which broadcast like the arrays)."""
        return Limits(*(getattr(self, name)[rows] for name in _LIMIT_FIELDS))

    def column(self) -> Limits:
        """The same limits as columns ``(R, 1)``, to broadcast against ``(R, M)`` obstacles."""
        return Limits(*(getattr(self, name)[:, None] for name in _LIMIT_FIELDS))


_LIMIT_FIELDS = ("max_speed", "acceleration", "braking", "turn_rate", "cycle")


def stopping_margin(v: _Real, speed_bound: _Real, dynamics: Dynamics | Limits) -> _Real:
    """The right-hand side of ``safe``: the gap (mm) a robot at speed `v` needs.

    Parameters
    ----------
    v : float or ndarray
        Translational speed now, mm/s (>= 0).
    speed_bound : float or ndarray
        :math:`V_o`, the most the obstacle moves, mm/s.
    dynamics : Dynamics or Limits
        :math:`A`, :math:`b`, :math:`\\varepsilon` (arrays broadcast with `v` and `speed_bound`).
    """
    return own_margin(v, dynamics) + speed_bound * stopping_horizon(v, dynamics)


def own_margin(v: _Real, dynamics: Dynamics | Limits) -> _Real:
    """:func:`stopping_margin` before an obstacle moves (:math:`V_o = 0`): the robot's own
    stopping distance, mm, :math:`(A/b + 1)(A\\varepsilon^2/2 + \\varepsilon v) + v^2/2b`.

    Parameters
    ----------
    v : float or ndarray
        Translational speed now, mm/s (>= 0).
    dynamics : Dynamics or Limits
        :math:`A`, :math:`b`, :math:`\\varepsilon` (arrays broadcast with `v`).
    """
    a, b, eps = dynamics.acceleration, dynamics.braking, dynamics.cycle
    return (a / b + 1.0) * (a / 2.0 * eps**2 + eps * v) + v * v / (2.0 * b)


def stopping_horizon(v: _Real, dynamics: Dynamics | Limits) -> _Real:
    """:math:`T = \\varepsilon + (v + A\\varepsilon)/b`: the latest time a robot at `v` stands still, s.

    Parameters
    ----------
    v : float or ndarray
        Translational speed now, mm/s (>= 0).
    dynamics : Dynamics or Limits
        :math:`A`, :math:`b`, :math:`\\varepsilon` (arrays broadcast with `v`).
    """
    a, b, eps = dynamics.acceleration, dynamics.braking, dynamics.cycle
    return eps + (v + a * eps) / b


def obstacle_speed(horizon: _Real, top: _Real, speed_now: _Real, acceleration: _Real) -> NDArray[np.float64]:
    r"""The speed bound :math:`V_o = \min(v^{top}_o, v_o + A_o T/2)` of an obstacle over `horizon`.

    Parameters
    ----------
    horizon : float or ndarray
        :math:`T`, s (see :func:`stopping_horizon`).
    top : float or ndarray
        The obstacle's top speed, mm/s (``inf`` acceleration: a person, bounded by this alone).
    speed_now : float or ndarray
        Its current speed, mm/s.
    acceleration : float or ndarray
        Its acceleration limit, mm/s² (``inf`` when unknown).

    Returns
    -------
    ndarray
        A speed whose product with `horizon` bounds the obstacle's displacement, mm/s (0-d for
        scalar arguments).
    """
    with np.errstate(invalid="ignore"):
        reach = np.asarray(speed_now) + np.asarray(acceleration) * np.asarray(horizon) / 2.0
    return np.minimum(top, np.where(np.isnan(reach), np.inf, reach))


def is_safe(gap: _Real, v: _Real, speed_bound: _Real, dynamics: Dynamics | Limits) -> NDArray[np.bool_]:
    """The paper's ``safe``: ``gap > stopping_margin(v, V)`` (elementwise).

    Parameters
    ----------
    gap : float or ndarray
        The gap to the obstacle (:math:`\\lVert p_r - p_o \\rVert_\\infty` in the condition), mm.
    v, speed_bound, dynamics
        As for :func:`stopping_margin`.
    """
    return np.asarray(gap) > stopping_margin(v, speed_bound, dynamics)


def admissible_speed(gap: _Real, speed_bound: _Real, dynamics: Dynamics | Limits) -> NDArray[np.float64]:
    """The Corollary's :math:`v_{max}`: ``safe`` holds exactly for ``0 <= v < v_max``.

    Negative when not even a standing robot may start (the gap is below
    :math:`(A/b + 1) A\\varepsilon^2/2 + V_o\\varepsilon(1 + A/b)`).

    Parameters
    ----------
    gap : float or ndarray
        The gap to the obstacle (:math:`\\lVert p_r - p_o \\rVert_\\infty` in the condition), mm.
    speed_bound : float or ndarray
        :math:`V_o`, the most the obstacle moves, mm/s.
    dynamics : Dynamics or Limits
        :math:`A`, :math:`b`, :math:`\\varepsilon` (arrays broadcast with the others).
    """
    a, b, eps = dynamics.acceleration, dynamics.braking, dynamics.cycle
    gap = np.asarray(gap, dtype=float)
    root = np.sqrt(np.maximum((a / b + 1.0) * eps**2 + (speed_bound / b) ** 2 + 2.0 * gap / b, 0.0))
    return b * root - b * eps * (a / b + 1.0) - speed_bound


def cycle_distance(v0: _Real, v1: _Real, t: _Real, braking: _Real, cycle: _Real) -> NDArray[np.float64]:
    r"""How far a robot has driven `t` seconds into a control cycle that takes it from `v0` to `v1`.

    Speeding up, the speed ramps at a constant acceleration over the cycle,
    :math:`v_0 t + (v_1 - v_0) t^2 / 2\varepsilon`; slowing down, it brakes at :math:`-b`
    until :math:`v_1` is reached, at :math:`(v_0 - v_1)/b`, and holds it (the control passive
    safety assumes).  The simulator moves robots so (:func:`cosmop.sim.unicycle.integrate`),
    and the dynamic window's check of an arc follows it (:mod:`cosmop.control.dwa`).

    Parameters
    ----------
    v0, v1 : float or ndarray
        The speeds at the start and the end of the cycle, mm/s.
    t : float or ndarray
        Time into the cycle, s (``0 <= t <= cycle``).
    braking : float or ndarray
        :math:`b`, mm/s².
    cycle : float or ndarray
        :math:`\varepsilon`, s.

    Returns
    -------
    ndarray
        The distance, mm (the arguments broadcast).

    Examples
    --------
    >>> round(float(cycle_distance(0.0, 30.0, 0.1, 500.0, 0.1)), 9)
    1.5
    >>> round(float(cycle_distance(100.0, 50.0, 0.05, 500.0, 0.1)), 9)  # braking all the cycle
    4.375
    """
    v0, v1, t = np.asarray(v0), np.asarray(v1), np.asarray(t)
    slowing = v1 < v0
    reached = np.where(slowing, (v0 - v1) / np.maximum(braking, 1e-9), cycle)  # when v1 is reached, s
    ramp = v0 * t + (v1 - v0) * t * t / (2.0 * cycle)
    tb = np.minimum(t, reached)
    braked = v0 * tb - braking * tb * tb / 2.0 + v1 * np.maximum(t - reached, 0.0)
    out: NDArray[np.float64] = np.where(slowing, braked, ramp)
    return out
