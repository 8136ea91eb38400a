"""Shortest plans per robot (paper, Section IV) pass the exact plan checker.

Reproduced: in Example 1, R2's shortest plan has 6 steps; R1 is infeasible without requests
(the reason names O2), and its shortest plan with requests has 7 steps with Req(O2) first.
Minimality: no plan of length K - 1 exists.  In the 10x10 example every robot gets a checked
shortest plan whose requests form the coordination structure of the paper's 10x10 example
(R1 <- O2, O3; R2 <- O3; R4 <- O5, O6; R5 <- O6; R7 <- O8; R9 <- O10).  These results
hold under the paper's rule that goods are handled from their west side (:func:`west_only`);
from any side R1 needs no request at all.
"""

from __future__ import annotations

import itertools
from pathlib import Path

import pytest

import cosmop.planning.synthesis as synthesis
from cosmop.planning.checker import check_robot_plan
from cosmop.planning.specification import RobotProblem, events_of, specification
from cosmop.planning.synthesis import ROUTE_ROUNDS, synthesize
from cosmop.scenario import load_scenario
from paper_rules import west_only

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def small():
    return load_scenario(ROOT / "examples" / "01_warehouse_2x2" / "scenario.yaml")


@pytest.fixture(scope="module")
def big():
    return load_scenario(ROOT / "examples" / "02_warehouse_10x10" / "scenario.yaml")


def test_r2_shortest_plan_has_six_steps(small):
    res = synthesize(small.scene, "R2", small.mission.tasks["R2"])
    assert res.feasible and res.horizon == 6 and res.requests == ()
    assert [s.primitive for s in res.plan.steps] == ["GoTo", "PickUp", "GoTo", "DropOff", "GoTo", "GoTo"]
    assert check_robot_plan(small.scene, "R2", res.plan) == []
    shorter = synthesize(small.scene, "R2", small.mission.tasks["R2"], max_horizon=5)
    assert not shorter.feasible  # unsat at K - 1


def test_r1_needs_o2_moved_away(small):
    small = west_only(small)
    alone = synthesize(small.scene, "R1", small.mission.tasks["R1"], requests=False, max_horizon=8)
    assert not alone.feasible and alone.plan is None
    assert "pick(R1,O1)" in alone.reason
    # O2 blocks: it stands where R1 must be (or within the room R1 keeps while picking up)
    assert any(b in ("object O2", "room from O2 while handling O1") for b in alone.blocking)
    res = synthesize(small.scene, "R1", small.mission.tasks["R1"])
    assert res.feasible and res.horizon == 7 and res.requests == ("O2",)
    assert [s.label for s in res.plan.steps][:3] == ["Req(O2)", "GoTo", "PickUp(O1)"]
    assert check_robot_plan(small.scene, "R1", res.plan) == []


def test_responder_plan_with_res(small):
    mission = ["pick(R2,O2)", "away(O2,R1,R2)", "drop(R2,O2,W2)", "return(R2)"]
    res = synthesize(small.scene, "R2", mission)
    assert res.feasible and res.horizon == 7
    labels = [s.label for s in res.plan.steps]
    assert labels.index("PickUp(O2)") < labels.index("Res(O2)") < labels.index("DropOff(O2)")
    assert check_robot_plan(small.scene, "R2", res.plan) == []


def test_requests_are_never_for_own_objects(small):
    p = RobotProblem(small.scene, "R1", events_of(small.mission.tasks["R1"]))
    assert {(a.primitive, a.obj) for a in p.actions} == {
        ("GoTo", None),
        ("PickUp", "O1"),
        ("DropOff", "O1"),
        ("Req", "O2"),
    }
    names = [str(n) for n, _ in specification(p)]
    assert "object O2" in names and any(n.startswith("wall 4") for n in names)


def test_every_robot_of_the_10x10_example_gets_a_checked_shortest_plan(big):
    big = west_only(big)
    expected = {
        "R1": {"O2", "O3"},
        "R2": {"O3"},
        "R4": {"O5", "O6"},
        "R5": {"O6"},
        "R7": {"O8"},
        "R9": {"O10"},
    }
    for robot in big.scene.robots:
        res = synthesize(big.scene, robot, big.mission.tasks[robot], max_horizon=12)
        assert res.feasible, res.reason
        assert check_robot_plan(big.scene, robot, res.plan) == []
        assert set(res.requests) == expected.get(robot, set()), robot


def test_synthesis_is_deterministic(small, big):
    first = synthesize(small.scene, "R1", small.mission.tasks["R1"])
    synthesize(big.scene, "R3", big.mission.tasks["R3"])  # unrelated solving in between
    again = synthesize(small.scene, "R1", small.mission.tasks["R1"])
    assert first.plan.to_dict() == again.plan.to_dict()


