"""The neighbourhood cut-off: each robot's dynamic window scores only what can change its command.

:func:`~cosmop.control.dwa.dwa_commands` measures every driver against every wall and box, a
cost of :math:`R (W + M)` per cycle for :math:`R` drivers, :math:`W` walls and :math:`M` boxes.
Almost all of them are too far to matter: :func:`reach` bounds, for each driver, the L-infinity
gap beyond which an obstacle cannot change anything the window decides, and
:func:`dwa_commands_near` gives each group of nearby drivers only the obstacles within reach.

**Why the commands do not change (passive safety included).**  Let :math:`\\bar v` be the
driver's top speed, :math:`(A, b, \\varepsilon)` its limits, :math:`T` its stopping horizon
at :math:`\\bar v` (:func:`~cosmop.control.safety.stopping_horizon`), :math:`h` the window's
prediction horizon and :math:`\\bar V` the largest speed of any box (its top speed, and its
sensed speed).  Every decision of the window compares a gap with a bound, or takes a minimum of
gaps capped from above:

* ``safe`` asks, per obstacle, for a gap (less the standoff, for a robot or person) above
  :func:`~cosmop.control.safety.stopping_margin` :math:`(v, V_o)`, which grows with
  :math:`v \\le \\bar v` and :math:`V_o \\le \\bar V`; an obstacle farther than the standoff
  plus that margin at :math:`(\\bar v, \\bar V)` passes it.  ``safe`` is the conjunction over
  the obstacles, so it is the same without them.
* The score takes the least gap along each arc: an arc stays within :math:`\\bar v h` of the
  robot and a box moves at most :math:`\\bar V h` meanwhile, and gaps above the clearance cap
  (walls, objects) or the personal space (robots, people) score as if infinite.  A farther
  obstacle is never the minimum that counts, nor below zero.
* An escape arc (checked only when ``safe`` fails) is held for a cycle and then brakes
  straight on: its points stay within :math:`\\bar v T` of the robot, a box moves
  :math:`\\bar V T`, and the slack between samples is below :math:`\\bar v T`; a farther
  obstacle passes every sample.
* The retreat steps away from the nearest robot or person when it is within the standoff,
  checking the walls twice the standoff away; both are within reach.

:func:`reach` adds these terms (walls with :math:`\\bar V = 0`) with a margin of one standoff,
so each driver's group sees a superset of its neighbourhood.  The obstacles a group keeps are
in their original order and go through the same expressions, and the dropped ones never
decide a test or attain a minimum, so the commands (speeds, turn rates, ``safe``) are those of
the full computation, bit for bit; only :attr:`DwaCommand.gap` is ``inf`` instead of a gap
beyond reach when nothing is near.  The cost per cycle is the drivers times the obstacles near
them: linear in the team and independent of the size of the map (plus a pass over the
obstacles' bounding boxes per group, which is cheap).

**One call for every group.**  The groups' sets differ, but the window runs once for all
drivers: each driver gets its group's set as its own row
(:meth:`~cosmop.control.dwa.Obstacles.per_driver`), shorter sets padded with walls and boxes at
infinity.  Their gaps are ``inf``, so they too never decide a test or attain a minimum, and
every driver's commands are those of a call with its set alone
(``tests/test_neighbourhood.py``).  A call costs a few hundred NumPy operations whatever
its size, so one call instead of one per group is what makes a cycle of many scattered
drivers cheap.

**Few obstacles.**  Choosing costs a few dozen NumPy calls too.  With at most ``_FEW`` walls
and boxes in all (a small map such as the paper's 10×10: 4 walls, 20 boxes) that is more than
scoring them all costs, so they go to the window as they are: the same commands, by the
argument above, and an exact :attr:`~cosmop.control.dwa.DwaCommand.gap`.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from cosmop.control.dwa import (
    Drivers,
    DwaCommand,
    DwaSettings,
    Obstacles,
    dwa_commands,
    first_true,
    take_columns,
)
from cosmop.control.geometry import rect_gaps, segment_bounds
from cosmop.control.safety import stopping_horizon, stopping_margin

__all__ = ["dwa_commands_near", "reach"]

# Below this many walls and boxes in all, choosing the near ones costs more than scoring them
# all (measured: one driver, 0.33 ms a call with 24 obstacles against 0.39 ms with the cut-off;
# the two cross near 36; benchmarks/BENCHMARKS.md).  The commands are the same either way.
_FEW = 32


def reach(
    drivers: Drivers, obstacles: Obstacles, settings: DwaSettings
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The gaps (mm) beyond which a wall, and a box, cannot change each driver's command.

    Parameters
    ----------
    drivers : Drivers
        The robots and their limits.
    obstacles : Obstacles
        The walls and boxes they sense (one shared set).
    settings : DwaSettings
        The window's horizon, clearance, personal space and standoff.

    Returns
    -------
    walls, boxes : ndarray, shape (R,)
        See the module docstring for the bound; walls do not move.
    """
    limits = drivers.limits
    top = np.maximum(limits.max_speed, drivers.v)
    boxes_top = float(obstacles.speed.max(initial=0.0))
    if obstacles.velocity is not None and len(obstacles.velocity):
        boxes_top = max(boxes_top, float(np.hypot(*obstacles.velocity.T).max()))
    time = np.maximum(settings.horizon, stopping_horizon(top, limits))
    room = max(settings.clearance, settings.personal_space, 3 * settings.standoff)
    walls = stopping_margin(top, 0.0, limits) + 2 * top * time + room + settings.standoff
    boxes = stopping_margin(top, boxes_top, limits) + 2 * (top + boxes_top) * time + room + settings.standoff
    return walls, boxes


