"""Plan values and the plan file ``cosmop.plan/1``: round trips, states, text, and bad files."""

from __future__ import annotations

import copy
import json
import pickle
from pathlib import Path
from typing import Any

import pytest

from cosmop.errors import CosmopInputError
from cosmop.io import write_atomic
from cosmop.planning import (
    PLAN_FORMAT,
    Coordination,
    ObjectState,
    ObjectStates,
    PlanError,
    PlanSet,
    RobotPlan,
    State,
    Step,
    initial_state,
    load_plan,
    plan_from_actions,
    successor,
)
from cosmop.planning.plan_file import read_plan
from cosmop.planning.primitive_effects import scenario_objects
from cosmop.scenario import load_scenario

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "01_warehouse_2x2" / "scenario.yaml"
SCENE = load_scenario(EXAMPLE).scene

from handmade_plans import R1_ACTIONS, R1_MISSION  # noqa: E402
from handmade_plans import R2_RES_ACTIONS as R2_ACTIONS  # noqa: E402
from handmade_plans import R2_RES_MISSION as R2_MISSION  # noqa: E402


def plan_set() -> PlanSet:
    return PlanSet(
        "warehouse-2x2",
        True,
        {
            "R1": plan_from_actions(SCENE, "R1", R1_MISSION, R1_ACTIONS),
            "R2": plan_from_actions(SCENE, "R2", R2_MISSION, R2_ACTIONS),
        },
        (Coordination("O2", "R1", "R2"),),
    )


# ----------------------------------------------------------------------------------------------
# Values and round trips
# ----------------------------------------------------------------------------------------------


def test_to_dict_has_the_documented_shape() -> None:
    data = plan_set().to_dict()
    assert list(data) == ["format", "scenario", "feasible", "units", "robots", "coordination", "messages"]
    assert data["format"] == PLAN_FORMAT == "cosmop.plan/1"
    r1 = data["robots"]["R1"]
    assert r1["mission"] == [e.name for e in R1_MISSION]
    assert r1["horizon"] == 7 == len(r1["steps"])
    assert r1["steps"][0] == {
        "primitive": "Req",
        "object": "O2",
        "robot": [-2000, -1000, 0],
        "objects": {
            "O1": {"position": [2000, -1000], "carried": False, "away": False},
            "O2": {"position": [1900, -1000], "carried": False, "away": True},
        },
    }
    assert r1["steps"][1]["object"] is None
    assert all(isinstance(v, int) for v in r1["steps"][1]["robot"])  # integral values as integers
    assert data["coordination"] == [{"object": "O2", "requester": "R1", "responder": "R2"}]


def test_dict_round_trip() -> None:
    plans = plan_set()
    assert read_plan(plans.to_dict()) == plans
    assert read_plan(json.loads(json.dumps(plans.to_dict()))) == plans


def test_save_and_load_round_trip(tmp_path: Path) -> None:
    plans = plan_set()
    path = tmp_path / "plan.json"
    plans.save(path)
    assert load_plan(path) == plans
    assert json.loads(path.read_text(encoding="utf-8"))["format"] == "cosmop.plan/1"
    assert path.read_text(encoding="utf-8").endswith("}\n")
    assert [p.name for p in tmp_path.iterdir()] == ["plan.json"]  # no temporary file left behind


def test_decimal_coordinates_round_trip(tmp_path: Path) -> None:
    step = Step("GoTo", None, (1199.9, -0.25, 12.5), {"O1": ObjectState((0.1, 2000), False, False)})
    plans = PlanSet("s", True, {"R1": RobotPlan.from_steps([], [step])})
    path = tmp_path / "plan.json"
    plans.save(path)
    assert load_plan(path) == plans
    assert json.loads(path.read_text())["robots"]["R1"]["steps"][0]["robot"] == [1199.9, -0.25, 12.5]


def test_infeasible_plan_set_round_trip(tmp_path: Path) -> None:
    plans = PlanSet("warehouse-2x2", False, {}, reason="R1 cannot reach O1: the walls enclose it")
    assert plans.to_dict() == {
        "format": "cosmop.plan/1",
        "scenario": "warehouse-2x2",
        "feasible": False,
        "units": {"length": "mm", "angle": "deg", "time": "s"},
        "reason": "R1 cannot reach O1: the walls enclose it",
        "robots": {},
        "coordination": [],
        "messages": [],
    }
    plans.save(tmp_path / "p.json")
    assert load_plan(tmp_path / "p.json") == plans


