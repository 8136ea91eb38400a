"""Receding-horizon replanning: a stalled robot plans its remaining mission from where it is.

The paper (end of Section IV): when the environment is not fair and a robot cannot go on, it
stays safe, and "we can update the scene description and search for new plans at the current
state in a receding horizon strategy".  :func:`replan` builds that scene -- the scenario's
walls plus every sensed obstacle as a square of four walls -- and solves the robot's remaining
mission events with :func:`cosmop.planning.synthesis.synthesize` from the robot's current state
(integer mm and degrees), without new requests (a new request would need the top-down layer to
re-verify the team).  The new plan must pass the exact plan checker, like every plan the tool
returns.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import replace

from cosmop.missions.events import Event
from cosmop.planning.checker import check_robot_plan
from cosmop.planning.plan import RobotPlan, State
from cosmop.planning.synthesis import synthesize
from cosmop.scenario import Scene, Wall

__all__ = ["replan", "sensed_scene"]


def sensed_scene(scene: Scene, boxes: Iterable[tuple[float, float, float]]) -> Scene:
    """The scene with each sensed box ``(x, y, half side)`` (mm) added as four walls."""
    walls = list(scene.obstacles)
    for x, y, h in boxes:
        corners = [(x - h, y - h), (x + h, y - h), (x + h, y + h), (x - h, y + h)]
        walls += [Wall(corners[i], corners[(i + 1) % 4]) for i in range(4)]
    return replace(scene, obstacles=tuple(walls))


def replan(
    scene: Scene,
    robot: str,
    events: Sequence[Event],
    start: State,
    sensed: Iterable[tuple[float, float, float]] = (),
    *,
    max_horizon: int = 12,
    rlimit: int = 50_000_000,
) -> RobotPlan | None:
    """The shortest plan of `events` from `start` among the walls and the sensed boxes.

    Parameters
    ----------
    scene : Scene
        The scenario's scene (its robot pose stays the ``return`` target).
    robot : str
    events : sequence of Event
        The mission events not done yet, in order.
    start : State
        The robot's pose and the objects as it knows them now, in integers (mm, degrees).
    sensed : iterable of (float, float, float)
        Obstacles sensed around the robot, as boxes ``x, y, half side`` (mm).
    max_horizon, rlimit : int
        Bounds of the solver (see :func:`~cosmop.planning.synthesis.synthesize`).

    Returns
    -------
    RobotPlan or None
        A plan that passes :func:`~cosmop.planning.checker.check_robot_plan` from `start`, or
        ``None`` when there is none within the bound.
    """
    world = sensed_scene(scene, sensed)
    result = synthesize(
        world,
        robot,
        tuple(events),
        requests=False,
        max_horizon=max_horizon,
        rlimit=rlimit,
        start=start,
        explain=False,
    )
    if not result.feasible or result.plan is None:
        return None
    if check_robot_plan(world, robot, result.plan, start=start):
        return None  # unsound plans are never executed
    return result.plan
