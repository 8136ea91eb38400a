"""Robots the scene parks closer than the clearance: they may leave, and come home that close.

The conflict rule grows robots by the 100 mm the simulator keeps between them; two robots
parked side by side at the start (touching) would then overlap from instant 0, and no order
could ever let either leave.  Where one of them stands at its start, the other standing at or
driving off its own keeps only the gap the scene gave them; likewise where one stands at its
home at the end and the other stands at or drives into its own, and a robot re-planned around
another parked there keeps out of it by that gap only.
"""

from __future__ import annotations

import copy
from dataclasses import replace

import pytest

from cosmop.lifelong import FleetSettings, run_fleet
from cosmop.planning.realisation import message_links
from cosmop.scenario import parse_scenario
from cosmop.sim import footprint_overlaps, simulate
from cosmop.squares import square, swept_square
from cosmop.team.conflicts import (
    Conflict,
    ConflictSettings,
    Occupancy,
    conflicts,
    occupancies,
    ranked_detours,
    replan_rank,
)
from cosmop.team.loop import plan_team
from cosmop.team.plan_set_checker import check_plan
from cosmop.team.precedence import Precedence

ROOM = [
    [[-4000, -3000], [4000, -3000]],
    [[4000, -3000], [4000, 3000]],
    [[4000, 3000], [-4000, 3000]],
    [[-4000, 3000], [-4000, -3000]],
]
SIDE_BY_SIDE = {
    "name": "side-by-side",
    "scene": {
        "obstacles": ROOM,
        "robots": {"R1": {"size": 400, "pose": [0, 0, 0]}, "R2": {"size": 400, "pose": [0, 400, 0]}},
        "objects": {
            "O1": {"size": 100, "position": [-3000, -2000]},
            "O2": {"size": 100, "position": [3000, 2000]},
        },
        "workspaces": {
            "W1": {"x": [2500, 3500], "y": [-2500, -1500]},
            "W2": {"x": [-3500, -2500], "y": [1500, 2500]},
        },
    },
    "mission": {"tasks": {"R1": ["pick O1", "drop O1 at W1"], "R2": ["pick O2", "drop O2 at W2"]}},
}


@pytest.fixture(scope="module")
def planned():
    scenario = parse_scenario(SIDE_BY_SIDE)
    return scenario, plan_team(scenario, workers=1)


def test_robots_parked_touching_are_planned_checked_and_leave(planned):
    scenario, result = planned
    assert result.plans.feasible, result.plans.reason
    assert check_plan(scenario, result.plans).ok
    run = simulate(scenario, result.plans)
    assert run.completed and run.contacts_while_moving == 0
    assert not footprint_overlaps(scenario.scene, run)


def test_only_the_starts_keep_the_smaller_gap(planned):
    scenario, result = planned
    plans = result.plans.robots
    order = Precedence({r: p.horizon for r, p in plans.items()}, message_links(plans))
    items, _ = occupancies(scenario.scene, plans, order, ConflictSettings())
    starts = [o for o in items if o.start is not None]
    # each robot: its standing from instant 0 and its first drive, nothing later
    assert sorted((o.what, o.is_drive) for o in starts) == [
        ("R1", False),
        ("R1", True),
        ("R2", False),
        ("R2", True),
    ]
    both = [c for c in conflicts(items) if c.a.first is None and c.b.first is None]
    assert not both  # the two starts touch: no conflict between them
    # told the regions were grown by nothing, the rule exempts nothing: the grown starts conflict
    grown = [c for c in conflicts(items, clearance=0.0) if c.a.first is None and c.b.first is None]
    assert len(grown) == 1


def test_robots_parked_touching_come_home_touching_again():
    """Both return: each home is where the scene parked it, at the gap the scene gave (touching);
    the plans keep that gap there, and in the run the second one home creeps up to it."""
    data = copy.deepcopy(SIDE_BY_SIDE)
    data["mission"]["tasks"] = {r: [*tasks, "return"] for r, tasks in data["mission"]["tasks"].items()}
    scenario = parse_scenario(data)
    result = plan_team(scenario, workers=1)
    assert result.plans.feasible, result.plans.reason
    assert check_plan(scenario, result.plans).ok
    plans = result.plans.robots
    order = Precedence({r: p.horizon for r, p in plans.items()}, message_links(plans))
    items, _ = occupancies(scenario.scene, plans, order, ConflictSettings())
    homes = [o for o in items if o.start is not None and o.last is None]
    assert sorted(o.what for o in homes) == ["R1", "R2"]  # each robot's rest at home, for good
    run = simulate(scenario, result.plans)
    assert run.completed and run.contacts_while_moving == 0
    assert not footprint_overlaps(scenario.scene, run)


def test_a_robot_parked_for_good_beside_another_is_driven_around_at_the_scene_gap():
    """R1 never moves; R2, parked touching it, must pass it: its re-plan keeps out of R1's
    square only by the gap the scene gave them (the clearance would wall R2 in where it stands)."""
    data = copy.deepcopy(SIDE_BY_SIDE)
    data["scene"]["objects"]["O2"]["position"] = [3000, -2000]  # below R1's row: R2 goes past R1
    data["mission"]["tasks"] = {"R2": ["pick O2", "drop O2 at W2", "return"]}
    scenario = parse_scenario(data)
    result = plan_team(scenario, workers=1)
    assert result.plans.feasible, result.plans.reason
    assert any("R2 re-planned around" in why for why in result.replans)
    assert check_plan(scenario, result.plans).ok
    first = result.plans.robots["R2"].steps[0].robot
    assert first[1] - 200 >= 200 - 1e-6  # R2's first drive keeps its square above R1's (y <= 200)
    run = simulate(scenario, result.plans)
    assert run.completed and run.contacts_while_moving == 0
    assert not footprint_overlaps(scenario.scene, run)


