"""Units: ``units: m`` scenarios (metres, radians) load to the same scene as mm/degree ones, and
every JSON output says its units while older files without a ``units`` key stay readable."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from typer.testing import CliRunner

from cosmop.cli import app
from cosmop.errors import ScenarioError
from cosmop.events import parse_event
from cosmop.planning.plan_file import PlanError, load_plan
from cosmop.planning.plan_types import Coordination, PlanSet
from cosmop.planning.primitive_effects import plan_from_actions
from cosmop.scenario import load_scenario
from cosmop.team.plan_set_checker import check_plan
from cosmop.units import INTERNAL_UNITS, localize, mm_from_m, show_length, show_point, show_pose, show_speed
from handmade_plans import R1_ACTIONS, R1_MISSION, R2_RES_ACTIONS, R2_RES_MISSION

ROOT = Path(__file__).resolve().parents[1]
MM_FILE = ROOT / "examples" / "01_warehouse_2x2" / "scenario.yaml"
runner = CliRunner()

SI_TEXT = """
name: warehouse-2x2
units: m
scene:
  obstacles:
    - [[-2.5, -2.5], [2.5, -2.5]]
    - [[2.5, -2.5], [2.5, 2.5]]
    - [[2.5, 2.5], [-2.5, 2.5]]
    - [[-2.5, 2.5], [-2.5, -2.5]]
    - [[0, 0], [0, 2.5]]
    - [[-1, 0], [1, 0]]
  robots:
    R1: {size: 0.4, pose: [-2, -1, 0]}
    R2: {size: 0.4, pose: [-2, -2, 0]}
  objects:
    O1: {size: 0.1, position: [2, -1]}
    O2: {size: 0.1, position: [1.9, -1]}
  workspaces:
    W1: {x: [-1.5, -1], y: [2, 2.5]}
    W2: {x: [1, 1.5], y: [2, 2.5]}
mission:
  tasks:
    R1: [pick O1, drop O1 at W1, return]
    R2: [pick O2, drop O2 at W2, return]
"""


def test_a_scenario_in_metres_is_the_same_scene_as_in_millimetres(tmp_path):
    si = tmp_path / "si.yaml"
    si.write_text(SI_TEXT)
    assert load_scenario(si).scene == load_scenario(MM_FILE).scene  # exact, to the last bit


def test_metres_convert_headings_speeds_and_people_and_keep_the_defaults(tmp_path):
    text = SI_TEXT.replace("pose: [-2, -1, 0]", "pose: [-2, -1, 1.5707963267948966]")
    text = text.replace(
        "  workspaces:",
        "  dynamics: {max_speed: 0.5, turn_rate: 1.0}\n"
        "  humans: {H1: {size: 0.5, speed: 0.6, path: [[0, -1.5], [0, -2.2, 5]]}}\n  workspaces:",
    )
    path = tmp_path / "si.yaml"
    path.write_text(text)
    scene = load_scenario(path).scene
    r1 = scene.robots["R1"]
    assert r1.pose == (-2000.0, -1000.0, 90.0)
    assert r1.dynamics.max_speed == 500.0 and r1.dynamics.turn_rate == pytest.approx(math.degrees(1.0))
    assert r1.dynamics.acceleration == 300.0 and r1.dynamics.braking == 500.0  # defaults untouched
    assert r1.dynamics.cycle == 0.1
    h1 = scene.humans["H1"]
    assert (h1.size, h1.speed, h1.path) == (500.0, 600.0, ((0.0, -1500.0, 0.0), (0.0, -2200.0, 5.0)))
    assert mm_from_m(2.3) == 2300.0  # 2.3 * 1000 is 2299.9999999999995 in floating point


def test_errors_in_a_metre_file_speak_in_metres(tmp_path):
    path = tmp_path / "si.yaml"
    path.write_text(SI_TEXT.replace("size: 0.4, pose: [-2, -1, 0]", "size: -0.4, pose: [-2, -1, 0]"))
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    assert info.value.field == "scene.robots.R1.size"
    assert "(side of the square robot, m)" in info.value.expected
    assert localize("a pose [x, y, heading]: three numbers (mm, mm, degrees)", "m") == (
        "a pose [x, y, heading]: three numbers (m, m, radians)"
    )


def test_unknown_units_exit_2_naming_the_field(tmp_path):
    path = tmp_path / "cm.yaml"
    path.write_text(SI_TEXT.replace("units: m", "units: cm"))
    result = runner.invoke(app, ["validate", str(path)])
    assert result.exit_code == 2
    assert f"{path}: units: expected mm (millimetres and degrees, the default) or m" in result.stderr


def test_plan_files_say_their_units_and_old_ones_still_load(tmp_path):
    scene = load_scenario(MM_FILE).scene
    plans = PlanSet(
        "warehouse-2x2",
        True,
        {
            "R1": plan_from_actions(scene, "R1", R1_MISSION, R1_ACTIONS),
            "R2": plan_from_actions(scene, "R2", R2_RES_MISSION, R2_RES_ACTIONS),
        },
        (Coordination("O2", "R1", "R2"),),
    )
    out = tmp_path / "plan.json"
    plans.save(out)
    data = json.loads(out.read_text())
    assert data["units"] == dict(INTERNAL_UNITS) == {"length": "mm", "angle": "deg", "time": "s"}
    old = dict(data)
    del old["units"]  # a file written before units existed means mm and degrees
    (tmp_path / "old.json").write_text(json.dumps(old))
    assert load_plan(tmp_path / "old.json") == load_plan(out)
    wrong = dict(data, units={"length": "m", "angle": "rad", "time": "s"})
    (tmp_path / "si.json").write_text(json.dumps(wrong))
    with pytest.raises(PlanError) as info:
        load_plan(tmp_path / "si.json")
    assert info.value.field == "units" and "mm" in info.value.expected


# -- every message in the file's units ---------------------------------------------------------

WALLED_IN = """
name: walled-in
units: m
scene:
  obstacles:                    # a box around R1, far from its goods
    - [[799, 999], [801, 999]]
    - [[801, 999], [801, 1001]]
    - [[801, 1001], [799, 1001]]
    - [[799, 1001], [799, 999]]
  robots:
    R1: {size: 0.4, pose: [800, 1000, 0]}
  objects:
    O1: {size: 0.1, position: [805, 1000]}
  workspaces:
    W1: {point: [807, 1000]}