def test_the_design_example_loads(tmp_path: Path) -> None:
    text = """{
      "format": "cosmop.plan/1",
      "scenario": "warehouse-2x2",
      "feasible": true,
      "robots": {
        "R1": {
          "mission": ["away(O2,R1,R2)", "R1pO1", "drop O1 at W1", "r1"],
          "horizon": 1,
          "steps": [
            {"primitive": "Req", "object": "O2",
             "robot": [-2000, -1000, 0],
             "objects": {"O1": {"position": [2000, -1000], "carried": false, "away": false},
                         "O2": {"position": [1900, -1000], "carried": false, "away": true}}}
          ]
        }
      },
      "coordination": [{"object": "O2", "requester": "R1", "responder": "R2"}]
    }"""
    path = tmp_path / "plan.json"
    write_atomic(path, text)
    plans = load_plan(path)
    # every accepted event form is stored canonically
    assert plans.robots["R1"].mission == tuple(R1_MISSION)
    assert plans.robots["R1"].steps[0].objects["O2"] == ObjectState((1900, -1000), carried=False, away=True)
    assert plans.coordination[0].event.name == "away(O2,R1,R2)"
    assert plans.reason is None


def test_plan_values_are_read_only() -> None:
    plans = plan_set()
    with pytest.raises(TypeError):
        plans.robots["R3"] = plans.robots["R1"]  # type: ignore[index]
    with pytest.raises(TypeError):
        plans.robots["R1"].steps[0].objects["O1"] = ObjectState((0, 0))  # type: ignore[index]
    assert isinstance(plans.robots["R1"].steps, tuple)


def test_constructor_validation() -> None:
    objects = {"O1": ObjectState((0, 0))}
    with pytest.raises(ValueError, match="unknown primitive 'Goto'"):
        Step("Goto", None, (0, 0, 0), objects)
    with pytest.raises(ValueError, match="PickUp needs the object"):
        Step("PickUp", None, (0, 0, 0), objects)
    with pytest.raises(ValueError, match="GoTo acts on no object"):
        Step("GoTo", "O1", (0, 0, 0), objects)
    with pytest.raises(ValueError, match="needs 3 numbers"):
        Step("GoTo", None, (0, 0), objects)
    with pytest.raises(ValueError, match="horizon 2 differs from the number of steps 1"):
        RobotPlan((), 2, (Step("GoTo", None, (0, 0, 0), objects),))
    with pytest.raises(ValueError, match="needs a reason"):
        PlanSet("s", False, {})
    with pytest.raises(TypeError, match="holds Event values"):
        RobotPlan(("pick(R1,O1)",), 0, ())  # text is parsed where it is read


# ----------------------------------------------------------------------------------------------
# States and text
# ----------------------------------------------------------------------------------------------


def test_initial_state_is_the_scenario() -> None:
    state = initial_state(SCENE, "R2")
    assert state.robot == (-2000.0, -2000.0, 0.0)
    assert state.objects == {
        "O1": ObjectState((2000, -1000), carried=False, away=False),
        "O2": ObjectState((1900, -1000), carried=False, away=False),
    }


def test_state_at_an_instant() -> None:
    plan = plan_set().robots["R1"]
    initial = initial_state(SCENE, "R1")
    assert plan.state(0, initial) is initial
    assert plan.state(1) == State((-2000, -1000, 0), plan.steps[0].objects)
    assert plan.state(3).objects["O1"].carried
    assert plan.state(6).objects["O1"] == ObjectState((-1250, 2050), carried=False, away=False)
    assert plan.state(7).robot == initial.robot
    with pytest.raises(ValueError, match="instant 0 is the scenario"):
        plan.state(0)
    with pytest.raises(IndexError):
        plan.state(8)
    with pytest.raises(IndexError):
        plan.state(-1)


