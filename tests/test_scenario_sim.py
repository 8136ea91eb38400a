"""Scenario files for the simulator: robot dynamics (unicycle limits) and humans (people).

Every error test checks that the message names the file, the field path and what was expected.
"""

from __future__ import annotations

import copy
import dataclasses
import os
import pickle
from collections.abc import Callable
from pathlib import Path
from types import MappingProxyType
from typing import Any

import pytest
import yaml
from typer.testing import CliRunner

from cosmop.cli import EXIT_INPUT_ERROR, app
from cosmop.errors import ScenarioError
from cosmop.io import write_atomic
from cosmop.scenario import load_scenario, parse_scenario
from cosmop.scene import Dynamics, Human, Robot, Scene, Wall

BASE: dict[str, Any] = {
    "name": "corridor",
    "scene": {
        "obstacles": [[[-2500, -2500], [2500, -2500]], [[2500, -2500], [2500, 2500]]],
        "robots": {
            "R1": {"size": 400, "pose": [-2000, -1000, 0]},
            "R2": {"size": 400, "pose": [-2000, -2000, 0]},
        },
        "objects": {"O1": {"size": 100, "position": [2000, -1000]}},
        "workspaces": {"W1": {"x": [-1500, -1000], "y": [2000, 2500]}},
    },
    "mission": {"tasks": {"R1": ["pick O1", "drop O1 at W1", "return"], "R2": ["return"]}},
}

# The format as documented: scene-wide dynamics, a per-robot override and two humans.
SIM_YAML = """\
name: corridor-with-people
scene:
  obstacles:
    - [[-2500, -2500], [2500, -2500]]
  dynamics: {max_speed: 600, braking: 400}
  robots:
    R1: {size: 400, pose: [-2000, -1000, 0], dynamics: {max_speed: 500, turn_rate: 90}}
    R2: {size: 400, pose: [-2000, -2000, 0]}
  objects:
    O1: {size: 100, position: [2000, -1000]}
  workspaces:
    W1: {x: [-1500, -1000], y: [2000, 2500]}
  humans:
    H2: {size: 350, speed: 600, path: [[0, -1500]], walk: {x: [-2000, 2000], y: [-2000, -500]}}
    H1: {size: 400, speed: 500, path: [[0, -1500], [0, -2200, 5], [100.5, -2200]], loop: true}
    H3: {size: 300, speed: 800, path: [[1000, 0, 2], [1000, 1000]], loop: false}
mission:
  tasks:
    R1: [pick O1, drop O1 at W1, return]
    R2: [return]
"""

PERSON = {"size": 400, "speed": 600, "path": [[0, -1500], [0, -2200, 5]]}


def mutated(change: Callable[[dict[str, Any]], object]) -> dict[str, Any]:
    data = copy.deepcopy(BASE)
    change(data)
    return data


def with_human(**fields: Any) -> Callable[[dict[str, Any]], object]:
    """Add human H1: `PERSON` with `fields` changed (a value of ``...`` drops the key)."""

    def change(data: dict[str, Any]) -> None:
        person = {**copy.deepcopy(PERSON), **fields}
        data["scene"]["humans"] = {"H1": {k: v for k, v in person.items() if v is not ...}}

    return change


def scene_dynamics(value: Any) -> Callable[[dict[str, Any]], object]:
    return lambda data: data["scene"].__setitem__("dynamics", value)


def robot_dynamics(robot: str, value: Any) -> Callable[[dict[str, Any]], object]:
    return lambda data: data["scene"]["robots"][robot].__setitem__("dynamics", value)


def write(path: Path, content: str | dict[str, Any]) -> Path:
    text = content if isinstance(content, str) else yaml.safe_dump(content, sort_keys=False)
    write_atomic(path, text)
    return path


def load_error(path: Path, content: str | dict[str, Any]) -> ScenarioError:
    write(path, content)
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    return info.value


def assert_error(err: ScenarioError, file: Path | None, field: str, *fragments: str) -> None:
    """The error names the file, the field and (in these words) what was expected."""
    assert err.file == (None if file is None else os.fspath(file))
    assert err.field == field
    message = str(err)
    assert message.startswith(": ".join(str(part) for part in (err.file, field) if part is not None))
    for fragment in fragments:
        assert fragment in err.expected, (fragment, err.expected)
    assert "\n" not in message


def line_of(text: str, needle: str) -> int:
    return next(number for number, row in enumerate(text.splitlines(), 1) if needle in row)


