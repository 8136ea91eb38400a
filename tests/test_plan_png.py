"""The plan picture a new user reads first: the verdict in its title, a big map cut to where the
team works, labels kept inside the map (thinned where crowded), and every message drawn."""

from __future__ import annotations

import pytest

pytest.importorskip("matplotlib")
from cosmop.events import Event, parse_event
from cosmop.planning.plan_types import PlanMessage, PlanSet, RobotPlan, Step
from cosmop.planning.primitive_effects import plan_from_actions
from cosmop.scenario import parse_scenario
from cosmop.viz import draw_plan
from cosmop.viz.labels import Label, place_labels
from rooms import box_walls
from run_2x2 import run_2x2

REASON = (
    "R2 cannot reach pick(R2,O2) (event 1 of its mission) at any horizon: walls separate its start "
    "(9500, 5500) from its pick poses on the sides tried: west (7750, 2500), south (8000, 2250), "
    "east (8250, 2500), north (8000, 2750)"
)
SIDE = 40_000  # mm: a big map, with the team in its lower left corner

BIG = parse_scenario(
    {
        "name": "big-hall",
        "scene": {
            "obstacles": [*box_walls(0, 0, SIDE, SIDE), [[20_000, 5_000], [20_000, 35_000]]],
            "robots": {
                "R1": {"size": 400, "pose": [1000, 1000, 0]},
                "R2": {"size": 400, "pose": [1000, 2000, 0]},
            },
            "objects": {
                "O1": {"size": 100, "position": [3000, 2000]},
                "O9": {"size": 100, "position": [30_000, 30_000]},  # no plan touches it
            },
            "workspaces": {"W1": {"x": [500, 1500], "y": [3000, 3500]}, "W9": {"point": [35_000, 5_000]}},
        },
        "mission": {"tasks": {"R1": ["pick O1", "drop O1 at W1", "return"], "R2": ["return"]}},
    }
)


def _big_plans() -> PlanSet:
    r1 = plan_from_actions(
        BIG.scene,
        "R1",
        [parse_event("pick(R1,O1)"), parse_event("drop(R1,O1,W1)"), parse_event("return(R1)")],
        [
            ("GoTo", (2750, 2000, 0)),  # west of O1, touching it
            ("PickUp", "O1"),
            ("GoTo", (1000, 2950, 90)),  # below W1, facing north
            ("DropOff", "O1"),
            ("GoTo", (1000, 1000, 0)),
        ],
    )
    return PlanSet("big-hall", True, {"R1": r1})


@pytest.fixture
def close_figures():
    import matplotlib.pyplot as plt

    yield
    plt.close("all")


def _inside(inner, outer, slack: float = 0.5) -> bool:
    return (
        inner.x0 >= outer.x0 - slack
        and inner.x1 <= outer.x1 + slack
        and inner.y0 >= outer.y0 - slack
        and inner.y1 <= outer.y1 + slack
    )


def test_an_infeasible_plan_says_so_and_why_in_red_in_its_title(close_figures):
    from matplotlib.colors import to_rgba

    scene = run_2x2()[0].scene
    fig = draw_plan(scene, PlanSet("corridor", False, {}, reason=REASON))
    ax = fig.axes[0]
    title = ax.title
    text = title.get_text()
    assert text.startswith("corridor: infeasible: R2 cannot reach")
    assert " ".join(text.split()) == f"corridor: infeasible: {REASON}"  # the whole reason, wrapped
    assert text.count("\n") >= 2  # wrapped, not one line running off the picture
    assert to_rgba(title.get_color()) == to_rgba("red")
    fig.canvas.draw()
    assert _inside(title.get_window_extent(), fig.bbox)


def test_a_feasible_plan_keeps_the_scenario_name_and_counts_its_robots(close_figures):
    scenario, plans, _ = run_2x2()
    ax = draw_plan(scenario.scene, plans).axes[0]
    assert ax.get_title() == "warehouse-2x2: feasible, 2 robots"
    assert ax.title.get_color() == "black"


def test_a_big_map_is_cut_to_the_activity_and_full_map_shows_every_wall(close_figures):
    plans = _big_plans()
    ax = draw_plan(BIG.scene, plans).axes[0]
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    assert x1 - x0 < SIDE / 5 and y1 - y0 < SIDE / 5  # the team's corner, not the hall
    points = [r.pose[:2] for r in BIG.scene.robots.values()]
    points += [s.robot[:2] for s in plans.robots["R1"].steps]
    assert all(x0 < x < x1 and y0 < y < y1 for x, y in points)
    assert x0 >= -SIDE * 0.06 and y0 >= -SIDE * 0.06  # never beyond the map as drawn in full
    texts = {t.get_text() for t in ax.texts}
    assert {"R1", "R2", "O1", "W1"} <= texts and not {"O9", "W9"} & texts  # cut away, not written

    full = draw_plan(BIG.scene, plans, full_map=True).axes[0]
    (x0, x1), (y0, y1) = full.get_xlim(), full.get_ylim()
    walls = [p for w in BIG.scene.obstacles for p in (w.start, w.end)]
    assert all(x0 <= x <= x1 and y0 <= y <= y1 for x, y in walls)
    assert {"O9", "W9"} <= {t.get_text() for t in full.texts}


