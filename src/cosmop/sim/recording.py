"""Recording a run: one frame of the world per control cycle, for the trace.

The frames become :attr:`cosmop.sim.result.SimResult.frames`: poses in mm and degrees, speeds
in mm/s and deg/s, seconds.
"""

from __future__ import annotations

import numpy as np

from cosmop.sim.result import FRAME_PRIMITIVES
from cosmop.sim.world import World

__all__ = ["Recorder"]

_FIELDS = ("t", "pose", "v", "w", "carrying", "primitive", "waiting", "delayed", "humans", "objects")


class Recorder:
    """Collects the frames of a run (:meth:`record` once per cycle, :meth:`frames` at the end)."""

    def __init__(self) -> None:
        self._rows: dict[str, list] = {k: [] for k in _FIELDS}

    def record(self, world: World) -> None:
        """Append the world's current state as a frame."""
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
        rows["humans"].append(np.array([w.position for w in world.walkers]).reshape(-1, 2))
        rows["objects"].append(world.object_positions())

    def frames(self, world: World) -> dict[str, np.ndarray]:
        """The frames as arrays (:attr:`~cosmop.sim.result.SimResult.frames`), shaped for `world`."""
        frames = {k: np.array(v) for k, v in self._rows.items()}
        n = len(frames["t"])
        frames["pose"] = frames["pose"].reshape(n, len(world.robot_ids), 3)
        frames["humans"] = frames["humans"].reshape(n, len(world.walkers), 2)
        frames["objects"] = frames["objects"].reshape(n, len(world.object_ids), 2)
        return frames
