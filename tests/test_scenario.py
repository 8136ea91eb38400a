"""Scenario files: loading the examples, and one test per validation rule.

Every error test checks that the message names the file, the field path and what was expected.
"""

from __future__ import annotations

import copy
import os
import pickle
import stat
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import yaml

from cosmop.errors import CosmopInputError, ScenarioError
from cosmop.events import Event, parse_event
from cosmop.io import write_atomic
from cosmop.scenario import load_scenario, parse_scenario
from cosmop.scene import DfaSpec, Mission, MovableObject, Robot, Scenario, Scene, Wall, Workspace

EXAMPLE_DIR = Path(__file__).resolve().parents[1] / "examples" / "01_warehouse_2x2"
TASKS_FILE = EXAMPLE_DIR / "scenario.yaml"
DFA_FILE = EXAMPLE_DIR / "scenario_dfa.yaml"

BASE: dict[str, Any] = {
    "name": "warehouse-2x2",
    "scene": {
        "obstacles": [
            [[-2500, -2500], [2500, -2500]],
            [[2500, -2500], [2500, 2500]],
            [[2500, 2500], [-2500, 2500]],
            [[-2500, 2500], [-2500, -2500]],
            [[0, 0], [0, 2500]],
            [[-1000, 0], [1000, 0]],
        ],
        "robots": {
            "R1": {"size": 400, "pose": [-2000, -1000, 0]},
            "R2": {"size": 400, "pose": [-2000, -2000, 0]},
        },
        "objects": {
            "O1": {"size": 100, "position": [2000, -1000]},
            "O2": {"size": 100, "position": [1900, -1000]},
        },
        "workspaces": {
            "W1": {"x": [-1500, -1000], "y": [2000, 2500]},
            "W2": {"x": [1000, 1500], "y": [2000, 2500]},
        },
    },
    "mission": {
        "tasks": {
            "R1": ["pick O1", "drop O1 at W1", "return"],
            "R2": ["pick O2", "drop O2 at W2", "return"],
        }
    },
}

SMALL_DFA = {
    "initial": "q0",
    "transitions": [["q0", "R1pO1", "q1"], ["q1", "drop(R1,O1,W1)", "q2"], ["q2", "r1", "q3"]],
}

R1_EVENTS = [Event("pick", "R1", "O1"), Event("drop", "R1", "O1", "W1"), Event("return", "R1")]
R2_EVENTS = [Event("pick", "R2", "O2"), Event("drop", "R2", "O2", "W2"), Event("return", "R2")]


def write(path: Path, content: str | dict[str, Any]) -> Path:
    text = content if isinstance(content, str) else yaml.safe_dump(content, sort_keys=False)
    write_atomic(path, text)
    return path


def load_error(path: Path, content: str | dict[str, Any]) -> ScenarioError:
    write(path, content)
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    return info.value


def assert_error(err: CosmopInputError, file: Path | str | None, field: str | None, *fragments: str) -> None:
    """The error names the file, the field and (in these words) what was expected."""
    assert err.file == (None if file is None else os.fspath(file))
    assert err.field == field
    message = str(err)
    prefix = ": ".join(str(part) for part in (err.file, field) if part is not None)
    assert message.startswith(prefix)
    for fragment in fragments:
        assert fragment in err.expected, (fragment, err.expected)
        assert fragment in message
    assert "\n" not in message


def mutated(change: Callable[[dict[str, Any]], object]) -> dict[str, Any]:
    data = copy.deepcopy(BASE)
    change(data)
    return data


# -- the examples ------------------------------------------------------------------------------


def test_tasks_example_loads() -> None:
    scenario = load_scenario(TASKS_FILE)
    assert isinstance(scenario, Scenario)
    assert scenario.name == "warehouse-2x2"
    assert scenario.source == TASKS_FILE
    scene = scenario.scene
    assert len(scene.obstacles) == 6
    assert scene.obstacles[0] == Wall((-2500.0, -2500.0), (2500.0, -2500.0))
    assert scene.obstacles[4] == Wall((0.0, 0.0), (0.0, 2500.0))
    assert scene.obstacles[5] == Wall((-1000.0, 0.0), (1000.0, 0.0))
    assert scene.robots["R1"] == Robot("R1", 400.0, (-2000.0, -1000.0, 0.0))
    assert scene.robots["R2"] == Robot("R2", 400.0, (-2000.0, -2000.0, 0.0))
    assert scene.objects["O1"] == MovableObject("O1", 100.0, (2000.0, -1000.0))
    assert scene.objects["O2"] == MovableObject("O2", 100.0, (1900.0, -1000.0))
    assert scene.workspaces["W1"] == Workspace("W1", x=(-1500.0, -1000.0), y=(2000.0, 2500.0))
    assert scene.workspaces["W2"] == Workspace("W2", x=(1000.0, 1500.0), y=(2000.0, 2500.0))
    assert list(scene.robots) == ["R1", "R2"]
    mission = scenario.mission
    assert mission.form == "tasks"
    assert mission.dfa is None
    assert mission.tasks == {"R1": tuple(R1_EVENTS), "R2": tuple(R2_EVENTS)}


