"""Planned against realised: when each step of a run was expected, and when it happened.

A plan set's itinerary (:class:`~cosmop.planning.plan_types.Itinerary`) says when every step is
expected to start and end.  The simulator logs, per robot, every step it completes with the
cycle it started and the cycle it ended (a step starts when the robot's previous one ends;
instant 0 at time 0), and which instant of the *original* plan it was.  Re-planning replaces
a robot's remaining steps: the steps of a new plan carry no instant (nothing was planned for
them), and an original step that a re-plan dropped, or a run that stopped early, leaves a
planned step without a realised time.  When the team-safety layer re-orders the other robots
around a new plan, their steps are matched to their old ones in order (:func:`carry_instants`),
so an inserted message step is new and every other step keeps its instant.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from cosmop.planning.plan_types import Itinerary

__all__ = ["StepTimes", "carry_instants", "step_times"]


@dataclass(frozen=True)
class StepTimes:
    """One step of a run: what it was, when it was planned and when it happened (s).

    Attributes
    ----------
    step : str
        The primitive with its object or message (``PickUp(O1)``).
    instant : int or None
        Its instant in the plan the run started from; ``None`` for a step a re-plan added.
    planned, realised : tuple of float or None
        ``(start, end)``: expected (from the itinerary) and as executed; ``None`` when there
        is none (no itinerary, a step a re-plan added, or one that never ran).
    """

    step: str
    instant: int | None
    planned: tuple[float, float] | None
    realised: tuple[float, float] | None

    @property
    def delay(self) -> float | None:
        """How much later than planned the step ended, s (``None`` without both times)."""
        if self.planned is None or self.realised is None:
            return None
        return self.realised[1] - self.planned[1]

    def to_dict(self) -> dict[str, Any]:
        """The JSON form: ``{"step", "instant", "planned": [s, e] | null, "realised": [s, e] | null}``."""

        def pair(times: tuple[float, float] | None) -> list[float] | None:
            return None if times is None else [round(times[0], 3), round(times[1], 3)]

        return {
            "step": self.step,
            "instant": self.instant,
            "planned": pair(self.planned),
            "realised": pair(self.realised),
        }


def carry_instants(
    old: Sequence[object], instants: Sequence[int | None], new: Sequence[object]
) -> list[int | None]:
    """The instants of `new` steps: each equal to the next unmatched `old` step keeps its instant.

    Parameters
    ----------
    old : sequence
        The steps before.
    instants : sequence of int or None
        The instant of each old step.
    new : sequence
        The steps after.

    Examples
    --------
    >>> carry_instants("abc", [1, 2, 3], "axbc")
    [1, None, 2, 3]
    """
    out: list[int | None] = []
    j = 0
    for step in new:
        match = next((i for i in range(j, len(old)) if old[i] == step), None)
        if match is None:
            out.append(None)
        else:
            out.append(instants[match])
            j = match + 1
    return out


def step_times(
    labels: Mapping[str, Sequence[str]],
    itinerary: Itinerary | None,
    done: Mapping[str, Sequence[tuple[int | None, str, float, float]]],
) -> dict[str, tuple[StepTimes, ...]]:
    """Every robot's steps, planned beside realised: those it ran, in order, then the planned
    steps it never ran.

    Parameters
    ----------
    labels : Mapping[str, sequence of str]
        The labels of each robot's planned steps, instants 1..K.
    itinerary : Itinerary or None
        The planned times.
    done : Mapping[str, sequence of (instant, label, start, end)]
        The steps each robot completed, in order (instant ``None``: added by a re-plan).

    Returns
    -------
    dict
        Robot -> tuple of :class:`StepTimes`.
    """
    out = {}
    for robot, planned_labels in labels.items():

        def planned(k: int | None, robot: str = robot) -> tuple[float, float] | None:
            return itinerary.slot(robot, k) if itinerary is not None and k is not None else None

        rows = [StepTimes(label, k, planned(k), (start, end)) for k, label, start, end in done.get(robot, ())]
        ran = {row.instant for row in rows}
        rows += [
            StepTimes(label, k, planned(k), None) for k, label in enumerate(planned_labels, 1) if k not in ran
        ]
        out[robot] = tuple(rows)
    return out
