"""The command line: ``cosmop validate``, ``--version`` and the handling of bad input."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from cosmop import __version__
from cosmop.cli import EXIT_INPUT_ERROR, app
from cosmop.io import write_atomic

EXAMPLE_DIR = Path(__file__).resolve().parents[1] / "examples" / "01_warehouse_2x2"
TASKS_FILE = EXAMPLE_DIR / "scenario.yaml"
DFA_FILE = EXAMPLE_DIR / "scenario_dfa.yaml"
LIFELONG_FILE = EXAMPLE_DIR.parent / "13_lifelong" / "scenario.yaml"

runner = CliRunner()


def bad_scenario(tmp_path: Path) -> Path:
    """The example with R1's second step naming a workspace that does not exist."""
    path = tmp_path / "bad.yaml"
    write_atomic(path, TASKS_FILE.read_text().replace("drop O1 at W1", "drop O1 at W9"))
    return path


def test_validate_tasks_example() -> None:
    result = runner.invoke(app, ["validate", str(TASKS_FILE)])
    assert result.exit_code == 0, result.output
    out = result.stdout
    assert "warehouse-2x2" in out
    for fragment in ("robots", "R1", "R2", "objects", "O1", "O2", "workspaces", "W1", "W2", "walls", "6"):
        assert fragment in out
    assert "tasks: 6 steps for 2 robots, 6 events" in out
    assert "valid" in out
    assert result.stderr == ""


def test_validate_dfa_example() -> None:
    result = runner.invoke(app, ["validate", str(DFA_FILE)])
    assert result.exit_code == 0, result.output
    assert "dfa: 16 states, 24 transitions, 16 marked, 6 events" in result.stdout
    # prefix-closed: complete where no event is left
    assert "in q15 (the states with no outgoing event)" in result.stdout


def test_validate_prints_where_the_mission_is_complete(tmp_path: Path) -> None:
    result = runner.invoke(app, ["validate", str(TASKS_FILE)])
    assert "when every robot's task list is done" in result.stdout
    path = tmp_path / "marked.yaml"
    write_atomic(
        path, DFA_FILE.read_text().replace("    transitions:", "    marked: [q15, q3]\n    transitions:", 1)
    )
    result = runner.invoke(app, ["validate", str(path)])
    assert result.exit_code == 0, result.output
    assert "in q15, q3 (the marked states)" in result.stdout


def test_unreachable_completion_is_bad_input(tmp_path: Path) -> None:
    # complete only in q15, and every way into q15 removed: the mission can never be complete
    text = DFA_FILE.read_text().replace("    transitions:", "    marked: [q15]\n    transitions:", 1)
    kept = [line for line in text.splitlines() if not line.strip().startswith("- [") or "q15]" not in line]
    path = tmp_path / "never.yaml"
    write_atomic(path, "\n".join(kept) + "\n")
    result = runner.invoke(app, ["validate", str(path)])
    assert result.exit_code == EXIT_INPUT_ERROR
    assert "mission.dfa" in result.stderr and "can never be complete" in result.stderr
    assert "marked: q15" in result.stderr
    assert "Traceback" not in result.stderr
    # the same file with its transitions into q15 is valid
    write_atomic(path, text)
    assert runner.invoke(app, ["validate", str(path)]).exit_code == 0


def test_validate_point_workspace(tmp_path: Path) -> None:
    path = tmp_path / "s.yaml"
    text = TASKS_FILE.read_text().replace(
        "    W2: {x: [1000, 1500], y: [2000, 2500]}",
        "    W2: {x: [1000, 1500], y: [2000, 2500]}\n    W3: {point: [-2250, 2000]}",
    )
    write_atomic(path, text)
    result = runner.invoke(app, ["validate", str(path)])
    assert result.exit_code == 0, result.output
    assert "W3 (point)" in result.stdout


def test_bad_scenario_is_one_line_on_stderr_with_status_2(tmp_path: Path) -> None:
    path = bad_scenario(tmp_path)
    result = runner.invoke(app, ["validate", str(path)])
    assert result.exit_code == EXIT_INPUT_ERROR == 2
    assert result.stdout == ""
    lines = result.stderr.splitlines()
    assert len(lines) == 1
    assert lines[0].startswith(f"error: {path}: mission.tasks.R1[1]: unknown workspace 'W9'")
    assert "Traceback" not in result.output
    assert result.exception is None or isinstance(result.exception, SystemExit)


def test_markup_like_text_is_printed_verbatim(tmp_path: Path) -> None:
    # field paths contain [brackets]; they must not be swallowed as rich markup
    path = tmp_path / "bad.yaml"
    write_atomic(path, TASKS_FILE.read_text().replace("[pick O2,", '["[bold]pick O2",'))
    result = runner.invoke(app, ["validate", str(path)])
    assert result.exit_code == 2
    assert "mission.tasks.R2[0]: invalid event '[bold]pick O2'" in result.stderr