mission:
  tasks:
    R1: [pick O1, drop O1 at W1]
"""


def test_a_metres_file_is_answered_in_metres_by_validate_and_plan(tmp_path):
    path = tmp_path / "walled.yaml"
    path.write_text(WALLED_IN)
    result = runner.invoke(app, ["validate", str(path)])
    assert result.exit_code == 0 and "R1 (size 0.4 m)" in result.stdout
    out = tmp_path / "plan.json"
    result = runner.invoke(app, ["plan", str(path), "-o", str(out)])
    assert result.exit_code == 1
    reason = load_plan(out).reason
    # it said "start (800000, 1e+06)": millimetres, and not even in full
    assert "walls separate its start (800, 1000) from its pick poses" in reason
    assert "west (804.75, 1000)" in reason
    assert "800000" not in reason and "e+" not in reason


def test_the_checker_speaks_metres_for_a_metres_file(tmp_path):
    si = tmp_path / "si.yaml"
    si.write_text(SI_TEXT)
    scenario = load_scenario(si)
    assert scenario.units == "m" and load_scenario(MM_FILE).units == "mm"
    through = plan_from_actions(
        scenario.scene, "R1", [parse_event("return(R1)")], [("GoTo", (1000, 1000, 0))]
    )
    report = check_plan(scenario, PlanSet("warehouse-2x2", True, {"R1": through}))
    messages = " ".join(v.message for v in report.violations)
    assert "GoTo from (-2, -1) to (1, 1) crosses wall [[-1,0],[1,0]]" in messages
    mm = check_plan(load_scenario(MM_FILE), PlanSet("warehouse-2x2", True, {"R1": through}))
    assert "GoTo from (-2000, -1000) to (1000, 1000) crosses wall [[-1000,0],[1000,0]]" in " ".join(
        v.message for v in mm.violations
    )


def test_show_writes_lengths_points_poses_and_speeds_in_the_files_units():
    assert show_point((800000.0, 1e6), "m") == "(800, 1000)"
    assert show_point((1433.5, -2000.0), "mm") == "(1433.5, -2000)"
    assert show_length(2300.0, "m") == "2.3 m" and show_length(1e9, "mm") == "1000000000 mm"
    assert show_pose((0.0, 500.0, 90.0), "m") == "(0, 0.5, 1.5708 rad)"
    assert show_pose((0.0, 500.0, 90.0), "mm") == "(0, 500, 90°)"
    assert show_speed(750.0, "m") == "0.75 m/s" and show_speed(750.0, "mm") == "750 mm/s"


def test_simulates_table_shows_poses_and_distances_in_the_files_units(tmp_path):
    from types import SimpleNamespace

    from rich.console import Console

    from cosmop.cli.simulate import _robots_table

    run = SimpleNamespace(
        robots={"R1": ((-2000.0, -1000.0, 90.0), 12345.0)}, finished={"R1": True}, steps={}, delays=None
    )
    si = tmp_path / "si.yaml"
    si.write_text(SI_TEXT)
    for scenario, pose, distance in (
        (load_scenario(si), "-2.000, -1.000, 1.57", "12.35 m"),
        (load_scenario(MM_FILE), "-2000, -1000, 90", "12345 mm"),
    ):
        console = Console(width=200, record=True)
        console.print(_robots_table(scenario, run, 0))
        text = console.export_text()
        assert pose in text and distance in text
        assert ("pose [m, rad]" if scenario.units == "m" else "pose [mm, deg]") in text
