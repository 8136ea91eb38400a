"""Recording a run: one frame of the world per control cycle, for the trace.

The frames become :attr:`cosmop.sim.result.SimResult.frames`: poses in mm and degrees, speeds
in mm/s and deg/s, seconds.  Besides where everything is, a frame says why a robot stands:
the message it waits for (``awaits``) and the robot or person it gives way to (``yields_to``),
so that the pictures can say it in words.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from cosmop.control.geometry import box_gaps
from cosmop.events import Primitive
from cosmop.sim.result import FRAME_PRIMITIVES
from cosmop.sim.world import Agent, World

__all__ = ["YIELD_AFTER_S", "Recorder"]

_FIELDS = (
    "t", "pose", "v", "w", "carrying", "primitive", "waiting", "delayed", "awaits", "yields_to",
    "humans", "objects",
)  # fmt: skip

YIELD_AFTER_S = 0.5
"""Seconds a robot that should move stands before the trace says whom it gives way to: a robot
stands for a cycle or two at every start and waypoint, which is no giving way."""

_STANDING = 1.0  # mm/s and deg/s under which a robot counts as standing
_MOVING_STEPS = (Primitive.GOTO, Primitive.PICKUP, Primitive.DROPOFF)


class Recorder:
    """Collects the frames of a run (:meth:`record` once per cycle, :meth:`frames` at the end)."""

    def __init__(self) -> None:
        self._rows: dict[str, list[Any]] = {k: [] for k in _FIELDS}
        self._standing_since: dict[int, float] = {}  # robot index: when it stopped while it should move

    def record(self, world: World) -> None:
        """Append the world's current state as a frame.

        Parameters
        ----------
        world : World
            The running simulation.
        """
        rows = self._rows
        rows["t"].append(world.t)
        pose = world.pose.copy()
        pose[:, 2] = np.degrees(pose[:, 2])
        rows["pose"].append(pose)
        rows["v"].append(world.v.copy())
        rows["w"].append(np.degrees(world.w))
        carrying = np.full(len(world.robot_ids), -1)  # object index, -1: none
        for j, r in enumerate(world.carried_by):
            if r >= 0:
                carrying[r] = j
        rows["carrying"].append(carrying)
        rows["primitive"].append(
            np.array([0 if a.done else FRAME_PRIMITIVES.index(a.step.primitive) for a in world.agents])
        )
        rows["waiting"].append(np.array([a.waiting for a in world.agents]))
        rows["delayed"].append(np.array([a.stopped_until is not None for a in world.agents]))
        rows["awaits"].append(np.array([_awaits(world, a) for a in world.agents], dtype=object))
        rows["yields_to"].append(np.array([self._yields_to(world, a) for a in world.agents], dtype=object))
        rows["humans"].append(np.array([w.position for w in world.walkers]).reshape(-1, 2))
        rows["objects"].append(world.object_positions())

    def _yields_to(self, world: World, agent: Agent) -> str | None:
        """The robot or person `agent` gives way to: the nearest one it senses, once it has stood
        for :data:`YIELD_AFTER_S` while its step wants it to move (None otherwise)."""
        i = agent.index
        should_move = (
            not agent.done
            and not agent.waiting
            and agent.stopped_until is None
            and agent.step.primitive in _MOVING_STEPS
            and agent.dock_stage != "handle"  # the gripper works: standing is the job
        )
        if not should_move or abs(world.v[i]) > _STANDING or abs(np.degrees(world.w[i])) > _STANDING:
            self._standing_since.pop(i, None)
            return None
        since = self._standing_since.setdefault(i, world.t)
        if world.t - since < YIELD_AFTER_S:
            return None
        gaps = world.gaps_to_robots(i)
        gaps[i] = np.inf
        names = list(world.robot_ids)
        if world.walkers:
            gaps = np.concatenate(
                [gaps, box_gaps(world.pose[i, :2], world.robot_half[i], world.people_boxes())]
            )
            names += world.human_ids
        k = int(np.argmin(gaps)) if len(gaps) else -1
        return names[k] if k >= 0 and gaps[k] < world.settings.sense_range else None

    def frames(self, world: World) -> dict[str, np.ndarray]:
        """The frames as arrays (:attr:`~cosmop.sim.result.SimResult.frames`), shaped for `world`.

        Parameters
        ----------
        world : World
            The simulation that was recorded.
        """
        frames = {k: np.array(v) for k, v in self._rows.items()}
        n = len(frames["t"])
        frames["pose"] = frames["pose"].reshape(n, len(world.robot_ids), 3)
        for key in ("awaits", "yields_to"):  # object arrays: an empty team still has shape (n, 0)
            frames[key] = np.array(self._rows[key], dtype=object).reshape(n, len(world.robot_ids))
        frames["humans"] = frames["humans"].reshape(n, len(world.walkers), 2)
        frames["objects"] = frames["objects"].reshape(n, len(world.object_ids), 2)
        return frames


def _awaits(world: World, agent: Agent) -> str | None:
    """The name of the message `agent` stands waiting for (None: it does not wait)."""
    if not agent.waiting or agent.done:
        return None
    event = world.awaited(agent, agent.step)
    return event.name if event is not None else None