def test_a_lifelong_fleet_parked_touching_serves_its_orders():
    """Idle robots are obstacles to a new order's plan, grown by the clearance only where the
    robots do not already stand closer: else a robot parked touching another could plan nothing
    from where it stands."""
    data = copy.deepcopy(SIDE_BY_SIDE)
    del data["mission"]
    data["orders"] = [
        {"at": 0, "object": "O1", "to": "W1", "by": "R1"},
        {"at": 1, "object": "O2", "to": "W2", "by": "R2"},
    ]
    result = run_fleet(parse_scenario(data), fleet=FleetSettings(until=120.0))
    summary = result.summary()
    assert summary["orders"]["delivered"] == 2 and summary["orders"]["lost"] == 0
    assert [e["accepted"] for e in summary["dispatch_log"]] == [True, True]
    assert result.contacts_while_moving == 0


def test_a_robot_that_starts_beside_goods_another_moves_lets_them_be_picked():
    """R2 starts 10 mm from O1, which R1 picks: a standing robot's body is grown by the 20 mm it
    may stop off its pose (``ConflictSettings.rest``), but one that has not moved yet is exactly
    where the scene put it, beside goods that lie where the scene put them: no order of the plans
    could change that, so it is no conflict (it was refused as one).  Goods coming to rest that
    close later still conflict."""
    data = copy.deepcopy(SIDE_BY_SIDE)
    data["scene"]["robots"]["R2"]["pose"] = [-3000, -2260, 90]  # 10 mm below O1's square
    data["mission"]["tasks"] = {"R1": ["pick O1", "drop O1 at W1", "return"], "R2": ["pick O2", "return"]}
    scenario = parse_scenario(data)
    result = plan_team(scenario, workers=1)
    assert result.plans.feasible, result.plans.reason
    assert check_plan(scenario, result.plans).ok
    run = simulate(scenario, result.plans)
    assert run.completed and run.contacts_while_moving == 0
    plans = result.plans.robots
    order = Precedence({r: p.horizon for r, p in plans.items()}, message_links(plans))
    items, _ = occupancies(scenario.scene, plans, order, ConflictSettings())
    start = next(o for o in items if o.what == "R2" and o.first is None and not o.is_drive)
    o1 = next(o for o in items if o.what == "O1" and o.first is None)
    assert start.body.intersects(o1.region) and not start.start.intersects(o1.region.buffer(-1e-6))
    assert not conflicts([start, o1])
    # goods brought that close later conflict with R2 standing there from the start, and R2
    # coming home that close to the goods still lying there conflicts too (ordered: R1 takes
    # them first)
    assert conflicts([start, replace(o1, first=("R1", 1))])
    home = next(o for o in items if o.what == "R2" and o.first is not None and o.last is None)
    assert conflicts([home, o1]) and result.plans.feasible


def _home_and_drive(drive_start: bool) -> tuple[Conflict, Occupancy, dict]:
    """R2 home for good at (0, 0); R1, whose home at (400, 100) touches R2's, drives over R2's
    home 20 mm above it: the drive off or into R1's home (`drive_start`) or another drive."""
    home = Occupancy(
        "R2", frozenset({"R2"}), square(0, 0, 500), ("R2", 5), None, "R2 standing at home", False,
        square(0, 0, 400), start=square(0, 0, 400),
    )  # fmt: skip
    body = swept_square((-600, 420), (600, 420), 400)
    drive = Occupancy(
        "R1", frozenset({"R1"}), swept_square((-600, 420), (600, 420), 500), ("R1", 3), ("R1", 3),
        "R1's GoTo at instant 3", True, body, start=square(400, 100, 400) if drive_start else None,
    )  # fmt: skip
    return Conflict(drive, home), home, {"R1": [square(400, 100, 500)], "R2": [square(0, 0, 500)]}


def test_a_drive_the_rule_holds_to_the_clearance_is_not_kept_out_at_the_scene_gap_first():
    """Walls at the scene's gap (R1's home is 0 mm from R2's) would let R1's drive pass R2's home
    closer than the clearance, which the rule allows only the drives off or into a robot's
    start or home: that way around is ranked last, so that the search sets aside another
    conflict of the cycle first (seed 1093 of the generated scenes was refused for it)."""
    conflict, home, fixed = _home_and_drive(drive_start=False)
    assert ranked_detours(conflict, fixed) == [(3, "R1", home)]
    assert replan_rank(conflict, fixed) == 2
    conflict, home, fixed = _home_and_drive(drive_start=True)
    assert ranked_detours(conflict, fixed) == [(0, "R1", home)]
    assert replan_rank(conflict, fixed) == 0


def test_a_way_around_known_not_to_work_is_left_out():
    conflict, home, fixed = _home_and_drive(drive_start=True)
    futile = frozenset({("R1", home.label)})
    assert ranked_detours(conflict, fixed, futile) == []
    assert replan_rank(conflict, fixed, futile) == 3
    assert ranked_detours(conflict, fixed, frozenset({("R1", "another space")})) == [(0, "R1", home)]