def test_without_plans_the_view_holds_the_robots_objects_and_workspaces(close_figures):
    ax = draw_plan(BIG.scene, None).axes[0]
    (x0, x1), y1 = ax.get_xlim(), ax.get_ylim()[1]
    assert x0 < 1000 and x1 > 35_000 and y1 > 30_000  # O9 and W9 are part of the scene's content


@pytest.mark.parametrize("full_map", [False, True])
def test_no_label_leaves_the_axes(close_figures, full_map):
    scenario, plans_2x2, _ = run_2x2()
    for scene, plans in ((BIG.scene, _big_plans()), (scenario.scene, plans_2x2)):
        fig = draw_plan(scene, plans, full_map=full_map)
        fig.canvas.draw()
        ax = fig.axes[0]
        boxes = [t.get_window_extent() for t in ax.texts if t.get_text()]
        assert boxes and all(_inside(box, ax.bbox) for box in boxes)


def test_crowded_labels_are_thinned_but_robot_ids_always_show(close_figures):
    import matplotlib.pyplot as plt
    from matplotlib.text import Text

    fig, ax = plt.subplots(figsize=(3, 3))
    ax.set_xlim(0, 100)
    ax.set_ylim(0, 100)
    style = {"fontsize": 8}
    robots = [Label(1, 1, f"R{k}", style, center=True, keep=True) for k in range(1, 4)]  # in a corner
    goods = [Label(50, 50, f"O{k}", style) for k in range(60)]  # all on one point
    placement = place_labels(ax, [*robots, *goods, Label(150, 50, "far", style)])
    written = [a.get_text() for a in placement.annotations]
    assert written[:3] == ["R1", "R2", "R3"]  # kept, in the corner though it is crowded
    assert len(placement.dropped) == 60 - (len(written) - 3) > 0  # the rest are left out
    assert all(label.text.startswith("O") for label in placement.dropped)
    assert [label.text for label in placement.outside] == ["far"]  # its point is off the view
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    boxes = [Text.get_window_extent(a, renderer) for a in placement.annotations]
    assert all(_inside(box, ax.bbox) for box in boxes)  # none on the ticks or the spines
    goods_boxes = boxes[3:]
    assert not any(a.overlaps(b) for i, a in enumerate(goods_boxes) for b in goods_boxes[i + 1 :])


def _send_and_wait(plan: RobotPlan, after: int, primitive: str, events: list[Event]) -> RobotPlan:
    """`plan` with a step that sends (Res) or waits for (Req) each of `events` after step `after`."""
    steps = list(plan.steps)
    here = steps[after - 1]
    extra = [Step(primitive, None, here.robot, here.objects, message=event) for event in events]
    return RobotPlan.from_steps([*plan.mission, *events], [*steps[:after], *extra, *steps[after:]])


def _message_plans(count: int) -> PlanSet:
    """The 2x2 plans with `count` messages from R2 (sent after its pick) to R1 (waited for before
    its pick), and one more message that no plan sends or waits for."""
    plans = run_2x2()[1]
    events = [parse_event(f"msg(R2,R1,clear{k})") for k in range(count)]
    robots = {
        "R1": _send_and_wait(plans.robots["R1"], 1, "Req", events),
        "R2": _send_and_wait(plans.robots["R2"], 2, "Res", events),
    }
    messages = [PlanMessage(e, "conflict", "R1 waits until R2 has picked O2") for e in events]
    messages.append(PlanMessage(parse_event("msg(R1,R2,lost)"), "order", "not in the plans"))
    return PlanSet(plans.scenario, True, robots, plans.coordination, messages=messages)


def test_every_message_is_an_arrow_from_its_sender_to_the_receiver_who_waits(close_figures):
    scene = run_2x2()[0].scene
    plans = _message_plans(1)
    ax = draw_plan(scene, plans).axes[0]
    arrows = [p for p in ax.patches if p.get_gid() == "message"]
    assert len(arrows) == 1  # msg(R1,R2,lost) has no steps: no arrow
    sent = next(s for s in plans.robots["R2"].steps if s.message == parse_event("msg(R2,R1,clear0)"))
    waited = next(s for s in plans.robots["R1"].steps if s.message == parse_event("msg(R2,R1,clear0)"))
    start, end = arrows[0]._posA_posB
    assert tuple(start) == sent.robot[:2] and tuple(end) == waited.robot[:2]
    r2 = next(t for t in ax.texts if t.get_text() == "R2")
    assert arrows[0].get_edgecolor()[:3] == pytest.approx(r2.get_color()[:3])  # the sender's colour
    assert [p for p in ax.patches if p.get_gid() == "order"]  # the Req/Res pair is still drawn
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "message: sender → receiver (waits until sent)" in legend


def test_many_messages_are_drawn_thin_and_faint(close_figures):
    scene = run_2x2()[0].scene
    ax = draw_plan(scene, _message_plans(45)).axes[0]
    arrows = [p for p in ax.patches if p.get_gid() == "message"]
    assert len(arrows) == 45
    assert all(a.get_linewidth() <= 0.5 and a.get_alpha() < 0.5 for a in arrows)