def test_dfa_example_is_the_papers_4x4_grid() -> None:
    scenario = load_scenario(DFA_FILE)
    dfa = scenario.mission.dfa
    assert scenario.mission.form == "dfa"
    assert scenario.mission.tasks is None
    assert dfa.states == tuple(f"q{n}" for n in range(16))
    assert dfa.initial == "q0"
    assert dfa.marked == dfa.states  # prefix-closed by default
    assert len(dfa.transitions) == 24
    # state q(4j+i): i of R1's events done, j of R2's; each state offers exactly the next
    # event of each robot that has not finished.
    expected = set()
    for j in range(4):
        for i in range(4):
            if i < 3:
                expected.add((f"q{4 * j + i}", R1_EVENTS[i], f"q{4 * j + i + 1}"))
            if j < 3:
                expected.add((f"q{4 * j + i}", R2_EVENTS[j], f"q{4 * (j + 1) + i}"))
    assert set(dfa.transitions) == expected


def test_examples_describe_the_same_scene_and_event_set() -> None:
    tasks, dfa = load_scenario(TASKS_FILE), load_scenario(DFA_FILE)
    assert tasks.scene == dfa.scene
    assert tasks.mission.events == dfa.mission.events == frozenset(R1_EVENTS + R2_EVENTS)
    assert dfa.mission.dfa.alphabet == tuple(sorted(R1_EVENTS + R2_EVENTS))


def test_dfa_example_uses_the_compact_names() -> None:
    raw = yaml.safe_load(DFA_FILE.read_text())
    texts = {text for _, text, _ in raw["mission"]["dfa"]["transitions"]}
    assert texts == {"R1pO1", "R1dO1aW1", "r1", "R2pO2", "R2dO2aW2", "r2"}


def test_parse_scenario_accepts_the_same_data() -> None:
    scenario = parse_scenario(copy.deepcopy(BASE))
    assert scenario.source is None
    assert scenario.scene == load_scenario(TASKS_FILE).scene
    assert parse_scenario(copy.deepcopy(BASE), source="mem.yaml").source == Path("mem.yaml")


# -- the loaded values -------------------------------------------------------------------------


def test_scenario_values_are_immutable() -> None:
    scenario = load_scenario(TASKS_FILE)
    with pytest.raises(TypeError):
        scenario.scene.robots["R3"] = scenario.scene.robots["R1"]  # type: ignore[index]
    with pytest.raises(TypeError):
        scenario.mission.tasks["R1"] = ()  # type: ignore[index]
    with pytest.raises(AttributeError):
        scenario.name = "other"  # type: ignore[misc]
    assert isinstance(scenario.scene.obstacles, tuple)
    assert isinstance(scenario.mission.tasks["R1"], tuple)


def test_workspace_geometry() -> None:
    rect = Workspace("W1", x=(-1500.0, -1000.0), y=(2000.0, 2500.0))
    assert rect.center == (-1250.0, 2250.0)
    assert rect.contains(-1250, 2250)
    assert rect.contains(-1500, 2000) and rect.contains(-1000, 2500)  # boundary included
    assert not rect.contains(-999, 2250)
    assert rect.contains(-999, 2250, tol=1)
    assert not rect.is_point
    point = Workspace("W3", point=(-4250.0, 4000.0))
    assert point.is_point
    assert point.center == (-4250.0, 4000.0)
    assert point.contains(-4250, 4000)
    assert not point.contains(-4249, 4000)
    assert point.contains(-4249, 4000, tol=1.5)
    with pytest.raises(ValueError):
        Workspace("W4")
    with pytest.raises(ValueError):
        Workspace("W4", x=(0.0, 1.0))
    with pytest.raises(ValueError):
        Workspace("W4", x=(2.0, 1.0), y=(0.0, 1.0))
    with pytest.raises(ValueError):
        Workspace("W4", x=(0.0, 1.0), y=(0.0, 1.0), point=(0.0, 0.0))


def test_wall_length_and_mission_form_checks() -> None:
    assert Wall((0.0, 0.0), (3.0, 4.0)).length == 5.0
    with pytest.raises(ValueError):
        Mission()
    with pytest.raises(ValueError):
        Mission(tasks={}, dfa=DfaSpec(("q0",), "q0", ("q0",), ()))


def test_scene_constructed_in_code_is_read_only() -> None:
    scene = Scene(obstacles=[], robots={"R1": Robot("R1", 1.0, (0.0, 0.0, 0.0))})
    assert scene.obstacles == ()
    assert dict(scene.objects) == {}
    with pytest.raises(TypeError):
        scene.robots["R2"] = scene.robots["R1"]  # type: ignore[index]


def test_workspace_point_form_and_null_collections(tmp_path: Path) -> None:
    data = mutated(lambda d: d["scene"]["workspaces"].__setitem__("W3", {"point": [-4250, 4000]}))
    scenario = load_scenario(write(tmp_path / "s.yaml", data))
    assert scenario.scene.workspaces["W3"] == Workspace("W3", point=(-4250.0, 4000.0))
    text = (
        "name: bare\nscene:\n  obstacles:\n  robots: {R1: {size: 1, pose: [0, 0, 0]}}\n  objects:\n"
        "  workspaces:\nmission:\n  tasks: {R1: [return]}\n"
    )
    bare = load_scenario(write(tmp_path / "bare.yaml", text))
    assert bare.scene.obstacles == ()
    assert dict(bare.scene.objects) == {} and dict(bare.scene.workspaces) == {}
    assert bare.mission.tasks == {"R1": (Event("return", "R1"),)}


