"""The command line: ``cosmop check SCENARIO PLAN``."""

from __future__ import annotations

import json
from pathlib import Path

from typer.testing import CliRunner

from cosmop.cli import EXIT_INPUT_ERROR, app
from cosmop.io import write_atomic
from cosmop.planning import Coordination, PlanSet, plan_from_actions
from cosmop.scenario import load_scenario
from cosmop.team.safe_plans import make_team_safe

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "01_warehouse_2x2" / "scenario.yaml"
SCENE = load_scenario(EXAMPLE).scene

runner = CliRunner()

from handmade_plans import R1_ACTIONS, R1_MISSION  # noqa: E402
from handmade_plans import R2_RES_ACTIONS as R2_ACTIONS  # noqa: E402
from handmade_plans import R2_RES_MISSION as R2_MISSION  # noqa: E402


def write_plan(tmp_path: Path, r1_actions=R1_ACTIONS, name: str = "plan.json", safe: bool = True) -> Path:
    """The hand-made plans, made team-safe (their conflicts ordered by messages) unless not `safe`."""
    robots = {
        "R1": plan_from_actions(SCENE, "R1", R1_MISSION, r1_actions),
        "R2": plan_from_actions(SCENE, "R2", R2_MISSION, R2_ACTIONS),
    }
    plans = PlanSet("warehouse-2x2", True, robots, (Coordination("O2", "R1", "R2"),))
    if safe:
        ordered = make_team_safe(SCENE, robots)
        plans = PlanSet("warehouse-2x2", True, ordered.plans, plans.coordination, messages=ordered.messages)
    path = tmp_path / name
    plans.save(path)
    return path


def steps_in(path: Path) -> int:
    return sum(len(p["steps"]) for p in json.loads(path.read_text())["robots"].values())


def crossing_plan(tmp_path: Path) -> Path:
    """R1's waypoint below the gap moved under the inner wall: step 5 crosses it."""
    actions = list(R1_ACTIONS)
    actions[3] = ("GoTo", (-900, -200, 0))
    return write_plan(tmp_path, actions, "crossing.json", safe=False)


def test_valid_plan_exits_0(tmp_path: Path) -> None:
    path = write_plan(tmp_path)
    result = runner.invoke(app, ["check", str(EXAMPLE), str(path)])
    assert result.exit_code == 0, result.output
    assert result.stdout.strip() == f"plan valid: {steps_in(path)} steps checked"
    assert result.stderr == ""


def test_valid_plan_json(tmp_path: Path) -> None:
    path = write_plan(tmp_path)
    result = runner.invoke(app, ["check", str(EXAMPLE), str(path), "--json"])
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout) == {"ok": True, "checked_steps": steps_in(path), "violations": []}


def test_plans_that_can_meet_exit_1(tmp_path: Path) -> None:
    # each plan alone is sound; together R1 drives into R2 standing at O2: a conflict
    path = write_plan(tmp_path, safe=False)
    result = runner.invoke(app, ["check", str(EXAMPLE), str(path), "--json"])
    assert result.exit_code == 1
    rules = {v["rule"] for v in json.loads(result.stdout)["violations"]}
    assert rules == {"conflict"}


def test_violations_exit_1_with_a_table(tmp_path: Path) -> None:
    result = runner.invoke(app, ["check", str(EXAMPLE), str(crossing_plan(tmp_path))], env={"COLUMNS": "250"})
    assert result.exit_code == 1, result.output
    out = result.stdout
    for fragment in ("violations of crossing.json", "robot", "instant", "rule", "problem", "R1", "wall"):
        assert fragment in out
    assert "GoTo from (-900, -200) to (-1500, 2050) crosses wall" in out
    assert out.strip().splitlines()[-1] == "plan invalid: 1 violation in 14 steps checked"


def test_violations_json(tmp_path: Path) -> None:
    result = runner.invoke(app, ["check", str(EXAMPLE), str(crossing_plan(tmp_path)), "--json"])
    assert result.exit_code == 1
    report = json.loads(result.stdout)
    assert report["ok"] is False
    assert report["checked_steps"] == 14
    (violation,) = report["violations"]
    assert violation["robot"] == "R1"
    assert violation["instant"] == 5
    assert violation["rule"] == "wall"
    assert violation["message"].startswith("R1 at instant 5: GoTo from (-900, -200) to (-1500, 2050)")