# -- dynamics ----------------------------------------------------------------------------------


def test_dynamics_defaults() -> None:
    d = Dynamics()
    assert (d.max_speed, d.acceleration, d.braking, d.turn_rate, d.cycle) == (750.0, 300.0, 500.0, 100.0, 0.1)
    assert d.max_speed < 1200.0  # within the P3-DX's 1.2 m/s
    assert Robot("R1", 400.0, (0.0, 0.0, 0.0)).dynamics == d  # positional construction still works


def test_defaults_when_absent() -> None:
    scene = parse_scenario(BASE).scene
    assert scene.dynamics == Dynamics()
    assert all(robot.dynamics == Dynamics() for robot in scene.robots.values())
    assert isinstance(scene.humans, MappingProxyType)
    assert dict(scene.humans) == {}


def test_null_humans_and_dynamics_mean_none(tmp_path: Path) -> None:
    text = yaml.safe_dump(BASE, sort_keys=False).replace("scene:\n", "scene:\n  humans:\n  dynamics:\n", 1)
    scene = load_scenario(write(tmp_path / "s.yaml", text)).scene
    assert dict(scene.humans) == {}
    assert scene.dynamics == Dynamics()


def test_scene_default_and_robot_override_field_by_field(tmp_path: Path) -> None:
    scene = load_scenario(write(tmp_path / "s.yaml", SIM_YAML)).scene
    assert scene.dynamics == Dynamics(max_speed=600, braking=400)
    assert scene.robots["R2"].dynamics == Dynamics(max_speed=600, braking=400)
    assert scene.robots["R1"].dynamics == Dynamics(
        max_speed=500, acceleration=300, braking=400, turn_rate=90, cycle=0.1
    )
    assert isinstance(scene.robots["R1"].dynamics.max_speed, float)


def test_robot_override_without_scene_default() -> None:
    scene = parse_scenario(mutated(robot_dynamics("R2", {"acceleration": 250, "cycle": 0.1}))).scene
    assert scene.robots["R2"].dynamics == Dynamics(acceleration=250)
    assert scene.robots["R1"].dynamics == Dynamics()
    assert scene.dynamics == Dynamics()


def test_scene_cycle_applies_to_every_robot() -> None:
    scene = parse_scenario(mutated(scene_dynamics({"cycle": 0.05, "turn_rate": 45}))).scene
    assert {robot.dynamics.cycle for robot in scene.robots.values()} == {0.05}
    assert {robot.dynamics.turn_rate for robot in scene.robots.values()} == {45.0}


def test_robots_may_all_override_the_cycle_alike() -> None:
    def change(data: dict[str, Any]) -> None:
        for robot in data["scene"]["robots"].values():
            robot["dynamics"] = {"cycle": 0.25}

    scene = parse_scenario(mutated(change)).scene
    assert [robot.dynamics.cycle for robot in scene.robots.values()] == [0.25, 0.25]
    assert scene.dynamics.cycle == 0.1  # the scene-wide default as given (here: not given)


def test_dynamics_rejects_nonpositive_values_in_code() -> None:
    for name in ("max_speed", "acceleration", "braking", "turn_rate", "cycle"):
        for bad in (0, -1.0, float("inf"), float("nan"), True, "1"):
            with pytest.raises(ValueError, match=name):
                Dynamics(**{name: bad})


# -- humans ------------------------------------------------------------------------------------


def test_humans_parsed_with_dwell_and_loop_defaults(tmp_path: Path) -> None:
    scene = load_scenario(write(tmp_path / "s.yaml", SIM_YAML)).scene
    assert list(scene.humans) == ["H2", "H1", "H3"]  # file order
    h1 = scene.humans["H1"]
    assert h1 == Human("H1", 400.0, 500.0, ((0.0, -1500.0, 0.0), (0.0, -2200.0, 5.0), (100.5, -2200.0, 0.0)))
    assert h1.loop is True
    assert h1.walk is None
    assert h1.start == (0.0, -1500.0)
    assert all(isinstance(value, float) for point in h1.path for value in point)
    h3 = scene.humans["H3"]
    assert h3.loop is False
    assert h3.path == ((1000.0, 0.0, 2.0), (1000.0, 1000.0, 0.0))


def test_loop_defaults_to_true() -> None:
    human = parse_scenario(mutated(with_human())).scene.humans["H1"]
    assert human.loop is True
    assert human.path == ((0.0, -1500.0, 0.0), (0.0, -2200.0, 5.0))


