"""Draw a scene and its plans like the paper's figures: walls, objects, workspaces, waypoints.

matplotlib is imported lazily (``pip install cosmop[viz]``); the non-interactive Agg backend is
used, so drawing works without a display. Every robot has its own colour (:mod:`.palette`,
distinct for 50 robots and more), every id is written where it does not cover another label
(:mod:`.labels`), a legend explains the markers, and the order between robots is drawn: each
coordination pair is an arrow from the responder's ``Res`` to the requester's ``Req``, each
message a dashed arrow from the step that sends it to the step that waits for it. The title
says whether the plans are feasible, and if not why, in red. By default the picture shows
where the team works (:mod:`.view`), not a whole big map.
"""

from __future__ import annotations

import io
import textwrap
from pathlib import Path
from typing import Any

from cosmop.events import Event
from cosmop.io import write_atomic
from cosmop.planning.plan_types import MESSAGE_PRIMITIVES, PlanSet, RobotPlan
from cosmop.scene import Scene
from cosmop.viz.labels import Label, place_labels
from cosmop.viz.scene_drawing import (
    DEFAULT_ROBOT_SIZE,
    PLAN_STYLE,
    STEP_MARKS,
    SceneArtists,
    draw_scene,
    planned_path,
    scene_legend,
)
from cosmop.viz.view import activity_box, crop

_LISTED_ROBOTS = 12  # beyond this many robots the legend only says that robots are labelled
_MANY_MESSAGES = 40  # beyond this many messages their arrows are thin and faint, and unlabelled
_TITLE_SIZE = 12.0  # pt
_TITLE_LINES = 6  # a longer reason is cut: the terminal and the plan file have it whole


def available() -> bool:
    """Whether matplotlib can be imported (the ``viz`` extra is installed)."""
    import importlib.util

    return importlib.util.find_spec("matplotlib") is not None


def _pyplot() -> Any:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:  # pragma: no cover - depends on the installation
        raise ImportError("drawing plans needs matplotlib: pip install 'cosmop[viz]'") from exc
    return plt


def _legend(ax: Any, plans: PlanSet | None, colours: dict[str, Any]) -> None:
    """What the marks of the plan plot mean, on the right of the axes; with few robots, each one."""
    from matplotlib.lines import Line2D

    def marker(symbol: str, text: str) -> Line2D:
        return Line2D([], [], ls="none", marker=f"${symbol}$", color="black", ms=8, label=text)

    def arrow(style: str, text: str) -> Line2D:
        return Line2D([], [], color="grey", lw=1, ls=style, marker=">", ms=5, label=text)

    handles = [
        *scene_legend(),
        Line2D([], [], ls="none", marker="s", color="saddlebrown", ms=5, label="object"),
        Line2D([], [], ls="none", marker="s", mfc="none", mec="black", ms=9, label="robot at its start"),
        Line2D([], [], color="black", lw=1.2, marker="o", ms=3, label="planned path (GoTo waypoints)"),
        marker("P", "P: pick up"),
        marker("D", "D: drop off"),
        marker("?", "?O: request (waits for O away)"),
        marker("!", "!O: response (O moved away)"),
        arrow("-", "order: responder → requester"),
        arrow("--", "message: sender → receiver (waits until sent)"),
    ]
    if plans is not None and len(plans.robots) <= _LISTED_ROBOTS:
        for rid, plan in plans.robots.items():
            handles.append(Line2D([], [], color=colours[rid], lw=2, label=f"{rid}: {plan.horizon} steps"))
    elif plans is not None:
        handles.append(Line2D([], [], ls="none", label=f"{len(plans.robots)} robots, labelled on the map"))
    ax.legend(handles=handles, loc="upper left", fontsize=7, bbox_to_anchor=(1.01, 1.0), frameon=False)


def _coordination(ax: Any, plans: PlanSet, colours: dict[str, Any]) -> list[Label]:
    """Arrows from each responder's Res(O) to its requester's Req(O); their labels to place."""
    from matplotlib.patches import FancyArrowPatch

    labels = []
    for k, pair in enumerate(plans.coordination, start=1):
        ends = []
        for rid, primitive in ((pair.responder, "Res"), (pair.requester, "Req")):
            plan = plans.robots.get(rid)
            steps = [
                s
                for s in (plan.steps if plan else ())
                if s.primitive == primitive and s.object == pair.object
            ]
            ends.append(steps[0].robot[:2] if steps else None)
        start, end = ends
        if start is None or end is None or start == end:
            continue
        colour = colours.get(pair.responder, "grey")
        ax.add_patch(
            FancyArrowPatch(
                start,
                end,
                arrowstyle="-|>",
                mutation_scale=12,
                lw=1,
                color=colour,
                connectionstyle="arc3,rad=0.15",
                zorder=4,
                gid="order",
            )
        )
        mid = ((start[0] + end[0]) / 2, (start[1] + end[1]) / 2)
        text = f"{k}. {pair.responder}→{pair.requester}: {pair.object}"
        labels.append(Label(*mid, text, {"fontsize": 7, "color": colour}))
    return labels


