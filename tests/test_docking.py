"""Docking from any side an object allows, and goods set down wholly inside their docks.

A good at the back of a bay that opens to the north can only be handled from the north side
(heading 270); the planner finds that side, the exact checker accepts it, the simulator docks
there.  Restricted to the paper's west side, the same mission is refused before the solver,
with a reason that names the sides tried.
"""

from __future__ import annotations

import pytest

from cosmop.docking import SIDES, docking_pose, facing, in_front
from cosmop.errors import ScenarioError
from cosmop.planning.checker import check_robot_plan
from cosmop.planning.plan_types import PlanSet
from cosmop.planning.synthesis import synthesize
from cosmop.scenario import parse_scenario
from cosmop.sim.simulation import SimSettings, simulate
from cosmop.squares import docking_places
from rooms import box_walls


def _bay(sides=None, workspace=None):
    """A room with a bay of inner walls open to the north; O1 at its back, W1 in the open."""
    obj = {"size": 100, "position": [1000, -1150]}
    if sides is not None:
        obj["sides"] = sides
    return parse_scenario(
        {
            "name": "north-bay",
            "scene": {
                "obstacles": [
                    *box_walls(-2000, -1500, 2000, 1500),
                    [[750, -1500], [750, -500]],  # the bay: 500 wide, open at the top
                    [[1250, -1500], [1250, -500]],
                ],
                "robots": {"R1": {"size": 400, "pose": [-1500, 0, 0]}},
                "objects": {"O1": obj},
                "workspaces": {"W1": workspace or {"x": [-1000, -500], "y": [800, 1300]}},
            },
            "mission": {"tasks": {"R1": ["pick O1", "drop O1 at W1", "return"]}},
        }
    )


def test_the_docking_geometry_is_exact_and_inverse():
    for heading in SIDES.values():
        pose = docking_pose((1000, -1150), 250, heading)
        assert in_front(pose, 250, heading) == (1000, -1150)
        ux, uy = facing(heading)
        assert isinstance(ux, int) and isinstance(uy, int) and abs(ux) + abs(uy) == 1
    with pytest.raises(ValueError, match="0, 90, 180, 270"):
        facing(45)
    places = docking_places((0, 100), (0, 0), 250, headings=(90,))
    assert [p.bounds for p in places] == [(0.0, -250.0, 100.0, -250.0)]


def test_goods_at_the_back_of_a_north_bay_are_picked_from_the_north():
    scenario = _bay()
    result = synthesize(scenario.scene, "R1", scenario.mission.tasks["R1"], max_horizon=10)
    assert result.feasible, result.reason
    assert check_robot_plan(scenario.scene, "R1", result.plan) == []
    pick = next(s for s in result.plan.steps if s.primitive == "PickUp")
    assert pick.robot == (1000, -900, 270)  # on the north side, facing south (-y)


def test_the_west_side_only_is_refused_before_the_solver_naming_the_sides_tried():
    scenario = _bay(sides=["west"])
    result = synthesize(scenario.scene, "R1", scenario.mission.tasks["R1"], max_horizon=10)
    assert not result.feasible
    assert "pick(R1,O1)" in result.reason and "sides tried: west (750, -1150)" in result.reason


def test_a_heading_the_object_does_not_allow_is_a_violation():
    scenario = _bay()
    plan = synthesize(scenario.scene, "R1", scenario.mission.tasks["R1"], max_horizon=10).plan
    restricted = _bay(sides=["west", "east"]).scene
    (violation,) = [v for v in check_robot_plan(restricted, "R1", plan) if v.rule == "pick-pose"]
    assert "O1 is picked up facing one of its sides west, east: at heading 0° or 180°" in violation.message


@pytest.mark.parametrize("width", [100, 160])
def test_a_drop_puts_the_whole_good_inside_its_dock(width: int):
    # a dock exactly as wide as the good leaves one position; a wider one a range
    workspace = {"x": [-1000, -1000 + width], "y": [800, 900]}
    scenario = _bay(workspace=workspace)
    result = synthesize(scenario.scene, "R1", scenario.mission.tasks["R1"], max_horizon=10)
    assert result.feasible and check_robot_plan(scenario.scene, "R1", result.plan) == []
    drop = next(s for s in result.plan.steps if s.primitive == "DropOff")
    x, y = drop.objects["O1"].position
    assert -950 <= x <= -1050 + width and y == 850


def test_a_dock_smaller_than_its_good_is_bad_input():
    with pytest.raises(ScenarioError, match=r"W1 \(90 mm x 500 mm\) cannot hold O1"):
        _bay(workspace={"x": [-1000, -910], "y": [800, 1300]})


def test_the_simulator_docks_from_the_planned_side():
    scenario = _bay()
    result = synthesize(scenario.scene, "R1", scenario.mission.tasks["R1"], max_horizon=10)
    plans = PlanSet(scenario.name, True, {"R1": result.plan})
    run = simulate(scenario, plans, settings=SimSettings(max_time=300.0))
    assert run.completed and not run.contacts
    (x, y), carried_by = run.objects["O1"]
    assert carried_by is None and -950 <= x <= -550 and 850 <= y <= 1250  # wholly inside W1
    picked = [t for t, robot, event in run.events if event == "pick(R1,O1)"]
    frames = run.frames
    k = int((frames["t"] <= picked[0]).sum()) - 1
    assert frames["pose"][k, 0, 2] == pytest.approx(-90.0, abs=2.0)  # facing south, on the north side