def test_random_walk_human(tmp_path: Path) -> None:
    h2 = load_scenario(write(tmp_path / "s.yaml", SIM_YAML)).scene.humans["H2"]
    assert h2.path == ((0.0, -1500.0, 0.0),)  # only the start point: it roams from there
    assert h2.walk == ((-2000.0, 2000.0), (-2000.0, -500.0))
    assert h2.size == 350.0 and h2.speed == 600.0
    # a walk may also follow a path that ends, and a degenerate (lo == hi) range is a line
    change = with_human(walk={"x": [5, 5], "y": [-1, 1]}, loop=False)
    walker = parse_scenario(mutated(change)).scene.humans["H1"]
    assert len(walker.path) == 2
    assert walker.loop is False
    assert walker.walk == ((5.0, 5.0), (-1.0, 1.0))


def test_humans_are_read_only() -> None:
    scene = parse_scenario(mutated(with_human())).scene
    with pytest.raises(TypeError):
        scene.humans["H9"] = scene.humans["H1"]  # type: ignore[index]
    with pytest.raises(dataclasses.FrozenInstanceError):
        scene.humans["H1"].speed = 1.0  # type: ignore[misc]
    with pytest.raises(dataclasses.FrozenInstanceError):
        scene.robots["R1"].dynamics.cycle = 1.0  # type: ignore[misc]


def test_human_checks_in_code() -> None:
    human = Human("H1", 400, 600, ((0, 0), (1, 2, 3)))
    assert human.path == ((0.0, 0.0, 0.0), (1.0, 2.0, 3.0))
    assert Human("H2", 400, 600, ((0, 0),), walk=((0, 1), (2, 3))).walk == ((0.0, 1.0), (2.0, 3.0))
    for bad in (
        {"path": ((0, 0),)},
        {"path": ()},
        {"path": ((0, 0), (1, 1, -1))},
        {"path": ((0, 0), (1,))},
        {"size": 0},
        {"speed": -1},
        {"path": ((0, 0),), "walk": ((1, 0), (0, 1))},
    ):
        arguments = {"id": "H1", "size": 400, "speed": 600, "path": ((0, 0), (1, 1)), **bad}
        with pytest.raises(ValueError, match="H1"):
            Human(**arguments)


# -- positional compatibility and pickling -----------------------------------------------------


def test_scene_constructed_in_code_keeps_old_signature() -> None:
    robot = Robot("R1", 400.0, (0.0, 0.0, 0.0))
    scene = Scene((Wall((0, 0), (1, 0)),), {"R1": robot})
    assert dict(scene.humans) == {}
    assert scene.dynamics == Dynamics()
    scene = Scene((), {"R1": robot}, {}, {}, {"H1": Human("H1", 1, 1, ((0, 0), (1, 1)))}, Dynamics(cycle=0.2))
    assert isinstance(scene.humans, MappingProxyType)
    assert scene.dynamics.cycle == 0.2


def test_scene_with_humans_and_dynamics_survives_pickling(tmp_path: Path) -> None:
    scenario = load_scenario(write(tmp_path / "s.yaml", SIM_YAML))
    copy_ = pickle.loads(pickle.dumps(scenario))
    scene, original = copy_.scene, scenario.scene
    assert isinstance(scene.humans, MappingProxyType)
    assert isinstance(scene.robots, MappingProxyType)
    assert dict(scene.humans) == dict(original.humans)
    assert list(scene.humans) == ["H2", "H1", "H3"]
    assert dict(scene.robots) == dict(original.robots)
    assert scene.robots["R1"].dynamics == Dynamics(max_speed=500, braking=400, turn_rate=90)
    assert scene.dynamics == original.dynamics == Dynamics(max_speed=600, braking=400)
    assert scene.obstacles == original.obstacles
    assert copy_.mission.tasks == scenario.mission.tasks


# -- validation --------------------------------------------------------------------------------

