"""Plans a controller can drive: a motion keeps its margin between its ends (issue 12, point 5)."""

from __future__ import annotations

from cosmop.events import Event
from cosmop.planning.checker import check_robot_plan
from cosmop.planning.regions import wall_regions
from cosmop.planning.specification import MOTION_MARGIN, STEEPNESS
from cosmop.planning.synthesis import synthesize
from cosmop.scenario import parse_scenario
from rooms import box_walls

MISSION = (
    Event("pick", "R1", obj="O1"),
    Event("drop", "R1", obj="O1", workspace="W1"),
    Event("return", "R1"),
)


def _scene():
    # R1's home touches the left wall; O1's pick pose touches the bottom wall; W1 is open
    return parse_scenario(
        {
            "name": "margin",
            "scene": {
                "obstacles": [*box_walls(-2000, -1500, 2000, 1500), [[-600, 1500], [-600, 300]]],
                "robots": {"R1": {"size": 400, "pose": [-1800, 0, 0]}},
                # the paper's west side only: from the others the plan slides along nothing
                "objects": {"O1": {"size": 100, "position": [500, -1300], "sides": ["west"]}},
                "workspaces": {"W1": {"x": [700, 1300], "y": [500, 1100]}},
            },
            "mission": {"tasks": {"R1": ["pick O1", "drop O1 at W1", "return"]}},
        }
    ).scene


def _object_sides(position, d):
    """Left, right, below and above a square object as ``(a, b, c)``: :math:`a x + b y \\ge c`."""
    ox, oy = position
    return [(-1, 0, d - ox), (1, 0, ox + d), (0, -1, d - oy), (0, 1, oy + d)]


def _kept_apart(a, b, touching, far) -> bool:
    """On one side: the motion ends at the margin or beyond, or comes steeply from there."""
    for (na, nb, c), (_, _, c_far) in zip(touching, far, strict=True):
        start, end = (na * p[0] + nb * p[1] for p in (a, b))
        if start >= c and end >= c_far:
            return True
        dx, dy = b[0] - a[0], b[1] - a[1]
        closer, along = start - end, abs(na * dy - nb * dx)
        if start >= c_far and end >= c and along <= STEEPNESS * closer:
            return True
    return False


def _sliding_motions(scene, plan, margin):
    """The GoTo motions of `plan` that slide along a wall or resting object within `margin`."""
    states = [scene.robots["R1"].pose[:2], *(s.robot[:2] for s in plan.steps)]
    out = []
    for k, step in enumerate(plan.steps):
        if step.primitive != "GoTo":
            continue
        a, b = states[k], states[k + 1]
        for w in scene.obstacles:
            touching = [(h.a, h.b, h.c) for h in wall_regions(w.start, w.end, 400)]
            far = [(h.a, h.b, h.c) for h in wall_regions(w.start, w.end, 400 + 2 * margin)]
            if not _kept_apart(a, b, touching, far):
                out.append((a, b, w))
        obj = plan.steps[k - 1].objects["O1"] if k else None
        if obj is not None and not obj.carried and not obj.away:
            sides = _object_sides(obj.position, 250), _object_sides(obj.position, 250 + margin)
            if not _kept_apart(a, b, *sides):
                out.append((a, b, "O1"))
    return out


def test_touching_poses_are_approached_and_left_but_never_slid_along():
    scene = _scene()
    result = synthesize(scene, "R1", MISSION, max_horizon=12)
    assert result.feasible
    assert not check_robot_plan(scene, "R1", result.plan)
    assert _sliding_motions(scene, result.plan, MOTION_MARGIN) == []
    # the rule bites in this scene: without the margin the plan slides along the dropped O1
    loose = synthesize(scene, "R1", MISSION, max_horizon=12, margin=0)
    assert loose.feasible and _sliding_motions(scene, loose.plan, MOTION_MARGIN)


def test_the_margin_only_removes_plans():
    # every plan with the margin is a plan without it: never shorter with the margin
    scene = _scene()
    loose = synthesize(scene, "R1", MISSION, max_horizon=12, margin=0)
    tight = synthesize(scene, "R1", MISSION, max_horizon=12)
    assert loose.feasible and tight.feasible
    assert loose.horizon <= tight.horizon
