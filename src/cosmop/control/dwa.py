"""The extended Dynamic Window Approach: passive-safe arcs towards a global path.

Every control cycle :math:`\\varepsilon` each driving robot (Fox, Burgard and Thrun's DWA, as
extended in the paper):

1. measures the L-infinity gap to every sensed obstacle -- walls and resting objects
   (:math:`V_o = 0`), other robots and people (their top speeds);
2. decides passive safety (:mod:`cosmop.control.safety`): if ``safe`` holds it may pick any
   acceleration in :math:`[-b, A]`; otherwise it may take only arcs whose own worst case
   (held for a cycle, then braking straight on, as every brake is) provably keeps clear of
   every obstacle -- arcs along a wall or leading away -- and else brakes with :math:`-b`
   straight on, the brake the last cycle's check covered;
3. samples arcs :math:`(v, \\omega)` in the dynamic window
   :math:`[v - b\\varepsilon, \\min(v + A\\varepsilon, v_{top})] \\times [-\\Omega, \\Omega]`
   (only :math:`v - b\\varepsilon` when braking), predicts each for ``horizon`` seconds, and
4. scores them by progress towards a look-ahead point on the global path, heading towards it,
   clearance along the arc (moving obstacles pessimistically grown by :math:`V_o t`) and speed.
   A robot that stops at its target (its speed capped so that it can) counts an arc that the
   horizon carries past the target as reaching it: it brakes on the way, and does not close in
   at ever lower speed.

The safety of step 2 does not depend on the score: the score only chooses *where* to go among
arcs the safety rule admits.  Everything is vectorised over robots, arcs and obstacles.

Steps 2 and 4 measure less and answer the same, bit for bit: each drops the obstacles it has
proved too far to decide anything (:func:`_far_for_the_score`, :func:`_far_for_escape`; on
small arrays only the score does, with one choice for all robots), and the escape arcs of step
2 are checked best score first, a few at a time, until one is admitted (:func:`_best_escapes`):
only the best admitted arc is taken.
Units: mm, mm/s, radians and rad/s inside; degrees at the interfaces of :mod:`cosmop.sim`.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import lru_cache
from typing import Any, TypeVar

import numpy as np
from numpy.typing import NDArray

from cosmop.control.geometry import box_gaps, point_segment_linf
from cosmop.control.safety import Limits, cycle_distance, obstacle_speed, own_margin, stopping_horizon

_Scalar = TypeVar("_Scalar", bound=np.generic)

__all__ = ["Drivers", "DwaCommand", "DwaSettings", "Obstacles", "dwa_commands", "robot_gaps"]


@dataclass(frozen=True)
class DwaSettings:
    """Tuning of the dynamic window's search (not of its safety, which has no parameters).

    Attributes
    ----------
    speeds, turns : int
        Samples of :math:`v` and :math:`\\omega` in the window.
    horizon : float
        Prediction time of an arc, s.
    samples : int
        Points checked along a predicted arc.
    lookahead : float
        Distance of the target point ahead on the global path, mm.
    clearance : float
        Gap to walls and objects beyond which more room does not score, mm.
    personal_space : float
        The same for robots and people, mm: robots keep their distance from movers.
    standoff : float
        Extra gap (mm) that ``safe`` keeps from robots and people.  Passive safety alone lets a
        robot come arbitrarily close to a standing robot, and two robots that touch can never
        both move again; with a standoff they stop apart, and the per-arc check then lets them
        leave without closing in.  It is half the clearance the team's plans keep between
        robots (:class:`~cosmop.team.conflicts.ConflictSettings`, 100 mm): a robot that
        tracks its plan a few millimetres off still passes another where the plans let it
        (at the full clearance, a drift of 9 mm stopped robots for minutes in an aisle).
    turn_in_place : float
        Heading error (degrees) above which the robot turns on the spot instead of driving.
    progress_weight, heading_weight, clearance_weight, speed_weight : float
        Weights of an arc's score: progress towards the target (relative to the best the
        window allows), heading towards it at the arc's end, clearance (up to ``clearance``
        or ``personal_space``) and speed (relative to the top speed).
    """

    speeds: int = 5
    turns: int = 9
    horizon: float = 1.0
    samples: int = 3
    lookahead: float = 500.0
    clearance: float = 60.0
    personal_space: float = 300.0
    standoff: float = 50.0
    turn_in_place: float = 50.0
    progress_weight: float = 1.0
    heading_weight: float = 0.5
    clearance_weight: float = 0.4
    speed_weight: float = 0.05


@dataclass(frozen=True)
class DwaCommand:
    """The commands of one cycle for a batch of robots (arrays of shape ``(R,)``).

    Attributes
    ----------
    v : ndarray
        Translational speed to reach at the end of the cycle, mm/s (acceleration
        :math:`(v - v_0)/\\varepsilon \\in [-b, A]`).
    w : ndarray
        Turn rate, rad/s.
    safe : ndarray of bool
        Whether ``safe`` held (False: the robot brakes).
    gap : ndarray
        Smallest L-infinity gap to any obstacle, mm.
    """

    v: NDArray[np.float64]
    w: NDArray[np.float64]
    safe: NDArray[np.bool_]
    gap: NDArray[np.float64]


def robot_gaps(
    centres: NDArray[np.float64],
    half: NDArray[np.float64],
    walls: NDArray[np.float64],
    boxes: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """L-infinity gaps of robot squares to walls ``(R, W)`` and to boxes ``(R, M)``, every box
    measured (a caller hides the boxes a robot does not sense for each use of the gaps).
    `walls` and `boxes` are shared by every robot, or one set per robot
    (:meth:`Obstacles.per_driver`).

    Parameters
    ----------
    centres : ndarray, shape (R, 2)
        The robots' centres, mm.
    half : ndarray, shape (R,)
        Their half sides, mm.
    walls : ndarray, shape (W, 4) or (R, W, 4)
        Wall segments ``x1, y1, x2, y2``, mm.
    boxes : ndarray, shape (M, 3) or (R, M, 3)
        Boxes ``x, y, half side``, mm.
    """
    R = len(centres)
    wall_gap = point_segment_linf(centres, walls) - half[:, None] if walls.shape[-2] else np.zeros((R, 0))
    box_gap = box_gaps(centres, half[:, None], boxes) if boxes.shape[-2] else np.zeros((R, 0))
    return wall_gap, box_gap


def first_true(mask: NDArray[np.bool_]) -> NDArray[np.intp]:
    """Each row's indices of the True columns of `mask` ``(R, M)``, in order, padded with ``M``
    to the longest row: ``(R, m)`` (the form :meth:`Obstacles.take` and :func:`take_columns`
    take).

    Parameters
    ----------
    mask : ndarray of bool, shape (R, M)
        Which columns each row keeps.
    """
    counts = mask.sum(axis=1)
    width = int(counts.max(initial=0))
    order = np.argsort(~mask, axis=1, kind="stable")[:, :width]  # the True columns first, in order
    return np.where(np.arange(width) < counts[:, None], order, mask.shape[1])


def take_columns(values: NDArray[_Scalar], index: NDArray[np.intp], fill: float = False) -> NDArray[_Scalar]:
    """`values` ``(R, M)`` at the columns `index`: one list for every row ``(m,)``, or one per
    row ``(R, m)`` where ``M`` (padding) gives `fill`.

    Parameters
    ----------
    values : ndarray, shape (R, M)
        One value per row and box.
    index : ndarray of int, shape (m,) or (R, m)
        The columns to take, as from :func:`first_true`.
    fill : float or bool, default False
        The value of the padding columns.
    """
    if index.ndim == 1:
        return values[:, index]
    padded = np.concatenate([values, np.full((len(values), 1), fill, dtype=values.dtype)], axis=1)
    return padded[np.arange(len(values))[:, None], index]


# The clearance and the escape arcs first drop the boxes too far to matter to them when their
# arrays (points times boxes) would be larger than this; smaller, dropping costs more than it
# saves (a dozen NumPy calls on the drivers' boxes).
_LARGE = 50_000


def _large(points: int, obstacles: Obstacles) -> bool:
    """Whether measuring `points` points against every box of `obstacles` is worth a pruning."""
    return bool(points * obstacles.boxes.shape[-2] > _LARGE)


def _without_far(
    obstacles: Obstacles,
    centres: NDArray[np.float64],
    half: NDArray[np.float64],
    wall_beyond: NDArray[np.float64],
    box_beyond: NDArray[np.float64],
    *columns: tuple[NDArray[Any], float],
) -> tuple[Obstacles, tuple[NDArray[Any], ...]]:
    """Per driver, the walls and the boxes whose gap now (mm, as :func:`robot_gaps` measures
    it) is at most `wall_beyond` ``(R, 1)`` and `box_beyond` ``(R, M)``; `columns` (``(values
    (R, M), fill)`` pairs, over the boxes) taken alike.

    A phase drops an obstacle only when it has proved that one that far never decides its
    tests or minima; those kept are padded at infinity (:meth:`Obstacles.take`), so the
    phase's results are those it has with every obstacle, bit for bit.
    """
    wall_gap, box_gap = robot_gaps(centres, half, obstacles.walls, obstacles.boxes)
    walls, boxes = first_true(~(wall_gap > wall_beyond)), first_true(~(box_gap > box_beyond))
    return obstacles.take(walls, boxes), tuple(take_columns(v, boxes, fill) for v, fill in columns)


@dataclass(frozen=True)
class Obstacles:
    """Everything a robot senses in one cycle: the walls and the boxes (objects, robots, people).

    The shapes below are those of one set shared by every driver.  One set per driver has a
    leading axis of the drivers on every array (``(R, W, 4)``, ``(R, M, 3)``, ``(R, M)``, ...;
    :meth:`per_driver`); the dynamic window works on that form.

    Attributes
    ----------
    walls : ndarray, shape (W, 4)
        Wall segments ``x1, y1, x2, y2``, mm.
    boxes : ndarray, shape (M, 3)
        Axis-aligned squares ``x, y, half side``, mm.
    speed : ndarray, shape (M,)
        :math:`V_o`, the top speed of each box, mm/s (0 for resting objects and parked robots).
    velocity : ndarray, shape (M, 2), optional
        Current velocities, mm/s, to extrapolate the boxes along a predicted arc when scoring
        (the safety rule assumes the worst, :math:`V_o`, instead).
    acceleration : ndarray, shape (M,), optional
        Acceleration limits, mm/s² (``inf`` for people, 0 for objects): with the current
        speeds they tighten :math:`V_o` to :func:`~cosmop.control.safety.obstacle_speed` over
        each robot's stopping horizon.
    agents : ndarray of bool, shape (M,), optional
        Which boxes are robots or people, kept at the standoff (default: those that move).
    names : tuple of str
        The id of each box (for the caller; the controller does not read it).
    """

    walls: NDArray[np.float64]
    boxes: NDArray[np.float64]
    speed: NDArray[np.float64]
    velocity: NDArray[np.float64] | None = None
    acceleration: NDArray[np.float64] | None = None
    agents: NDArray[np.bool_] | None = None
    names: tuple[str, ...] = ()

    def select(self, walls: NDArray[np.intp], boxes: NDArray[np.intp]) -> Obstacles:
        """The walls and boxes at the indices `walls` and `boxes` (kept in their order); of
        one shared set, or of every row of per-driver sets alike.

        Parameters
        ----------
        walls, boxes : ndarray of int, shape (W',) and (M',)
            Indices of the walls and of the boxes to keep.
        """

        def pick(values: NDArray[np.float64] | None) -> NDArray[np.float64] | None:
            return None if values is None else values[..., boxes, :]

        return Obstacles(
            self.walls[..., walls, :],
            self.boxes[..., boxes, :],
            self.speed[..., boxes],
            pick(self.velocity),
            None if self.acceleration is None else self.acceleration[..., boxes],
            None if self.agents is None else self.agents[..., boxes],
            tuple(self.names[j] for j in boxes) if self.names else (),
        )

    def take(self, walls: NDArray[np.intp], boxes: NDArray[np.intp]) -> Obstacles:
        """One set per driver: row ``r`` holds the walls ``walls[r]`` and the boxes ``boxes[r]``
        (index matrices ``(R, W')`` and ``(R, M')``, from :func:`first_true`) of this shared set
        or of this set's row ``r``.  The index one past the end is padding: a wall or box at
        infinity (no speed, no mover), whose gaps are ``inf`` and so never decide a test or
        attain a minimum.

        Parameters
        ----------
        walls, boxes : ndarray of int, shapes (R, W') and (R, M')
            Per driver, the indices of the walls and of the boxes it keeps.
        """
        rows = np.arange(len(walls))[:, None] if self.walls.ndim == 3 else None

        def pick(values: NDArray[_Scalar], filler: object, index: NDArray[np.intp]) -> NDArray[_Scalar]:
            axis = 0 if rows is None else 1  # the obstacles' axis
            shape = list(values.shape)
            shape[axis] = 1
            pad = np.broadcast_to(np.asarray(filler, values.dtype), shape)
            padded = np.concatenate([values, pad], axis=axis)
            return padded[index] if rows is None else padded[rows, index]

        return Obstacles(
            pick(self.walls, [np.inf] * 4, walls),
            pick(self.boxes, [np.inf, np.inf, 0.0], boxes),
            pick(self.speed, 0.0, boxes),
            None if self.velocity is None else pick(self.velocity, [0.0, 0.0], boxes),
            None if self.acceleration is None else pick(self.acceleration, 0.0, boxes),
            None if self.agents is None else pick(self.agents, False, boxes),
        )

    def per_driver(self, drivers: int) -> Obstacles:
        """The same obstacles as one set per driver: every array gains a leading axis of length
        `drivers` (copies: small next to the window's own arrays, and cheaper to make than
        broadcast views); obstacles already per driver are returned as they are.

        Per-driver sets may differ (:func:`~cosmop.control.neighbourhood.dwa_commands_near`
        gives each driver what is near it); a shorter set is padded with boxes and walls at
        infinity (:func:`~cosmop.control.geometry.per_row`), which no test or minimum sees.

        Parameters
        ----------
        drivers : int
            The number of drivers ``R``.
        """
        if self.walls.ndim == 3:
            return self

        def each(values: NDArray[_Scalar]) -> NDArray[_Scalar]:
            return values[None].repeat(drivers, axis=0)

        return Obstacles(
            each(self.walls),
            each(self.boxes),
            each(self.speed),
            None if self.velocity is None else each(self.velocity),
            None if self.acceleration is None else each(self.acceleration),
            None if self.agents is None else each(self.agents),
            self.names,
        )

    def rows(self, rows: NDArray[np.intp]) -> Obstacles:
        """The per-driver sets of the drivers `rows` (obstacles made by :meth:`per_driver`).

        Parameters
        ----------
        rows : ndarray of int
            Indices of the drivers.
        """

        def pick(values: NDArray[_Scalar] | None) -> NDArray[_Scalar] | None:
            return None if values is None else values[rows]

        return Obstacles(
            self.walls[rows],
            self.boxes[rows],
            self.speed[rows],
            pick(self.velocity),
            pick(self.acceleration),
            pick(self.agents),
            self.names,
        )

    @property
    def movers(self) -> NDArray[np.bool_]:
        """Which boxes are kept at the standoff: :attr:`agents`, else those that move."""
        return self.speed > 0 if self.agents is None else self.agents

    def speed_bound(self, horizon: float | NDArray[np.float64]) -> NDArray[np.float64]:
        """:math:`V_o` of every box over a stopping `horizon` (s), mm/s.

        :func:`~cosmop.control.safety.obstacle_speed` of the boxes' current speeds and
        accelerations, or their top speed when those are unknown.  `horizon` broadcasts against
        the boxes: a scalar gives ``(M,)``, a column ``(R, 1)`` gives ``(R, M)``.

        Parameters
        ----------
        horizon : float or ndarray
            The stopping horizon, s.
        """
        if self.acceleration is None or self.velocity is None or not self.boxes.shape[-2]:
            return np.broadcast_to(self.speed, np.broadcast_shapes(np.shape(horizon), self.speed.shape))
        now = np.hypot(self.velocity[..., 0], self.velocity[..., 1])
        return obstacle_speed(horizon, self.speed, now, self.acceleration)


@dataclass(frozen=True)
class Drivers:
    """The robots that drive this cycle, and where each heads (arrays over robots, ``(R, ...)``).

    Attributes
    ----------
    pose : ndarray, shape (R, 3)
        ``x, y`` (mm) and heading (rad).
    v : ndarray, shape (R,)
        Translational speeds now, mm/s.
    half : ndarray, shape (R,)
        Half sides of the robots, mm.
    limits : Limits
        Their unicycle limits.
    target : ndarray, shape (R, 2)
        The look-ahead point on each robot's global path, mm.
    stop_distance : ndarray, shape (R,)
        Distance left to the goal along the path (mm): the speed is capped so that the robot
        can stop there.
    room_cap : ndarray, shape (R,), optional
        The most clearance that scores (mm; default ``DwaSettings.clearance``).  Set it to the
        gap at the goal so that a goal close to an obstacle (a docking pose) does not repel its
        own robot.
    """

    pose: NDArray[np.float64]
    v: NDArray[np.float64]
    half: NDArray[np.float64]
    limits: Limits
    target: NDArray[np.float64]
    stop_distance: NDArray[np.float64]
    room_cap: NDArray[np.float64] | None = None

    def __getitem__(self, rows: NDArray[np.intp] | NDArray[np.bool_]) -> Drivers:
        """The drivers `rows` (an index array or a mask)."""
        return Drivers(
            self.pose[rows],
            self.v[rows],
            self.half[rows],
            self.limits[rows],
            self.target[rows],
            self.stop_distance[rows],
            None if self.room_cap is None else self.room_cap[rows],
        )


def dwa_commands(
    drivers: Drivers,
    obstacles: Obstacles,
    settings: DwaSettings = DwaSettings(),
    *,
    ignore: NDArray[np.bool_] | None = None,
    grip: NDArray[np.bool_] | None = None,
) -> DwaCommand:
    """One cycle of the extended DWA for `R` robots at once.

    Parameters
    ----------
    drivers : Drivers
        The robots, their limits and their targets.
    obstacles : Obstacles
        The walls and the boxes they sense.
    settings : DwaSettings
    ignore : ndarray of bool, shape (R, M), optional
        Boxes each robot does not treat as obstacles (itself).
    grip : ndarray of bool, shape (R, M), optional
        The object each robot touches with its gripper (just docked or just dropped): it does
        not count for ``safe`` (the robot touches it by design) but arcs into it score as
        touching, so the robot leaves it.

    Returns
    -------
    DwaCommand
    """
    obstacles = obstacles.per_driver(len(drivers.v))  # one set per driver from here on
    skip = ignore if grip is None else (grip if ignore is None else ignore | grip)
    gaps = robot_gaps(drivers.pose[:, :2], drivers.half, obstacles.walls, obstacles.boxes)
    wall_gap, box_gap = gaps
    if skip is not None and box_gap.size:
        box_gap = np.where(skip, np.inf, box_gap)
    safe = _passive_safety(drivers, obstacles, wall_gap, box_gap, settings)
    min_gap = np.minimum(wall_gap.min(axis=1, initial=np.inf), box_gap.min(axis=1, initial=np.inf))
    if not safe.all() and obstacles.boxes.shape[-2]:
        # Not safe: head away from the nearest robot or person along the axis of its L-infinity
        # gap first, out of the standoff; the path is taken up again once safe holds.
        drivers = _retreat(drivers, obstacles, box_gap, ~safe, settings)
    low, high, V, W = _window(drivers, settings)
    t, pts, th = _arcs(drivers, V, W, settings)
    near, near_ignore = _far_for_the_score(drivers, obstacles, ignore, t, pts, settings, gaps)
    clear, mover_clear = _clearance(drivers, near, near_ignore, t, pts)
    score = _score(drivers, settings, high, V, pts, th, clear, mover_clear)
    w_out = np.zeros(len(drivers.v))
    if not safe.all():
        # Not safe: only arcs whose own braking path provably keeps clear (checked below), else
        # brake straight on -- the brake the last cycle's check covered.
        rows = np.flatnonzero(~safe)
        pick, found = _best_escapes(
            drivers[rows],
            V[rows],
            W[rows],
            score[rows],
            obstacles.rows(rows),
            None if ignore is None or skip is None else skip[rows],
            _keep(box_gap[rows], obstacles.movers[rows], settings),
        )
        admitted = np.full((len(rows), V.shape[1]), -np.inf)  # the best escape arc alone
        admitted[found, pick[found]] = score[rows[found], pick[found]]
        score[rows] = admitted
    best = np.argmax(score, axis=1)
    rows_all = np.arange(len(drivers.v))
    finite = np.isfinite(score[rows_all, best])
    v_out = np.where(finite, V[rows_all, best], low)
    w_out = np.where(finite, W[rows_all, best], w_out)
    return DwaCommand(v=v_out, w=w_out, safe=safe, gap=min_gap)


def _passive_safety(
    drivers: Drivers,
    obstacles: Obstacles,
    wall_gap: NDArray[np.float64],
    box_gap: NDArray[np.float64],
    settings: DwaSettings,
) -> NDArray[np.bool_]:
    """The paper's ``safe`` for every robot against every obstacle at once, ``(R,)``.

    Walls and resting objects have :math:`V_o = 0`; robots and people keep the standoff, and
    their :math:`V_o` is :func:`~cosmop.control.safety.obstacle_speed` over the robot's
    stopping horizon when their velocities and accelerations are known.
    """
    limits, v = drivers.limits.column(), drivers.v[:, None]
    # stopping_margin(v, V_o) is own + V_o * horizon, summed in that order: each part once
    own, horizon = own_margin(v, limits), stopping_horizon(v, limits)
    safe: NDArray[np.bool_] = np.all(wall_gap > own, axis=1)  # walls stand still
    if obstacles.boxes.shape[-2]:
        gap = box_gap - settings.standoff * obstacles.movers
        safe &= np.all(gap > own + obstacles.speed_bound(horizon) * horizon, axis=1)
    return safe


def _retreat(
    drivers: Drivers,
    obstacles: Obstacles,
    box_gap: NDArray[np.float64],
    unsafe: NDArray[np.bool_],
    settings: DwaSettings,
) -> Drivers:
    """`drivers` with the unsafe ones inside the standoff of a robot or person aimed at a point
    away from it, and no stop distance (they leave at once)."""
    rows = np.flatnonzero(unsafe)
    xy, boxes = drivers.pose[:, :2], obstacles.boxes
    # the standoff is kept from movers only: a robot that passes close by a resting object
    # (goods on a shelf face) drives on along it, not away sideways
    gap = np.where(obstacles.movers[rows], box_gap[rows], np.inf)
    near = np.argmin(gap, axis=1)
    close = gap[np.arange(len(rows)), near] < settings.standoff
    delta = xy[rows] - boxes[rows, near, :2]
    along_x = np.abs(delta[:, 0]) >= np.abs(delta[:, 1])
    away = np.where(along_x[:, None], [[1.0, 0.0]], [[0.0, 1.0]]) * np.sign(delta).clip(-1, 1)
    away[np.all(away == 0, axis=1)] = [1.0, 0.0]
    walls = obstacles.walls[rows]
    retreat = _open_retreat(xy[rows], drivers.half[rows], away, delta, walls, settings.standoff * 2)
    target = drivers.target.copy()
    target[rows[close]] = retreat[close]
    stop = drivers.stop_distance.copy()
    stop[rows] = np.inf  # the unsafe leave at once; the others keep their stop at the goal
    return replace(drivers, target=target, stop_distance=stop)


def _arcs(
    drivers: Drivers, V: NDArray[np.float64], W: NDArray[np.float64], settings: DwaSettings
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Predicted arcs: the times ``t`` (S,), positions ``(R, K, S, 2)`` and headings
    ``(R, K, S)`` at :math:`t_k = k\\,T/S`, k = 1..S, with ``(v, w)`` held."""
    xy, theta = drivers.pose[:, :2], drivers.pose[:, 2]
    t = _instants(settings.horizon, settings.samples)  # (S,)
    th = theta[:, None, None] + W[:, :, None] * t[None, None, :]
    straight = np.abs(W) < 1e-6
    sin0, cos0 = np.sin(theta)[:, None, None], np.cos(theta)[:, None, None]
    vt = V[:, :, None] * t  # a straight arc's length
    radius = V[:, :, None] / np.where(straight, 1.0, W)[:, :, None]  # a turning arc's (signed) radius
    # (-v / w) * c is -(v / w * c) exactly: the sign is the only difference
    px = np.where(straight[:, :, None], vt * cos0, radius * (np.sin(th) - sin0))
    py = np.where(straight[:, :, None], vt * sin0, -(radius * (np.cos(th) - cos0)))
    pts = np.empty((*px.shape, 2))
    pts[..., 0] = xy[:, 0, None, None] + px
    pts[..., 1] = xy[:, 1, None, None] + py
    return t, pts, th


