"""Deliveries without named robots: the form, its language, the assignment and the plan."""

from __future__ import annotations

import itertools
import json
import random
from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner

from cosmop.cli import EXIT_INPUT_ERROR, app
from cosmop.errors import ScenarioError
from cosmop.missions.allocation import assign
from cosmop.missions.mission import GlobalMission
from cosmop.scenario import parse_scenario

runner = CliRunner()

SCENE = {
    "obstacles": [
        [[-3000, -2500], [3000, -2500]],
        [[3000, -2500], [3000, 2500]],
        [[3000, 2500], [-3000, 2500]],
        [[-3000, 2500], [-3000, -2500]],
    ],
    "robots": {"R1": {"size": 400, "pose": [-2000, -1500, 0]}, "R2": {"size": 400, "pose": [2000, -1500, 0]}},
    "objects": {"O1": {"size": 100, "position": [1500, 0]}, "O2": {"size": 100, "position": [-1500, 0]}},
    "workspaces": {
        "W1": {"x": [1500, 2800], "y": [1500, 2300]},
        "W2": {"x": [-2800, -1500], "y": [1500, 2300]},
    },
}


def scenario(mission: dict, scene: dict | None = None) -> dict:
    return {"name": "d", "scene": scene or SCENE, "mission": mission}


def test_the_form_reads_one_or_many_docks_and_robots():
    s = parse_scenario(
        scenario(
            {"deliveries": [{"object": "O1", "to": "W1"}, {"object": "O2", "to": ["W1", "W2"], "by": "R1"}]}
        )
    )
    (d1, d2) = s.mission.deliveries
    assert (d1.object, d1.to, d1.by) == ("O1", ("W1",), ("R1", "R2"))  # any robot by default
    assert (d2.to, d2.by) == (("W1", "W2"), ("R1",))
    assert s.mission.form == "deliveries" and not s.mission.returns
    names = {e.name for e in s.mission.events}
    assert names == {
        "pick(R1,O1)",
        "pick(R2,O1)",
        "drop(R1,O1,W1)",
        "drop(R2,O1,W1)",
        "pick(R1,O2)",
        "drop(R1,O2,W1)",
        "drop(R1,O2,W2)",
    }


@pytest.mark.parametrize(
    ("mission", "field", "fragment"),
    [
        (
            {"deliveries": [{"object": "O9", "to": "W1"}]},
            "mission.deliveries[0].object",
            "unknown object 'O9'",
        ),
        (
            {"deliveries": [{"object": "O1", "to": ["W1", "W7"]}]},
            "mission.deliveries[0].to[1]",
            "unknown workspace",
        ),
        (
            {"deliveries": [{"object": "O1", "to": "W1", "by": ["R3"]}]},
            "mission.deliveries[0].by[0]",
            "unknown robot",
        ),
        (
            {"deliveries": [{"object": "O1", "to": "W1"}, {"object": "O1", "to": "W2"}]},
            "mission.deliveries[1].object",
            "already delivered",
        ),
        ({"deliveries": [{"object": "O1", "to": []}]}, "mission.deliveries[0].to", "non-empty"),
        ({"deliveries": []}, "mission.deliveries", "non-empty"),
        ({"tasks": {"R1": ["return"]}, "return": True}, "mission.return", "goes with 'deliveries'"),
        (
            {"tasks": {"R1": ["return"]}, "deliveries": [{"object": "O1", "to": "W1"}]},
            "mission",
            "exactly one of",
        ),
        ({"deliveries": [{"object": "O1", "to": "W1"}], "return": "yes"}, "mission.return", "true or false"),
        ({"deliveries": [{"object": "O1", "to": "W1"}], "returns": True}, "mission.returns", "unknown key"),
    ],
)
def test_bad_deliveries_name_the_field(tmp_path: Path, mission, field, fragment):
    with pytest.raises(ScenarioError) as err:
        parse_scenario(scenario(mission))
    assert err.value.field == field, str(err.value)
    assert fragment in str(err.value)
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(scenario(mission)))
    result = runner.invoke(app, ["validate", str(path)])
    assert (
        result.exit_code == EXIT_INPUT_ERROR and field in result.stderr and "Traceback" not in result.stderr
    )


