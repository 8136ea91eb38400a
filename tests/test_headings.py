"""Any heading (issue 39, point 2): a start or home heading that is not whole degrees plans.

The heading was an integer variable, so a ROS file's ``-1.5708`` rad (``-90.000210459``
degrees) or ``45.5`` degrees made every plan infeasible at any horizon.  The heading is now an
exact rational whenever a given heading is fractional (:func:`heading_sort`), and whole
degrees (the paper's integers, the same plans) otherwise.
"""

from __future__ import annotations

import json
import math
import random
from pathlib import Path

import pytest
from typer.testing import CliRunner

from cosmop.cli import app
from cosmop.errors import ScenarioError
from cosmop.planning.checker import check_robot_plan
from cosmop.planning.plan_file import load_plan
from cosmop.planning.plan_types import State
from cosmop.planning.primitive_effects import initial_state
from cosmop.planning.specification import RobotProblem, heading_sort
from cosmop.planning.synthesis import synthesize
from cosmop.scenario import load_scenario
from cosmop.sim import SimSettings, simulate
from cosmop.team.loop import plan_team
from cosmop.team.plan_set_checker import check_plan

ROOT = Path(__file__).resolve().parents[1]
runner = CliRunner()

ROOM = """name: turn
units: UNITS
scene:
  obstacles:
    - [[-1500, -1500], [1500, -1500]]
    - [[1500, -1500], [1500, 1500]]
    - [[1500, 1500], [-1500, 1500]]
    - [[-1500, 1500], [-1500, -1500]]
  robots:
    R1: {size: 400, pose: [-1000, -1000, HEADING]}
  objects:
    O1: {size: 100, position: [800, -1000]}
  workspaces:
    W1: {x: [-1000, -500], y: [800, 1300]}
mission:
  tasks:
    R1: [pick O1, drop O1 at W1, return]
"""


def _room(tmp_path: Path, heading: str, units: str = "mm") -> Path:
    """The small room with R1 at `heading` (degrees, or radians with ``units: m``)."""
    text = ROOM.replace("HEADING", heading).replace("UNITS", units)
    if units == "m":  # the same room in metres
        for mm in ("1500", "1000", "800", "500", "1300", "400", "100"):
            text = text.replace(mm, str(int(mm) / 1000))
    path = tmp_path / f"room_{units}.yaml"
    path.write_text(text)
    return path


_RNG = random.Random(39)  # a few headings no one chose, the same on every run
_RANDOM_DEGREES = [f"{_RNG.uniform(-720, 720):.{_RNG.randint(1, 7)}f}" for _ in range(3)]
_RANDOM_RADIANS = [f"{_RNG.uniform(-2 * math.pi, 2 * math.pi):.{_RNG.randint(1, 6)}f}" for _ in range(3)]
HEADINGS = [
    *[("mm", h) for h in ("45.5", "-90.0002", "359.9", "0.001", "-1e-5", "7200.25", *_RANDOM_DEGREES)],
    *[("m", h) for h in ("-1.5708", "1.57", "0.5", "3.14159", *_RANDOM_RADIANS)],
]


@pytest.mark.parametrize(("units", "heading"), HEADINGS)
def test_any_start_heading_plans_exactly_and_passes_the_checker(tmp_path, units, heading):
    scene = load_scenario(_room(tmp_path, heading, units)).scene
    given = scene.robots["R1"].pose[2]
    expected = float(heading) if units == "mm" else math.degrees(float(heading))
    assert given == pytest.approx(expected, abs=1e-9)
    assert not float(given).is_integer() and heading_sort(scene, "R1") == "real"
    result = synthesize(scene, "R1", ["pick(R1,O1)", "drop(R1,O1,W1)", "return(R1)"])
    assert result.feasible, result.reason
    assert check_robot_plan(scene, "R1", result.plan) == []
    assert result.plan.steps[-1].robot == scene.robots["R1"].pose  # home, to the last bit