def test_numbers_may_be_ints_or_floats(tmp_path: Path) -> None:
    text = TASKS_FILE.read_text().replace(
        "R2: {size: 400, pose: [-2000, -2000, 0]}", "R2: {size: 4.0e2, pose: [-2000.5, -2e3, 90.0]}"
    )
    scenario = load_scenario(write(tmp_path / "s.yaml", text))
    assert scenario.scene.robots["R2"] == Robot("R2", 400.0, (-2000.5, -2000.0, 90.0))
    assert all(isinstance(v, float) for v in scenario.scene.robots["R1"].pose)


def test_optional_version_key(tmp_path: Path) -> None:
    assert load_scenario(write(tmp_path / "s.yaml", {"version": 1, **BASE})).name == "warehouse-2x2"
    path = tmp_path / "v2.yaml"
    err = load_error(path, {"version": 2, **BASE})
    assert_error(err, path, "version", "expected 1", "got 2")


def test_task_events_may_use_every_form(tmp_path: Path) -> None:
    data = mutated(
        lambda d: d["mission"]["tasks"].update(
            R1=["pick(R1, O1)", "R1dO1aW1", "away(O2,R1,R2)", "r1"], R2=["away(O2,R1,R2)", "return(R2)"]
        )
    )
    scenario = load_scenario(write(tmp_path / "s.yaml", data))
    away = Event("away", "R1", "O2", responder="R2")
    assert scenario.mission.tasks["R1"] == (R1_EVENTS[0], R1_EVENTS[1], away, R1_EVENTS[2])
    assert scenario.mission.tasks["R2"] == (away, R2_EVENTS[2])


def test_dfa_defaults_and_options(tmp_path: Path) -> None:
    data = mutated(lambda d: d.__setitem__("mission", {"dfa": copy.deepcopy(SMALL_DFA)}))
    dfa = load_scenario(write(tmp_path / "s.yaml", data)).mission.dfa
    assert dfa.states == ("q0", "q1", "q2", "q3")  # order of appearance
    assert dfa.marked == dfa.states
    assert dfa.transitions[1] == ("q1", Event("drop", "R1", "O1", "W1"), "q2")

    options = {**SMALL_DFA, "states": ["q3", "q2", "q1", "q0", "q9"], "marked": ["q3"]}
    data = mutated(lambda d: d.__setitem__("mission", {"dfa": options}))
    dfa = load_scenario(write(tmp_path / "t.yaml", data)).mission.dfa
    assert dfa.states == ("q3", "q2", "q1", "q0", "q9")  # as listed, unreachable q9 included
    assert dfa.marked == ("q3",)

    text = (
        "name: n\nscene: {robots: {R1: {size: 1, pose: [0, 0, 0]}}}\n"
        "mission:\n  dfa: {initial: 0, transitions: [[0, r1, 1]], marked: [1]}\n"
    )
    dfa = load_scenario(write(tmp_path / "u.yaml", text)).mission.dfa
    assert dfa.states == ("0", "1") and dfa.marked == ("1",)


# -- YAML-level errors ---------------------------------------------------------------------------


def test_missing_file(tmp_path: Path) -> None:
    path = tmp_path / "nope.yaml"
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    assert_error(info.value, path, None, "file not found")
    assert str(info.value) == f"{path}: file not found"


def test_directory_is_not_a_scenario(tmp_path: Path) -> None:
    with pytest.raises(ScenarioError) as info:
        load_scenario(tmp_path)
    assert_error(info.value, tmp_path, None, "is a directory")


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0, reason="needs POSIX permissions, not root")
def test_unreadable_file(tmp_path: Path) -> None:
    path = write(tmp_path / "s.yaml", BASE)
    path.chmod(0)
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    assert_error(info.value, path, None, "permission denied")


def test_not_utf8(tmp_path: Path) -> None:
    path = tmp_path / "s.yaml"
    write_atomic(path, b"name: \xff\n")
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    assert_error(info.value, path, None, "expected UTF-8 text")


def test_yaml_syntax_error_reports_the_line(tmp_path: Path) -> None:
    path = tmp_path / "s.yaml"
    text = TASKS_FILE.read_text().replace("  robots:\n", "  robots: : ]\n")
    line = text.splitlines().index("  robots: : ]") + 1
    err = load_error(path, text)
    assert_error(err, path, None, "invalid YAML")
    assert err.line == line
    assert f"(line {line}, column" in str(err)


def test_yaml_with_two_documents_is_rejected(tmp_path: Path) -> None:
    path = tmp_path / "s.yaml"
    err = load_error(path, TASKS_FILE.read_text() + "---\nname: other\n")
    assert_error(err, path, None, "invalid YAML", "single document")


@pytest.mark.parametrize(
    ("text", "what"),
    [
        ("", "the file is empty"),
        ("# only a comment\n", "the file is empty"),
        ("- a\n- b\n", "got list"),
        ("hello\n", "got str"),
    ],
)
def test_top_level_must_be_a_mapping(tmp_path: Path, text: str, what: str) -> None:
    path = tmp_path / "s.yaml"
    err = load_error(path, text)
    assert_error(err, path, None, "expected a mapping with keys name, scene, mission", what)


def test_top_level_mapping_in_memory() -> None:
    with pytest.raises(ScenarioError) as info:
        parse_scenario(["not", "a", "mapping"])  # type: ignore[arg-type]
    assert_error(info.value, None, None, "expected a mapping")


