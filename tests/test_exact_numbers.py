"""Exact numbers: lengths on a micrometre grid, odd sizes planned exactly (issue 12, point 4).

A scenario's lengths must be multiples of :data:`cosmop.scene.LENGTH_GRID`; finer ones are
refused at validation with the precision named.  On that grid, positions are integers (whole
mm) when every pose a primitive can force is whole, and exact rationals otherwise, so an object
of side 101 mm is picked from x = 1749.5 instead of being called unreachable.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from cosmop.errors import ScenarioError
from cosmop.planning.checker import check_robot_plan
from cosmop.planning.plan_types import State
from cosmop.planning.primitive_effects import initial_state
from cosmop.planning.specification import position_sort
from cosmop.planning.synthesis import synthesize
from cosmop.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[1]
TEXT = (ROOT / "examples" / "01_warehouse_2x2" / "scenario.yaml").read_text()
# O1 of side 101 with O2 moved half a millimetre so that they touch
ODD = TEXT.replace("O1: {size: 100,", "O1: {size: 101,").replace("[1900, -1000]", "[1899.5, -1000]")


def _scenario(tmp_path, text):
    path = tmp_path / "s.yaml"
    path.write_text(text)
    return load_scenario(path)


@pytest.mark.parametrize(
    ("old", "new", "field"),
    [
        ("R1: {size: 400,", "R1: {size: 400.0000001,", "scene.robots.R1.size"),
        (
            "O1: {size: 100, position: [2000,",
            "O1: {size: 100, position: [2000.0004,",
            "scene.objects.O1.position[0]",
        ),
        ("W1: {x: [-1500, -1000]", "W1: {x: [-1500.00001, -1000]", "scene.workspaces.W1.x[0]"),
        ("[[0, 0], [0, 2500]]", "[[0, 0], [0, 2500.0000001]]", "scene.obstacles[4][1][1]"),
    ],
)
def test_lengths_finer_than_a_micrometre_are_refused_naming_the_precision(tmp_path, old, new, field):
    assert old in TEXT
    with pytest.raises(ScenarioError, match=r"expected a multiple of 0\.001 mm") as info:
        _scenario(tmp_path, TEXT.replace(old, new))
    assert info.value.field == field


def test_in_metres_the_precision_is_said_in_metres(tmp_path):
    text = TEXT.replace("name: warehouse-2x2", "units: m\nname: warehouse-2x2")
    with pytest.raises(ScenarioError, match=r"multiple of 0\.000001 m\b.*got 0\.40000001"):
        _scenario(tmp_path, text.replace("R1: {size: 400,", "R1: {size: 0.40000001,"))


def test_lengths_beyond_1000_km_are_refused(tmp_path):
    with pytest.raises(ScenarioError, match="at most 1000000000 mm, got 10000000000 ") as info:
        _scenario(tmp_path, TEXT.replace("O1: {size: 100,", "O1: {size: 1e10,"))
    assert info.value.field == "scene.objects.O1.size"


def test_whole_scenes_keep_integer_positions_and_odd_ones_get_exact_rationals(tmp_path):
    assert position_sort(_scenario(tmp_path, TEXT).scene) == "int"
    assert position_sort(_scenario(tmp_path, ODD).scene) == "real"
    # walls only bound positions: a wall at half a millimetre forces no fractional pose
    wall = TEXT.replace("[[-1000, 0], [1000, 0]]", "[[-1000, 0.5], [1000, 0.5]]")
    assert position_sort(_scenario(tmp_path, wall).scene) == "int"
    good = TEXT.replace("[2000, -1000]", "[2000, -999.5]")
    assert position_sort(_scenario(tmp_path, good).scene) == "real"


def test_a_start_state_off_the_millimetre_grid_gets_exact_positions(tmp_path):
    scenario = _scenario(tmp_path, TEXT)
    start = initial_state(scenario.scene, "R1")
    moved = State((start.robot[0] + 0.25, start.robot[1], start.robot[2]), start.objects)
    assert position_sort(scenario.scene, start) == "int"
    assert position_sort(scenario.scene, moved) == "real"
    result = synthesize(scenario.scene, "R1", ["return(R1)"], start=moved, rlimit=50_000_000)
    assert result.feasible and result.plan.steps[-1].robot[:2] == (-2000, -1000)


@pytest.mark.parametrize(
    ("old", "new", "pick_x"),
    [
        ("", "", 1749.5),  # ODD: (400 + 101) / 2 = 250.5 from O1
        ("R1: {size: 400,", "R1: {size: 399,", 1750.5),
        ("O1: {size: 100, position: [2000,", "O1: {size: 100, position: [2000.25,", 1750.25),
    ],
)
def test_odd_sizes_and_positions_plan_exactly_and_pass_the_checker(tmp_path, old, new, pick_x):
    scenario = _scenario(tmp_path, TEXT.replace(old, new) if old else ODD)
    result = synthesize(scenario.scene, "R1", scenario.mission.tasks["R1"], rlimit=50_000_000)
    assert result.feasible, result.reason
    picks = [s for s in result.plan.steps if s.primitive == "PickUp"]
    assert picks[0].robot[0] == pick_x
    assert check_robot_plan(scenario.scene, "R1", result.plan) == []
