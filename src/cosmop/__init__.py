"""cosmop: cooperative missions for teams of mobile robots, with formal guarantees.

The front door, for a script or a notebook::

    import cosmop

    scn = cosmop.load("examples/01_warehouse_2x2/scenario.yaml")  # a Scenario
    plans = cosmop.plan(scn)  # a PlanSet: every robot's shortest safe plan, team-safe, checked
    run = cosmop.simulate(scn, plans)  # a SimResult: the robots at work, people walking through
    run.plot()  # a matplotlib figure of the run (the viz extra)
    report = cosmop.check(scn, plans)  # the exact checker's verdict on any plan set

Each verb is a thin door onto the layer that does the work: :func:`cosmop.scenario.load_scenario`,
:func:`cosmop.team.loop.plan_team` (the whole team: decomposition, synthesis, coordination,
verification), :func:`cosmop.sim.simulate` and :func:`cosmop.team.plan_set_checker.check_plan`; the
result types are :class:`Scenario`, :class:`PlanSet`, :class:`TeamResult`, :class:`SimResult`
and :class:`CheckReport`.  ``import cosmop`` loads none of them until they are used, so the
command line starts fast.  See ``ARCHITECTURE.md`` for the layers and the data flow.
"""

from __future__ import annotations

import importlib
import os
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from cosmop.planning.checker import CheckReport
    from cosmop.planning.plan_types import PlanSet
    from cosmop.scene import Scenario
    from cosmop.sim import SimResult, SimSettings
    from cosmop.team.loop import TeamResult

from cosmop._version import __version__

__all__ = [
    "CheckReport",
    "PlanSet",
    "Scenario",
    "SimResult",
    "TeamResult",
    "__version__",
    "check",
    "load",
    "plan",
    "simulate",
]

# the result types, imported when first named (``cosmop.PlanSet``)
_TYPES = {
    "CheckReport": "cosmop.planning.checker",
    "PlanSet": "cosmop.planning.plan_types",
    "Scenario": "cosmop.scene",
    "SimResult": "cosmop.sim",
    "TeamResult": "cosmop.team.loop",
}


def __getattr__(name: str) -> Any:
    if name in _TYPES:
        return getattr(importlib.import_module(_TYPES[name]), name)
    raise AttributeError(f"module 'cosmop' has no attribute {name!r}")


def load(path: str | os.PathLike[str]) -> Scenario:
    """Read and check a scenario file (YAML, mm and degrees or ``units: m``).

    Parameters
    ----------
    path : str or os.PathLike
        The scenario file.

    Returns
    -------
    Scenario

    Raises
    ------
    cosmop.errors.CosmopInputError
        Naming the file, the field and what was expected there.
    """
    from cosmop.scenario import load_scenario

    return load_scenario(path)


def plan(scenario: Scenario, *, max_horizon: int | None = None, workers: int | None = None) -> PlanSet:
    """The team's plans: each robot's shortest safe plan, coordinated, team-safe and checked.

    :func:`cosmop.team.loop.plan_team` with its defaults; call it for its statistics (the
    verification, the itinerary, the planning times) and its other settings.

    Parameters
    ----------
    scenario : Scenario
    max_horizon : int, optional
        Cap on each robot's plan length (steps); by default 3 per mission event + 6, at least 16.
    workers : int, optional
        Processes for the robots' syntheses (default one per core; 1 plans in this process).

    Returns
    -------
    PlanSet
        ``feasible`` says whether every robot has a plan; if not, ``reason`` says why.
    """
    from cosmop.team.loop import plan_team

    return plan_team(scenario, max_horizon=max_horizon, workers=workers).plans


def simulate(
    scenario: Scenario, plans: PlanSet, *, seed: int = 0, settings: SimSettings | None = None
) -> SimResult:
    """Execute the plans in the scenario's world, people walking through (:func:`cosmop.sim.simulate`).

    Parameters
    ----------
    scenario : Scenario
    plans : PlanSet
        A feasible plan set for `scenario`.
    seed : int
        Seed of the people's walks and of the delays.
    settings : SimSettings, optional
        The controller's, the monitor's and the run's settings (``max_time``, ``delays``...).

    Returns
    -------
    SimResult
        Status (``completed``, contacts), statistics, the trace, ``summary()`` and ``plot()``.
    """
    from cosmop.sim import simulate as run

    return run(scenario, plans, seed=seed, settings=settings)


def check(scenario: Scenario, plans: PlanSet) -> CheckReport:
    """The exact plan checker's verdict on a plan set (:func:`cosmop.team.plan_set_checker.check_plan`).

    Parameters
    ----------
    scenario : Scenario
    plans : PlanSet

    Returns
    -------
    CheckReport
        ``ok``, and each violation with the robot, the step and why.
    """
    from cosmop.team.plan_set_checker import check_plan

    return check_plan(scenario, plans)