def test_duplicate_robot_id_key(tmp_path: Path) -> None:
    path = tmp_path / "s.yaml"
    text = TASKS_FILE.read_text().replace(
        "R2: {size: 400, pose: [-2000, -2000, 0]}", "R1: {size: 400, pose: [-2000, -2000, 0]}"
    )
    lines = text.splitlines()
    first = next(n for n, line in enumerate(lines, 1) if line.startswith("    R1: {size"))
    second = next(n for n, line in enumerate(lines, 1) if n > first and line.startswith("    R1: {size"))
    err = load_error(path, text)
    assert_error(err, path, "scene.robots.R1", "duplicate key 'R1'", f"first defined on line {first}")
    assert err.line == second
    assert f"(line {second}, column 5)" in str(err)


@pytest.mark.parametrize(
    ("old", "new", "field", "key"),
    [
        ("name: warehouse-2x2", "name: warehouse-2x2\nname: again", "name", "name"),
        ("R2: {size: 400,", "R2: {size: 400, size: 300,", "scene.robots.R2.size", "size"),
        ("    W2: {x:", "    W1: {x:", "scene.workspaces.W1", "W1"),
        ("    R2: [pick O2", "    R1: [pick O2", "mission.tasks.R1", "R1"),
    ],
)
def test_duplicate_keys_anywhere(tmp_path: Path, old: str, new: str, field: str, key: str) -> None:
    path = tmp_path / "s.yaml"
    text = TASKS_FILE.read_text()
    assert old in text
    err = load_error(path, text.replace(old, new, 1))
    assert_error(err, path, field, f"duplicate key {key!r}", "first defined on line")
    assert err.line is not None


def test_merge_keys_may_be_overridden(tmp_path: Path) -> None:
    text = TASKS_FILE.read_text()
    text = text.replace(
        "R1: {size: 400, pose: [-2000, -1000, 0]}", "R1: &r {size: 400, pose: [-2000, -1000, 0]}"
    )
    text = text.replace("R2: {size: 400, pose: [-2000, -2000, 0]}", "R2: {<<: *r, pose: [-2000, -2000, 0]}")
    scenario = load_scenario(write(tmp_path / "s.yaml", text))
    assert scenario.scene.robots["R2"] == Robot("R2", 400.0, (-2000.0, -2000.0, 0.0))


def test_yaml_11_booleans_stay_text(tmp_path: Path) -> None:
    text = TASKS_FILE.read_text()
    text = text.replace("name: warehouse-2x2", "name: no")
    text = (
        text.replace("R1", "on")
        .replace("R2", "off")
        .replace("O1", "y")
        .replace("O2", "n")
        .replace("W1", "yes")
    )
    scenario = load_scenario(write(tmp_path / "s.yaml", text))
    assert scenario.name == "no"
    assert list(scenario.scene.robots) == ["on", "off"]
    assert list(scenario.scene.objects) == ["y", "n"]
    assert list(scenario.scene.workspaces) == ["yes", "W2"]
    assert scenario.mission.tasks["on"][1] == Event("drop", "on", "y", "yes")
    assert all(isinstance(key, str) for key in scenario.scene.robots)


def test_yaml_dates_and_sexagesimals_stay_text(tmp_path: Path) -> None:
    text = TASKS_FILE.read_text().replace("name: warehouse-2x2", "name: 2024-01-01")
    assert load_scenario(write(tmp_path / "s.yaml", text)).name == "2024-01-01"
    path = tmp_path / "t.yaml"
    err = load_error(path, TASKS_FILE.read_text().replace("R2: {size: 400", "R2: {size: 1:20"))
    assert_error(err, path, "scene.robots.R2.size", "expected a positive number", "got '1:20'")


def test_yes_is_not_a_number(tmp_path: Path) -> None:
    path = tmp_path / "s.yaml"
    text = TASKS_FILE.read_text().replace("R2: {size: 400", "R2: {size: yes")
    err = load_error(path, text)
    assert_error(err, path, "scene.robots.R2.size", "expected a positive number", "got 'yes'")
    assert err.line == next(n for n, line in enumerate(text.splitlines(), 1) if "size: yes" in line)


def test_true_is_not_a_number(tmp_path: Path) -> None:
    path = tmp_path / "s.yaml"
    err = load_error(path, TASKS_FILE.read_text().replace("R2: {size: 400", "R2: {size: true"))
    assert_error(err, path, "scene.robots.R2.size", "expected a positive number", "got true")


def test_leading_zero_is_decimal(tmp_path: Path) -> None:
    text = TASKS_FILE.read_text().replace("R2: {size: 400", "R2: {size: 0400")
    assert load_scenario(write(tmp_path / "s.yaml", text)).scene.robots["R2"].size == 400.0


def test_unknown_yaml_tag(tmp_path: Path) -> None:
    path = tmp_path / "s.yaml"
    err = load_error(path, TASKS_FILE.read_text().replace("name: warehouse-2x2", "name: !custom x"))
    assert_error(err, path, None, "invalid YAML", "!custom")


# -- structural and semantic errors ------------------------------------------------------------