def test_minus_half_pi_in_radians_is_not_minus_90_degrees(tmp_path):
    scene = load_scenario(_room(tmp_path, "-1.5708", "m")).scene
    assert scene.robots["R1"].pose[2] == -90.000210459  # degrees(-1.5708) to 1e-9 degrees
    result = synthesize(scene, "R1", ["return(R1)"])  # already home: no step needed
    assert result.feasible and result.plan.horizon == 0


def test_whole_headings_keep_the_integer_heading(tmp_path):
    for heading in ("0", "90", "-180", "720", "45.0"):
        scene = load_scenario(_room(tmp_path, heading)).scene
        assert heading_sort(scene, "R1") == "int"
        assert RobotProblem(scene, "R1", ()).h.sort == "int"


def test_only_the_robots_own_headings_decide_its_sort(tmp_path):
    scenario = load_scenario(ROOT / "examples" / "01_warehouse_2x2" / "scenario.yaml")
    start = initial_state(scenario.scene, "R1")
    assert heading_sort(scenario.scene, "R1", start) == "int"
    turned = State((start.robot[0], start.robot[1], 12.25), start.objects)  # a replan mid-turn
    assert heading_sort(scenario.scene, "R1", turned) == "real"
    assert heading_sort(scenario.scene, "R2", initial_state(scenario.scene, "R2")) == "int"


def test_a_replan_from_a_fractional_heading_plans_and_passes_the_checker(tmp_path):
    scene = load_scenario(_room(tmp_path, "0")).scene
    start = initial_state(scene, "R1")
    start = State((start.robot[0], start.robot[1], -33.125), start.objects)
    result = synthesize(scene, "R1", ["pick(R1,O1)", "drop(R1,O1,W1)", "return(R1)"], start=start)
    assert result.feasible, result.reason
    assert check_robot_plan(scene, "R1", result.plan, start=start) == []


def test_a_ros_heading_plans_writes_and_simulates_end_to_end(tmp_path):
    """The issue's case: -1.5708 rad in a metre file, two robots, a request kept at that heading."""
    text = (ROOT / "tests" / "test_units.py").read_text().split('SI_TEXT = """')[1].split('"""')[0]
    path = tmp_path / "ros.yaml"
    path.write_text(text.replace("pose: [-2, -1, 0]", "pose: [-2, -1, -1.5708]"))
    scenario = load_scenario(path)
    team = plan_team(scenario, workers=1)
    assert team.plans.feasible, team.plans.reason
    home = scenario.scene.robots["R1"].pose
    steps = team.plans.robots["R1"].steps
    assert steps[-1].robot == home
    poses = [home, *(step.robot for step in steps)]
    for k, step in enumerate(steps):  # a step that is no drive keeps the heading exactly (a Req first)
        assert step.primitive == "GoTo" or step.robot == poses[k]
    assert check_plan(scenario, team.plans).ok
    team.plans.save(tmp_path / "plan.json")
    written = json.loads((tmp_path / "plan.json").read_text())["robots"]["R1"]["steps"]
    assert written[-1]["robot"][2] == -90.000210459  # a plan file may hold any heading
    loaded = load_plan(tmp_path / "plan.json")
    assert loaded == team.plans
    run = simulate(scenario, loaded)
    assert run.completed and run.contacts_while_moving == 0
    assert abs((run.robots["R1"][0][2] - home[2] + 180) % 360 - 180) <= SimSettings().heading_tolerance


@pytest.mark.parametrize(
    ("units", "heading"), [("mm", ".nan"), ("mm", ".inf"), ("m", "-.inf"), ("m", "1e308")]
)
def test_a_heading_that_is_not_a_finite_number_is_bad_input(tmp_path, units, heading):
    path = _room(tmp_path, heading, units)
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    assert info.value.field.startswith("scene.robots.R1.pose")
    result = runner.invoke(app, ["validate", str(path)])
    assert result.exit_code == 2
    assert "scene.robots.R1.pose" in result.output and "Traceback" not in result.output