@pytest.mark.parametrize(
    ("content", "fragment"),
    [
        ("name: [unclosed\n", "invalid YAML"),
        ("", "the file is empty"),
        ("name: x\nname: y\n", "duplicate key 'name'"),
    ],
)
def test_other_bad_files(tmp_path: Path, content: str, fragment: str) -> None:
    path = tmp_path / "s.yaml"
    write_atomic(path, content)
    result = runner.invoke(app, ["validate", str(path)])
    assert result.exit_code == 2
    assert result.stderr.startswith(f"error: {path}: ")
    assert fragment in result.stderr
    assert "Traceback" not in result.output


def test_missing_file(tmp_path: Path) -> None:
    path = tmp_path / "absent.yaml"
    result = runner.invoke(app, ["validate", str(path)])
    assert result.exit_code == 2
    assert result.stderr.strip() == f"error: {path}: file not found"


def test_usage_errors_exit_2() -> None:
    missing_argument = runner.invoke(app, ["validate"])
    assert missing_argument.exit_code == 2
    assert "Missing argument" in missing_argument.output
    unknown_command = runner.invoke(app, ["frobnicate"])
    assert unknown_command.exit_code == 2
    assert "Traceback" not in missing_argument.output + unknown_command.output


@pytest.mark.parametrize(
    ("args", "named"),
    [
        (
            ["plan", str(TASKS_FILE), "-o", "p.json", "--workers", "0"],
            "cosmop plan: Invalid value for '--workers'",
        ),
        (
            ["plan", str(TASKS_FILE), "-o", "p.json", "--budget", "0"],
            "cosmop plan: Invalid value for '--budget'",
        ),
        (
            ["plan", str(TASKS_FILE), "-o", "p.json", "--budget", "inf"],
            "cosmop plan: Invalid value for '--budget': expected a finite number, got inf",
        ),
        (
            ["simulate", str(TASKS_FILE), "--max-time", "-1"],
            "cosmop simulate: Invalid value for '--max-time'",
        ),
        (
            ["simulate", str(TASKS_FILE), "--max-time", "inf"],
            "cosmop simulate: Invalid value for '--max-time': expected a finite number, got inf",
        ),
        (
            ["run", str(LIFELONG_FILE), "--until", "inf"],
            "cosmop run: Invalid value for '--until': expected a finite number, got inf",
        ),
        (["simulate", str(TASKS_FILE), "--seed", "-1"], "cosmop simulate: Invalid value for '--seed'"),
        (["plan", str(TASKS_FILE), "-o", "p.json", "--wrkers", "2"], "cosmop plan: No such option: --wrkers"),
        (["plan", str(TASKS_FILE)], "cosmop plan: Missing option '-o'"),
        (["validate"], "cosmop validate: Missing argument 'SCENARIO'"),
        (["frobnicate"], "cosmop: No such command 'frobnicate'"),
        (["--bogus"], "cosmop: No such option: --bogus"),
    ],
    ids=[
        "workers-0",
        "budget-0",
        "budget-infinite",
        "max-time-negative",
        "max-time-infinite",
        "until-infinite",
        "seed-negative",
        "unknown-option",
        "missing-option",
        "missing-argument",
        "unknown-command",
        "unknown-group-option",
    ],
)
def test_a_usage_error_is_one_line_naming_the_option(args, named) -> None:
    # issue 39: usage errors printed a five-line box; --seed -1 died in numpy
    result = runner.invoke(app, args)
    assert result.exit_code == 2
    assert result.stdout == ""
    assert result.stderr.startswith(f"error: {named}") and result.stderr.count("\n") == 1, result.stderr


def test_version() -> None:
    result = runner.invoke(app, ["--version"])
    assert result.exit_code == 0
    assert result.stdout.strip() == f"cosmop {__version__}"


def test_help_lists_validate() -> None:
    result = runner.invoke(app, ["--help"])
    assert result.exit_code == 0
    assert "validate" in result.stdout


def _run_module(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "NO_COLOR": "1", "PYTHONIOENCODING": "utf-8"}
    return subprocess.run(
        [sys.executable, "-m", "cosmop", *args],
        capture_output=True,
        text=True,
        cwd=cwd,
        env=env,
        timeout=120,
        check=False,
    )