RULES: list[tuple[str, Callable[[dict[str, Any]], object], str, tuple[str, ...]]] = [
    # (id, change, field, fragments of what is expected)
    (
        "unknown top-level key",
        lambda d: d.__setitem__("extra", 1),
        "extra",
        ("unknown key 'extra'", "name, scene, mission"),
    ),
    ("missing name", lambda d: d.pop("name"), "name", ("missing required key 'name'",)),
    ("empty name", lambda d: d.__setitem__("name", ""), "name", ("non-empty name",)),
    ("missing scene", lambda d: d.pop("scene"), "scene", ("missing required key 'scene'", "robots")),
    ("missing mission", lambda d: d.pop("mission"), "mission", ("missing required key 'mission'",)),
    (
        "unknown scene key",
        lambda d: d["scene"].__setitem__("lights", []),
        "scene.lights",
        ("unknown key 'lights'", "robots"),
    ),
    ("no robots", lambda d: d["scene"].__setitem__("robots", {}), "scene.robots", ("non-empty mapping",)),
    (
        "missing robots",
        lambda d: d["scene"].pop("robots"),
        "scene.robots",
        ("missing required key 'robots'",),
    ),
    (
        "robot not a mapping",
        lambda d: d["scene"]["robots"].__setitem__("R1", 5),
        "scene.robots.R1",
        ("mapping with keys size, pose", "got 5"),
    ),
    (
        "unknown robot key",
        lambda d: d["scene"]["robots"]["R1"].__setitem__("colour", "red"),
        "scene.robots.R1.colour",
        ("unknown key 'colour'", "size, pose"),
    ),
    (
        "missing size",
        lambda d: d["scene"]["robots"]["R1"].pop("size"),
        "scene.robots.R1.size",
        ("missing required key 'size'", "positive number"),
    ),
    (
        "zero size",
        lambda d: d["scene"]["robots"]["R1"].__setitem__("size", 0),
        "scene.robots.R1.size",
        ("positive number", "got 0"),
    ),
    (
        "negative size",
        lambda d: d["scene"]["robots"]["R1"].__setitem__("size", -400),
        "scene.robots.R1.size",
        ("positive number", "got -400"),
    ),
    (
        "text size",
        lambda d: d["scene"]["robots"]["R1"].__setitem__("size", "400"),
        "scene.robots.R1.size",
        ("positive number", "got '400'"),
    ),
    (
        "infinite size",
        lambda d: d["scene"]["objects"]["O1"].__setitem__("size", float("inf")),
        "scene.objects.O1.size",
        ("positive number", "got inf"),
    ),
    (
        "negative object size",
        lambda d: d["scene"]["objects"]["O2"].__setitem__("size", -1.5),
        "scene.objects.O2.size",
        ("positive number", "got -1.5"),
    ),
    (
        "missing pose",
        lambda d: d["scene"]["robots"]["R2"].pop("pose"),
        "scene.robots.R2.pose",
        ("missing required key 'pose'", "[x, y, heading]"),
    ),
    (
        "short pose",
        lambda d: d["scene"]["robots"]["R1"].__setitem__("pose", [1, 2]),
        "scene.robots.R1.pose",
        ("[x, y, heading]", "three numbers", "got [1, 2]"),
    ),
    (
        "long pose",
        lambda d: d["scene"]["robots"]["R1"].__setitem__("pose", [1, 2, 3, 4]),
        "scene.robots.R1.pose",
        ("[x, y, heading]", "got [1, 2, 3, 4]"),
    ),
    (
        "text in pose",
        lambda d: d["scene"]["robots"]["R1"].__setitem__("pose", [1, 2, "north"]),
        "scene.robots.R1.pose",
        ("[x, y, heading]", "'north'"),
    ),
    (
        "pose not a list",
        lambda d: d["scene"]["robots"]["R1"].__setitem__("pose", 7),
        "scene.robots.R1.pose",
        ("[x, y, heading]", "got 7"),
    ),
    (
        "bad position",
        lambda d: d["scene"]["objects"]["O1"].__setitem__("position", [1]),
        "scene.objects.O1.position",
        ("[x, y]", "got [1]"),
    ),
    (
        "unknown object key",
        lambda d: d["scene"]["objects"]["O1"].__setitem__("pose", [0, 0, 0]),
        "scene.objects.O1.pose",
        ("unknown key 'pose'", "size, position"),
    ),
    (
        "wall of one point",
        lambda d: d["scene"]["obstacles"].append([[1, 2], [1, 2]]),
        "scene.obstacles[6]",
        ("two distinct end points", "got [[1, 2], [1, 2]]"),
    ),
    (
        "malformed wall",
        lambda d: d["scene"]["obstacles"].append([[1, 2], [3]]),
        "scene.obstacles[6]",
        ("[[x1, y1], [x2, y2]]", "got [[1, 2], [3]]"),
    ),
    (
        "wall not a list",
        lambda d: d["scene"]["obstacles"].__setitem__(0, "wall"),
        "scene.obstacles[0]",
        ("[[x1, y1], [x2, y2]]", "got 'wall'"),
    ),
    (
        "obstacles not a list",
        lambda d: d["scene"].__setitem__("obstacles", 3),
        "scene.obstacles",
        ("a list of walls", "got 3"),
    ),
    (
        "workspace both forms",
        lambda d: d["scene"]["workspaces"]["W1"].__setitem__("point", [0, 0]),
        "scene.workspaces.W1",
        ("either", "not both"),
    ),
    (
        "workspace no form",
        lambda d: d["scene"]["workspaces"].__setitem__("W1", {}),
        "scene.workspaces.W1",
        ("{x: [lo, hi], y: [lo, hi]} or {point: [x, y]}", "neither"),
    ),
    (
        "workspace x without y",
        lambda d: d["scene"]["workspaces"]["W1"].pop("y"),
        "scene.workspaces.W1.y",
        ("missing required key 'y'", "[lo, hi]"),
    ),
    (
        "workspace lo > hi",
        lambda d: d["scene"]["workspaces"]["W2"].__setitem__("x", [1500, 1000]),
        "scene.workspaces.W2.x",
        ("lo <= hi", "got lo = 1500 > hi = 1000"),
    ),
    (
        "workspace lo > hi in y",
        lambda d: d["scene"]["workspaces"]["W2"].__setitem__("y", [3, -3]),
        "scene.workspaces.W2.y",
        ("lo <= hi",),
    ),
    (
        "workspace bad range",
        lambda d: d["scene"]["workspaces"]["W2"].__setitem__("x", [1]),
        "scene.workspaces.W2.x",
        ("[lo, hi]", "got [1]"),
    ),
    (
        "workspace bad point",
        lambda d: d["scene"]["workspaces"].__setitem__("W3", {"point": [1, 2, 3]}),
        "scene.workspaces.W3.point",
        ("[x, y]", "got [1, 2, 3]"),
    ),
    (
        "unknown workspace key",
        lambda d: d["scene"]["workspaces"]["W1"].__setitem__("z", [0, 1]),
        "scene.workspaces.W1.z",
        ("unknown key 'z'", "x, y, point"),
    ),
    (
        "robot and object share an id",
        lambda d: d["scene"]["objects"].__setitem__("R1", {"size": 1, "position": [0, 0]}),
        "scene.objects.R1",
        ("'R1' is already used by a robot (scene.robots.R1)",),
    ),
    (
        "object and workspace share an id",
        lambda d: d["scene"]["workspaces"].__setitem__("O2", {"point": [0, 0]}),
        "scene.workspaces.O2",
        ("already used by an object (scene.objects.O2)",),
    ),
    (
        "bad id",
        lambda d: d["scene"]["objects"].__setitem__("my box", {"size": 1, "position": [0, 0]}),
        "scene.objects['my box']",
        ("an id matching", "'my box'"),
    ),
    (
        "numeric id",
        lambda d: d["scene"]["robots"].__setitem__(7, {"size": 1, "pose": [0, 0, 0]}),
        "scene.robots",
        ("keys here must be ids", "got 7"),
    ),
    (
        "both tasks and dfa",
        lambda d: d["mission"].__setitem__("dfa", copy.deepcopy(SMALL_DFA)),
        "mission",
        ("exactly one of 'tasks', 'dfa' or 'deliveries'", "got tasks and dfa"),
    ),
    (
        "neither tasks nor dfa",
        lambda d: d.__setitem__("mission", {}),
        "mission",
        ("exactly one of 'tasks', 'dfa' or 'deliveries'", "got none"),
    ),
    (
        "unknown mission key",
        lambda d: d["mission"].__setitem__("ltl", "F goal"),
        "mission.ltl",
        ("unknown key 'ltl'", "tasks, dfa"),
    ),
    (
        "task list for an unknown robot",
        lambda d: d["mission"]["tasks"].__setitem__("R3", ["return"]),
        "mission.tasks.R3",
        ("unknown robot 'R3'", "R1, R2"),
    ),
    (
        "task of another robot",
        lambda d: d["mission"]["tasks"]["R1"].append("pick(R2,O2)"),
        "mission.tasks.R1[3]",
        ("an event of robot R1", "pick(R2,O2)", "belongs to R2"),
    ),
    (
        "compact task of another robot",
        lambda d: d["mission"]["tasks"]["R2"].insert(0, "r1"),
        "mission.tasks.R2[0]",
        ("an event of robot R2", "return(R1)"),
    ),
    (
        "away not involving the robot",
        lambda d: d["mission"]["tasks"]["R1"].append("away(O1,R2,R3)"),
        "mission.tasks.R1[3]",
        ("an event of robot R1", "belongs to R2 and R3"),
    ),
    (
        "task with unknown object",
        lambda d: d["mission"]["tasks"]["R1"].__setitem__(0, "pick O9"),
        "mission.tasks.R1[0]",
        ("unknown object 'O9'", "pick(R1,O9)", "O1, O2"),
    ),
    (
        "task with unknown workspace",
        lambda d: d["mission"]["tasks"]["R2"].__setitem__(1, "drop O2 at W7"),
        "mission.tasks.R2[1]",
        ("unknown workspace 'W7'", "W1, W2"),
    ),
    (
        "away with unknown responder",
        lambda d: d["mission"]["tasks"]["R1"].insert(0, "away(O2,R1,R5)"),
        "mission.tasks.R1[0]",
        ("unknown robot 'R5'", "away(O2,R1,R5)"),
    ),
    (
        "unparsable task",
        lambda d: d["mission"]["tasks"]["R2"].__setitem__(2, "go home"),
        "mission.tasks.R2[2]",
        ("invalid event 'go home'", "accepted forms"),
    ),
    (
        "task not text",
        lambda d: d["mission"]["tasks"]["R2"].__setitem__(2, 5),
        "mission.tasks.R2[2]",
        ("a task step", "got 5"),
    ),
    (
        "tasks not a list",
        lambda d: d["mission"]["tasks"].__setitem__("R2", "return"),
        "mission.tasks.R2",
        ("a list of task steps", "got 'return'"),
    ),
    (
        "away with itself",
        lambda d: d["mission"]["tasks"]["R1"].append("away(O2,R1,R1)"),
        "mission.tasks.R1[3]",
        ("must be different robots",),
    ),
]