def test_incremental_and_fresh_search_agree(small):
    for robot in ("R1", "R2"):
        a = synthesize(small.scene, robot, small.mission.tasks[robot], incremental=True)
        b = synthesize(small.scene, robot, small.mission.tasks[robot], incremental=False)
        assert (a.horizon, sorted(a.requests)) == (b.horizon, sorted(b.requests))
        assert check_robot_plan(small.scene, robot, b.plan) == []


QUICK = [{"copies": True}, {"from_bound": True}, {"copies": True, "from_bound": True}]


@pytest.mark.parametrize("quick", QUICK)
def test_the_quick_searches_find_the_same_shortest_plans(big, quick):
    # the same constraints made by copies, the search from the counted bound: the same horizons
    # and requests (the plans may differ among the equally short ones), every plan checked,
    # and the same plan again when rerun
    for robot in ("R1", "R4", "R7"):
        walked = synthesize(big.scene, robot, big.mission.tasks[robot], max_horizon=12)
        found = synthesize(big.scene, robot, big.mission.tasks[robot], max_horizon=12, **quick)
        assert (found.horizon, sorted(found.requests)) == (walked.horizon, sorted(walked.requests))
        if quick.get("from_bound"):  # lengths below the bound (drives round shelves) not searched
            assert set(found.unsat_horizons) < set(walked.unsat_horizons)
        else:
            assert found.unsat_horizons == walked.unsat_horizons
        assert check_robot_plan(big.scene, robot, found.plan) == []
        again = synthesize(big.scene, robot, big.mission.tasks[robot], max_horizon=12, **quick)
        assert again.plan.to_dict() == found.plan.to_dict()


def test_minimality_evidence(small):
    res = synthesize(small.scene, "R1", small.mission.tasks["R1"])
    assert res.unsat_horizons == tuple(range(2, res.horizon))  # 2 non-return events: K >= 2


def _one_robot_scene(extra_walls):
    from cosmop.scenario import parse_scenario

    return parse_scenario(
        {
            "name": "gripper",
            "scene": {
                "obstacles": [
                    [[-2000, -2000], [2000, -2000]],
                    [[2000, -2000], [2000, 2000]],
                    [[2000, 2000], [-2000, 2000]],
                    [[-2000, 2000], [-2000, -2000]],
                    *extra_walls,
                ],
                "robots": {"R1": {"size": 400, "pose": [-1000, 0, 0]}},
                "objects": {"O1": {"size": 100, "position": [1000, 0]}},
                "workspaces": {"W1": {"x": [-1500, -500], "y": [1000, 1500]}},
            },
            "mission": {"tasks": {"R1": ["pick O1", "drop O1 at W1", "return"]}},
        }
    )


def test_no_pick_through_a_wall():
    open_scene = _one_robot_scene([])
    res = synthesize(open_scene.scene, "R1", open_scene.mission.tasks["R1"], max_horizon=8)
    assert res.feasible and check_robot_plan(open_scene.scene, "R1", res.plan) == []
    # a short wall exactly on the object's left edge, between the pick pose and the object
    walled = _one_robot_scene([[[950, -40], [950, 40]]])
    blocked = synthesize(west_only(walled).scene, "R1", walled.mission.tasks["R1"], max_horizon=8)
    assert not blocked.feasible
    assert any(name.startswith("gripper clear of wall 4") for name in blocked.blocking), blocked.blocking
    # from any side: picked from another side, never through the wall
    around = synthesize(walled.scene, "R1", walled.mission.tasks["R1"], max_horizon=8)
    assert around.feasible and check_robot_plan(walled.scene, "R1", around.plan) == []
    pick = next(s for s in around.plan.steps if s.primitive == "PickUp")
    assert pick.robot[2] in (90, 180, 270)


def test_a_robot_without_a_mission_gets_an_empty_plan(small):
    res = synthesize(small.scene, "R2", [])
    assert res.feasible and res.horizon == 0 and res.plan.steps == ()


def test_a_solver_that_gives_up_is_reported_not_raised(small):
    res = synthesize(small.scene, "R1", small.mission.tasks["R1"], rlimit=2_000)
    assert not res.feasible and res.plan is None
    assert "the solver gave up" in res.reason and "resource limit 2000" in res.reason


def test_a_horizon_too_short_is_named_as_the_cause_not_the_walls(small):
    res = synthesize(small.scene, "R1", small.mission.tasks["R1"], max_horizon=3)
    assert not res.feasible and res.blocking == ()
    assert "needs at least" in res.reason and "horizon 3" in res.reason and "--max-horizon" in res.reason