def test_successor_effects() -> None:
    start = initial_state(SCENE, "R1")
    moved = successor(SCENE, "R1", start, "GoTo", to=(1750, -1000, 0))
    assert moved.robot == (1750, -1000, 0) and moved.objects == start.objects
    picked = successor(SCENE, "R1", moved.state, "PickUp", "O1")
    assert picked.objects["O1"].carried and picked.robot == moved.robot
    dropped = successor(SCENE, "R1", picked.state, "DropOff", "O1")
    assert dropped.objects["O1"] == ObjectState((2000, -1000), carried=False, away=False)
    requested = successor(SCENE, "R1", start, "Req", "O2")
    assert requested.objects["O2"].away
    with pytest.raises(ValueError, match="GoTo needs a target pose"):
        successor(SCENE, "R1", start, "GoTo")


def test_to_text_is_one_line_per_step() -> None:
    plan = plan_set().robots["R1"]
    lines = plan.to_text().splitlines()
    assert len(lines) == plan.horizon == 7
    assert lines[0] == "1  Req(O2)      robot (-2000, -1000, 0°)  away: O2"
    assert lines[2] == "3  PickUp(O1)   robot (1750, -1000, 0°)  carrying O1; away: O2"
    assert lines[5] == "6  DropOff(O1)  robot (-1500, 2050, 0°)  O1 at (-1250, 2050); away: O2"


def test_plan_set_text() -> None:
    text = plan_set().to_text()
    assert text.splitlines()[0] == "plan for warehouse-2x2: feasible"
    assert "R2 (7 steps): pick(R2,O2), away(O2,R1,R2), drop(R2,O2,W2), return(R2)" in text
    assert text.splitlines()[-1] == "coordination: R2 moves O2 away for R1"


# ----------------------------------------------------------------------------------------------
# Bad plan files
# ----------------------------------------------------------------------------------------------


def _set(data: dict[str, Any], path: tuple, value: Any) -> None:
    target = data
    for key in path[:-1]:
        target = target[key]
    if value is _DELETE:
        del target[path[-1]]
    else:
        target[path[-1]] = value


_DELETE = object()
_STEP = ("robots", "R1", "steps")

_NUMBER = "expected a finite number, got"
_ID = "([A-Za-z_][A-Za-z0-9_-]*)"

