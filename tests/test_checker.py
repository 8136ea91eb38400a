"""The exact plan checker on hand-made plans for the 2x2 warehouse (paper, Example 1).

Robots are squares of side 400 mm, objects of side 100 mm, so d = (400 + 100)/2 = 250 mm: a robot
picks O1 (2000, -1000) from (1750, -1000), where its square overlaps O2 (1900, -1000) unless O2
has been moved away -- hence R1's Req(O2). Each rule test makes one small edit to a valid plan
and expects exactly the violation that edit causes.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import LineString, box

from cosmop.events import parse_event
from cosmop.planning import (
    RULES,
    CheckReport,
    Coordination,
    ObjectState,
    PlanSet,
    RobotPlan,
    Step,
    Violation,
    check_robot_plan,
    overlaps,
    plan_from_actions,
    square,
    swept_square,
)
from cosmop.planning.plan_types import PlanMessage
from cosmop.scenario import load_scenario, parse_scenario
from cosmop.team.plan_set_checker import check_plan
from cosmop.team.safe_plans import make_team_safe

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "01_warehouse_2x2" / "scenario.yaml"
SCENARIO = load_scenario(EXAMPLE)
SCENE = SCENARIO.scene

from handmade_plans import (  # noqa: E402 - the shared hand-made plans
    R1_ACTIONS,
    R1_MISSION,
    R2_ACTIONS,
    R2_MISSION,
    R2_RES_ACTIONS,
    R2_RES_MISSION,
)


def _events(mission) -> list:
    """The mission as events (the tests write some events as text)."""
    return [parse_event(e) if isinstance(e, str) else e for e in mission]


def r1_plan(actions=R1_ACTIONS, mission=R1_MISSION) -> RobotPlan:
    return plan_from_actions(SCENE, "R1", _events(mission), actions)


def r2_plan(actions=R2_ACTIONS, mission=R2_MISSION) -> RobotPlan:
    return plan_from_actions(SCENE, "R2", _events(mission), actions)


def coordinated() -> PlanSet:
    return PlanSet(
        "warehouse-2x2",
        True,
        {"R1": r1_plan(), "R2": r2_plan(R2_RES_ACTIONS, R2_RES_MISSION)},
        (Coordination("O2", "R1", "R2"),),
    )


def replaced(actions, index: int, action) -> list:
    """The actions with ``actions[index]`` (step ``index + 1``) replaced."""
    result = list(actions)
    result[index] = action
    return result


def edit_step(plan: RobotPlan, k: int, **changes) -> RobotPlan:
    """The plan with fields of step ``k`` (1-based) changed."""
    steps = list(plan.steps)
    steps[k - 1] = dataclasses.replace(steps[k - 1], **changes)
    return RobotPlan(plan.mission, plan.horizon, tuple(steps))


def edit_object(plan: RobotPlan, k: int, oid: str, **changes) -> RobotPlan:
    """The plan with the state of object `oid` in step ``k`` changed."""
    objects = dict(plan.steps[k - 1].objects)
    objects[oid] = dataclasses.replace(objects[oid], **changes)
    return edit_step(plan, k, objects=objects)


def only(violations: list[Violation], rule: str, instant: int | None) -> Violation:
    assert len(violations) == 1, "\n".join(v.message for v in violations)
    (violation,) = violations
    assert (violation.rule, violation.instant) == (rule, instant), violation.message
    assert violation.rule in RULES
    return violation


# ----------------------------------------------------------------------------------------------
# The valid plans
# ----------------------------------------------------------------------------------------------


def test_r1_plan_with_request_is_valid() -> None:
    plan = r1_plan()
    assert plan.horizon == 7
    assert [s.label for s in plan.steps] == [
        "Req(O2)",
        "GoTo",
        "PickUp(O1)",
        "GoTo",
        "GoTo",
        "DropOff(O1)",
        "GoTo",
    ]
    assert plan.steps[5].objects["O1"].position == (-1250.0, 2050.0)
    assert check_robot_plan(SCENE, "R1", plan) == []


def test_r2_plan_alone_is_valid_with_two_gotos_home() -> None:
    plan = r2_plan()
    assert plan.horizon == 6
    assert plan.steps[3].objects["O2"].position == (1250.0, 2050.0)  # dropped facing north
    assert check_robot_plan(SCENE, "R2", plan) == []


def test_each_plan_is_valid_but_the_team_may_meet() -> None:
    # R1 drives to (1750, -1000) as soon as R2 has answered, while R2 still stands at
    # (1650, -1000) holding O2: each plan is sound alone, the two together are not
    report = check_plan(SCENARIO, coordinated())
    assert not report.ok and {v.rule for v in report.violations} == {"conflict"}
    first = report.violations[0].message
    assert "R1" in first and "R2" in first and "no message orders them" in first


def test_team_safe_plan_set_is_valid() -> None:
    plans = coordinated()
    safe = make_team_safe(SCENE, plans.robots)
    assert safe.safe and safe.messages and safe.conflicts > safe.ordered_before
    ordered = dataclasses.replace(plans, robots=safe.plans, messages=safe.messages)
    report = check_plan(SCENARIO, ordered)
    assert report == CheckReport(True, (), sum(p.horizon for p in safe.plans.values()))
    assert report.to_dict()["violations"] == []


def test_a_message_nobody_sends_is_a_violation() -> None:
    plans = coordinated()
    safe = make_team_safe(SCENE, plans.robots)
    name = safe.messages[0].event
    sender = safe.messages[0].sender
    muted = dataclasses.replace(
        safe.plans[sender],
        steps=tuple(s for s in safe.plans[sender].steps if s.message != name),
        horizon=safe.plans[sender].horizon - 1,
        mission=tuple(e for e in safe.plans[sender].mission if e != name),
    )
    robots = dict(safe.plans) | {sender: muted}
    report = check_plan(SCENARIO, dataclasses.replace(plans, robots=robots, messages=safe.messages))
    rules = {v.rule for v in report.violations}
    assert "message" in rules and "deadlock" in rules
    assert any("never sends" in v.message for v in report.violations)


def test_a_request_nobody_answers_is_a_violation() -> None:
    # R1 keeps its Req(O2), but the away(O2,R1,R2) that R2 would answer is gone from the file
    plans = coordinated()
    safe = make_team_safe(SCENE, plans.robots)
    robots = {
        r: dataclasses.replace(p, mission=tuple(e for e in p.mission if e.kind != "away"))
        for r, p in safe.plans.items()
    }
    r1 = robots["R1"]
    unasked = dataclasses.replace(plans, robots=robots, messages=safe.messages, coordination=())
    report = check_plan(SCENARIO, unasked)
    instant = next(k for k, s in enumerate(r1.steps, 1) if s.primitive == "Req" and s.object == "O2")
    (v,) = [v for v in report.violations if "no robot answers" in v.message]
    assert (v.robot, v.instant, v.rule) == ("R1", instant, "message")
    assert not report.ok


def test_messages_that_wait_on_each_other_deadlock() -> None:
    # R1 waits for R2's message before sending its own, R2 waits for R1's first: nobody moves
    r1 = plans_with_messages("R1", [("Req", "msg(R2,R1,a)"), ("Res", "msg(R1,R2,b)")])
    r2 = plans_with_messages("R2", [("Req", "msg(R1,R2,b)"), ("Res", "msg(R2,R1,a)")])
    messages = tuple(PlanMessage(parse_event(m), "order", "test") for m in ("msg(R2,R1,a)", "msg(R1,R2,b)"))
    scenario = parse_scenario(
        {
            "name": "two",
            "scene": {
                "robots": {"R1": {"size": 400, "pose": [0, 0, 0]}, "R2": {"size": 400, "pose": [2000, 0, 0]}}
            },
            # the plans' own missions: an empty mission is refused, and each message is listed
            # by both its sender and its receiver
            "mission": {
                "tasks": {"R1": ["msg(R2,R1,a)", "msg(R1,R2,b)"], "R2": ["msg(R1,R2,b)", "msg(R2,R1,a)"]}
            },
        }
    )
    report = check_plan(scenario, PlanSet("two", True, {"R1": r1, "R2": r2}, messages=messages))
    (v,) = report.violations
    assert v.rule == "deadlock" and "R1 at instant 1" in v.message and "R2 at instant 1" in v.message


def plans_with_messages(robot: str, steps) -> RobotPlan:
    pose = (0, 0, 0) if robot == "R1" else (2000, 0, 0)
    made = [Step(p, None, pose, {}, parse_event(m)) for p, m in steps]
    return RobotPlan.from_steps([parse_event(m) for _, m in steps], made)


def test_instant_zero_is_the_scenario() -> None:
    # a return at instant 0 is realised by the initial pose itself
    plan = plan_from_actions(SCENE, "R1", [parse_event("return(R1)")], [])
    assert check_robot_plan(SCENE, "R1", plan) == []


# ----------------------------------------------------------------------------------------------
# GoTo
# ----------------------------------------------------------------------------------------------


def test_goto_crossing_a_wall() -> None:
    # the waypoint below the gap moved right, under the inner wall: going up from there crosses it
    plan = r1_plan(replaced(R1_ACTIONS, 3, ("GoTo", (-900, -200, 0))))
    v = only(check_robot_plan(SCENE, "R1", plan), "wall", 5)
    assert v.robot == "R1"
    assert v.message.startswith("R1 at instant 5: GoTo from (-900, -200) to (-1500, 2050) crosses wall ")
    assert "[[-1000,0],[1000,0]]" in v.message


def test_goto_crossing_the_wall_by_a_tenth_of_a_millimetre() -> None:
    # R2 goes home past the inner wall's end (1000, 0); 0.1 mm further left and its square cuts it
    actions = [(p, (1199.9, *x[1:])) if p == "GoTo" and x[0] == 1250 else (p, x) for p, x in R2_ACTIONS]
    v = only(check_robot_plan(SCENE, "R2", r2_plan(actions)), "wall", 5)
    assert "GoTo from (1199.9, 1800) to (1199.9, -2000) crosses wall [[-1000,0],[1000,0]]" in v.message


def test_touching_a_wall_exactly_is_allowed() -> None:
    # R2's square passes the inner wall's end point with its left edge exactly on it (x = 1000),
    # and slides along the bottom wall (its lower edge on y = -2500) on the way home.
    actions = [(p, (1200, *x[1:])) if p == "GoTo" and x[0] == 1250 else (p, x) for p, x in R2_ACTIONS]
    actions = [*actions[:-1], ("GoTo", (-2000, -2300, 0)), ("GoTo", (-2300, -2300, 0)), actions[-1]]
    plan = r2_plan(actions)
    assert plan.steps[3].objects["O2"].position == (1200.0, 2050.0)
    assert check_robot_plan(SCENE, "R2", plan) == []


def test_touching_a_wall_along_an_edge_at_the_end_of_a_goto() -> None:
    # the waypoint's top edge lies on the inner wall (y = 0): allowed; the next GoTo then crosses it
    plan = r1_plan(replaced(R1_ACTIONS, 3, ("GoTo", (-800, -200, 0))))
    only(check_robot_plan(SCENE, "R1", plan), "wall", 5)


def test_goto_clipping_a_resting_object() -> None:
    # without the request, going to O1's pick pose sweeps over O2 (and so does leaving it)
    plan = r1_plan(R1_ACTIONS[1:], R1_MISSION[1:])
    violations = check_robot_plan(SCENE, "R1", plan)
    assert [(v.instant, v.rule) for v in violations] == [(1, "object-collision"), (3, "object-collision")]
    assert violations[0].message == (
        "R1 at instant 1: GoTo from (-2000, -1000) to (1750, -1000) sweeps over O2, resting at "
        "(1900, -1000) (size 100 mm); go around it or request it away with Req(O2)"
    )


def test_goto_sweep_between_two_clear_squares_hits_an_object() -> None:
    # both end squares are clear of O1; the swept area between them is not
    plan = r1_plan([("Req", "O2"), ("GoTo", (1700, -1500, 0)), ("GoTo", (2300, -700, 0))], ["away(O2,R1,R2)"])
    assert not overlaps(square(1700, -1500, 400), square(2000, -1000, 100))
    assert not overlaps(square(2300, -700, 400), square(2000, -1000, 100))
    v = only(check_robot_plan(SCENE, "R1", plan), "object-collision", 3)
    assert "sweeps over O1" in v.message


def test_goto_touching_a_resting_object_is_allowed() -> None:
    # R2's pick pose: its square touches O2 along an edge
    plan = r2_plan(R2_ACTIONS[:1], [])
    assert check_robot_plan(SCENE, "R2", plan) == []


def test_goto_must_not_change_flags() -> None:
    plan = edit_object(r1_plan(), 4, "O1", carried=False)
    violations = check_robot_plan(SCENE, "R1", plan)
    # instant 4 drops the carried flag by GoTo, instant 5 (a GoTo too) raises it again
    assert [(v.instant, v.rule) for v in violations] == [(4, "carried"), (5, "carried")]
    assert "the carried flag of O1 changes from true to false" in violations[0].message


def test_goto_may_turn_the_robot() -> None:
    plan = r1_plan(replaced(R1_ACTIONS, 3, ("GoTo", (-1500, -200, 90))))
    assert check_robot_plan(SCENE, "R1", plan) == []


def test_carried_object_keeps_its_pick_position() -> None:
    # moving O1 along with the robot contradicts phi_carry: positions change only on DropOff
    plan = r1_plan()
    plan = edit_object(plan, 4, "O1", position=(-1250, 2000))
    plan = edit_object(plan, 5, "O1", position=(-1250, 2000))
    v = only(check_robot_plan(SCENE, "R1", plan), "position", 4)
    assert "O1 moves from (2000, -1000) to (-1250, 2000)" in v.message
    assert "a carried object stays where it was picked up" in v.message


# ----------------------------------------------------------------------------------------------
# PickUp
# ----------------------------------------------------------------------------------------------


def test_picking_from_the_wrong_pose() -> None:
    actions = replaced(R1_ACTIONS, 1, ("GoTo", (1740, -1000, 0)))
    v = only(check_robot_plan(SCENE, "R1", r1_plan(actions)), "pick-pose", 3)
    assert v.message == (
        "R1 at instant 3, PickUp(O1): the robot is at (1740, -1000), but picking O1 at (2000, -1000) "
        "at heading 0° requires standing in front of it at (1750, -1000) (d = 250 mm)"
    )


def test_picking_facing_another_side_needs_that_sides_pose() -> None:
    # facing north (90°) from the west pose: the pose of heading 90 is below O1
    actions = replaced(R1_ACTIONS, 1, ("GoTo", (1750, -1000, 90)))
    v = only(check_robot_plan(SCENE, "R1", r1_plan(actions)), "pick-pose", 3)
    assert "at heading 90° requires standing in front of it at (2000, -1250)" in v.message


@pytest.mark.parametrize("heading", [45, 10, 300])
def test_picking_at_a_heading_that_faces_no_side(heading: float) -> None:
    actions = replaced(R1_ACTIONS, 1, ("GoTo", (1750, -1000, heading)))
    v = only(check_robot_plan(SCENE, "R1", r1_plan(actions)), "pick-pose", 3)
    assert f"heading is {heading}°" in v.message and "0°, 90°, 180° or 270°" in v.message


@pytest.mark.parametrize(
    ("pose", "heading"), [((2250, -1000), 180), ((2000, -1250), 90), ((2000, -750), 270), ((2000, -750), -90)]
)
def test_picking_from_each_free_side_is_valid(pose, heading) -> None:
    # O1's east, south and north sides are free: no request is needed from there
    actions = [
        ("GoTo", (pose[0], -1500, 0)),
        ("GoTo", (*pose, heading)),
        ("PickUp", "O1"),
        ("GoTo", (pose[0], -1500, 0)),
        ("GoTo", (-1500, -200, 0)),
        *R1_ACTIONS[4:],
    ]
    if pose[1] > -1000:  # from the north: go round O1's east side, not through O2
        actions = [("GoTo", (2250, -1500, 0)), ("GoTo", (2250, -750, 0)), *actions[1:]]
        actions[4] = ("GoTo", (2250, -750, 0))
        actions.insert(5, ("GoTo", (2250, -1500, 0)))
    plan = r1_plan(actions, ["pick(R1,O1)", "drop(R1,O1,W1)", "return(R1)"])
    assert check_robot_plan(SCENE, "R1", plan) == []


def test_headings_compare_modulo_360_and_positions_within_tolerance() -> None:
    actions = replaced(R1_ACTIONS, 1, ("GoTo", (1750, -1000 + 5e-7, 360)))
    assert check_robot_plan(SCENE, "R1", r1_plan(actions)) == []
    actions = replaced(R1_ACTIONS, 1, ("GoTo", (1750 - 1e-4, -1000, 0)))
    v = only(check_robot_plan(SCENE, "R1", r1_plan(actions)), "pick-pose", 3)
    assert "the robot is at (1749.9999, -1000)" in v.message


def test_geometry_is_exact_not_within_tolerance() -> None:
    # 0.5 micrometre into O1 is an overlap, although poses compare within 1 micrometre
    actions = replaced(R1_ACTIONS, 1, ("GoTo", (1750 + 5e-7, -1000, 0)))
    v = only(check_robot_plan(SCENE, "R1", r1_plan(actions)), "object-collision", 2)
    assert "to (1750.0000005, -1000) sweeps over O1" in v.message


def test_picking_while_carrying() -> None:
    actions = [*R2_ACTIONS[:2], ("GoTo", (1750, -1000, 0)), ("PickUp", "O1")]
    violations = check_robot_plan(SCENE, "R2", r2_plan(actions, ["pick(R2,O2)"]))
    assert [(v.instant, v.rule) for v in violations] == [(4, "carried"), (4, "carried")]
    assert "already carries O2" in violations[0].message


def test_picking_an_object_moved_away() -> None:
    plan = r1_plan([("Req", "O2"), ("GoTo", (1650, -1000, 0)), ("PickUp", "O2")], ["away(O2,R1,R2)"])
    v = only(check_robot_plan(SCENE, "R1", plan), "away", 3)
    assert "O2 has been moved away" in v.message


def test_pickup_must_mark_the_object_carried() -> None:
    plan = r1_plan()
    for k in range(3, 6):
        plan = edit_object(plan, k, "O1", carried=False)
    violations = check_robot_plan(SCENE, "R1", plan)
    assert [(v.instant, v.rule) for v in violations] == [(3, "carried"), (6, "carried")]
    assert violations[0].message == "R1 at instant 3, PickUp(O1): O1 is not marked carried after PickUp(O1)"


def test_robot_must_not_move_while_picking() -> None:
    plan = edit_step(r1_plan(), 3, robot=(1750, -1000, 0))  # unchanged: valid
    assert check_robot_plan(SCENE, "R1", plan) == []
    plan = edit_step(r1_plan(), 1, robot=(-2000, -900, 0))  # Req(O2) moves the robot
    v = only(check_robot_plan(SCENE, "R1", plan), "robot-static", 1)
    assert "the robot moves from (-2000, -1000, 0°) to (-2000, -900, 0°)" in v.message


# ----------------------------------------------------------------------------------------------
# DropOff
# ----------------------------------------------------------------------------------------------


def test_dropping_onto_an_object() -> None:
    actions = [*R2_ACTIONS[:2], ("GoTo", (1700, -1000, 0)), ("DropOff", "O2")]
    v = only(check_robot_plan(SCENE, "R2", r2_plan(actions, ["pick(R2,O2)"])), "object-collision", 4)
    assert v.message == (
        "R2 at instant 4, DropOff(O2): O2 dropped at (1950, -1000) overlaps O1, resting at (2000, -1000); "
        "drop it elsewhere"
    )


def test_dropping_onto_a_wall() -> None:
    actions = [*R2_ACTIONS[:2], ("GoTo", (1650, -1500, 0)), ("GoTo", (2250, -1500, 0)), ("DropOff", "O2")]
    v = only(check_robot_plan(SCENE, "R2", r2_plan(actions, ["pick(R2,O2)"])), "wall", 5)
    assert "O2 dropped at (2500, -1500) overlaps wall [[2500,-2500],[2500,2500]]" in v.message


def test_dropping_through_a_wall() -> None:
    # the robot touches the right wall and would put O2 on its far side, touching it
    actions = [*R2_ACTIONS[:2], ("GoTo", (1650, -1500, 0)), ("GoTo", (2300, -1500, 0)), ("DropOff", "O2")]
    v = only(check_robot_plan(SCENE, "R2", r2_plan(actions, ["pick(R2,O2)"])), "wall", 5)
    assert "on the two sides of wall [[2500,-2500],[2500,2500]]" in v.message


def test_dropping_outside_the_workspace() -> None:
    # drop pose 250 mm further right: O2's centre lands on W2's edge x = 1500, half of it outside
    actions = replaced(R2_ACTIONS, 2, ("GoTo", (1500, 1800, 90)))
    v = only(check_robot_plan(SCENE, "R2", r2_plan(actions)), "mission", None)
    assert v.message == (
        "R2: mission event drop(R2,O2,W2) (2nd of 3) is not realised: there is no DropOff(O2) that "
        "leaves O2 in W2 after instant 2 (pick(R2,O2)); DropOff(O2) at instant 4 leaves it at "
        "(1500, 2050), not wholly inside W2 (x in [1000, 1500], y in [2000, 2500]) (size 100 mm) "
        "(so return(R2) cannot be matched either)"
    )


@pytest.mark.parametrize(
    ("at", "inside"), [((1450, 2050), True), ((1451, 2050), False), ((1200, 2049), False)]
)
def test_dropping_wholly_inside_the_workspace_boundary_counts(at, inside: bool) -> None:
    # O2's square (side 100) may touch W2's edges from inside, not cross them
    actions = replaced(R2_ACTIONS, 2, ("GoTo", (at[0], at[1] - 250, 90)))
    actions = replaced(actions, 4, ("GoTo", (at[0], -2000, 0)))
    plan = r2_plan(actions)
    assert plan.steps[3].objects["O2"].position == at
    assert [v.rule for v in check_robot_plan(SCENE, "R2", plan)] == ([] if inside else ["mission"])


def test_dropping_at_a_point_workspace() -> None:
    data = {
        "name": "points",
        "scene": {
            "obstacles": [[[-2500, -2500], [2500, -2500]]],
            "robots": {"R1": {"size": 400, "pose": [0, 0, 0]}},
            "objects": {"O1": {"size": 100, "position": [1000, 0]}},
            "workspaces": {"W1": {"point": [1250, 500]}},
        },
        "mission": {"tasks": {"R1": ["pick O1", "drop O1 at W1"]}},
    }
    scenario = parse_scenario(data)
    mission = [parse_event("pick(R1,O1)"), parse_event("drop(R1,O1,W1)")]
    good = plan_from_actions(
        scenario.scene,
        "R1",
        mission,
        [("GoTo", (750, 0, 0)), ("PickUp", "O1"), ("GoTo", (1000, 500, 0)), ("DropOff", "O1")],
    )
    assert check_robot_plan(scenario.scene, "R1", good) == []
    bad = plan_from_actions(
        scenario.scene,
        "R1",
        mission,
        [("GoTo", (750, 0, 0)), ("PickUp", "O1"), ("GoTo", (1000, 501, 0)), ("DropOff", "O1")],
    )
    v = only(check_robot_plan(scenario.scene, "R1", bad), "mission", None)
    assert "not on W1 (the point (1250, 500))" in v.message


def test_picking_through_a_wall() -> None:
    # the robot's front edge and the object's back edge both touch a short wall between them
    data = {
        "name": "behind-a-wall",
        "scene": {
            "obstacles": [[[1200, -500], [1200, 500]]],
            "robots": {"R1": {"size": 400, "pose": [0, 0, 0]}},
            "objects": {"O1": {"size": 100, "position": [1250, 0]}},
            "workspaces": {},
        },
        "mission": {"tasks": {"R1": ["pick O1"]}},
    }
    scene = parse_scenario(data).scene
    plan = plan_from_actions(
        scene, "R1", [parse_event("pick(R1,O1)")], [("GoTo", (1000, 0, 0)), ("PickUp", "O1")]
    )
    v = only(check_robot_plan(scene, "R1", plan), "wall", 2)
    assert v.message == (
        "R1 at instant 2, PickUp(O1): the robot at (1000, 0) and O1 at (1250, 0) are on the two sides of "
        "wall [[1200,-500],[1200,500]]; the gripper cannot reach through it"
    )


def test_dropoff_must_put_the_object_in_front_of_the_robot() -> None:
    plan = r1_plan()
    plan = edit_object(plan, 6, "O1", position=(-1240, 2060))
    plan = edit_object(plan, 7, "O1", position=(-1240, 2060))
    v = only(check_robot_plan(SCENE, "R1", plan), "drop-pose", 6)
    assert "O1 is put at (-1240, 2060), but a robot at (-1500, 2050) facing 0° puts it" in v.message


def test_dropping_what_is_not_carried() -> None:
    plan = r2_plan([("GoTo", (1650, -1000, 0)), ("DropOff", "O2")], [])
    v = only(check_robot_plan(SCENE, "R2", plan), "carried", 2)
    assert "O2 is not carried at instant 1" in v.message


# ----------------------------------------------------------------------------------------------
# Req and Res
# ----------------------------------------------------------------------------------------------


def test_request_while_standing_in_the_pick_pose() -> None:
    actions = [("GoTo", (1650, -1000, 0)), *R1_ACTIONS]
    v = only(check_robot_plan(SCENE, "R1", r1_plan(actions)), "req-room", 2)
    assert v.message == (
        "R1 at instant 2, Req(O2): the requester at (1650, -1000) stands in the way of a robot picking O2 "
        "from (1650, -1000) (heading 0°), (1900, -1250) (heading 90°), (1900, -750) (heading 270°); "
        "request from a pose that leaves the pick pose on each of its sides free"
    )


@pytest.mark.parametrize(
    ("x", "y", "ok"),
    [
        (1250, -1000, True),
        (1250.5, -1000, False),
        (1300, -1000, False),
        (1650, -1400, False),
        (1900, -1650, True),
        (1900, -1649, False),
    ],
)
def test_request_room_touching_is_allowed(x: float, y: float, ok: bool) -> None:
    # O2's west pick pose is (1650, -1000), square x 1450..1850, y -1200..-800; its south pose
    # (1900, -1250), square x 1700..2100, y -1450..-1050
    actions = [("GoTo", (x, y, 0)), *R1_ACTIONS]
    violations = [v for v in check_robot_plan(SCENE, "R1", r1_plan(actions)) if v.instant == 2]
    assert [v.rule for v in violations] == ([] if ok else ["req-room"])


def test_request_twice() -> None:
    actions = [("Req", "O2"), *R1_ACTIONS]
    violations = check_robot_plan(SCENE, "R1", r1_plan(actions))
    assert [(v.instant, v.rule) for v in violations] == [(2, "away")]
    assert "O2 is already away at instant 1; request it only once" in violations[0].message


def test_request_must_mark_the_object_away() -> None:
    plan = edit_object(r1_plan(), 1, "O2", away=False)
    violations = check_robot_plan(SCENE, "R1", plan)
    # then GoTo sets the flag, and sweeps over O2 which is not away at instant 1
    assert [(v.instant, v.rule) for v in violations] == [(1, "away"), (2, "away"), (2, "object-collision")]
    assert "O2 is not marked away after Req(O2)" in violations[0].message


def test_response_needs_the_object_carried() -> None:
    plan = r2_plan([("Res", "O2")], [])
    v = only(check_robot_plan(SCENE, "R2", plan), "carried", 1)
    assert "the robot must carry O2 at instants 0 and 1" in v.message


def test_response_changes_nothing() -> None:
    plan = edit_object(r2_plan(R2_RES_ACTIONS, R2_RES_MISSION), 3, "O1", away=True)
    violations = check_robot_plan(SCENE, "R2", plan)
    assert [(v.instant, v.rule) for v in violations] == [(3, "away"), (4, "away")]


# ----------------------------------------------------------------------------------------------
# The mission
# ----------------------------------------------------------------------------------------------


def test_missing_return() -> None:
    v = only(check_robot_plan(SCENE, "R2", r2_plan(R2_ACTIONS[:-1])), "mission", None)
    assert v.message == (
        "R2: mission event return(R2) (3rd of 3) is not realised: the robot is never at its initial pose "
        "(-2000, -2000, 0°) after instant 4 (drop(R2,O2,W2)); the last pose is (1250, -2000, 0°): add a "
        "GoTo back to the initial pose"
    )


def test_return_needs_the_initial_heading() -> None:
    actions = replaced(R2_ACTIONS, 5, ("GoTo", (-2000, -2000, 180)))
    only(check_robot_plan(SCENE, "R2", r2_plan(actions)), "mission", None)


def test_events_out_of_order() -> None:
    mission = [R1_MISSION[0], R1_MISSION[2], R1_MISSION[1], R1_MISSION[3]]
    v = only(check_robot_plan(SCENE, "R1", r1_plan(mission=mission)), "mission", None)
    assert v.message == (
        "R1: mission event pick(R1,O1) (3rd of 4) is not realised: there is no PickUp(O1) after instant 6 "
        "(drop(R1,O1,W1)); it holds only at instant 3, before drop(R1,O1,W1): the events are out of order "
        "(so return(R1) cannot be matched either)"
    )


def test_request_event_needs_a_req_step() -> None:
    plan = r1_plan(replaced(R1_ACTIONS, 0, ("GoTo", (-2000, -1000, 0))), R1_MISSION)
    violations = check_robot_plan(SCENE, "R1", plan)
    assert [v.rule for v in violations] == ["object-collision", "object-collision", "mission"]
    assert "mission event away(O2,R1,R2) (1st of 4) is not realised: there is no Req(O2) anywhere" in (
        violations[-1].message
    )


def test_response_event_needs_a_res_step() -> None:
    v = only(check_robot_plan(SCENE, "R2", r2_plan(R2_ACTIONS, R2_RES_MISSION)), "mission", None)
    assert "there is no Res(O2) after instant 2 (pick(R2,O2))" in v.message


def test_mission_event_of_another_robot() -> None:
    v = only(check_robot_plan(SCENE, "R1", r1_plan(mission=["pick(R2,O2)"])), "mission", None)
    assert "pick(R2,O2), an event of R2" in v.message


def test_mission_with_unknown_workspace() -> None:
    v = only(check_robot_plan(SCENE, "R1", r1_plan(mission=["drop(R1,O1,W9)"])), "mission", None)
    assert "workspace W9, which is not in the scene (W1, W2)" in v.message


# ----------------------------------------------------------------------------------------------
# Malformed states
# ----------------------------------------------------------------------------------------------


def test_step_missing_an_object() -> None:
    plan = r1_plan()
    objects = dict(plan.steps[3].objects)
    del objects["O2"]
    plan = edit_step(plan, 4, objects=objects)
    v = only(check_robot_plan(SCENE, "R1", plan), "objects", 4)
    assert "every step must list every object of the scene (O1, O2); missing O2" in v.message


def test_step_naming_an_unknown_object() -> None:
    plan = r1_plan()
    state = plan.steps[0]
    bad = Step("Req", "O9", state.robot, {**state.objects, "O9": ObjectState((0, 0), False, True)})
    plan = RobotPlan(plan.mission, plan.horizon, (bad, *plan.steps[1:]))
    violations = check_robot_plan(SCENE, "R1", plan)
    assert [(v.instant, v.rule) for v in violations] == [(1, "objects"), (1, "objects"), (None, "mission")]
    assert "O9 not in the scene" in violations[0].message
    assert "O9 is not an object of the scene (O1, O2)" in violations[1].message


def test_unknown_robot() -> None:
    v = only(check_robot_plan(SCENE, "R9", r1_plan()), "robot", None)
    assert v.message == "R9: there is no robot R9 in the scene (R1, R2)"


# ----------------------------------------------------------------------------------------------
# The plan set
# ----------------------------------------------------------------------------------------------


def test_plan_for_another_scenario() -> None:
    report = check_plan(SCENARIO, dataclasses.replace(coordinated(), scenario="other"))
    assert not report.ok
    (v,) = report.violations
    assert (v.robot, v.instant, v.rule) == (None, None, "scenario")
    assert report.to_dict()["violations"][0]["robot"] is None


def test_missing_robot_plan() -> None:
    plans = PlanSet("warehouse-2x2", True, {"R2": r2_plan()})
    (v,) = check_plan(SCENARIO, plans).violations
    assert (v.robot, v.rule) == ("R1", "mission")
    assert "the plan has no plan for R1" in v.message


def test_plan_mission_must_contain_the_tasks() -> None:
    plans = PlanSet("warehouse-2x2", True, {"R1": r1_plan(R1_ACTIONS[:-1], R1_MISSION[:-1]), "R2": r2_plan()})
    plans = dataclasses.replace(plans, coordination=(Coordination("O2", "R1", "R2"),))
    violations = check_plan(SCENARIO, plans).violations
    assert [(v.robot, v.rule) for v in violations] == [("R1", "mission"), ("R2", "coordination")]
    assert "return(R1) is missing" in violations[0].message
    assert "names R2 as responder, but its mission does not include away(O2,R1,R2)" in violations[1].message


def test_plan_mission_may_add_only_away_events() -> None:
    extra = r2_plan(
        [*R2_ACTIONS, ("GoTo", (1650, -1000, 0)), ("PickUp", "O1")], [*R2_MISSION, parse_event("pick(R2,O1)")]
    )
    plans = PlanSet("warehouse-2x2", True, {"R1": r1_plan(), "R2": extra}, (Coordination("O2", "R1", "R2"),))
    violations = [v for v in check_plan(SCENARIO, plans).violations if v.rule == "mission"]
    assert len(violations) == 1
    assert "adds pick(R2,O1)" in violations[0].message


def test_away_event_needs_a_coordination_pair() -> None:
    plans = dataclasses.replace(coordinated(), coordination=())
    violations = check_plan(SCENARIO, plans).violations
    assert [(v.robot, v.rule) for v in violations] == [("R1", "coordination"), ("R2", "coordination")]


def test_a_plan_file_marked_infeasible_is_not_valid() -> None:
    plans = PlanSet("warehouse-2x2", False, {}, reason="no shortest plan within the horizon bound")
    report = check_plan(SCENARIO, plans)
    assert not report.ok and report.checked_steps == 0
    (v,) = report.violations
    assert v.rule == "infeasible" and "no shortest plan" in v.message


# ----------------------------------------------------------------------------------------------
# Geometry
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("segment", "expected"),
    [
        (((0, -10), (0, 10)), True),  # through the middle
        (((-1, 1), (1, 1)), False),  # along the top edge
        (((1, -5), (1, 5)), False),  # along the right edge, longer than it
        (((1, 0), (5, 0)), False),  # ends on the right edge
        (((0.999, 0), (5, 0)), True),  # reaches inside by 1 micrometre
        (((2, 2), (3, 3)), False),  # apart
        (((1, 1), (3, 3)), False),  # touches a corner
    ],
)
def test_segment_overlap_means_interiors(segment, expected: bool) -> None:
    assert overlaps(LineString(segment), box(-1, -1, 1, 1)) is expected


def test_squares_sharing_an_edge_do_not_overlap() -> None:
    assert not overlaps(square(0, 0, 2), square(2, 0, 2))
    assert not overlaps(square(0, 0, 2), square(2, 2, 2))
    assert overlaps(square(0, 0, 2), square(1.999, 0, 2))


@settings(max_examples=60)
@given(
    st.integers(-3000, 3000),
    st.integers(-3000, 3000),
    st.integers(-3000, 3000),
    st.integers(1, 1000),
    st.booleans(),
)
def test_axis_aligned_sweep_is_the_bounding_box(
    x0: int, y0: int, delta: int, side: int, vertical: bool
) -> None:
    start, end = (x0, y0), ((x0, y0 + delta) if vertical else (x0 + delta, y0))
    area = swept_square(start, end, side)
    half = side / 2
    expected = box(
        min(start[0], end[0]) - half,
        min(start[1], end[1]) - half,
        max(start[0], end[0]) + half,
        max(start[1], end[1]) + half,
    )
    assert area.symmetric_difference(expected).area == pytest.approx(0, abs=1e-6)


@settings(max_examples=60)
@given(
    st.tuples(st.integers(-2000, 2000), st.integers(-2000, 2000)),
    st.tuples(st.integers(-2000, 2000), st.integers(-2000, 2000)),
    st.floats(0, 1),
)
def test_sweep_covers_every_intermediate_square(start, end, t: float) -> None:
    area = swept_square(start, end, 400)
    middle = (start[0] + t * (end[0] - start[0]), start[1] + t * (end[1] - start[1]))
    assert area.buffer(1e-6).contains(square(*middle, 400))


@settings(max_examples=60, deadline=None)
@given(st.integers(-2400, 2400), st.integers(-2400, 2400))
def test_a_drive_is_tested_against_every_wall_and_good_it_could_meet(x, y):
    # the checker tests exactly only what a drive's box meets; every wall and resting good the
    # swept square overlaps, tested one by one, is still reported, and nothing else
    plan = plan_from_actions(SCENE, "R1", [parse_event("return(R1)")], [("GoTo", (x, y, 0))])
    found = check_robot_plan(SCENE, "R1", plan)
    home = SCENE.robots["R1"].pose
    area = swept_square(home, (x, y, 0), SCENE.robots["R1"].size)
    walls = [w for w in SCENE.obstacles if overlaps(LineString([w.start, w.end]), area)]
    goods = [o for o, ob in SCENE.objects.items() if overlaps(square(*ob.position, ob.size), area)]
    assert sum(v.rule == "wall" and v.instant == 1 for v in found) == len(walls)
    assert sum(v.rule == "object-collision" and v.instant == 1 for v in found) == len(goods)


@settings(max_examples=40, deadline=None)
@given(st.lists(st.tuples(st.integers(-600, 600), st.integers(-600, 600)), min_size=4, max_size=4))
def test_the_box_filter_reports_what_testing_every_wall_and_good_reports(shifts):
    # R1's plan with its drives moved: drives, picks, drops and the gripper's reach then meet
    # walls and goods; the checker that tests only what a step's box meets reports the same
    # violations, in the same order, as one that tests every wall and every resting good
    from cosmop.planning import checker

    moves = iter(shifts)
    actions = []
    for kind, arg in R1_ACTIONS:
        if kind == "GoTo":
            dx, dy = next(moves)
            arg = (arg[0] + dx, arg[1] + dy, arg[2])
        actions.append((kind, arg))
    plan = r1_plan(actions)
    filtered = [v.message for v in check_robot_plan(SCENE, "R1", plan)]
    every_wall = checker._RobotChecker.walls_meeting
    every_good = checker._RobotChecker.resting
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(
            checker._RobotChecker,
            "walls_meeting",
            lambda self, shape: every_wall(self, shape.envelope.buffer(1e9)),
        )
        patch.setattr(
            checker._RobotChecker,
            "resting",
            lambda self, state, exclude=None, near=None: every_good(self, state, exclude),
        )
        unfiltered = [v.message for v in check_robot_plan(SCENE, "R1", plan)]
    assert filtered == unfiltered