@pytest.mark.parametrize(("change", "field", "fragments"), [r[1:] for r in RULES], ids=[r[0] for r in RULES])
def test_validation_rule(tmp_path: Path, change: Callable, field: str, fragments: tuple[str, ...]) -> None:
    path = tmp_path / "scenario.yaml"
    err = load_error(path, mutated(change))
    assert_error(err, path, field, *fragments)
    if not (fragments[0].startswith("missing required key") and "." not in field):
        assert err.line is not None  # every problem but a missing top-level key is located in the file


@pytest.mark.parametrize(
    ("change", "field", "fragments"), [r[1:] for r in RULES[:12]], ids=[r[0] for r in RULES[:12]]
)
def test_validation_rule_in_memory(change: Callable, field: str, fragments: tuple[str, ...]) -> None:
    with pytest.raises(ScenarioError) as info:
        parse_scenario(mutated(change))
    err = info.value
    assert_error(err, None, field, *fragments)
    assert str(err).startswith(f"{field}: ")
    assert err.line is None


def _dfa(**changes: Any) -> Callable[[dict[str, Any]], object]:
    def change(data: dict[str, Any]) -> None:
        data["mission"] = {"dfa": {**copy.deepcopy(SMALL_DFA), **changes}}

    return change


def _drop_key(key: str) -> Callable[[dict[str, Any]], object]:
    def change(data: dict[str, Any]) -> None:
        data["mission"] = {"dfa": {k: v for k, v in copy.deepcopy(SMALL_DFA).items() if k != key}}

    return change