# the field, then the start of the message after it (the whole of it, but for long event errors)
BAD_FILES = [
    (
        ("format",),
        "cosmop.plan/2",
        "format",
        "expected 'cosmop.plan/1', the plan file format, got 'cosmop.plan/2'",
    ),
    (
        ("format",),
        _DELETE,
        "format",
        "missing required key 'format': expected 'cosmop.plan/1', the plan file format",
    ),
    (("feasible",), "true", "feasible", "expected true or false (whether a plan was found), got 'true'"),
    (
        ("feasible",),
        False,
        "reason",
        "expected a reason a person can act on (the plan is infeasible), got nothing",
    ),
    (
        ("robots",),
        [],
        "robots",
        "expected a mapping from robot ids to plans {mission, horizon, steps}, got []",
    ),
    (
        (*_STEP, 3, "primitive"),
        "Goto",
        "robots.R1.steps[3].primitive",
        "expected one of GoTo, PickUp, DropOff, Req, Res, got 'Goto'",
    ),
    (
        (*_STEP, 2, "object"),
        None,
        "robots.R1.steps[2].object",
        "expected the id of the object PickUp acts on, got nothing (null)",
    ),
    (
        (*_STEP, 2, "object"),
        _DELETE,
        "robots.R1.steps[2].object",
        "expected the id of the object PickUp acts on, got nothing",
    ),
    (
        (*_STEP, 0, "object"),
        _DELETE,
        "robots.R1.steps[0].object",
        "expected the id of the object Req acts on, got nothing",
    ),
    (
        (*_STEP, 1, "object"),
        "O1",
        "robots.R1.steps[1].object",
        "expected null (GoTo acts on no object), got 'O1'",
    ),
    (
        (*_STEP, 2, "object"),
        "O9",
        "robots.R1.steps[2].object",
        "expected one of the step's objects (O1, O2), got 'O9'",
    ),
    (("robots", "R1", "horizon"), 6, "robots.R1.horizon", "expected the number of steps, 7, got 6"),
    (
        ("robots", "R1", "horizon"),
        7.0,
        "robots.R1.horizon",
        "expected the number of steps, an integer >= 0, got 7.0",
    ),
    (
        ("robots", "R1", "horizon"),
        True,
        "robots.R1.horizon",
        "expected the number of steps, an integer >= 0, got true",
    ),
    (
        (*_STEP, 0, "robot"),
        [1, 2],
        "robots.R1.steps[0].robot",
        "expected a list [x, y, heading] (mm, mm, degrees), got [1, 2]",
    ),
    (
        (*_STEP, 0, "robot"),
        "here",
        "robots.R1.steps[0].robot",
        "expected a list [x, y, heading] (mm, mm, degrees), got 'here'",
    ),
    ((*_STEP, 0, "robot", 2), None, "robots.R1.steps[0].robot[2]", f"{_NUMBER} nothing (null)"),
    ((*_STEP, 0, "robot", 0), True, "robots.R1.steps[0].robot[0]", f"{_NUMBER} true"),
    (
        (*_STEP, 4, "objects", "O1", "position"),
        [1],
        "robots.R1.steps[4].objects.O1.position",
        "expected a list [x, y] (mm), got [1]",
    ),
    (
        (*_STEP, 4, "objects", "O1", "carried"),
        "yes",
        "robots.R1.steps[4].objects.O1.carried",
        "expected true or false (whether this robot carries it), got 'yes'",
    ),
    (
        (*_STEP, 4, "objects", "O1", "away"),
        _DELETE,
        "robots.R1.steps[4].objects.O1.away",
        "missing required key 'away': expected true or false (whether another robot has moved it away)",
    ),
    (
        (*_STEP, 4, "objects"),
        [],
        "robots.R1.steps[4].objects",
        "expected a mapping from object ids to states {position, carried, away}, got []",
    ),
    (
        (*_STEP, 0, "colour"),
        "red",
        "robots.R1.steps[0].colour",
        "unknown key 'colour'; expected one of: primitive, object, message, start, end, robot, objects",
    ),
    (
        (*_STEP, 0),
        "GoTo",
        "robots.R1.steps[0]",
        "expected a step {primitive, object, robot, objects}, got 'GoTo'",
    ),
    (("robots", "R1", "steps"), {}, "robots.R1.steps", "expected a list of at most 1,000 steps, got {}"),
    (
        ("robots", "R1", "mission", 1),
        "grab(R1,O1)",
        "robots.R1.mission[1]",
        "invalid event 'grab(R1,O1)': unknown event kind 'grab'; accepted forms: pick(R,O);",
    ),
    (
        ("robots", "R1", "mission", 1),
        7,
        "robots.R1.mission[1]",
        "expected an event such as 'pick(R1,O1)' (text), got 7",
    ),
    (
        ("robots", "R1", "mission"),
        "pick(R1,O1)",
        "robots.R1.mission",
        "expected a list of events such as 'pick(R1,O1)', got 'pick(R1,O1)'",
    ),
    (
        ("robots", "R1", "extra"),
        1,
        "robots.R1.extra",
        "unknown key 'extra'; expected one of: mission, horizon, steps",
    ),
    (("robots", "R1 x"), {}, "robots['R1 x']", f"expected a robot id {_ID}, got 'R1 x'"),
    (
        ("coordination",),
        {},
        "coordination",
        "expected a list of pairs {object, requester, responder}, got {}",
    ),
    (
        ("coordination", 0, "responder"),
        "R1",
        "coordination[0].responder",
        "expected a robot other than the requester 'R1', got 'R1'",
    ),
    (
        ("coordination", 0, "object"),
        _DELETE,
        "coordination[0].object",
        f"missing required key 'object': expected an object id {_ID}",
    ),
]


@pytest.mark.parametrize(("path", "value", "field", "fragment"), BAD_FILES)
def test_bad_plan_files_name_file_field_and_expectation(
    tmp_path: Path, path: tuple, value: Any, field: str | None, fragment: str
) -> None:
    data = copy.deepcopy(plan_set().to_dict())
    _set(data, path, value)
    file = tmp_path / "plan.json"
    write_atomic(file, json.dumps(data))
    with pytest.raises(PlanError) as info:
        load_plan(file)
    err = info.value
    assert isinstance(err, CosmopInputError)
    assert (err.file, err.field) == (str(file), field)
    assert err.expected.startswith(fragment)
    (line,) = str(err).splitlines()  # one line: the file, the field, what was expected and found
    assert line.startswith(f"{file}: {field}: {fragment}")