def dwa_commands_near(
    drivers: Drivers,
    obstacles: Obstacles,
    settings: DwaSettings | None = None,
    *,
    ignore: NDArray[np.bool_] | None = None,
    grip: NDArray[np.bool_] | None = None,
    cell: float | None = None,
) -> DwaCommand:
    """:func:`~cosmop.control.dwa.dwa_commands`, each group of drivers against what is near it.

    Drivers are grouped by square cells of side `cell` (mm; default: the largest reach); each
    group's drivers get the walls and boxes within reach of any of them, and one call of the
    dynamic window serves every group (module docstring).  The commands are those of one call
    with everything.

    Parameters
    ----------
    drivers, obstacles, settings, ignore, grip
        As for :func:`~cosmop.control.dwa.dwa_commands` (`obstacles` one shared set).
    cell : float, optional
        Side of the cells that group the drivers, mm.
    """
    R, settings = len(drivers.v), settings or DwaSettings()
    if R == 0:
        return DwaCommand(v=np.zeros(0), w=np.zeros(0), safe=np.ones(0, dtype=bool), gap=np.zeros(0))
    if cell is None and len(obstacles.walls) + len(obstacles.boxes) <= _FEW:
        return dwa_commands(drivers, obstacles, settings, ignore=ignore, grip=grip)
    wall_reach, box_reach = reach(drivers, obstacles, settings)
    xy, half = drivers.pose[:, :2], drivers.half
    side = cell if cell is not None else float(max(wall_reach.max(), box_reach.max()))
    group = _cells(xy, side)
    w_lo, w_hi = segment_bounds(obstacles.walls)
    centres, halves = obstacles.boxes[:, :2], obstacles.boxes[:, 2:]
    # per group: the bounding box of its drivers and their largest reach, then the walls and
    # boxes within that reach of the bounding box, all groups at once
    order = np.argsort(group, kind="stable")
    starts = np.searchsorted(group[order], np.arange(int(group.max()) + 1))
    lo, hi = (f.reduceat(xy[order], starts, axis=0)[:, None, :] for f in (np.minimum, np.maximum))
    far = [np.maximum.reduceat((r + half)[order], starts)[:, None] for r in (wall_reach, box_reach)]
    wall_far, box_far = far
    walls = first_true(rect_gaps(lo, hi, w_lo, w_hi) <= wall_far)
    boxes = first_true(rect_gaps(lo, hi, centres - halves, centres + halves) <= box_far)
    if len(walls) == 1:  # one group: one set, shared (no padding: a single row is never padded)
        sets, near = obstacles.select(walls[0], boxes[0]), boxes[0]
    else:
        walls, near = walls[group], boxes[group]
        sets = obstacles.take(walls, near)
    return dwa_commands(
        drivers,
        sets,
        settings,
        ignore=None if ignore is None else take_columns(ignore, near),
        grip=None if grip is None else take_columns(grip, near),
    )


def _cells(xy: NDArray[np.float64], side: float) -> NDArray[np.int64]:
    """The group of each point ``(R, 2)``: the square cell of side `side` it lies in, numbered
    in order of first appearance (a dictionary: the points are few, and sorting them is not
    needed)."""
    numbers: dict[tuple[int, int], int] = {}
    keys = np.floor(xy / side).astype(np.int64).tolist()
    return np.array([numbers.setdefault((x, y), len(numbers)) for x, y in keys], dtype=np.int64)