RULES: list[tuple[str, Callable[[dict[str, Any]], object], str, tuple[str, ...]]] = [
    # (id, change, field, fragments of what is expected)
    (
        "unknown scene dynamics key",
        scene_dynamics({"speed": 700}),
        "scene.dynamics.speed",
        ("unknown key 'speed'", "max_speed, acceleration, braking, turn_rate, cycle"),
    ),
    (
        "unknown robot dynamics key",
        robot_dynamics("R1", {"max_speed": 500, "omega": 90}),
        "scene.robots.R1.dynamics.omega",
        ("unknown key 'omega'", "max_speed, acceleration, braking, turn_rate, cycle"),
    ),
    (
        "dynamics not a mapping",
        scene_dynamics(750),
        "scene.dynamics",
        ("a mapping with any of the keys max_speed", "got 750"),
    ),
    (
        "zero max speed",
        scene_dynamics({"max_speed": 0}),
        "scene.dynamics.max_speed",
        ("positive number", "mm/s", "got 0"),
    ),
    (
        "negative acceleration",
        scene_dynamics({"acceleration": -300}),
        "scene.dynamics.acceleration",
        ("positive number", "mm/s^2", "got -300"),
    ),
    (
        "text braking",
        robot_dynamics("R2", {"braking": "500"}),
        "scene.robots.R2.dynamics.braking",
        ("positive number", "mm/s^2", "got '500'"),
    ),
    (
        "boolean turn rate",
        robot_dynamics("R1", {"turn_rate": True}),
        "scene.robots.R1.dynamics.turn_rate",
        ("positive number", "degrees/s", "got true"),
    ),
    (
        "infinite cycle",
        scene_dynamics({"cycle": float("inf")}),
        "scene.dynamics.cycle",
        ("positive number", "control cycle, s", "got inf"),
    ),
    (
        "null cycle",
        scene_dynamics({"cycle": None}),
        "scene.dynamics.cycle",
        ("positive number", "got nothing (null)"),
    ),
    (
        "robot with its own cycle",
        robot_dynamics("R2", {"cycle": 0.2}),
        "scene.robots.R2.dynamics.cycle",
        ("every robot must share one control cycle", "this robot's is 0.2 s", "the others use 0.1 s"),
    ),
    (
        "robot off the scene's cycle",
        lambda d: (scene_dynamics({"cycle": 0.05})(d), robot_dynamics("R1", {"cycle": 0.1})(d)),
        "scene.robots.R1.dynamics.cycle",
        ("share one control cycle", "this robot's is 0.1 s", "the others use 0.05 s"),
    ),
    (
        "human id used by a robot",
        lambda d: d["scene"].__setitem__("humans", {"R2": copy.deepcopy(PERSON)}),
        "scene.humans.R2",
        ("'R2' is already used by a robot (scene.robots.R2)", "robots, objects, workspaces and humans"),
    ),
    (
        "human id used by a workspace",
        lambda d: d["scene"].__setitem__("humans", {"W1": copy.deepcopy(PERSON)}),
        "scene.humans.W1",
        ("already used by a workspace (scene.workspaces.W1)",),
    ),
    (
        "bad human id",
        lambda d: d["scene"].__setitem__("humans", {"person 1": copy.deepcopy(PERSON)}),
        "scene.humans['person 1']",
        ("an id matching", "'person 1'"),
    ),
    (
        "humans not a mapping",
        lambda d: d["scene"].__setitem__("humans", [copy.deepcopy(PERSON)]),
        "scene.humans",
        ("a mapping from human ids to {size, speed, path}",),
    ),
    (
        "human not a mapping",
        lambda d: d["scene"].__setitem__("humans", {"H1": 400}),
        "scene.humans.H1",
        ("mapping with keys size, speed, path", "got 400"),
    ),
    (
        "unknown human key",
        with_human(pose=[0, 0, 0]),
        "scene.humans.H1.pose",
        ("unknown key 'pose'", "size, speed, path, loop, walk"),
    ),
    (
        "missing human speed",
        with_human(speed=...),
        "scene.humans.H1.speed",
        ("missing required key 'speed'", "positive number (walking speed, mm/s)"),
    ),
    (
        "zero human size",
        with_human(size=0),
        "scene.humans.H1.size",
        ("positive number (side of the square person, mm)", "got 0"),
    ),
    (
        "negative human speed",
        with_human(speed=-600),
        "scene.humans.H1.speed",
        ("positive number (walking speed, mm/s)", "got -600"),
    ),
    (
        "missing path",
        with_human(path=...),
        "scene.humans.H1.path",
        ("missing required key 'path'", "non-empty list of waypoints"),
    ),
    (
        "empty path",
        with_human(path=[]),
        "scene.humans.H1.path",
        ("non-empty list of waypoints", "got []"),
    ),
    (
        "path not a list",
        with_human(path="there"),
        "scene.humans.H1.path",
        ("non-empty list of waypoints", "got 'there'"),
    ),
    (
        "one-point path without a walk",
        with_human(path=[[0, -1500]]),
        "scene.humans.H1.path",
        ("at least two waypoints", "or a walk area", "got one point"),
    ),
    (
        "short waypoint",
        with_human(path=[[0, -1500], [1]]),
        "scene.humans.H1.path[1]",
        ("[x, y] or [x, y, dwell]", "(mm, mm, seconds)", "got [1]"),
    ),
    (
        "long waypoint",
        with_human(path=[[0, -1500], [1, 2, 3, 4]]),
        "scene.humans.H1.path[1]",
        ("[x, y] or [x, y, dwell]", "got [1, 2, 3, 4]"),
    ),
    (
        "text in a waypoint",
        with_human(path=[[0, "left"], [1, 2]]),
        "scene.humans.H1.path[0]",
        ("[x, y] or [x, y, dwell]", "'left'"),
    ),
    (
        "negative dwell",
        with_human(path=[[0, -1500], [0, -2200, -5]]),
        "scene.humans.H1.path[1][2]",
        ("dwell time >= 0 (seconds)", "got -5"),
    ),
    (
        "loop as text",
        with_human(loop="yes"),
        "scene.humans.H1.loop",
        ("true or false", "got 'yes'"),
    ),
    (
        "loop as a number",
        with_human(loop=1),
        "scene.humans.H1.loop",
        ("true or false", "got 1"),
    ),
    (
        "walk not a mapping",
        with_human(walk=[[0, 1], [0, 1]]),
        "scene.humans.H1.walk",
        ("an area {x: [lo, hi], y: [lo, hi]} (mm)", "got [[0, 1], [0, 1]]"),
    ),
    (
        "walk without y",
        with_human(walk={"x": [0, 1]}),
        "scene.humans.H1.walk.y",
        ("missing required key 'y'", "[lo, hi]", "lo <= hi"),
    ),
    (
        "walk with lo > hi",
        with_human(walk={"x": [-2000, 2000], "y": [-500, -2000]}),
        "scene.humans.H1.walk.y",
        ("lo <= hi", "got lo = -500 > hi = -2000"),
    ),
    (
        "malformed walk range",
        with_human(walk={"x": [0], "y": [0, 1]}),
        "scene.humans.H1.walk.x",
        ("[lo, hi]", "got [0]"),
    ),
    (
        "unknown walk key",
        with_human(walk={"x": [0, 1], "y": [0, 1], "z": [0, 1]}),
        "scene.humans.H1.walk.z",
        ("unknown key 'z'", "x, y"),
    ),
]


