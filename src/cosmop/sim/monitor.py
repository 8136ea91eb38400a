"""The safety monitor: every contact of a robot's square, and whether the robot was moving.

A contact is a robot's square touching a wall, a resting object, another robot or a person
(within :data:`~cosmop.sim.world.TOUCH`).  Passive safety guarantees that the robot is never
moving then (a person may walk into a standing robot).  :func:`footprint_overlaps` checks a
finished run's trace for robots that overlap.  Units: mm, mm/s, seconds.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from cosmop.control.dwa import robot_gaps
from cosmop.scene import Scene
from cosmop.sim.result import Contact, SimResult
from cosmop.sim.world import TOUCH, World

__all__ = ["footprint_overlaps", "monitor"]


def monitor(world: World, moving_speed: NDArray[np.float64]) -> None:
    """Log this cycle's contacts in ``world.contacts``: a new episode for every pair that starts
    touching, marked moving if the robot's speed (`moving_speed`, mm/s) is above zero at any
    cycle of it.

    Parameters
    ----------
    world : World
        The running simulation; its contact log is updated.
    moving_speed : ndarray, shape (R,)
        Each robot's speed this cycle, mm/s (:func:`~cosmop.sim.unicycle.integrate`).
    """
    now = _touching(world)
    for pair in list(world.open_contacts):
        if pair not in now:
            del world.open_contacts[pair]
    for pair in sorted(now):  # in a fixed order: the log is deterministic
        moving = bool(moving_speed[pair[0]] > 0)
        if pair not in world.open_contacts:
            world.open_contacts[pair] = len(world.contacts)
            world.contacts.append(Contact(round(world.t, 6), world.robot_ids[pair[0]], pair[1], moving))
        elif moving and not world.contacts[world.open_contacts[pair]].moving:
            c = world.contacts[world.open_contacts[pair]]
            world.contacts[world.open_contacts[pair]] = Contact(c.t, c.robot, c.other, True)


def _touching(world: World) -> set[tuple[int, str]]:
    """The pairs (robot index, what it touches) now; ``wall k`` names a wall.  The gripper's
    contact with the object it grips is no contact, unless the two overlap."""
    boxes, names = world.boxes()
    wall_gap, box_gap = robot_gaps(world.pose[:, :2], world.robot_half, world.walls, boxes)
    R = len(world.robot_ids)
    own = world.first_robot_box(len(names)) + np.arange(R)  # each robot's own box: no contact
    box_gap[np.arange(R), own] = np.inf
    # one pass over the touching pairs (a few), not one per robot and kind of obstacle
    walls = zip(*np.nonzero(wall_gap <= TOUCH), strict=True)
    now: set[tuple[int, str]] = {(int(i), f"wall {int(w)}") for i, w in walls}
    for i, b in zip(*np.nonzero(box_gap <= TOUCH), strict=True):
        agent, name = world.agents[i], names[b]
        gripped = agent.gripped is not None and name == world.object_ids[agent.gripped]
        if gripped and box_gap[i, b] >= -TOUCH:
            continue
        now.add((int(i), name))
    return now


def footprint_overlaps(
    scene: Scene, result: SimResult, tolerance: float = 1e-6
) -> list[tuple[float, str, str, float]]:
    """Every recorded instant at which two robots' squares overlap (touching allowed).

    Returns ``(t, robot, other, depth)`` for the first instant of each overlapping pair and
    episode, depth in mm; an empty list for a run in which robots never overlap.

    Parameters
    ----------
    scene : Scene
        The scene that was run.
    result : SimResult
        The run, with its frames.
    tolerance : float, default 1e-6
        Overlaps no deeper than this (mm) count as touching.
    """
    pose = result.frames["pose"]
    half = np.array([scene.robots[r].size / 2.0 for r in result.robot_ids])
    out = []
    for i in range(len(half)):
        for j in range(i + 1, len(half)):
            gap = np.abs(pose[:, i, :2] - pose[:, j, :2]).max(axis=1) - (half[i] + half[j])
            bad = gap < -tolerance
            starts = np.flatnonzero(bad & ~np.concatenate([[False], bad[:-1]]))
            for n in starts:
                out.append(
                    (float(result.frames["t"][n]), result.robot_ids[i], result.robot_ids[j], float(-gap[n]))
                )
    return sorted(out)
