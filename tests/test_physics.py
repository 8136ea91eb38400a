"""A physically possible scene or exit 2: bodies touch but never overlap; tasks that make sense.

Each impossible scene is rejected with the field to blame and what collides with what; the
same scenes with the bodies exactly touching are accepted (the planner allows touching).
"""

from __future__ import annotations

import copy
from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner

from cosmop.cli import app
from cosmop.errors import ScenarioError
from cosmop.scenario import load_scenario, parse_scenario
from cosmop.scenario.overlaps import overlaps

ROOT = Path(__file__).resolve().parents[1]
BASE = yaml.safe_load((ROOT / "examples" / "01_warehouse_2x2" / "scenario.yaml").read_text())
runner = CliRunner()


def _with(change) -> dict:
    data = copy.deepcopy(BASE)
    change(data)
    return data


# the 2x2's outer wall is x = -2500; robots are 400 mm, objects 100 mm
IMPOSSIBLE = [
    (
        "robot in a wall",
        lambda d: d["scene"]["robots"]["R1"].update(pose=[-2450, -1000, 0]),
        "scene.robots.R1.pose",
        "robot R1 (400 mm square at (-2450, -1000)) overlaps wall [[-2500, 2500], [-2500, -2500]]",
    ),
    (
        "two robots overlapping",
        lambda d: d["scene"]["robots"]["R2"].update(pose=[-2000, -1300, 0]),
        "scene.robots.R2.pose",
        "robot R2 (400 mm square at (-2000, -1300)) overlaps robot R1",
    ),
    (
        "an object in a wall",
        lambda d: d["scene"]["objects"]["O1"].update(position=[2480, -1000]),
        "scene.objects.O1.position",
        "object O1 (100 mm square at (2480, -1000)) overlaps wall",
    ),
    (
        "a robot on an object",
        lambda d: d["scene"]["robots"]["R1"].update(pose=[1700, -1000, 0]),
        "scene.objects.O2.position",
        "object O2 (100 mm square at (1900, -1000)) overlaps robot R1",
    ),
    (
        "a person starting in a wall",
        lambda d: d["scene"].update(humans={"H1": {"size": 400, "speed": 500, "path": [[2400, 0], [0, 0]]}}),
        "scene.humans.H1.path[0]",
        "person H1 (400 mm square at (2400, 0)) overlaps wall",
    ),
]


@pytest.mark.parametrize(("name", "change", "field", "words"), IMPOSSIBLE, ids=[c[0] for c in IMPOSSIBLE])
def test_an_impossible_scene_is_bad_input(name, change, field, words):
    with pytest.raises(ScenarioError) as err:
        parse_scenario(_with(change))
    assert err.value.field == field
    assert words in str(err.value) and "bodies may touch but not overlap" in str(err.value)


def test_touching_is_allowed():
    def touch(d):
        d["scene"]["robots"]["R1"]["pose"] = [-2300, -1000, 0]  # flush against the west wall
        d["scene"]["robots"]["R2"]["pose"] = [-2300, -1400, 0]  # flush against R1
        d["scene"]["objects"]["O1"]["position"] = [2450, -1000]  # flush against the east wall

    scene = parse_scenario(_with(touch)).scene
    assert overlaps(scene) == []


def test_a_scene_in_metres_says_metres():
    data = _with(lambda d: None)
    data["units"] = "m"
    data["scene"]["obstacles"] = [
        [[x / 1000 for x in p] for p in wall] for wall in data["scene"]["obstacles"]
    ]
    for robot in data["scene"]["robots"].values():
        robot["size"] /= 1000
        robot["pose"] = [robot["pose"][0] / 1000, robot["pose"][1] / 1000, 0]
    for obj in data["scene"]["objects"].values():
        obj["size"] /= 1000
        obj["position"] = [v / 1000 for v in obj["position"]]
    for ws in data["scene"]["workspaces"].values():
        for key in ("x", "y"):
            if key in ws:
                ws[key] = [v / 1000 for v in ws[key]]
        if "point" in ws:
            ws["point"] = [v / 1000 for v in ws["point"]]
    parse_scenario(copy.deepcopy(data))  # touching in metres, after conversion to mm: fine
    data["scene"]["robots"]["R2"]["pose"] = [-2.0, -1.3, 0]
    with pytest.raises(ScenarioError) as err:
        parse_scenario(data)
    assert "robot R2 (0.4 m square at (-2, -1.3)) overlaps robot R1 (0.4 m square at (-2, -1))" in str(
        err.value
    )


def test_goods_in_two_task_lists_need_an_order():
    def twice(d):
        d["mission"]["tasks"]["R2"] = list(d["mission"]["tasks"]["R1"][:2]) + d["mission"]["tasks"]["R2"]

    data = _with(twice)
    for task in data["mission"]["tasks"]["R2"][:2]:
        assert "O1" in task  # the 2x2's R1 picks O1 and drops it first
    data["mission"]["tasks"]["R2"][:2] = [t.replace("R1", "R2") for t in data["mission"]["tasks"]["R2"][:2]]
    with pytest.raises(ScenarioError) as err:
        parse_scenario(data)
    assert err.value.field == "mission.tasks.R2[0]"
    assert "O1 is moved by R1 (mission.tasks.R1[0]) and by R2 with no order between them" in str(err.value)
    assert "msg(R1,R2,TAG)" in str(err.value)


def test_tasks_name_at_least_one_robot():
    with pytest.raises(ScenarioError) as err:
        parse_scenario(_with(lambda d: d["mission"].update(tasks={})))
    assert err.value.field == "mission.tasks" and "at least one robot" in str(err.value)


def test_a_dock_smaller_than_its_goods_is_bad_input():
    def small(d):
        d["scene"]["objects"]["O1"]["size"] = 300
        d["scene"]["objects"]["O1"]["position"] = [2000, 0]
        d["scene"]["workspaces"]["W1"] = {"x": [0, 200], "y": [1500, 2000]}

    with pytest.raises(ScenarioError) as err:
        parse_scenario(_with(small))
    assert err.value.field.startswith("mission.tasks.R1")
    assert "W1 (200 mm x 500 mm) cannot hold O1 (a 300 mm square)" in str(err.value)


def test_the_command_line_exits_2_naming_file_and_field(tmp_path):
    path = tmp_path / "inside.yaml"
    path.write_text(yaml.safe_dump(_with(IMPOSSIBLE[0][1])))
    for command in (["validate", str(path)], ["plan", str(path), "-o", str(tmp_path / "p.json")]):
        result = runner.invoke(app, command)
        assert result.exit_code == 2, result.output
        assert "inside.yaml" in result.stderr and "scene.robots.R1.pose" in result.stderr
        assert "Traceback" not in result.stderr
    assert not (tmp_path / "p.json").exists()


def test_every_example_is_physically_possible():
    for path in sorted(ROOT.glob("examples/*/scenario*.yaml")):
        assert overlaps(load_scenario(path).scene) == [], path