def _clearance(
    drivers: Drivers,
    obstacles: Obstacles,
    ignore: NDArray[np.bool_] | None,
    t: NDArray[np.float64],
    pts: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The least gap along each arc to anything, and to movers alone, ``(R, K)`` each, mm.

    Moving boxes are extrapolated with their velocities when known (else grown by nothing:
    the score only chooses among arcs the safety rule admits).  The window passes only the
    obstacles that can count (:func:`_far_for_the_score`).
    """
    R, K, S = pts.shape[:3]
    half, walls, boxes, movers = drivers.half, obstacles.walls, obstacles.boxes, obstacles.movers
    if ignore is not None and boxes.shape[-2]:
        # a box ignored is one at infinity: its gaps are inf, as the masked copy of all of them
        # would have them, at the cost of a copy of the boxes alone
        boxes = boxes.copy()
        boxes[..., :2][ignore] = np.inf
    flat = pts.reshape(R, -1, 2)
    mover_clear = np.full((R, K), np.inf)
    if walls.shape[-2]:
        clear = (point_segment_linf(flat, walls) - half[:, None, None]).min(axis=-1)
    else:
        clear = np.full(flat.shape[:2], np.inf)
    if boxes.shape[-2]:
        # the gaps with the boxes' axis first (M, R, K, S): the minima over the boxes then run
        # across whole rows, far faster than along a short last axis
        bx, by = boxes[..., 0].T[:, :, None, None], boxes[..., 1].T[:, :, None, None]
        if obstacles.velocity is not None:  # each box where it is at each instant (M, R, 1, S)
            bx = bx + t * obstacles.velocity[..., 0].T[:, :, None, None]
            by = by + t * obstacles.velocity[..., 1].T[:, :, None, None]
        bg = pts[..., 0] - bx  # max(|dx|, |dy|) - half - k, in place
        dy = pts[..., 1] - by
        np.abs(bg, out=bg)
        np.maximum(bg, np.abs(dy, out=dy), out=bg)
        bg -= half[:, None, None]
        bg -= boxes[..., 2].T[:, :, None, None]
        if movers.any():
            mover_clear = np.where(movers.T[:, :, None, None], bg, np.inf).min(axis=0).min(axis=-1)
        clear = np.minimum(clear, bg.min(axis=0).reshape(R, K * S))
    return clear.reshape(R, K, S).min(axis=-1), mover_clear


def _far_for_the_score(
    drivers: Drivers,
    obstacles: Obstacles,
    ignore: NDArray[np.bool_] | None,
    t: NDArray[np.float64],
    pts: NDArray[np.float64],
    settings: DwaSettings,
    gaps: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None,
) -> tuple[Obstacles, NDArray[np.bool_] | None]:
    """`obstacles` (and `ignore`) without the walls and boxes too far to change any arc's score.

    The score reads the least gap along an arc only up to the clearance cap :math:`c`, and the
    least gap to a mover only up to the personal space :math:`p` (so up to :math:`c` for walls
    and resting boxes, up to :math:`\\max(c, p)` for movers); whether a gap is above zero is
    its only other use.  The L-infinity gap is 1-Lipschitz in the L-infinity norm: at a
    point of an arc it is at least the gap now less the point's offset from the robot, less
    what the box moves by the last instant :math:`t_S` (at most :math:`|v_o| t_S`).  An
    obstacle whose gap now exceeds the largest offset, its move and what its gap counts up to
    (and 1 mm for rounding) is farther than that from every point of every arc, so it is never
    a minimum that counts.

    Large arrays are pruned row by row (:func:`_without_far`).  Small ones are not worth it;
    there the gaps now, `gaps` (``(R, W)`` and ``(R, M)`` as :func:`robot_gaps` measures them,
    nothing ignored), drop the walls and boxes too far for every row (one selection for all
    rows: most cycles, most of the boxes and all of the walls).
    """
    offset = np.abs(pts - drivers.pose[:, None, None, :2]).max(axis=(1, 2, 3))  # (R,)
    cap = max(settings.clearance, 0.0)  # the cap, and at least the gaps at or below zero
    walls = offset[:, None] + cap + 1.0  # walls count up to the cap alone
    moves = 0.0
    if obstacles.velocity is not None:
        moves = np.hypot(obstacles.velocity[..., 0], obstacles.velocity[..., 1]) * t[-1]
    counts = np.where(obstacles.movers, max(cap, settings.personal_space), cap)
    boxes = offset[:, None] + moves + counts + 1.0  # and so do resting boxes
    if _large(pts.size // 2, obstacles):
        columns = () if ignore is None else ((ignore, False),)
        kept, taken = _without_far(obstacles, drivers.pose[:, :2], drivers.half, walls, boxes, *columns)
        return kept, (taken[0] if taken else None)
    if gaps is None:
        return obstacles, ignore
    wall_gap, box_gap = gaps
    if ignore is not None and box_gap.size:
        # an ignored box is measured at infinity, so it is never a minimum (with a size that is
        # not finite its gap there is NaN, as :func:`_clearance` measures it: kept)
        box_gap = np.where(ignore & np.isfinite(obstacles.boxes[..., 2]), np.inf, box_gap)
    # kept: what is not provably too far for some row (a NaN gap is kept)
    wall_kept, box_kept = ~(wall_gap > walls).all(axis=0), ~(box_gap > boxes).all(axis=0)
    if wall_kept.all() and box_kept.all():
        return obstacles, ignore
    box_index = np.flatnonzero(box_kept)
    near = obstacles.select(np.flatnonzero(wall_kept), box_index)
    return near, (None if ignore is None else ignore[:, box_index])


def _score(
    drivers: Drivers,
    settings: DwaSettings,
    high: NDArray[np.float64],
    V: NDArray[np.float64],
    pts: NDArray[np.float64],
    th: NDArray[np.float64],
    clear: NDArray[np.float64],
    mover_clear: NDArray[np.float64],
) -> NDArray[np.float64]:
    """Each arc's score ``(R, K)``: progress towards the target, heading towards it at the
    arc's end, room (up to the clearance cap and the personal space) and speed."""
    xy, target = drivers.pose[:, :2], drivers.target
    end, end_heading = pts[:, :, -1, :], th[:, :, -1]
    d_now = np.hypot(target[:, 0] - xy[:, 0], target[:, 1] - xy[:, 1])
    dx, dy = target[:, None, 0] - end[..., 0], target[:, None, 1] - end[..., 1]  # end to target
    d_end = np.hypot(dx, dy)
    bearing = np.arctan2(dy, dx)
    heading = 1.0 - np.abs(np.angle(np.exp(1j * (bearing - end_heading)))) / np.pi
    heading = np.where(d_end < 1.0, 1.0, heading)
    passing = _passing(drivers, pts, d_now, d_end)
    if passing is not None:  # a robot stopping at its target: an arc carried past it gets there
        d_end, heading = np.minimum(d_end, passing), np.where(passing < d_end, 1.0, heading)
    # Progress relative to the best the window allows, so that it also decides at low speed.
    progress = (d_now[:, None] - d_end) / np.maximum(high * settings.horizon, 1.0)[:, None]
    R = len(drivers.v)
    cap = (
        np.full(R, settings.clearance)
        if drivers.room_cap is None
        else np.minimum(drivers.room_cap, settings.clearance)
    )
    cap = np.maximum(cap, 0.0)[:, None]
    room = np.where(cap > 0, np.minimum(clear, cap) / np.maximum(cap, 1e-9), 1.0)
    room = np.minimum(room, np.minimum(np.maximum(mover_clear / settings.personal_space, 0.0), 1.0))  # clip
    score = (
        settings.progress_weight * progress
        + settings.heading_weight * heading
        + settings.clearance_weight * room
        + settings.speed_weight * V / np.maximum(drivers.limits.max_speed, 1.0)[:, None]
    )
    # An arc that would touch something within the horizon is taken only if every arc would.
    scored: NDArray[np.float64] = np.where(clear > 0, score, score - 1e3 + clear / 1e3)
    return scored


def _passing(
    drivers: Drivers, pts: NDArray[np.float64], d_now: NDArray[np.float64], d_end: NDArray[np.float64]
) -> NDArray[np.float64] | None:
    r"""For a robot whose target is where it stops, each arc's least distance to the target
    ``(R, K)`` (``inf`` for the other robots); ``None`` when no robot stops at its target.

    The window caps such a robot's speed so that it can stop at the target
    (:math:`\sqrt{b\,d}`, :func:`_window`), so an arc whose horizon carries it past the target
    is one it brakes on before: scored by where it ends, it would look like overshooting, and
    the robot would close in at the speed that covers the rest in one horizon, slower and
    slower (a tail of seconds at every stop).  Measured to the arc's polyline (the robot, then
    the predicted points), it counts as reaching the target.
    """
    # the target is where it stops when no nearer than the stop (a corner on the way is not)
    stops = np.isfinite(drivers.stop_distance) & (d_now >= drivers.stop_distance - 1.0)
    if not stops.any():
        return None
    xy, target = drivers.pose[:, None, None, :2], drivers.target[:, None, None, :]
    R, K = pts.shape[:2]
    line = np.concatenate([np.broadcast_to(xy, (R, K, 1, 2)), pts], axis=2)  # (R, K, S+1, 2)
    a, ab = line[:, :, :-1], np.diff(line, axis=2)
    t = np.clip(np.sum((target - a) * ab, axis=-1) / np.maximum(np.sum(ab * ab, axis=-1), 1e-12), 0.0, 1.0)
    gap = target - (a + t[..., None] * ab)
    nearest = np.hypot(gap[..., 0], gap[..., 1]).min(axis=2)
    return np.where(stops[:, None], nearest, np.inf)


def _keep(near: NDArray[np.float64], movers: NDArray[np.bool_], settings: DwaSettings) -> NDArray[np.float64]:
    """Inside the standoff of a mover, an escape arc may not end closer to it than now (a few
    mm of slack per cycle, down to half the standoff, so that it can slide along); ``-inf``
    elsewhere."""
    floor = np.minimum(near, np.maximum(near - 2.0, settings.standoff / 2))
    return np.where(movers & (near < settings.standoff), floor, -np.inf)


def _open_retreat(
    xy: NDArray[np.float64],
    half: NDArray[np.float64],
    away: NDArray[np.float64],
    delta: NDArray[np.float64],
    walls: NDArray[np.float64],
    reach: float,
) -> NDArray[np.float64]:
    """Where to step back from the nearest box: `reach` along `away` unless a wall is in the way,
    then along the other axis (the side farther from the box first), else staying put."""
    other = np.where(away[:, :1] != 0, [[0.0, 1.0]], [[1.0, 0.0]])
    side = np.sign((delta * other).sum(axis=1, keepdims=True))
    side[side == 0] = 1.0
    points = xy[:, None, :] + np.stack([away, other * side, -other * side], axis=1) * reach  # (U, 3, 2)
    if not walls.shape[-2]:
        return points[:, 0]
    free = (point_segment_linf(points, walls).min(axis=-1) - half[:, None]) >= 0.0  # all three at once
    first = np.argmax(free, axis=1)  # the first free option, in order
    rows = np.arange(len(xy))
    return np.where(free[rows, first][:, None], points[rows, first], xy)


def _window(
    drivers: Drivers, settings: DwaSettings
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    r"""The sampled arcs of the dynamic window of each robot, towards its `target`.

    The speeds span :math:`[v - b\varepsilon, \min(v + A\varepsilon, v_{top},
    \sqrt{b\,d})]` (:math:`d`: `stop_distance`, so that the robot can stop at its goal),
    only the lower end when the target lies more than ``turn_in_place`` off the heading; the
    turn rates span :math:`[-\Omega, \Omega]` plus the one that aims at the target.

    Returns
    -------
    low, high : ndarray, shape (R,)
        The window's speed range, mm/s.
    V, W : ndarray, shape (R, K)
        Every sampled pair of speed (mm/s) and turn rate (rad/s).
    """
    R, v, target, stop_distance = len(drivers.v), drivers.v, drivers.target, drivers.stop_distance
    lim = drivers.limits
    top, acc, brk, omega, eps = lim.max_speed, lim.acceleration, lim.braking, lim.turn_rate, lim.cycle
    xy, theta = drivers.pose[:, :2], drivers.pose[:, 2]
    low = np.maximum(0.0, v - brk * eps)
    high = np.minimum(v + acc * eps, top)
    high = np.minimum(high, np.sqrt(np.maximum(brk * stop_distance, 0.0)))
    high = np.maximum(high, low)
    to_target = np.arctan2(target[:, 1] - xy[:, 1], target[:, 0] - xy[:, 0])
    error = np.angle(np.exp(1j * (to_target - theta)))
    turning = np.abs(error) > np.radians(settings.turn_in_place)
    high = np.where(turning, low, high)
    s = _spread(0.0, settings.speeds)
    vs = low[:, None] + (high - low)[:, None] * s[None, :]  # (R, Nv)
    ws = omega[:, None] * _spread(-1.0, settings.turns)[None, :]
    aim = np.minimum(np.maximum(error / max(settings.horizon / 2, eps.max()), -omega), omega)
    ws = np.concatenate([ws, aim[:, None]], axis=1)  # (R, Nw)
    V = np.repeat(vs[:, :, None], ws.shape[1], axis=2).reshape(R, -1)  # (R, K)
    W = np.repeat(ws[:, None, :], vs.shape[1], axis=1).reshape(R, -1)
    return low, high, V, W


@lru_cache(maxsize=8)
def _spread(start: float, count: int) -> NDArray[np.float64]:
    """``count`` evenly spaced values from `start` to 1 (the window's samples, made once)."""
    out = np.linspace(start, 1.0, count)
    out.flags.writeable = False
    return out


@lru_cache(maxsize=8)
def _instants(horizon: float, samples: int) -> NDArray[np.float64]:
    """The predicted instants :math:`k\\,T/S`, k = 1..S, of an arc (made once)."""
    out = horizon * np.arange(1, samples + 1) / samples
    out.flags.writeable = False
    return out


# Escape arcs are checked this many at a time, best scores first, until one is admitted.
_ESCAPE_BATCH = 8


def _best_escapes(
    drivers: Drivers,
    V: NDArray[np.float64],
    W: NDArray[np.float64],
    score: NDArray[np.float64],
    obstacles: Obstacles,
    skip: NDArray[np.bool_] | None,
    keep: NDArray[np.float64],
) -> tuple[NDArray[np.int64], NDArray[np.bool_]]:
    """For each unsafe driver, the best-scored arc that :func:`_escape_ok` admits: its index
    ``(U,)`` and whether there is one ``(U,)``.

    The arcs are checked in order of score (the lower index first among equal scores, as
    ``argmax`` takes them), a few at a time, and a driver's search stops at its first
    admitted arc; each arc's check depends on that arc alone (and on the longest stop of the
    driver's whole window, passed on), so the answer is the ``argmax`` of the scores of all
    admitted arcs, found without checking the arcs that score below it.
    """
    U, K = V.shape
    # best first, ties by index; NaN before all, as argmax takes the first NaN as the largest
    order = np.argsort(np.where(np.isnan(score), -np.inf, -score), axis=1, kind="stable")
    longest = (drivers.limits.cycle[:, None] + V / drivers.limits.braking[:, None]).max(axis=1)
    pick, found = np.zeros(U, dtype=np.int64), np.zeros(U, dtype=bool)
    for start in range(0, K, _ESCAPE_BATCH):
        todo = np.flatnonzero(~found)
        if not todo.size:
            break
        arcs = order[todo, start : start + _ESCAPE_BATCH]  # (u, b)
        lines = np.arange(len(todo))[:, None]
        ok = _escape_ok(
            drivers[todo],
            V[todo][lines, arcs],
            W[todo][lines, arcs],
            obstacles.rows(todo),
            None if skip is None else skip[todo],
            keep[todo],
            longest=longest[todo],
        )
        hit = ok.any(axis=1)
        pick[todo[hit]] = arcs[hit, ok[hit].argmax(axis=1)]
        found[todo[hit]] = True
    return pick, found


def _far_for_escape(
    drivers: Drivers,
    pts: NDArray[np.float64],
    longest: NDArray[np.float64],
    slack: NDArray[np.float64],
    obstacles: Obstacles,
    skip: NDArray[np.bool_] | None,
    keep: NDArray[np.float64],
) -> tuple[Obstacles, NDArray[np.bool_] | None, NDArray[np.float64]]:
    """`obstacles` (with `skip` and `keep`) without the boxes that pass every sample of every
    escape arc (:func:`_escape_ok`; `pts` ``(U, P, 2)`` its samples, `longest` ``(U,)`` the
    boxes' horizon, at least every arc's time to a stop, `slack` ``(U, K, n)``).

    A sample at time :math:`t` passes a box when its gap exceeds :math:`V_o t` plus the slack;
    its gap is at least the gap now less the sample's L-infinity offset from the robot (the
    gap is 1-Lipschitz).  So a box whose gap now exceeds the largest offset, :math:`V_o` times
    the longest time to a stop and the largest slack (and 1 mm for rounding) passes them all;
    the other rules of :func:`_escape_ok` only admit more, except ``keep``, and boxes with a
    ``keep`` rule are kept.
    """
    if not _large(pts.shape[0] * pts.shape[1], obstacles):
        return obstacles, skip, keep
    longest = longest[:, None]
    offset = np.abs(pts - drivers.pose[:, None, :2]).max(axis=(1, 2))[:, None]
    walls = offset + slack.max(axis=(1, 2))[:, None] + 1.0  # walls stand still
    boxes = walls + obstacles.speed_bound(longest) * longest
    boxes = np.where(keep > -np.inf, np.inf, boxes)
    columns = ((keep, -np.inf),) + (() if skip is None else ((skip, False),))
    kept, taken = _without_far(obstacles, drivers.pose[:, :2], drivers.half, walls, boxes, *columns)
    return kept, (None if skip is None else taken[1]), taken[0]


_CYCLE_SAMPLES = 4  # points of the cycle's own arc: the simulator's sub-steps (sim.unicycle)


def _brake_path(
    pose: NDArray[np.float64],
    v: NDArray[np.float64],
    V: NDArray[np.float64],
    W: NDArray[np.float64],
    brk: NDArray[np.float64],
    eps: NDArray[np.float64],
    steps: int,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    r"""Where each arc's worst case takes the robot: one cycle at ``(V, W)``, then a straight stop.

    During the cycle the robot turns at :math:`W` and changes speed as the simulator moves it
    (a ramp up to :math:`V`, or braking at :math:`-b` until :math:`V` and holding it), its
    position taken at the ends of :data:`_CYCLE_SAMPLES` sub-steps, each at its midpoint
    heading.  Then it brakes at :math:`-b` on a straight line: :math:`V^2/2b` long, sampled at
    `steps` points evenly spaced along it, at the times it passes them,
    :math:`\varepsilon + (V - \sqrt{V^2 - 2bs})/b`.

    Returns the sample times ``t``, positions ``x`` and ``y`` and the path length from the
    sample before ``slack`` (each ``(U, K, n)``, n = :data:`_CYCLE_SAMPLES` + `steps`): every
    point of the path lies within its sample's slack of it, and is passed no later.
    """
    n1 = _CYCLE_SAMPLES
    e = eps[:, None, None]
    frac = np.arange(1, n1 + 1) / n1  # (n1,)
    tc = e * frac  # (U, 1, n1)
    v1, b = V[:, :, None], brk[:, None, None]
    covered = cycle_distance(v[:, None, None], v1, tc, b, e)  # (U, K, n1) from the cycle's start
    step1 = np.diff(covered, axis=2, prepend=0.0)
    turn = W[:, :, None] * e / n1
    heading = pose[:, 2, None, None] + turn * (np.arange(n1) + 0.5)  # each sub-step's midpoint
    x1 = pose[:, 0, None, None] + np.cumsum(step1 * np.cos(heading), axis=2)
    y1 = pose[:, 1, None, None] + np.cumsum(step1 * np.sin(heading), axis=2)
    # then straight on at the cycle's last heading, braking to a stop
    final = pose[:, 2, None, None] + W[:, :, None] * e
    length = v1 * v1 / (2.0 * b)  # (U, K, 1)
    s = length * (np.arange(1, steps + 1) / steps)  # (U, K, steps)
    t2 = e + (v1 - np.sqrt(np.maximum(v1 * v1 - 2.0 * b * s, 0.0))) / b
    x2 = x1[:, :, -1:] + s * np.cos(final)
    y2 = y1[:, :, -1:] + s * np.sin(final)
    slack2 = np.broadcast_to(length / steps, s.shape)
    t = np.concatenate([np.broadcast_to(tc, step1.shape), t2], axis=2)
    return (
        t,
        np.concatenate([x1, x2], axis=2),
        np.concatenate([y1, y2], axis=2),
        np.concatenate([step1, slack2], axis=2),
    )


def _escape_ok(
    drivers: Drivers,
    V: NDArray[np.float64],
    W: NDArray[np.float64],
    obstacles: Obstacles,
    skip: NDArray[np.bool_] | None,
    keep: NDArray[np.float64],
    steps: int = 16,
    longest: NDArray[np.float64] | None = None,
) -> NDArray[np.bool_]:
    """Whether each arc's worst case keeps clear: held for one cycle, then braking to a stop.

    The robot moves one cycle on the arc, then brakes with :math:`-b` straight on
    (:func:`_brake_path`, `steps` samples on the straight part); at every sample, passed at
    :math:`t`, its square must be farther from each obstacle than :math:`V_o t` plus the path
    length from the sample before.  Turning only within the cycle, a robot driving along a
    narrow aisle can keep its heading there at speed (held for the whole stop, any turn would
    curve into the aisle's side).
    This is passive safety checked directly along one arc, used when ``safe`` (which covers
    every arc at once) fails, so that a robot standing close to something can still leave.
    ``keep`` (shape ``(U, M)``, mm): the gap to each box may not end below it (``-inf``: no
    such rule), so that a robot inside another's standoff only leaves or slides along.  Turning
    on the spot from a standstill is always admitted (the square footprint does not move).
    """
    U, K = V.shape
    pose, v, half, brk, eps = (
        drivers.pose,
        drivers.v,
        drivers.half,
        drivers.limits.braking,
        drivers.limits.cycle,
    )
    total = eps[:, None] + V / brk[:, None]  # (U, K): time until standing still
    longest = total.max(axis=1) if longest is None else longest  # (U,): the boxes' horizon
    t, x, y, slack = _brake_path(pose, v, V, W, brk, eps, steps)
    pts = np.stack([x, y], axis=-1).reshape(U, -1, 2)
    obstacles, skip, keep = _far_for_escape(drivers, pts, longest, slack, obstacles, skip, keep)
    walls, boxes = obstacles.walls, obstacles.boxes
    ok = np.ones((U, K), dtype=bool)
    if walls.shape[-2]:
        gap = (point_segment_linf(pts, walls) - half[:, None, None]).reshape(U, K, t.shape[-1], -1)
        now_gap = point_segment_linf(pose[:, :2], walls) - half[:, None]  # (U, W)
        # moving away never closes a gap, even one already (numerically) shut: it must open
        opens = gap > np.minimum(now_gap, 0.0)[:, None, None, :]
        fine = (gap > slack[..., None]) | ((gap >= now_gap[:, None, None, :] - 1e-9) & opens)
        ok &= fine.all(axis=(2, 3))
    if boxes.shape[-2]:
        gap = box_gaps(pts, half[:, None, None], boxes).reshape(U, K, t.shape[-1], -1)
        bound = obstacles.speed_bound(longest[:, None])  # (U, M)
        reach = t[..., None] * bound[:, None, None, :]
        fine = gap > reach + slack[..., None]
        # From a box that stands still (V = 0), moving away never closes the gap: an arc whose
        # sampled gaps never fall below the gap now (and open up at once) needs no slack.
        now_gap = box_gaps(pose[:, :2], half[:, None], boxes)  # (U, M)
        away = (gap >= now_gap[:, None, None, :] - 1e-9) & (gap > np.minimum(now_gap, 0.0)[:, None, None, :])
        fine |= away & (bound[:, None, None, :] == 0)
        fine[:, :, -1, :] &= gap[:, :, -1, :] >= keep[:, None, :] - 1e-9
        if skip is not None:
            fine |= skip[:, None, None, :]
        ok &= fine.all(axis=(2, 3))
    # A robot that stands and stays standing (it may turn: its square does not move) cannot
    # run into anything: that is always allowed, so a robot touching a wall can turn away.
    admitted: NDArray[np.bool_] = ok | ((v[:, None] == 0) & (V == 0))
    return admitted
