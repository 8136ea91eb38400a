"""A world whose one conflict order is stale (shared by the tests of re-ordering)."""

from __future__ import annotations

import functools

from cosmop.events import Primitive, message
from cosmop.planning import PlanSet
from cosmop.planning.plan_types import PlanMessage, RobotPlan, Step
from cosmop.scenario import parse_scenario
from cosmop.sim.result import SimSettings
from cosmop.sim.simulation import advance
from cosmop.sim.world import World


def stale_order_world() -> World:
    """R2 waits at its start for R1, which crosses R2's way only after a long drive up and
    back: the order a hand-over may have chosen when R2 was expected there later than it is."""
    scenario = parse_scenario(
        {
            "name": "stale",
            "scene": {
                "obstacles": [],
                "robots": {
                    "R1": {"size": 400, "pose": [-3000, 0, 0]},
                    "R2": {"size": 400, "pose": [0, -2500, 90]},
                },
                "objects": {},
                "workspaces": {},
            },
            "mission": {"tasks": {"R1": ["return"], "R2": ["return"]}},
        }
    )
    m = message("R1", "R2", "clear1")
    go = functools.partial(Step, Primitive.GOTO, None, objects={})
    plans = {
        "R1": RobotPlan.from_steps(
            (m,),
            (
                go((-3000.0, 6000.0, 90.0)),
                go((-3000.0, 0.0, -90.0)),
                go((3000.0, 0.0, 0.0)),
                Step(Primitive.RES, None, (3000.0, 0.0, 0.0), {}, message=m),
            ),
        ),
        "R2": RobotPlan.from_steps(
            (m,), (Step(Primitive.REQ, None, (0.0, -2500.0, 90.0), {}, message=m), go((0.0, 2500.0, 90.0)))
        ),
    }
    messages = (PlanMessage(m, "conflict", "R2 waits for R1's drive across", (-200.0, -200.0, 200.0, 200.0)),)
    return World(scenario, PlanSet(scenario.name, True, plans, messages=messages), 0, SimSettings())


def run_out(world: World, limit: int = 3000) -> None:
    """Advance `world` until every robot has done its plan (at most `limit` cycles)."""
    for _ in range(limit):
        if all(a.done for a in world.agents):
            return
        advance(world)
    raise AssertionError("the world did not finish")