def test_bad_plan_file_exits_2_naming_file_and_field(tmp_path: Path) -> None:
    path = write_plan(tmp_path)
    data = json.loads(path.read_text())
    data["robots"]["R1"]["steps"][3]["primitive"] = "Teleport"
    write_atomic(path, json.dumps(data))
    result = runner.invoke(app, ["check", str(EXAMPLE), str(path)])
    assert result.exit_code == EXIT_INPUT_ERROR == 2
    assert result.stdout == ""
    lines = result.stderr.splitlines()
    assert len(lines) == 1
    assert lines[0].startswith(
        f"error: {path}: robots.R1.steps[3].primitive: expected one of GoTo, PickUp, DropOff, Req, Res, "
        "got 'Teleport'"
    )
    assert "Traceback" not in result.output


def test_horizon_mismatch_exits_2(tmp_path: Path) -> None:
    path = write_plan(tmp_path)
    data = json.loads(path.read_text())
    data["robots"]["R2"]["horizon"] = 6
    steps = len(data["robots"]["R2"]["steps"])
    write_atomic(path, json.dumps(data))
    result = runner.invoke(app, ["check", str(EXAMPLE), str(path)])
    assert result.exit_code == 2
    assert f"error: {path}: robots.R2.horizon: expected the number of steps, {steps}, got 6" in result.stderr


def test_wrong_format_exits_2(tmp_path: Path) -> None:
    path = tmp_path / "plan.json"
    write_atomic(path, '{"format": "cosmop.plan/0"}')
    result = runner.invoke(app, ["check", str(EXAMPLE), str(path)])
    assert result.exit_code == 2
    assert result.stderr.strip() == (
        f"error: {path}: format: expected 'cosmop.plan/1', the plan file format, got 'cosmop.plan/0' "
        "(line 1, column 12)"
    )


def test_invalid_json_exits_2(tmp_path: Path) -> None:
    path = tmp_path / "plan.json"
    write_atomic(path, "{\n  oops\n}")
    result = runner.invoke(app, ["check", str(EXAMPLE), str(path)])
    assert result.exit_code == 2
    assert result.stderr.startswith(f"error: {path}: invalid JSON: ")
    assert "(line 2, column 3)" in result.stderr


def test_missing_plan_file_exits_2(tmp_path: Path) -> None:
    path = tmp_path / "absent.json"
    result = runner.invoke(app, ["check", str(EXAMPLE), str(path)])
    assert result.exit_code == 2
    assert result.stderr.strip() == f"error: {path}: file not found"


def test_bad_scenario_exits_2(tmp_path: Path) -> None:
    scenario = tmp_path / "bad.yaml"
    write_atomic(scenario, EXAMPLE.read_text().replace("size: 400", "size: -400", 1))
    result = runner.invoke(app, ["check", str(scenario), str(write_plan(tmp_path))])
    assert result.exit_code == 2
    assert result.stderr.startswith(f"error: {scenario}: scene.robots.R1.size")


def test_infeasible_plan_file_exits_1(tmp_path: Path) -> None:
    path = tmp_path / "plan.json"
    PlanSet("warehouse-2x2", False, {}, reason="O1 is out of reach").save(path)
    result = runner.invoke(app, ["check", str(EXAMPLE), str(path)], env={"COLUMNS": "250"})
    assert result.exit_code == 1, result.output
    assert "the plan file marks the scenario infeasible: O1 is out of reach" in result.stdout
    assert "plan invalid: 1 violation" in result.stdout


def test_help_lists_check() -> None:
    result = runner.invoke(app, ["--help"])
    assert result.exit_code == 0
    assert "check" in result.stdout
    usage = runner.invoke(app, ["check", "--help"])
    assert usage.exit_code == 0
    assert "SCENARIO" in usage.stdout and "PLAN" in usage.stdout