def test_python_dash_m_reports_bad_input_without_traceback(tmp_path: Path) -> None:
    path = bad_scenario(tmp_path)
    proc = _run_module("validate", path.name, cwd=tmp_path)
    assert proc.returncode == 2
    assert proc.stdout == ""
    assert proc.stderr.splitlines() == [
        f"error: bad.yaml: mission.tasks.R1[1]: unknown workspace 'W9' in drop(R1,O1,W9); "
        f"the scene's workspaces are W1, W2 ({_position(path, 'W9')})"
    ]
    assert "Traceback" not in proc.stderr


def test_python_dash_m_validates_the_example(tmp_path: Path) -> None:
    proc = _run_module("validate", str(TASKS_FILE), cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "warehouse-2x2" in proc.stdout
    assert proc.stderr == ""


def _position(path: Path, needle: str) -> str:
    for number, line in enumerate(path.read_text().splitlines(), 1):
        if needle in line:
            return f"line {number}, column {line.index('drop O1') + 1}"
    raise AssertionError(needle)


PEOPLE_FILE = EXAMPLE_DIR.parent / "03_people_2x2" / "scenario.yaml"
WIDE = {"COLUMNS": "200"}  # one line per row of the table, so that phrases are not wrapped apart


def _row(out: str, part: str) -> list[str]:
    """The details of a summary row, one entry per printed line (a row may hold several)."""
    lines = out.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith(f"│ {part} "))
    end = start + 1
    while lines[end].startswith("│") and not lines[end].split("│")[1].strip():  # no part: the same row
        end += 1
    return [line.split("│")[3].strip() for line in lines[start:end]]


def test_validate_shows_people_and_dynamics_in_mm() -> None:
    result = runner.invoke(app, ["validate", str(PEOPLE_FILE)], env=WIDE)
    assert result.exit_code == 0, result.output
    assert "│ people     │     2 │" in result.stdout
    assert _row(result.stdout, "people") == [
        "H1, 400 mm wide, walks at 600 mm/s: a route of 3 points once (stopping 2 s), "
        "then at random in x [-2200, 2200], y [-2200, -400] mm",
        "H2, 400 mm wide, walks at 600 mm/s: from (1800, 1500) at random in x [400, 2200], y [400, 2200] mm",
    ]
    assert _row(result.stdout, "dynamics") == [
        "defaults: top speed 750 mm/s, acceleration 300 mm/s^2, braking 500 mm/s^2, turning 100°/s, "
        "control cycle 0.1 s"
    ]


def test_validate_says_no_people() -> None:
    result = runner.invoke(app, ["validate", str(TASKS_FILE)], env=WIDE)
    assert result.exit_code == 0, result.output
    assert "│ people     │     0 │ no people" in result.stdout
    assert _row(result.stdout, "dynamics")[0].startswith("defaults: top speed 750 mm/s")


def test_validate_shows_a_metres_file_in_metres(tmp_path: Path) -> None:
    # the people example in metres, with limits set for the scene and for R1
    text = PEOPLE_FILE.read_text()
    text = text[text.index("name:") :].replace("name: warehouse-2x2-people", "name: si\nunits: m")
    text = text.replace(
        "R1: {size: 400, pose: [-2000, -1000, 0]}",
        "R1: {size: 400, pose: [-2000, -1000, 0], dynamics: {max_speed: 500}}",
    )
    text = text.replace("  humans:", "  dynamics: {braking: 800, turn_rate: 1.5}\n  humans:")
    text = text.replace("      loop: false\n", "")  # H1 walks its route over and over
    numbers = re.compile(r"(?<![\w.])-?\d{3,5}(?![\w.])")
    text = numbers.sub(lambda m: repr(int(m.group(0)) / 1000), text)  # mm -> m; rad/s stay
    path = tmp_path / "si.yaml"
    write_atomic(path, text)
    result = runner.invoke(app, ["validate", str(path)], env=WIDE)
    assert result.exit_code == 0, result.output
    assert _row(result.stdout, "people") == [
        "H1, 0.4 m wide, walks at 0.6 m/s: a route of 3 points over and over "
        "(stopping 2 s; its walk area is never used)",
        "H2, 0.4 m wide, walks at 0.6 m/s: from (1.8, 1.5) at random in x [0.4, 2.2], y [0.4, 2.2] m",
    ]
    assert _row(result.stdout, "dynamics") == [
        "R1: top speed 0.5 m/s, braking 0.8 m/s^2, turning 1.5 rad/s (set in the file); "
        "defaults: acceleration 0.3 m/s^2, control cycle 0.1 s",
        "R2: braking 0.8 m/s^2, turning 1.5 rad/s (set in the file); "
        "defaults: top speed 0.75 m/s, acceleration 0.3 m/s^2, control cycle 0.1 s",
    ]
    assert "mm" not in result.stdout[: result.stdout.index(str(path))]  # the table, not the file's name