def test_from_dict_without_a_file() -> None:
    data = plan_set().to_dict()
    data["robots"]["R1"]["steps"][3]["primitive"] = "Fly"
    with pytest.raises(PlanError) as info:
        read_plan(data)
    assert str(info.value) == (
        "robots.R1.steps[3].primitive: expected one of GoTo, PickUp, DropOff, Req, Res, got 'Fly'"
    )


@pytest.mark.parametrize(
    ("content", "fragment", "line"),
    [
        ('{"format": "cosmop.plan/1",\n "scenario": }', "invalid JSON: Expecting value", 2),
        ("", "the file is empty", None),
        (
            "[1, 2]",
            "expected a JSON object with keys format, scenario, feasible, robots (a cosmop.plan/1 file), "
            "got [1, 2]",
            None,
        ),
        # a value the parser refuses: the field and its line are named
        ('{"format": "cosmop.plan/1",\n "format": "x"}', "format: invalid JSON: duplicate key 'format'", 2),
        ('{"a": NaN}', "a: invalid JSON: NaN is not a number", 1),
        ('{"robots": {"R1": {"steps": [{},\n {"robot": [1e999, 0, 0]}]}}}', "robots.R1.steps[1].robot[0]", 2),
    ],
)
def test_unreadable_plan_files(tmp_path: Path, content: str, fragment: str, line: int | None) -> None:
    file = tmp_path / "plan.json"
    write_atomic(file, content)
    with pytest.raises(PlanError) as info:
        load_plan(file)
    assert str(info.value).startswith(f"{file}: ")
    assert fragment in str(info.value)
    assert info.value.line == line


def test_missing_plan_file(tmp_path: Path) -> None:
    with pytest.raises(PlanError) as info:
        load_plan(tmp_path / "absent.json")
    assert str(info.value) == f"{tmp_path / 'absent.json'}: file not found"


# ----------------------------------------------------------------------------------------------
# the objects' states of a step: one checked, shared map


def test_object_states_are_checked_once_and_shared_by_the_steps_that_keep_them() -> None:
    states = ObjectStates({"O1": ObjectState((1.0, 2.0)), "O2": ObjectState((3.0, 4.0))})
    with pytest.raises(TypeError, match="O3"):
        ObjectStates({"O3": (1.0, 2.0)})  # type: ignore[dict-item]
    step = Step("GoTo", None, (0.0, 0.0, 0.0), states)
    assert step.objects is states and State((0.0, 0.0, 0.0), states).objects is states
    moved = states.updated({"O1": ObjectState((1.0, 2.0), carried=True)})
    assert list(moved) == ["O1", "O2"] and moved["O1"].carried and not states["O1"].carried
    assert states.updated({}) is states
    with pytest.raises(TypeError):
        states.updated({"O2": "here"})  # type: ignore[dict-item]
    assert states == {"O1": ObjectState((1.0, 2.0)), "O2": ObjectState((3.0, 4.0))}
    assert states != moved and states != {"O1": ObjectState((1.0, 2.0))}
    assert pickle.loads(pickle.dumps(states)) == states
    with pytest.raises(TypeError):
        hash(states)
    # a plain mapping given to a step is checked and made one
    plain = Step("GoTo", None, (0.0, 0.0, 0.0), {"O1": ObjectState((1.0, 2.0))})
    assert isinstance(plain.objects, ObjectStates)


def test_scenario_objects_are_made_once_and_moved_goods_start_where_the_plan_lists_them() -> None:
    assert scenario_objects(SCENE) is scenario_objects(SCENE)
    assert {o: s.position for o, s in scenario_objects(SCENE).items()} == {
        o: tuple(ob.position) for o, ob in SCENE.objects.items()
    }
    robot, obj = next(iter(SCENE.robots)), next(iter(SCENE.objects))
    elsewhere = scenario_objects(SCENE).updated({obj: ObjectState((123.0, 456.0))})
    first = Step(
        "PickUp", obj, SCENE.robots[robot].pose, elsewhere.updated({obj: ObjectState((123.0, 456.0), True)})
    )
    start = initial_state(SCENE, robot, [first])
    assert start.objects[obj] == ObjectState((123.0, 456.0))
    assert all(start.objects[o] is scenario_objects(SCENE)[o] for o in SCENE.objects if o != obj)
