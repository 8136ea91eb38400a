"""One control cycle of motion: every robot's unicycle and its docking creep.

Robots are unicycles: each cycle a robot holds a turn rate in :math:`[-\\Omega, \\Omega]` and
speeds up at most at :math:`A` or brakes at :math:`-b` until it has the speed it was given.
The footprint is an axis-aligned square, so a turn on the spot moves no part of it.  Units:
mm, mm/s, radians and rad/s, seconds.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

from cosmop.control.safety import cycle_distance
from cosmop.planning.plan_types import Pose
from cosmop.sim.world import World, wrap_angle

__all__ = ["integrate"]

_SUBSTEPS = 4  # sub-steps of a cycle's arc (each at its midpoint heading)


def integrate(
    world: World, v_cmd: NDArray[np.float64], w_cmd: NDArray[np.float64], docks: Mapping[int, Pose]
) -> NDArray[np.float64]:
    """Move every robot for one cycle towards the speed `v_cmd`, turning at `w_cmd`.

    A robot slows down by braking at :math:`-b` until it reaches the commanded speed, then holds
    it (the control passive safety assumes: a stop from :math:`v < b\\varepsilon` takes
    :math:`v^2/2b`, not the :math:`v\\varepsilon/2` of a ramp spread over the cycle); it speeds
    up at a constant acceleration over the cycle (at most :math:`A`).  The distance of each
    sub-step is exact; its heading is the sub-step's midpoint heading.  The robots in `docks`
    (robot index to docking pose ``x, y, heading deg``) creep instead (:func:`_creep`).

    Returns each robot's translational speed at the end of the cycle, mm/s: what the monitor
    calls moving.  A docking creep is a stop-and-go no faster than one cycle's braking, so the
    robot is at rest at the start of every docking cycle and moving until it is on the pose.

    Parameters
    ----------
    world : World
        The simulation; its robots' poses, speeds and distances are updated.
    v_cmd : ndarray, shape (R,)
        Commanded translational speeds, mm/s.
    w_cmd : ndarray, shape (R,)
        Commanded turn rates, rad/s.
    docks : mapping of int to (float, float, float)
        The docking robots' poses to creep to, ``x, y`` mm and heading in degrees.
    """
    dt = world.dt
    acc, brk = world.limits.acceleration, world.limits.braking
    v0 = world.v
    v1 = np.minimum(np.maximum(v_cmd, np.maximum(0.0, v0 - brk * dt)), v0 + acc * dt)  # np.clip, cheaper
    v1 = np.minimum(v1, world.limits.max_speed)
    # distance from the cycle's start to each sub-step's end, (n + 1, R): a ramp, or braking
    # at -b until v1 is reached and holding it after
    n = _SUBSTEPS
    covered = cycle_distance(v0, v1, _instants(dt, n), brk, dt)
    steps = covered[1:] - covered[:-1]
    start = world.pose[:, :2].copy()
    half_turn, turn = w_cmd * dt / (2 * n), w_cmd * dt / n
    # the n sub-steps at once: accumulate adds left to right, so every pose is the same sum,
    # in the same order, as n updates one after the other
    heading = np.empty((n + 1, len(turn)))
    heading[0], heading[1:] = world.pose[:, 2], turn
    np.add.accumulate(heading, out=heading)
    theta = heading[:-1] + half_turn  # (n, R): each sub-step's midpoint heading
    xy = np.empty((2, n + 1, len(turn)))
    xy[:, 0] = world.pose[:, :2].T
    np.multiply(steps, np.cos(theta), out=xy[0, 1:])
    np.multiply(steps, np.sin(theta), out=xy[1, 1:])
    np.add.accumulate(xy, axis=1, out=xy)
    world.pose[:, :2] = xy[:, -1].T
    world.pose[:, 2] = wrap_angle(heading[-1])
    world.v = v1
    world.w = w_cmd.copy()
    moving: NDArray[np.float64] = v1.copy()
    for i, dock in docks.items():
        moving[i] = _creep(world, i, dock)
    world.distance += np.hypot(*(world.pose[:, :2] - start).T)
    return moving


@lru_cache(maxsize=4)
def _instants(dt: float, n: int) -> NDArray[np.float64]:
    """The sub-steps' ends in a cycle of `dt` s, ``(n + 1, 1)`` (made once)."""
    out = (np.arange(n + 1) * dt / n)[:, None]
    out.flags.writeable = False
    return out


def _creep(world: World, i: int, dock: Pose) -> float:
    """The docking controller: robot `i` creeps straight towards `dock` (``x, y`` mm, heading
    deg), turning at most its turn rate, and halts exactly on it.  Returns its speed, mm/s."""
    dt = world.dt
    x, y = world.pose[i, :2]
    dx, dy = dock[0] - x, dock[1] - y
    dist = math.hypot(dx, dy)
    step = world.creep_speed(i) * dt
    if dist <= step:
        world.pose[i, 0], world.pose[i, 1] = dock[0], dock[1]
    else:
        world.pose[i, 0] += dx * step / dist
        world.pose[i, 1] += dy * step / dist
    error = world.heading_error(i, math.radians(dock[2]))
    turn = world.limits.turn_rate[i] * dt
    h = world.pose[i, 2]
    world.pose[i, 2] = math.radians(dock[2]) if abs(error) <= turn else h + math.copysign(turn, error)
    world.v[i] = 0.0
    world.w[i] = 0.0
    return 0.0 if dist <= step else step / dt