@pytest.mark.parametrize(("change", "field", "fragments"), [r[1:] for r in RULES], ids=[r[0] for r in RULES])
def test_validation_rule(tmp_path: Path, change: Callable, field: str, fragments: tuple[str, ...]) -> None:
    path = tmp_path / "scenario.yaml"
    err = load_error(path, mutated(change))
    assert_error(err, path, field, *fragments)
    assert err.line is not None


@pytest.mark.parametrize(("change", "field", "fragments"), [r[1:] for r in RULES], ids=[r[0] for r in RULES])
def test_validation_rule_in_memory(change: Callable, field: str, fragments: tuple[str, ...]) -> None:
    with pytest.raises(ScenarioError) as info:
        parse_scenario(mutated(change))
    err = info.value
    assert_error(err, None, field, *fragments)
    assert str(err).startswith(f"{field}: ")
    assert err.line is None


def test_cycle_error_points_at_the_overriding_line(tmp_path: Path) -> None:
    text = SIM_YAML.replace("R2: {size: 400, pose: [-2000, -2000, 0]}", "R2: {size: 400, pose: [0, 0, 0]}")
    text = text.replace("dynamics: {max_speed: 500, turn_rate: 90}", "dynamics: {cycle: 0.2}")
    path = tmp_path / "s.yaml"
    err = load_error(path, text)
    assert_error(
        err, path, "scene.robots.R1.dynamics.cycle", "share one control cycle", "the others use 0.1 s"
    )
    assert err.line == line_of(text, "cycle: 0.2")
    assert err.column == text.splitlines()[err.line - 1].index("cycle") + 1