def test_the_reason_names_a_minimal_set_of_obstacles_and_the_sides_tried(small):
    scene = west_only(small).scene
    res = synthesize(scene, "R1", small.mission.tasks["R1"], requests=False, max_horizon=8)
    # O2 alone explains it: no wall is needed for the contradiction
    assert res.blocking == ("room from O2 while handling O1",)
    assert res.reason.endswith("blocked by: room from O2 while handling O1 (sides of O1 tried: west)")
    # at K = 6 the inner wall and O2 are named; the outer walls far from the route never are
    res = synthesize(small.scene, "R1", small.mission.tasks["R1"], max_horizon=6)
    assert not res.feasible and 0 < len(res.blocking) <= 3
    assert not any(b.startswith("wall 0") or b.startswith("wall 1") for b in res.blocking)


def test_a_synthesis_runs_with_the_collector_paused(small, monkeypatch):
    # the encoding makes many objects and next to no cycles: the collector waits (it walked
    # the whole heap again and again, a quarter of a synthesis in a Dask worker)
    import gc

    import cosmop.planning.synthesis as synthesis

    seen = []
    real = synthesis._shortest_plan
    monkeypatch.setattr(synthesis, "_shortest_plan", lambda *a: seen.append(gc.isenabled()) or real(*a))
    res = synthesize(small.scene, "R2", small.mission.tasks["R2"])
    assert res.feasible and seen == [False]
    assert gc.isenabled()  # and running again after it


@pytest.mark.parametrize(
    ("word", "why"),
    [
        (["drop(R1,O1,W1)"], "drop(R1,O1,W1) (event 1): its hands are empty"),
        (["pick(R1,O1)", "pick(R1,O2)"], "pick(R1,O2) (event 2) while it carries O1"),
        (["pick(R1,O1)", "drop(R1,O2,W1)"], "drop(R1,O2,W1) (event 2): it carries O1"),
    ],
)
def test_a_word_the_hands_cannot_do_is_refused_without_the_solver(small, word, why):
    # one good at a time, picked with empty hands, dropped only when carried: no horizon helps
    result = synthesize(small.scene, "R1", word)
    assert not result.feasible and why in result.reason
    assert result.horizon is None


def test_among_the_shortest_plans_the_route_is_made_shorter(big):
    # the solver's first plan of K steps may drive a long way round; asking for a shorter route
    # keeps K and the requests, and on the 10x10 shortens several robots' routes
    shorter = 0
    for robot, word in big.mission.tasks.items():
        first = synthesize(big.scene, robot, word)
        best = synthesize(big.scene, robot, word, route_rounds=ROUTE_ROUNDS)
        assert (best.horizon, best.requests) == (first.horizon, first.requests)
        assert 0 < best.route_mm <= first.route_mm
        poses = [big.scene.robots[robot].pose, *(step.robot for step in best.plan.steps)]
        manhattan = sum(abs(q[0] - p[0]) + abs(q[1] - p[1]) for p, q in itertools.pairwise(poses))
        assert best.route_mm == pytest.approx(manhattan)
        assert check_robot_plan(big.scene, robot, best.plan) == []
        shorter += best.route_mm < first.route_mm
    assert shorter >= 3


def test_a_route_is_never_asked_below_its_floor_and_the_plan_stays_the_same(big, monkeypatch):
    # the floor (the Manhattan length through the mission's places, walls ignored) is below
    # every route; a round that would ask below it is skipped, which changes no plan
    floors: list[float] = []
    real = synthesis._route_floor
    monkeypatch.setattr(synthesis, "_route_floor", lambda *a: floors.append(real(*a)) or floors[-1])
    skipped = 0
    for robot, word in big.mission.tasks.items():
        best = synthesize(big.scene, robot, word, route_rounds=ROUTE_ROUNDS)
        assert 0 < floors[-1] <= best.route_mm
        with monkeypatch.context() as without:
            without.setattr(synthesis, "_route_floor", lambda *a: 0.0)
            proved = synthesize(big.scene, robot, word, route_rounds=ROUTE_ROUNDS)
        assert proved.plan == best.plan and proved.route_mm == best.route_mm
        skipped += proved.checks - best.checks
    assert skipped >= 3  # most of the 10x10's routes are straight once made shorter


def test_an_ask_for_a_shorter_route_spends_at_most_its_budget(big, monkeypatch):
    # with no budget at all every ask ends undecided: the first plan is kept, as without rounds;
    # with the shipped budget the 10x10's routes are made shorter as before
    for robot, word in big.mission.tasks.items():  # the first robot whose route is made shorter
        first = synthesize(big.scene, robot, word)
        if synthesize(big.scene, robot, word, route_rounds=ROUTE_ROUNDS).route_mm < first.route_mm:
            break
    else:
        pytest.fail("no route of the 10x10 is made shorter")
    monkeypatch.setattr(synthesis, "ROUTE_RLIMIT", 1)
    spent = synthesize(big.scene, robot, word, route_rounds=ROUTE_ROUNDS)
    assert spent.plan == first.plan and spent.route_mm == first.route_mm
    assert spent.checks > first.checks  # it asked, and got no answer within the budget