def test_a_workspace_too_small_for_the_object_is_bad_input():
    scene = json.loads(json.dumps(SCENE))
    # a dock 80 mm wide for a 100 mm object
    scene["workspaces"]["W3"] = {"x": [0, 80], "y": [1500, 2000]}
    with pytest.raises(ScenarioError) as err:
        parse_scenario(scenario({"deliveries": [{"object": "O1", "to": ["W1", "W3"]}]}, scene))
    assert err.value.field == "mission.deliveries[0].to[1]"
    assert "W3 (80 mm x 500 mm) cannot hold O1 (a 100 mm square)" in str(err.value)
    # wide enough, but walls every 80 mm across it leave the object's centre nowhere to go
    scene["workspaces"]["W3"] = {"x": [0, 160], "y": [1500, 2000]}
    scene["obstacles"] += [[[x, 1000], [x, 2500]] for x in (0, 80, 160)]
    with pytest.raises(ScenarioError) as err:
        parse_scenario(scenario({"deliveries": [{"object": "O1", "to": ["W1", "W3"]}]}, scene))
    assert "too small for O1" in str(err.value)
    scene["obstacles"][-2] = [[100, 1000], [100, 2500]]  # a slot exactly the object's width: it fits
    parse_scenario(scenario({"deliveries": [{"object": "O1", "to": ["W1", "W3"]}]}, scene))


def test_the_language_moves_each_object_once_and_brings_movers_home():
    s = parse_scenario(
        scenario(
            {
                "deliveries": [{"object": "O1", "to": "W1"}, {"object": "O2", "to": ["W1", "W2"]}],
                "return": True,
            }
        )
    )
    k = GlobalMission.from_scenario(s)
    good = ["pick(R2,O1)", "drop(R2,O1,W1)", "pick(R1,O2)", "drop(R1,O2,W2)", "return(R2)", "return(R1)"]
    assert k.is_complete_word(good)
    assert k.is_complete_word(
        ["pick(R1,O1)", "drop(R1,O1,W1)", "pick(R1,O2)", "drop(R1,O2,W1)", "return(R1)"]
    )
    assert not k.is_complete_word(good[:-1])  # R1 moved O2 and is not home
    assert not k.is_complete_word(good[:2] + good[4:5])  # O2 never moved
    two_at_once = ["pick(R1,O1)", "pick(R1,O2)", "drop(R1,O1,W1)", "drop(R1,O2,W2)", "return(R1)"]
    assert not k.is_complete_word(two_at_once)  # one object at a time
    swapped = ["pick(R1,O1)", "drop(R2,O1,W1)", "pick(R2,O2)", "drop(R2,O2,W2)", "return(R1)", "return(R2)"]
    assert not k.is_complete_word(swapped)  # who picks it drops it
    # compositional: one factor per object and per robot, never the product of the alternatives
    assert len(k.automaton.components) == 4
    assert max(f.n_states for f in k.automaton.components) <= 5


