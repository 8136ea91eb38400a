"""The plan and trace files' readers: pydantic structures whose first error is one line naming the
file, the field, what was expected and what was found (and, for JSON text, where)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from cosmop.cli import app
from cosmop.planning.plan_file import PlanError, load_plan, read_plan
from cosmop.traces import TRACE_FORMAT, TraceError, check_trace, load_trace

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "01_warehouse_2x2" / "scenario.yaml"
PLAN = Path(__file__).resolve().parent / "data" / "plan_2x2.json"


def _plan_text(tmp_path: Path, old: str, new: str) -> Path:
    """The test plan file with the first `old` replaced by `new`."""
    text = PLAN.read_text(encoding="utf-8")
    assert old in text
    path = tmp_path / "plan.json"
    path.write_text(text.replace(old, new, 1), encoding="utf-8")
    return path


def _one_line(err: Exception) -> str:
    (line,) = str(err).splitlines()
    return line


# -- plan files ---------------------------------------------------------------------------------


def test_a_wrong_type_deep_in_a_step_is_one_line(tmp_path: Path) -> None:
    path = _plan_text(
        tmp_path, '"position": [2000, -1000], "carried": true', '"position": [2000, "-1000"], "carried": true'
    )
    with pytest.raises(PlanError) as info:
        load_plan(path)
    assert _one_line(info.value) == (
        f"{path}: robots.R1.steps[3].objects.O1.position[1]: expected a finite number (mm), got '-1000' "
        "(line 59, column 39)"
    )


def test_a_missing_key_is_one_line(tmp_path: Path) -> None:
    path = _plan_text(tmp_path, '"horizon": 9,\n      ', "")
    with pytest.raises(PlanError) as info:
        load_plan(path)
    assert _one_line(info.value) == (  # where the plan that lacks it starts
        f"{path}: robots.R1.horizon: missing required key 'horizon': expected the number of steps, an "
        "integer >= 0 (line 7, column 11)"
    )


def test_an_unknown_format_version_is_one_line(tmp_path: Path) -> None:
    path = _plan_text(tmp_path, '"cosmop.plan/1"', '"cosmop.plan/2"')
    with pytest.raises(PlanError) as info:
        load_plan(path)
    assert _one_line(info.value) == (
        f"{path}: format: expected 'cosmop.plan/1', the plan file format, got 'cosmop.plan/2' "
        "(line 2, column 13)"
    )


def test_an_unknown_key_lists_the_keys_expected(tmp_path: Path) -> None:
    path = _plan_text(tmp_path, '"horizon": ', '"horizon_": ')
    with pytest.raises(PlanError) as info:
        load_plan(path)
    assert _one_line(info.value) == (
        f"{path}: robots.R1.horizon_: unknown key 'horizon_'; expected one of: mission, horizon, steps "
        "(line 16, column 19)"
    )


def test_the_first_error_in_the_file_is_named(tmp_path: Path) -> None:
    data = json.loads(PLAN.read_text(encoding="utf-8"))
    steps = data["robots"]["R1"]["steps"]
    steps[4]["robot"][0] = "x"
    steps[2]["objects"]["O1"]["carried"] = 1
    with pytest.raises(PlanError) as info:
        read_plan(data, "p.json")  # no text: no line
    assert _one_line(info.value) == (
        "p.json: robots.R1.steps[2].objects.O1.carried: expected true or false (whether this robot carries "
        "it), got 1"
    )


# -- trace files --------------------------------------------------------------------------------


def _trace(frames: list[dict[str, Any]], **more: Any) -> dict[str, Any]:
    return {"format": TRACE_FORMAT, "scenario": "s", "dt": 0.1, "frames": frames, "messages": [], **more}


def _frame(t: float, robots: dict[str, Any]) -> dict[str, Any]:
    return {"t": t, "robots": robots, "humans": {}, "objects": {"O1": [0, 0]}}


GOOD = {"pose": [0, 0, 90], "v": 0.0, "w": 0.0, "carrying": None, "primitive": "GoTo", "waiting": False}


def _write(tmp_path: Path, data: dict[str, Any]) -> Path:
    path = tmp_path / "t.json"
    path.write_text(json.dumps(data, separators=(",", ":")), encoding="utf-8")
    return path


def test_a_bad_trace_frame_is_one_line(tmp_path: Path) -> None:
    path = _write(
        tmp_path, _trace([_frame(0.0, {"R1": GOOD}), _frame(0.1, {"R1": {**GOOD, "pose": [1, 2]}})])
    )
    with pytest.raises(TraceError) as info:
        load_trace(path)
    assert _one_line(info.value) == (
        f"{path}: frames[1].robots.R1.pose: expected [x, y, heading] (mm, mm, degrees), got [1, 2] "
        "(line 1, column 240)"
    )


def test_a_frame_without_a_time_is_one_line(tmp_path: Path) -> None:
    frame = _frame(0.1, {"R1": GOOD})
    del frame["t"]
    path = _write(tmp_path, _trace([_frame(0.0, {"R1": GOOD}), frame]))
    with pytest.raises(TraceError) as info:
        load_trace(path)
    assert _one_line(info.value) == (
        f"{path}: frames[1].t: missing required key 't': expected the frame's time t (s), a finite number "
        "(line 1, column 208)"
    )


def test_an_unknown_trace_format_is_one_line() -> None:
    with pytest.raises(TraceError) as info:
        check_trace({**_trace([_frame(0.0, {"R1": GOOD})]), "format": "cosmop.trace/2"}, "t.json")
    assert _one_line(info.value) == (
        "t.json: format: expected 'cosmop.trace/1', the trace file format, got 'cosmop.trace/2'"
    )


def test_keys_a_trace_does_not_know_pass_through(tmp_path: Path) -> None:
    data = _trace(
        [_frame(0.0, {"R1": {**GOOD, "battery": 0.9}})],
        messages=[{"t": 0, "from": "R1", "to": "R2", "why": "x"}],
    )
    data["frames"][0]["lights"] = "on"
    trace = load_trace(_write(tmp_path, data))
    assert trace.messages == ({"t": 0, "from": "R1", "to": "R2", "why": "x"},)


# -- the command line ---------------------------------------------------------------------------


def test_the_command_line_prints_one_line_and_exits_2(tmp_path: Path) -> None:
    path = _plan_text(tmp_path, '"primitive": "GoTo"', '"primitive": "Fly"')
    result = CliRunner().invoke(app, ["check", str(EXAMPLE), str(path)])
    assert result.exit_code == 2
    assert result.stderr.splitlines() == [
        f"error: {path}: robots.R1.steps[2].primitive: expected one of GoTo, PickUp, DropOff, Req, Res, "
        "got 'Fly' (line 42, column 24)"
    ]
    trace = _write(tmp_path, _trace([_frame(0.0, {"R1": {**GOOD, "waiting": "no"}})]))
    result = CliRunner().invoke(
        app, ["view", str(EXAMPLE), "-o", str(tmp_path / "v.html"), "--trace", str(trace)]
    )
    assert result.exit_code == 2
    assert result.stderr.splitlines() == [
        f"error: {trace}: frames[0].robots.R1.waiting: expected true or false, got 'no' (line 1, column 164)"
    ]
    assert not (tmp_path / "v.html").exists()