def _boxes(ax: Any, squares: list[tuple[float, float, float]]) -> list[tuple[float, float, float, float]]:
    """Display boxes of squares ``(x, y, side)`` given in data units."""
    out = []
    for x, y, side in squares:
        (x0, y0), (x1, y1) = ax.transData.transform(
            [(x - side / 2, y - side / 2), (x + side / 2, y + side / 2)]
        )
        out.append((min(x0, x1), min(y0, y1), max(x0, x1), max(y0, y1)))
    return out


def _message_ends(plans: PlanSet, event: Event) -> tuple[tuple[float, float], tuple[float, float]] | None:
    """Where a message is sent and where it is waited for: the poses (mm) of the sender's step
    that sends `event` and of the receiver's step that waits for it; None if either is missing."""
    ends = []
    for rid in (event.sender, event.receiver):
        plan = plans.robots.get(rid) if rid is not None else None
        step = next((s for s in plan.steps if s.message == event), None) if plan is not None else None
        if step is None:
            return None
        ends.append((step.robot[0], step.robot[1]))
    return ends[0], ends[1]


def _messages(ax: Any, plans: PlanSet, colours: dict[str, Any]) -> None:
    """A dashed arrow, in the sender's colour, from each message's sending step to its waiting
    step (``gid="message"``); a message whose steps are not in the plans has none."""
    from matplotlib.patches import FancyArrowPatch

    # hundreds of full-strength arrows would hide the map: with many, each is a faint hint
    many = len(plans.messages) > _MANY_MESSAGES
    look: dict[str, Any] = (  # matplotlib keywords
        {"lw": 0.5, "alpha": 0.35, "mutation_scale": 7}
        if many
        else {"lw": 1, "alpha": 0.9, "mutation_scale": 11}
    )
    for message in plans.messages:
        ends = _message_ends(plans, message.event)
        if ends is None:
            continue
        arrow = FancyArrowPatch(
            *ends,
            arrowstyle="-|>",
            linestyle="--",
            color=colours.get(message.sender, "grey"),
            connectionstyle="arc3,rad=-0.15",  # bends the other way than the orders'
            zorder=4,
            gid="message",
            **look,
        )
        ax.add_patch(arrow)


def _title(ax: Any, plans: PlanSet | None, name: str | None) -> None:
    """The title: the scenario's (or the given) name and the verdict, wrapped to the figure.

    A feasible plan set says so with its number of robots; an infeasible one says
    ``infeasible: <reason>`` in red, on as many lines as the figure's width needs (at most
    :data:`_TITLE_LINES`). Call it once the view is fixed: it lays the figure out to measure.
    """
    text, colour = name or (plans.scenario if plans is not None else ""), "black"
    if plans is not None and plans.feasible:
        count = len(plans.robots)
        text += f": feasible, {count} robot{'' if count == 1 else 's'}"
    elif plans is not None:
        text, colour = f"{text}: infeasible: {plans.reason}", "red"
    fig = ax.figure
    fig.tight_layout()
    ax.apply_aspect()  # the axes' final box, which the title is centred on
    left, _, right, _ = ax.get_position().extents  # figure fractions
    # the title may reach over the legend, as far on both sides of the axes' centre
    half = min(left + right, 2 - left - right) / 2 * fig.get_figwidth() * 72  # pt
    width = max(int(0.9 * 2 * half / (0.6 * _TITLE_SIZE)), 20)  # 0.6 em per DejaVu Sans character
    lines = textwrap.wrap(text, width, max_lines=_TITLE_LINES, placeholder=" …") or [""]
    ax.set_title("\n".join(lines), color=colour, fontsize=_TITLE_SIZE)


def _paths(
    ax: Any, scene: Scene, plans: PlanSet | None, drawn: SceneArtists
) -> tuple[list[Label], list[tuple[float, float, float]]]:
    """Each plan's path through its waypoints with its primitives' marks; the labels to place
    and the squares ``(x, y, side)`` (mm) that labels must not cover."""
    labels: list[Label] = []
    squares = [(*o.position, o.size) for o in scene.objects.values()]
    # hundreds of ?tag and !tag marks would bury the map: many messages show as their arrows only
    tags = plans is None or len(plans.messages) <= _MANY_MESSAGES
    for rid, robot in scene.robots.items():
        plan = plans.robots.get(rid) if plans is not None else None
        if plan is not None:
            path = planned_path(robot, plan)
            ax.plot(*zip(*path, strict=True), color=drawn.colours[rid], lw=1.2, marker="o", ms=3)
            labels += _primitive_labels(plan, drawn.colours[rid], messages=tags)
            squares += [(x, y, 0) for x, y in path]
    return labels, squares


