"""Drives cut where robots share places, and made whole again where standing at a cut is the trouble.

The conflict step cuts each drive where it enters and leaves places other robots use, so that a
robot waits only for the shared piece.  A cut is also a place to stand, and standing there may
close a cycle of waits.  When a robot stands at a cut in every conflict no order resolves, only
those drives are made whole again; the robot's other drives, and the other robots, keep theirs.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

import cosmop.team.safe_plans as safe_plans
from cosmop.events import Primitive
from cosmop.planning.messages import cut_drives
from cosmop.planning.realisation import message_links
from cosmop.scenario import load_scenario
from cosmop.team.conflicts import Conflict, ConflictSettings, occupancies
from cosmop.team.loop import plan_team
from cosmop.team.precedence import Precedence
from cosmop.team.timing import start_pose

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _points(plan):
    return [(s.robot[0], s.robot[1]) for s in plan.steps]


@pytest.fixture(scope="module")
def warehouse():
    scenario = load_scenario(EXAMPLES / "01_warehouse_2x2" / "scenario.yaml")
    return scenario, plan_team(scenario).plans.robots


def _two_drives_cut(scenario, plans):
    """A robot whose plan has two drives, each cut in three pieces, and its own waypoints."""
    robot, plan = next(
        (r, p) for r, p in plans.items() if sum(s.primitive == Primitive.GOTO for s in p.steps) >= 2
    )
    drives = [k for k, s in enumerate(plan.steps, 1) if s.primitive == Primitive.GOTO][:2]
    cut = cut_drives(plan, start_pose(scenario.scene, robot, None), {k: [0.25, 0.5] for k in drives})
    return robot, plan, cut, set(_points(plan))


def test_the_cuts_of_one_drive_are_those_between_its_ends(warehouse):
    scenario, plans = warehouse
    _, plan, cut, own = _two_drives_cut(scenario, plans)
    points = _points(cut)
    cuts = [k for k, p in enumerate(points, 1) if p not in own]
    assert len(cuts) == 4 and cut.horizon == plan.horizon + 4
    first, second = set(points[k - 1] for k in cuts[:2]), set(points[k - 1] for k in cuts[2:])
    for k in cuts[:2]:
        assert safe_plans._drive_cuts(cut, k, own) == first
    for k in cuts[2:]:
        assert safe_plans._drive_cuts(cut, k, own) == second
    # at one of its own waypoints (or its start) a robot stands at no cut
    assert safe_plans._drive_cuts(cut, cuts[1] + 1, own) == set()
    assert safe_plans._drive_cuts(cut, 0, own) == set()
    # made whole again, that drive is the plan's own; the other keeps its cuts
    joined = safe_plans._joined(cut, first)
    assert joined.horizon == plan.horizon + 2 and first.isdisjoint(_points(joined))
    assert second <= set(_points(joined))


def test_a_conflict_with_no_robot_standing_at_a_cut_leaves_the_drives_cut(warehouse):
    scenario, plans = warehouse
    robot, _, cut, own = _two_drives_cut(scenario, plans)
    tried = {**plans, robot: cut}
    waypoints = {r: set(_points(p)) for r, p in plans.items()} | {robot: own}
    items, _ = occupancies(
        scenario.scene, tried, Precedence({r: p.horizon for r, p in tried.items()}, message_links(tried))
    )
    stands = [o for o in items if o.what == robot and not o.is_drive and o.states and o.states[0] >= 1]
    at_cut = next(o for o in stands if _points(cut)[o.states[0] - 1] not in own)
    at_own = next(o for o in stands if _points(cut)[o.states[0] - 1] in own)
    other = next(o for o in items if o.what != robot and o.what in scenario.scene.robots)
    assert safe_plans._stands_at_cuts([Conflict(at_cut, other)], tried, waypoints) == {
        robot: safe_plans._drive_cuts(cut, at_cut.states[0], own),
        other.what: set(),
    }
    # one conflict without a robot standing at a cut: cutting is not what keeps them unresolved
    assert (
        safe_plans._stands_at_cuts([Conflict(at_cut, other), Conflict(at_own, other)], tried, waypoints)
        is None
    )


def test_only_the_drive_a_robot_stands_in_is_made_whole_and_then_the_robot(warehouse, monkeypatch):
    scenario, plans = warehouse
    order, tried, reported = safe_plans._order, [], []

    def unresolved_first(context, attempt, waypoints):
        # the first two attempts report a conflict with a robot standing at a cut, as a cycle
        # through that stand would; the step must join that drive, then order the robots whole
        tried.append((attempt, waypoints))
        result = order(context, attempt, waypoints)
        if len(tried) > 2:
            return result
        precedence = Precedence({r: p.horizon for r, p in attempt.items()}, message_links(attempt))
        items, _ = occupancies(scenario.scene, attempt, precedence, ConflictSettings())
        stand = next(
            o
            for o in items
            if o.what in attempt and not o.is_drive and o.states and o.states[0] >= 1
            if _points(attempt[o.what])[o.states[0] - 1] not in waypoints[o.what]
        )
        other = next(o for o in items if o.what != stand.what and o.what in attempt)
        reported.append(Conflict(stand, other))
        return replace(result, unresolved=(reported[-1],))

    monkeypatch.setattr(safe_plans, "_order", unresolved_first)
    safety = safe_plans.make_team_safe(scenario.scene, plans)
    assert safety.safe and len(tried) == 3
    (first, waypoints), (second, _), (third, _) = tried
    robot = reported[0].a.what
    assert [r for r in first if first[r] != second[r]] == [robot]
    gone = set(_points(first[robot])) - set(_points(second[robot]))
    assert gone == safe_plans._drive_cuts(first[robot], reported[0].a.states[0], waypoints[robot])
    # that drive was made whole: none of its cuts is left, and no other cut was touched
    assert set(_points(second[robot])) == set(_points(first[robot])) - gone
    # a conflict again, no fewer: its robots are ordered whole, every drive, the others untouched
    whole = set(reported[1].robots)
    for r in third:
        if r in whole:
            assert all(p in waypoints[r] for p in _points(third[r]))
        else:
            assert third[r] == second[r]
