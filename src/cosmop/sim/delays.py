"""Execution delays: robots that stop for a while, at random, as real robots do.

A plan's messages order what robots do, not when: a robot that waits for a message waits as
long as it takes.  The delay model of the League of Robot Runners' 2026 start-kit tests that:
every simulated second, each robot that has not finished its plan stops, with probability
``p``, for a time drawn uniformly in ``[low, high]`` seconds (:class:`Delays`).

The draws come from a generator of their own, seeded by the run's seed
(:class:`DelayDraws`): the same seed gives the same delays, and the people walk the same with
and without them.  Every second draws for every robot, whatever the robots do, so which robot
stops when is fixed by the seed alone; a draw that finds its robot finished, or already stopped,
is let go.

A stopped robot brakes with :math:`-b` straight on (the brake the dynamic window's last
check covered, so passive safety holds) and stands; it may be struck anywhere in its plan
-- driving, docking, its gripper working, waiting for a message or about to send one -- since
braking is always safe and a standing robot does nothing.  Its stop includes its braking; it
then carries on with its step where it left it.  The simulator does the rest
(:mod:`cosmop.sim.simulation`, :func:`cosmop.sim.execute.decide`).  Units: seconds.

>>> Delays.parse("0.01:2:10")
Delays(p=0.01, low=2.0, high=10.0)
>>> draws = DelayDraws(Delays(0.5, 2.0, 10.0), seed=1, robots=3)
>>> stops = draws.due(0.0)  # (robot, seconds) of the draw at 0 s
>>> all(0 <= i < 3 and 2.0 <= s <= 10.0 for i, s in stops)
True
>>> draws.due(0.5)  # the next draw is at 1 s
[]
>>> stops + draws.due(4.0) == DelayDraws(Delays(0.5, 2.0, 10.0), seed=1, robots=3).due(4.0)
True
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["DELAY_STREAM", "DelayDraws", "Delays"]

DELAY_STREAM = 0xDE1A
"""Mixed into the run's seed for the delays' own generator (the people keep theirs)."""

_SAID = {"p": "the probability P", "low": "the shortest stop MIN", "high": "the longest stop MAX"}
_EPS = 1e-9  # s: a cycle's clock, summed from its steps, may fall a hair short of a whole second


@dataclass(frozen=True)
class Delays:
    """Robots stop at random: every simulated second, each robot still executing its plan
    stops with probability `p` for a time drawn uniformly in ``[low, high]`` seconds.

    Attributes
    ----------
    p : float
        Probability per robot and simulated second, in ``[0, 1]``.
    low, high : float
        The shortest and the longest stop, s (``0 <= low <= high``).

    Raises
    ------
    ValueError
        For a value that is not a finite number or out of its range.
    """

    p: float
    low: float
    high: float

    def __post_init__(self) -> None:
        for name, said in _SAID.items():
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
                raise ValueError(f"{said} must be a finite number, got {value!r}")
            object.__setattr__(self, name, float(value))
        if not 0.0 <= self.p <= 1.0:
            raise ValueError(f"{_SAID['p']} must be in [0, 1], got {self.p:g}")
        if self.low < 0.0:
            raise ValueError(f"{_SAID['low']} must be 0 s or more, got {self.low:g}")
        if self.low > self.high:
            raise ValueError(
                f"{_SAID['low']} ({self.low:g} s) must not exceed {_SAID['high']} ({self.high:g} s)"
            )

    @classmethod
    def parse(cls, text: str) -> Delays:
        """The delays written ``P:MIN:MAX`` (``0.01:2:10``: 1 % a second, 2 to 10 s).

        Parameters
        ----------
        text : str
            ``P:MIN:MAX``: the probability per robot and second, and the shortest and the longest
            stop, s.

        Raises
        ------
        ValueError
            For text of another shape, or values out of range (:class:`Delays`).
        """
        parts = text.split(":")
        if len(parts) != 3:
            raise ValueError(f"expected P:MIN:MAX (e.g. 0.01:2:10), got {text!r}")
        try:
            p, low, high = (float(part) for part in parts)
        except ValueError:
            raise ValueError(f"expected three numbers P:MIN:MAX (e.g. 0.01:2:10), got {text!r}") from None
        return cls(p, low, high)

    def show(self) -> str:
        """In words: ``p = 0.01 a second, 2-10 s``."""
        return f"p = {self.p:g} a second, {self.low:g}-{self.high:g} s"

    def to_dict(self) -> dict[str, float]:
        """The JSON form: ``{"p", "min_s", "max_s"}``."""
        return {"p": self.p, "min_s": self.low, "max_s": self.high}


class DelayDraws:
    """The seeded draws of a run's delays: at every whole simulated second, for every robot,
    whether it stops and for how long.

    Parameters
    ----------
    delays : Delays
    seed : int
        The run's seed; the draws' generator is seeded by it and :data:`DELAY_STREAM`.
    robots : int
        How many robots draw.
    """

    def __init__(self, delays: Delays, seed: int, robots: int) -> None:
        self.delays = delays
        self._rng = np.random.default_rng((DELAY_STREAM, seed))
        self._robots = robots
        self._next = 0.0  # the time of the next draw, s

    def due(self, t: float) -> list[tuple[int, float]]:
        """The stops that strike by time `t` (s) and were not yet given: ``(robot index, seconds)``,
        in order of time, then of robot.

        Parameters
        ----------
        t : float
            Time now, s.
        """
        out: list[tuple[int, float]] = []
        d = self.delays
        while self._next <= t + _EPS:
            strike = self._rng.random(self._robots) < d.p  # both drawn every second, used or not
            seconds = self._rng.uniform(d.low, d.high, self._robots)
            out += [(int(i), float(seconds[i])) for i in np.flatnonzero(strike)]
            self._next += 1.0
        return out