def _view(ax: Any, scene: Scene, plans: PlanSet | None, full_map: bool) -> None:
    """Fix the axes' limits (mm): the whole map, or the activity with a margin within it."""
    ax.autoscale_view()
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    activity = None if full_map else activity_box(scene, plans)
    if activity is not None:
        robot = max((r.size for r in scene.robots.values()), default=DEFAULT_ROBOT_SIZE)
        x0, y0, x1, y1 = crop(activity, (x0, y0, x1, y1), robot)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)  # fixed before placing labels in pixels


def _fit(fig: Any, ax: Any, pad: float = 0.05) -> None:
    """Lay the figure out so that the map, its labels, title and legend all lie inside it.

    ``tight_layout`` does not know that an equal-aspect map of a nearly square view cannot
    grow wider without growing taller: with the legend beside it, the content can be wider than
    the figure. The figure is then widened by what sticks out (`pad`: inches kept free).
    """
    fig.tight_layout()
    ax.apply_aspect()  # the axes' box as drawn, which the labels are then placed in
    for _ in range(3):  # one widening is enough in practice; the loop guards odd fonts
        content = fig.get_tightbbox(fig.canvas.get_renderer())  # inches
        width, height = fig.get_size_inches()
        over = max(0.0, pad - content.x0) + max(0.0, content.x1 - (width - pad))
        if over < 0.02:
            return
        fig.set_size_inches(width + over, height)
        fig.tight_layout()
        ax.apply_aspect()


def draw_plan(
    scene: Scene, plans: PlanSet | None = None, *, title: str | None = None, full_map: bool = False
) -> Any:
    """A matplotlib figure of the scene and, if given, every robot's waypoints and primitives.

    Walls are black lines, workspaces grey (rectangles or crosses), objects small squares,
    robots their squares at the initial pose; each plan is a polyline through its waypoints
    with the primitives marked (P pick up, D drop off, ?O request, !O response), each
    coordination pair an arrow from the responder's response to the requester's request,
    numbered in the plan file's order, and each message a dashed arrow from the sender's step
    that sends it to the receiver's step that waits for it. A legend on the right explains the
    markers; the title gives the verdict (an infeasible plan's reason in red). Units are mm.

    Parameters
    ----------
    scene : Scene
    plans : PlanSet, optional
    title : str, optional
        The name at the head of the title (default: the plan set's scenario name); the
        verdict follows it.
    full_map : bool
        Draw the whole map. By default the view is cut to where the team works (robots'
        starts, planned poses, the objects and workspaces the plans use; see
        :func:`cosmop.viz.view.activity_box`) with a margin, so that a big map stays readable.

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(9, 7))
    drawn = draw_scene(ax, scene, style=PLAN_STYLE)
    labels, squares = _paths(ax, scene, plans, drawn)
    labels = [*drawn.labels, *labels]
    if plans is not None:
        labels += _coordination(ax, plans, drawn.colours)
        _messages(ax, plans, drawn.colours)
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    _legend(ax, plans, drawn.colours)
    _view(ax, scene, plans, full_map)
    _title(ax, plans, title)
    _fit(fig, ax)
    obstacles = [(x0 - 3, y0 - 3, x1 + 3, y1 + 3) for x0, y0, x1, y1 in _boxes(ax, squares)]
    place_labels(ax, labels, obstacles=obstacles)
    return fig


def _primitive_labels(plan: RobotPlan, colour: Any, messages: bool = True) -> list[Label]:
    """A mark where each primitive but GoTo is done: P, D, ?O (request about O), !O (response),
    ?tag and !tag (wait for, send a message), the last two only if `messages`."""
    labels = []
    for step in plan.steps:
        if step.primitive in STEP_MARKS and (messages or step.message is None):
            x, y, _ = step.robot
            what = step.object or (step.message.tag or "" if step.message is not None else "")
            text = STEP_MARKS[step.primitive] + (what if step.primitive in MESSAGE_PRIMITIVES else "")
            labels.append(Label(x, y, text, {"fontsize": 8, "color": colour, "weight": "bold"}))
    return labels


def save_plan_png(
    scene: Scene,
    plans: PlanSet | None,
    path: str | Path,
    *,
    title: str | None = None,
    full_map: bool = False,
) -> None:
    """Draw (:func:`draw_plan`, with the same `title` and `full_map`) and write a PNG atomically.

    Parameters
    ----------
    scene : Scene
        The scene to draw (mm).
    plans : PlanSet or None
        The plans to draw over it (None: the scene alone).
    path : str or pathlib.Path
        The PNG file to write.
    title : str, optional
        The name at the head of the title (default: the plan set's scenario name).
    full_map : bool, optional
        Draw the whole map rather than where the team works.
    """
    plt = _pyplot()
    fig = draw_plan(scene, plans, title=title, full_map=full_map)
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=110, bbox_inches="tight", pad_inches=0.15)  # no blank bands
    plt.close(fig)
    write_atomic(path, buffer.getvalue())
