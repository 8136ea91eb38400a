"""Numbers a scenario may hold: ranges the loader refuses outside (exit 2 naming the field and
the range), and plausible ones outside which it warns (a record on the loaded scenario, one line
on stderr from the command line, the exit status unchanged) -- in the file's own units, saying
when a slip of units is the likely mistake."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner

from cosmop.cli import app
from cosmop.errors import ScenarioError
from cosmop.scenario import load_scenario, parse_scenario
from cosmop.scenario.plausible import QUANTITIES

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "01_warehouse_2x2" / "scenario.yaml"
runner = CliRunner()

SI_TEXT = """
name: si
units: m
scene:
  obstacles: [[[-2.5, -2.5], [2.5, -2.5]], [[0, 0], [0, 2.5]]]
  robots:
    R1: {size: 0.4, pose: [-2, -1, 0]}
    R2: {size: 0.4, pose: [-2, -2, 0]}
  objects:
    O1: {size: 0.1, position: [2, -1]}
  workspaces:
    W1: {x: [-1.5, -1], y: [2, 2.5]}
mission:
  tasks:
    R1: [pick O1, drop O1 at W1, return]
"""


def _si(**changes: str) -> str:
    text = SI_TEXT
    for old, new in changes.items():
        assert old.replace("_", " ") in text or old in text
        text = text.replace(old, new)
    return text


def _load(tmp_path: Path, text: str):
    path = tmp_path / "s.yaml"
    path.write_text(text)
    return load_scenario(path)


def _refused(tmp_path: Path, text: str) -> ScenarioError:
    with pytest.raises(ScenarioError) as info:
        _load(tmp_path, text)
    return info.value


# -- warnings ----------------------------------------------------------------------------------


def test_millimetres_in_a_metres_file_warn_once_per_quantity_naming_the_field(tmp_path):
    text = EXAMPLE.read_text().replace("name: warehouse-2x2", "name: warehouse-2x2\nunits: m")
    scenario = _load(tmp_path, text)  # loads: a 400 m robot is not impossible, only implausible
    robots, objects = scenario.warnings
    assert (
        robots.field == "scene.robots.R1.size"
        and robots.line
        == text.splitlines().index("    R1: {size: 400, pose: [-2000, -1000, 0]}        # x, y, heading") + 1
    )
    assert robots.problem == (
        "a robot's side of 400 m is implausible (expected between 0.05 and 5 m); it looks like "
        "millimetres in a metres file (1 more such value in the file)"
    )
    assert objects.field == "scene.objects.O1.size" and "an object's side of 100 m" in objects.problem


def test_metres_in_a_millimetre_file_warn_with_the_likely_slip(tmp_path):
    text = EXAMPLE.read_text().replace("R2: {size: 400,", "R2: {size: 0.4,")
    (warning,) = _load(tmp_path, text).warnings
    assert warning.field == "scene.robots.R2.size"
    assert warning.problem == (
        "a robot's side of 0.4 mm is implausible (expected between 50 and 5000 mm); it looks like "
        "metres in a millimetre file (add units: m, or write millimetres)"
    )


def test_a_position_beyond_ten_kilometres_and_a_heading_in_degrees_in_a_radians_file_warn(tmp_path):
    text = _si(**{"pose: [-2, -1, 0]": "pose: [-2, -1, 90]", "position: [2, -1]": "position: [20000, -1]"})
    path = tmp_path / "s.yaml"
    path.write_text(text)
    heading, coordinate = (str(w) for w in load_scenario(path).warnings)  # in the file's order
    assert coordinate.startswith(f"{path}: scene.objects.O1.position[0]: a coordinate of 20000 m")
    assert "(expected at most 10000 m either way); it looks like millimetres in a metres file" in coordinate
    assert heading.startswith(f"{path}: scene.robots.R1.pose[2]: a heading of 90 radians is implausible")
    assert "it looks like degrees in a file in radians (units: m)" in heading


def test_the_examples_load_without_warnings():
    for path in sorted((ROOT / "examples").glob("*/*.yaml")):
        assert load_scenario(path).warnings == (), path


def test_the_library_is_silent_and_the_command_line_prints_each_warning_on_one_line(tmp_path, capsys):
    path = tmp_path / "s.yaml"
    path.write_text(_si(**{"  robots:": "  dynamics: {max_speed: 20}\n  robots:"}))
    assert len(load_scenario(path).warnings) == 1
    assert capsys.readouterr() == ("", "")
    result = runner.invoke(app, ["validate", str(path)])
    assert result.exit_code == 0  # a warning changes nothing else
    (line,) = result.stderr.splitlines()
    assert line == (
        f"warning: {path}: scene.dynamics.max_speed: a top speed of 20 m/s is implausible (expected "
        "between 0.02 and 10 m/s); it looks like millimetres in a metres file (line 6, column 14)"
    )
    assert result.stdout.rstrip().endswith("valid")  # rich may wrap the long path before it


def test_plausible_ranges_lie_within_the_valid_ones():
    for quantity in QUANTITIES:
        lo, hi = quantity.plausible
        assert lo <= hi
        if quantity.valid is not None:
            assert quantity.valid[0] <= lo and hi <= quantity.valid[1], quantity.what


# -- ranges ------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("dynamics", "field", "expected"),
    [
        # a control cycle of a nanosecond ran the simulator until it was killed
        (
            {"cycle": 1e-9},
            "scene.dynamics.cycle",
            "expected a control cycle between 0.001 and 1 s, got 1e-09",
        ),
        ({"cycle": 2}, "scene.dynamics.cycle", "between 0.001 and 1 s, got 2"),
        # a top speed of 1e-300 mm/s printed a finishing time of 300 digits
        (
            {"max_speed": 1e-300},
            "scene.dynamics.max_speed",
            "a top speed between 1 and 100000 mm/s, got 1e-300",
        ),
        ({"acceleration": 1e300}, "scene.dynamics.acceleration", "between 1 and 100000 mm/s^2, got 1e+300"),
        ({"braking": 0.5}, "scene.dynamics.braking", "a braking deceleration between 1 and 100000 mm/s^2"),
        ({"turn_rate": 1e4}, "scene.dynamics.turn_rate", "a turning rate between 1 and 3600 degrees/s"),
    ],
)
def test_dynamics_out_of_range_are_refused_naming_the_field_and_the_range(dynamics, field, expected):
    data = yaml.safe_load(EXAMPLE.read_text())
    data["scene"]["dynamics"] = dynamics
    with pytest.raises(ScenarioError) as info:
        parse_scenario(data)
    assert info.value.field == field
    assert expected in info.value.expected


def test_a_robots_own_dynamics_and_a_persons_speed_are_ranged_at_their_own_field():
    data = yaml.safe_load(EXAMPLE.read_text())
    data["scene"]["robots"]["R2"]["dynamics"] = {"max_speed": 0.75}
    with pytest.raises(ScenarioError) as info:
        parse_scenario(data)
    assert info.value.field == "scene.robots.R2.dynamics.max_speed"
    assert info.value.expected == (
        "expected a top speed between 1 and 100000 mm/s, got 0.75; it looks like metres in a millimetre "
        "file (add units: m, or write millimetres)"
    )
    data = yaml.safe_load(EXAMPLE.read_text())
    data["scene"]["humans"] = {"H1": {"size": 400, "speed": 1e-300, "path": [[0, -1500], [0, -2200]]}}
    with pytest.raises(ScenarioError) as info:
        parse_scenario(data)
    assert info.value.field == "scene.humans.H1.speed" and "a walking speed between 1 and 100000" in str(
        info.value
    )


def test_ranges_in_a_metres_file_speak_metres_and_refuse_before_converting(tmp_path):
    err = _refused(tmp_path, _si(**{"  robots:": "  dynamics: {max_speed: 750}\n  robots:"}))
    assert err.field == "scene.dynamics.max_speed"
    assert err.expected == (
        "expected a top speed between 0.001 and 100 m/s, got 750; it looks like millimetres in a metres file"
    )
    err = _refused(
        tmp_path, _si(**{"  robots:": "  dynamics: {turn_rate: 1e308}\n  robots:"})
    )  # inf in degrees
    assert err.field == "scene.dynamics.turn_rate" and "between 0.0174533 and 62.8319 rad/s" in err.expected
    err = _refused(tmp_path, _si(**{"pose: [-2, -1, 0]": "pose: [-2, -1, 1e308]"}))
    assert (
        err.field == "scene.robots.R1.pose[2]"
        and "expected a finite heading (radians), got 1e+308" in str(err)
    )
    err = _refused(tmp_path, _si(**{"pose: [-2, -1, 0]": "pose: [1e308, -1, 0]"}))
    assert err.field == "scene.robots.R1.pose[0]"
    assert err.expected == "expected a length of at most 1000000 m, got 1e+308"  # as written, in metres