def test_assignment_is_the_brute_force_optimum():
    rng = random.Random(3)
    for _ in range(60):
        robots = [f"R{i}" for i in range(rng.randint(1, 3))]
        objects = [f"O{i}" for i in range(rng.randint(1, 4))]
        options, costs = {}, {}
        for o in objects:
            docks = [f"W{i}" for i in range(rng.randint(1, 2))]
            allowed = rng.sample(robots, rng.randint(1, len(robots)))
            options[o] = [(r, w) for r in allowed for w in docks]
            for r, w in options[o]:
                costs[(r, o, w)] = rng.choice([None, 2, 3, 5, 7, 8])
        got = assign(options, costs)
        best = None
        for picks in itertools.product(*(options[o] for o in objects)):
            if any(costs[(r, o, w)] is None for o, (r, w) in zip(objects, picks, strict=True)):
                continue
            loads: dict[str, int] = {}
            for o, (r, w) in zip(objects, picks, strict=True):
                loads[r] = loads.get(r, 0) + costs[(r, o, w)]
            key = (max(loads.values()), sum(loads.values()))
            best = key if best is None or key < best else best
        if best is None:
            assert got.stuck and not got.tasks
            continue
        assert got.exhaustive and (got.makespan, got.total) == best
        loads = got.loads(costs)
        assert (max(loads.values()), sum(loads.values())) == best
        assert set(got.tasks) == set(objects) and all(got.tasks[o] in options[o] for o in objects)


def test_assignment_within_a_bound_says_so():
    rng = random.Random(7)
    options = {f"O{i}": [(f"R{r}", "W") for r in range(4)] for i in range(12)}
    costs = {(r, o, "W"): rng.randint(3, 12) for o, opts in options.items() for r, _ in opts}
    cut = assign(options, costs, max_nodes=3)
    full = assign(options, costs)
    assert not cut.exhaustive and cut.nodes == 3 and full.exhaustive
    assert (full.makespan, full.total) <= (cut.makespan, cut.total)  # the greedy start is never lost
    assert set(cut.tasks) == set(options)  # cut short, still a whole assignment


def test_an_object_no_allowed_robot_can_reach_exits_1_naming_it(tmp_path: Path):
    scene = json.loads(json.dumps(SCENE))
    # O1 walled into a box in the east; only R1 and R2 exist, neither can get in
    scene["obstacles"] += [
        [[1000, -700], [2200, -700]],
        [[2200, -700], [2200, 700]],
        [[2200, 700], [1000, 700]],
        [[1000, 700], [1000, -700]],
    ]
    path = tmp_path / "walled.yaml"
    path.write_text(
        yaml.safe_dump(scenario({"deliveries": [{"object": "O1", "to": "W1"}], "return": True}, scene))
    )
    out = tmp_path / "plan.json"
    result = runner.invoke(app, ["plan", str(path), "-o", str(out)])
    assert result.exit_code == 1, result.output
    plan = json.loads(out.read_text())
    assert not plan["feasible"]
    reason = plan["reason"]
    assert "no robot can deliver O1" in reason
    assert "R1 to W1" in reason and "R2 to W1" in reason and "walls separate" in reason


def test_deliveries_plan_and_record_the_allocation(tmp_path: Path):
    path = tmp_path / "d.yaml"
    path.write_text(
        yaml.safe_dump(
            scenario(
                {
                    "deliveries": [{"object": "O1", "to": "W1"}, {"object": "O2", "to": ["W1", "W2"]}],
                    "return": True,
                }
            )
        )
    )
    out = tmp_path / "plan.json"
    result = runner.invoke(app, ["plan", str(path), "-o", str(out)])
    assert result.exit_code == 0, result.output
    plan = json.loads(out.read_text())
    # each robot takes the good on its side, to the dock on its side
    assert plan["allocation"] == {"O1": "R2", "O2": "R1"}
    assert plan["robots"]["R1"]["mission"] == ["pick(R1,O2)", "drop(R1,O2,W2)", "return(R1)"]
    assert plan["robots"]["R2"]["mission"] == ["pick(R2,O1)", "drop(R2,O1,W1)", "return(R2)"]


def test_decompose_says_deliveries_need_a_choice_first():
    path = Path(__file__).resolve().parents[1] / "examples" / "05_deliveries" / "scenario.yaml"
    result = runner.invoke(app, ["decompose", str(path)])
    assert result.exit_code == 1 and "cosmop plan" in result.stdout and "Traceback" not in result.output