DFA_RULES: list[tuple[str, Callable[[dict[str, Any]], object], str, tuple[str, ...]]] = [
    (
        "missing initial",
        _drop_key("initial"),
        "mission.dfa.initial",
        ("missing required key 'initial'", "state name"),
    ),
    (
        "missing transitions",
        _drop_key("transitions"),
        "mission.dfa.transitions",
        ("missing required key 'transitions'", "[state, event, state]"),
    ),
    (
        "unknown dfa key",
        _dfa(accepting=["q3"]),
        "mission.dfa.accepting",
        ("unknown key 'accepting'", "initial, transitions, states, marked"),
    ),
    (
        "short transition",
        _dfa(transitions=[["q0", "R1pO1"]]),
        "mission.dfa.transitions[0]",
        ("[state, event, state]", "got ['q0', 'R1pO1']"),
    ),
    (
        "long transition",
        _dfa(transitions=[["q0", "R1pO1", "q1", "q2"]]),
        "mission.dfa.transitions[0]",
        ("[state, event, state]",),
    ),
    (
        "transitions not a list",
        _dfa(transitions="q0 -> q1"),
        "mission.dfa.transitions",
        ("a list of transitions",),
    ),
    (
        "unparsable event",
        _dfa(transitions=[["q0", "R1 picks O1", "q1"]]),
        "mission.dfa.transitions[0][1]",
        ("invalid event 'R1 picks O1'", "accepted forms"),
    ),
    (
        "implied robot in dfa",
        _dfa(transitions=[["q0", "pick O1", "q1"]]),
        "mission.dfa.transitions[0][1]",
        ("implied only inside a robot's task list",),
    ),
    (
        "unknown robot in dfa",
        _dfa(transitions=[["q0", "R3pO1", "q1"]]),
        "mission.dfa.transitions[0][1]",
        ("unknown robot 'R3'", "pick(R3,O1)"),
    ),
    (
        "unknown object in dfa",
        _dfa(transitions=[["q0", "R1pO3", "q1"]]),
        "mission.dfa.transitions[0][1]",
        ("unknown object 'O3'",),
    ),
    (
        "unknown workspace in dfa",
        _dfa(transitions=[["q0", "R1dO1aW3", "q1"]]),
        "mission.dfa.transitions[0][1]",
        ("unknown workspace 'W3'",),
    ),
    (
        "unknown responder in dfa",
        _dfa(transitions=[["q0", "away(O1,R1,R4)", "q1"]]),
        "mission.dfa.transitions[0][1]",
        ("unknown robot 'R4'",),
    ),
    (
        "nondeterminism",
        _dfa(transitions=[["q0", "R1pO1", "q1"], ["q1", "r1", "q2"], ["q0", "pick(R1,O1)", "q2"]]),
        "mission.dfa.transitions[2]",
        ("nondeterministic", "'q0'", "pick(R1,O1)", "'q1'", "'q2'", "transitions[0]"),
    ),
    (
        "repeated transition",
        _dfa(transitions=[["q0", "R1pO1", "q1"], ["q0", "pick(R1, O1)", "q1"]]),
        "mission.dfa.transitions[1]",
        ("repeats transitions[0]", "at most one transition"),
    ),
    (
        "initial not listed",
        _dfa(states=["q1", "q2", "q3"]),
        "mission.dfa.initial",
        ("unknown initial state 'q0'", "mission.dfa.states"),
    ),
    (
        "source not listed",
        _dfa(
            states=["q0", "q1", "q2", "q3"],
            transitions=[*SMALL_DFA["transitions"], ["q7", "R1pO1", "q1"]],
        ),
        "mission.dfa.transitions[3][0]",
        ("unknown source state 'q7'",),
    ),
    (
        "target not listed",
        _dfa(states=["q0", "q1", "q2"]),
        "mission.dfa.transitions[2][2]",
        ("unknown target state 'q3'",),
    ),
    (
        "marked not listed",
        _dfa(states=["q0", "q1", "q2", "q3"], marked=["q0", "q4"]),
        "mission.dfa.marked[1]",
        ("unknown marked state 'q4'", "mission.dfa.states"),
    ),
    (
        "marked unknown without states",
        _dfa(marked=["q3", "done"]),
        "mission.dfa.marked[1]",
        ("unknown marked state 'done'", "transitions or initial"),
    ),
    (
        "duplicate listed state",
        _dfa(states=["q0", "q1", "q2", "q3", "q1"]),
        "mission.dfa.states[4]",
        ("duplicate state 'q1'", "index 1"),
    ),
    ("duplicate marked state", _dfa(marked=["q3", "q3"]), "mission.dfa.marked[1]", ("duplicate state 'q3'",)),
    ("state not text", _dfa(initial=[1]), "mission.dfa.initial", ("a state name", "got [1]")),
    ("empty state name", _dfa(initial=""), "mission.dfa.initial", ("a state name", "got ''")),
]


