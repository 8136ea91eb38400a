"""``cosmop plan``: plan file + PNG, exit 0 / 1 (file still written) / 2 (nothing written)."""

from __future__ import annotations

import json
from pathlib import Path

import yaml
from typer.testing import CliRunner

from cosmop.cli import app
from cosmop.planning.plan_file import load_plan
from cosmop.scenario import load_scenario
from cosmop.team.plan_set_checker import check_plan

ROOT = Path(__file__).resolve().parents[1]
TASKS_FILE = ROOT / "examples" / "01_warehouse_2x2" / "scenario.yaml"
runner = CliRunner()


def test_plan_writes_a_checked_plan_and_a_png(tmp_path):
    out, png = tmp_path / "plan.json", tmp_path / "plan.png"
    result = runner.invoke(
        app, ["plan", str(TASKS_FILE), "-o", str(out), "--png", str(png)], env={"COLUMNS": "200"}
    )
    assert result.exit_code == 0, result.output
    plans = load_plan(out)
    # the paper's Example 1 after coordination: R1 7 steps with Req(O2), R2 7 with Res(O2),
    # then the messages that keep the two robots apart
    assert plans.feasible and plans.messages
    assert [(c.object, c.requester, c.responder) for c in plans.coordination] == [("O2", "R1", "R2")]
    assert plans.robots["R1"].mission[0].name == "away(O2,R1,R2)"
    assert [e.name for e in plans.robots["R2"].mission[:2]] == ["pick(R2,O2)", "away(O2,R1,R2)"]
    rows = {line.split("│")[1].strip(): line for line in result.stdout.splitlines() if line.count("│") > 5}
    assert "│ 7 " in rows["R1"] and "│ 7 " in rows["R2"]  # the shortest plans have 7 steps
    assert "Res(O2)" in [s.label for s in plans.robots["R2"].steps]
    assert check_plan(load_scenario(TASKS_FILE), plans).ok
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "O2 to R1" in result.stdout and "deadlock-free" in result.stdout and "all valid" in result.stdout


def test_infeasible_robot_exits_1_and_still_writes_the_file(tmp_path, monkeypatch):
    import cosmop.viz

    drawn, draw = [], cosmop.viz.save_plan_png
    monkeypatch.setattr(cosmop.viz, "save_plan_png", lambda *a, **k: (drawn.append(k), draw(*a, **k)))
    data = yaml.safe_load(TASKS_FILE.read_text())
    # box R2 in: four walls tight around its square
    data["scene"]["obstacles"] += [
        [[-2300, -2300], [-1700, -2300]],
        [[-1700, -2300], [-1700, -1700]],
        [[-1700, -1700], [-2300, -1700]],
        [[-2300, -1700], [-2300, -2300]],
    ]
    scenario = tmp_path / "boxed.yaml"
    scenario.write_text(yaml.safe_dump(data))
    out, png = tmp_path / "plan.json", tmp_path / "plan.png"
    result = runner.invoke(
        app, ["plan", str(scenario), "-o", str(out), "--max-horizon", "8", "--png", str(png), "--full-map"]
    )
    assert result.exit_code == 1, result.output
    assert drawn == [{"full_map": True}] and png.read_bytes()[:4] == b"\x89PNG"  # the whole map, asked
    written = json.loads(out.read_text())
    assert written["feasible"] is False
    assert "R2" in written["reason"] and "pick(R2,O2)" in written["reason"] and "wall" in written["reason"]
    assert set(written["robots"]) == {"R1"}


def test_bad_input_exits_2_and_writes_nothing(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text(TASKS_FILE.read_text().replace("size: 400", "size: -1", 1))
    out = tmp_path / "plan.json"
    result = runner.invoke(app, ["plan", str(bad), "-o", str(out)])
    assert result.exit_code == 2
    assert "size" in result.stderr and "Traceback" not in result.output
    assert not out.exists()


def test_png_without_matplotlib_is_a_clear_error(tmp_path, monkeypatch):
    import cosmop.viz

    monkeypatch.setattr(cosmop.viz, "available", lambda: False)
    out = tmp_path / "plan.json"
    result = runner.invoke(app, ["plan", str(TASKS_FILE), "-o", str(out), "--png", str(tmp_path / "p.png")])
    assert result.exit_code == 2
    assert "matplotlib" in result.stderr and "Traceback" not in result.output
    assert not out.exists()
