"""People: uncontrolled movers that walk their path (or at random) at most ``speed`` fast.

A person is an axis-aligned square that walks straight from one path point to the next at its
speed, stands ``dwell`` seconds on arriving at a point, and loops back to the first point (or
stays at the last one).  A person with a ``walk`` area then heads for random points of that
rectangle forever, drawn from the simulation's seeded generator and kept to straight lines
that cross no wall.  People ignore robots: they may walk into a standing robot (the paper's
environment is *fair*: people keep walking, so nobody blocks a robot forever unless the
scenario says so).  Units: mm, mm/s, s.
"""

from __future__ import annotations

import math

import numpy as np

from cosmop.control.geometry import point_segment_linf
from cosmop.scene import Human

__all__ = ["Walker"]


class Walker:
    """The state of one person during a simulation (mutable, owned by the simulation)."""

    def __init__(self, human: Human, walls: np.ndarray, rng: np.random.Generator) -> None:
        self.human = human
        self.walls = walls
        self.rng = rng
        self.position = np.array(human.path[0][:2], dtype=float)
        self.index = 0  # the path point reached last
        self.wait = float(human.path[0][2])
        self.target: np.ndarray | None = None
        self.random = False
        self.velocity = np.zeros(2)  # over the last step, mm/s
        self._next_target()

    @property
    def half(self) -> float:
        return self.human.size / 2.0

    def _next_target(self) -> None:
        path = self.human.path
        if not self.random and self.index + 1 < len(path):
            self.target = np.array(path[self.index + 1][:2], dtype=float)
        elif not self.random and self.human.loop and len(path) > 1:
            self.target = np.array(path[0][:2], dtype=float)
        elif self.human.walk is not None:
            self.random = True
            self.target = self._random_point()
        else:
            self.target = None  # stays at the last point

    def _random_point(self) -> np.ndarray:
        assert self.human.walk is not None  # a random walk has its area
        (x0, x1), (y0, y1) = self.human.walk
        for _ in range(50):
            point = np.array([self.rng.uniform(x0, x1), self.rng.uniform(y0, y1)])
            if self._clear_line(self.position, point):
                return point
        return self.position.copy()

    def _clear_line(self, a: np.ndarray, b: np.ndarray) -> bool:
        if not len(self.walls):
            return True
        n = max(2, int(math.dist(a, b) / max(self.half, 50.0)) + 2)
        pts = a[None, :] + np.linspace(0.0, 1.0, n)[:, None] * (b - a)[None, :]
        return bool((point_segment_linf(pts, self.walls) > self.half).all())

    def step(self, dt: float) -> None:
        """Walk for `dt` seconds.

        Parameters
        ----------
        dt : float
            The cycle, s.
        """
        before = self.position.copy()
        self._walk(dt)
        self.velocity = (self.position - before) / dt

    def _walk(self, dt: float) -> None:
        remaining = dt
        while remaining > 1e-12:
            if self.wait > 0:
                used = min(self.wait, remaining)
                self.wait -= used
                remaining -= used
                continue
            if self.target is None:
                return
            delta = self.target - self.position
            dist = float(np.hypot(*delta))
            reach = self.human.speed * remaining
            if dist > reach:
                self.position = self.position + delta * (reach / dist)
                return
            self.position = self.target.copy()
            remaining -= dist / self.human.speed
            self._arrive()

    def _arrive(self) -> None:
        path = self.human.path
        if self.random:
            self.target = self._random_point()
            return
        self.index = self.index + 1 if self.index + 1 < len(path) else 0
        self.wait = float(path[self.index][2])
        self._next_target()