def test_cycle_error_names_the_majority(tmp_path: Path) -> None:
    # R1 and R3 agree on 0.05 s; R2 keeps the scene-wide 0.1 s: R2 is the odd one out
    def change(data: dict[str, Any]) -> None:
        robots = data["scene"]["robots"]
        robots["R3"] = {"size": 400, "pose": [0, 0, 0], "dynamics": {"cycle": 0.05}}
        robots["R1"]["dynamics"] = {"cycle": 0.05}

    path = tmp_path / "s.yaml"
    err = load_error(path, mutated(change))
    assert_error(
        err, path, "scene.robots.R2.dynamics.cycle", "this robot's is 0.1 s", "the others use 0.05 s"
    )
    assert err.line == line_of(path.read_text(), "R2:")  # R2 has no cycle of its own: its entry


def test_cycle_error_with_three_cycles_prefers_the_scene_default() -> None:
    def change(data: dict[str, Any]) -> None:
        robots = data["scene"]["robots"]
        robots["R1"]["dynamics"] = {"cycle": 0.2}
        robots["R3"] = {"size": 400, "pose": [0, 0, 0], "dynamics": {"cycle": 0.3}}

    with pytest.raises(ScenarioError) as info:
        parse_scenario(mutated(change))
    assert_error(info.value, None, "scene.robots.R1.dynamics.cycle", "this robot's is 0.2 s", "R2 uses 0.1 s")


def test_errors_in_dynamics_and_humans_report_their_lines(tmp_path: Path) -> None:
    path = tmp_path / "s.yaml"
    text = SIM_YAML.replace("[0, -2200, 5]", "[0, -2200, -5]")
    err = load_error(path, text)
    assert_error(err, path, "scene.humans.H1.path[1][2]", "dwell time >= 0")
    assert err.line == line_of(text, "-2200, -5")
    text = SIM_YAML.replace("braking: 400", "braking: 0")
    err = load_error(path, text)
    assert_error(err, path, "scene.dynamics.braking", "positive number", "got 0")
    assert err.line == line_of(text, "braking: 0")


def test_yaml_11_booleans_are_not_loop_values(tmp_path: Path) -> None:
    path = tmp_path / "s.yaml"
    err = load_error(path, SIM_YAML.replace("loop: false", "loop: no"))
    assert_error(err, path, "scene.humans.H3.loop", "true or false", "got 'no'")


def test_duplicate_human_key(tmp_path: Path) -> None:
    path = tmp_path / "s.yaml"
    text = SIM_YAML.replace("    H3: {", "    H1: {")
    err = load_error(path, text)
    assert_error(err, path, "scene.humans.H1", "duplicate key 'H1'")
    assert err.line == line_of(text, "H1: {size: 300")


# -- the command line --------------------------------------------------------------------------

runner = CliRunner()


def test_validate_accepts_dynamics_and_humans(tmp_path: Path) -> None:
    result = runner.invoke(app, ["validate", str(write(tmp_path / "s.yaml", SIM_YAML))])
    assert result.exit_code == 0, result.output
    assert "corridor-with-people" in result.stdout
    assert result.stderr == ""


@pytest.mark.parametrize(
    ("old", "new", "at", "message"),
    [
        ("[0, -2200, 5]", "[0, -2200, -5]", "-5]", "scene.humans.H1.path[1][2]: expected a dwell time >= 0"),
        (
            "turn_rate: 90",
            "cycle: 0.5",
            "cycle",
            "scene.robots.R1.dynamics.cycle: every robot must share one",
        ),
        ("braking: 400", "brake: 400", "brake", "scene.dynamics.brake: unknown key 'brake'"),
    ],
)
def test_validate_bad_file_is_one_line_with_status_2(
    tmp_path: Path, old: str, new: str, at: str, message: str
) -> None:
    """The error is one line on stderr naming the file, field, line and column; status 2."""
    path = write(tmp_path / "bad.yaml", SIM_YAML.replace(old, new))
    result = runner.invoke(app, ["validate", str(path)])
    assert result.exit_code == EXIT_INPUT_ERROR == 2
    assert result.stdout == ""
    lines = result.stderr.splitlines()
    assert len(lines) == 1
    assert lines[0].startswith(f"error: {path}: {message}")
    row = line_of(path.read_text(), new)
    column = path.read_text().splitlines()[row - 1].index(at) + 1
    assert lines[0].endswith(f"(line {row}, column {column})")
    assert "Traceback" not in result.output
    assert result.exception is None or isinstance(result.exception, SystemExit)