@pytest.mark.parametrize(
    ("change", "field", "fragments"), [r[1:] for r in DFA_RULES], ids=[r[0] for r in DFA_RULES]
)
def test_dfa_validation_rule(
    tmp_path: Path, change: Callable, field: str, fragments: tuple[str, ...]
) -> None:
    path = tmp_path / "scenario.yaml"
    err = load_error(path, mutated(change))
    assert_error(err, path, field, *fragments)


def test_first_error_in_file_order_is_reported(tmp_path: Path) -> None:
    path = tmp_path / "s.yaml"

    def change(d: dict[str, Any]) -> None:
        d["scene"]["robots"]["R2"]["size"] = -1
        d["scene"]["robots"]["R1"]["pose"] = [0]

    err = load_error(path, mutated(change))
    assert err.field == "scene.robots.R1.pose"


def test_error_line_points_at_the_field(tmp_path: Path) -> None:
    path = tmp_path / "s.yaml"
    text = TASKS_FILE.read_text().replace("drop O2 at W2", "drop O2 at W9")
    line = next(n for n, row in enumerate(text.splitlines(), 1) if "W9" in row)
    err = load_error(path, text)
    assert_error(err, path, "mission.tasks.R2[1]", "unknown workspace 'W9'")
    assert err.line == line
    assert str(err).endswith(f"(line {line}, column {text.splitlines()[line - 1].index('drop O2') + 1})")


# -- errors ------------------------------------------------------------------------------------


def test_error_str_omits_missing_parts() -> None:
    assert str(CosmopInputError("bad", file="f.yaml", field="a.b")) == "f.yaml: a.b: bad"
    assert str(CosmopInputError("bad", field="a.b")) == "a.b: bad"
    assert str(CosmopInputError("bad", file="f.yaml")) == "f.yaml: bad"
    assert str(CosmopInputError("bad")) == "bad"
    assert str(CosmopInputError("bad", file="f.yaml", line=3)) == "f.yaml: bad (line 3)"
    assert (
        str(CosmopInputError("bad", file=Path("f.yaml"), line=3, column=4))
        == "f.yaml: bad (line 3, column 4)"
    )
    assert issubclass(ScenarioError, CosmopInputError)


def test_errors_survive_pickling() -> None:
    err = ScenarioError("expected x", file="f.yaml", field="scene.robots", line=2, column=3)
    copy_ = pickle.loads(pickle.dumps(err))
    assert type(copy_) is ScenarioError
    assert (copy_.file, copy_.field, copy_.expected, copy_.line, copy_.column) == (
        "f.yaml",
        "scene.robots",
        "expected x",
        2,
        3,
    )
    assert str(copy_) == str(err)


# -- write_atomic ------------------------------------------------------------------------------


def test_write_atomic_text_and_bytes(tmp_path: Path) -> None:
    path = tmp_path / "out.txt"
    write_atomic(path, "héllo\n")
    assert path.read_bytes() == "héllo\n".encode()
    write_atomic(path, b"\x00\x01")
    assert path.read_bytes() == b"\x00\x01"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.txt"]


@pytest.mark.skipif(os.name != "posix", reason="POSIX permission bits")
def test_write_atomic_keeps_permissions(tmp_path: Path) -> None:
    path = tmp_path / "out.txt"
    path.write_text("old")
    path.chmod(0o640)
    write_atomic(path, "new")
    assert stat.S_IMODE(path.stat().st_mode) == 0o640
    fresh = tmp_path / "fresh.txt"
    write_atomic(fresh, "x")
    umask = os.umask(0)
    os.umask(umask)
    assert stat.S_IMODE(fresh.stat().st_mode) == 0o666 & ~umask


def test_write_atomic_failure_leaves_old_file_and_no_temp(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = tmp_path / "out.txt"
    path.write_text("old")

    def broken_replace(src: str, dst: str) -> None:
        raise OSError("disk on fire")

    monkeypatch.setattr(os, "replace", broken_replace)
    with pytest.raises(OSError, match="disk on fire"):
        write_atomic(path, "new")
    assert path.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["out.txt"]


def test_write_atomic_bad_data_leaves_no_temp(tmp_path: Path) -> None:
    with pytest.raises(TypeError):
        write_atomic(tmp_path / "out.txt", 42)  # type: ignore[arg-type]
    assert list(tmp_path.iterdir()) == []


def test_write_atomic_missing_directory(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError):
        write_atomic(tmp_path / "no" / "out.txt", "x")


def test_parse_event_agrees_with_loader() -> None:
    scenario = load_scenario(TASKS_FILE)
    assert scenario.mission.tasks["R1"] == tuple(
        parse_event(t, robot="R1") for t in BASE["mission"]["tasks"]["R1"]
    )
