"""Draw a scene and its plans like the paper's figures: walls, objects, workspaces, waypoints.

matplotlib is imported lazily (``pip install cosmop[viz]``); the non-interactive Agg backend is
used, so drawing works without a display. Every robot has its own colour (:mod:`.palette`,
distinct for 50 robots and more), every id is written where it does not cover another label
(:mod:`.labels`), a legend explains the markers, and the order between robots is drawn: each
coordination pair is an arrow from the responder's ``Res`` to the requester's ``Req``.
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

from cosmop.io import write_atomic
from cosmop.planning.plan import MESSAGE_PRIMITIVES, PlanSet, RobotPlan
from cosmop.scene import Scene
from cosmop.viz.labels import Label, place_labels
from cosmop.viz.scene import PLAN_STYLE, STEP_MARKS, draw_scene, planned_path, scene_legend

_LISTED_ROBOTS = 12  # beyond this many robots the legend only says that robots are labelled


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

    handles = [
        *scene_legend(),
        Line2D([], [], ls="none", marker="s", color="saddlebrown", ms=5, label="object"),
        Line2D([], [], ls="none", marker="s", mfc="none", mec="black", ms=9, label="robot at its start"),
        Line2D([], [], color="black", lw=1.2, marker="o", ms=3, label="planned path (GoTo waypoints)"),
        marker("P", "P: pick up"),
        marker("D", "D: drop off"),
        marker("?", "?O: request (waits for O away)"),
        marker("!", "!O: response (O moved away)"),
        Line2D([], [], color="grey", lw=1, marker=">", ms=5, label="order: responder → requester"),
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
        if None in ends or ends[0] == ends[1]:
            continue
        colour = colours.get(pair.responder, "grey")
        ax.add_patch(
            FancyArrowPatch(
                ends[0],
                ends[1],
                arrowstyle="-|>",
                mutation_scale=12,
                lw=1,
                color=colour,
                connectionstyle="arc3,rad=0.15",
                zorder=4,
            )
        )
        mid = ((ends[0][0] + ends[1][0]) / 2, (ends[0][1] + ends[1][1]) / 2)
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


def draw_plan(scene: Scene, plans: PlanSet | None = None, *, title: str | None = None) -> Any:
    """A matplotlib figure of the scene and, if given, every robot's waypoints and primitives.

    Walls are black lines, workspaces grey (rectangles or crosses), objects small squares,
    robots their squares at the initial pose; each plan is a polyline through its waypoints
    with the primitives marked (P pick up, D drop off, ?O request, !O response), and each
    coordination pair an arrow from the responder's response to the requester's request,
    numbered in the plan file's order. A legend on the right explains the markers. Units are mm.
    """
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(9, 7))
    drawn = draw_scene(ax, scene, style=PLAN_STYLE)
    labels = list(drawn.labels)
    squares = [(*o.position, o.size) for o in scene.objects.values()]
    for rid, robot in scene.robots.items():
        plan = plans.robots.get(rid) if plans is not None else None
        if plan is not None:
            path = planned_path(robot, plan)
            ax.plot(*zip(*path, strict=True), color=drawn.colours[rid], lw=1.2, marker="o", ms=3)
            labels += _primitive_labels(plan, drawn.colours[rid])
            squares += [(x, y, 0) for x, y in path]
    if plans is not None:
        labels += _coordination(ax, plans, drawn.colours)
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    _legend(ax, plans, drawn.colours)
    ax.set_title(title or (plans.scenario if plans is not None else ""))
    fig.tight_layout()
    ax.autoscale_view()
    ax.set_xlim(ax.get_xlim())
    ax.set_ylim(ax.get_ylim())  # fixed before placing labels in pixels
    obstacles = [(x0 - 3, y0 - 3, x1 + 3, y1 + 3) for x0, y0, x1, y1 in _boxes(ax, squares)]
    place_labels(ax, labels, obstacles=obstacles)
    return fig


def _primitive_labels(plan: RobotPlan, colour: Any) -> list[Label]:
    """A mark where each primitive but GoTo is done: P, D, ?O (request about O), !O (response)."""
    labels = []
    for step in plan.steps:
        if step.primitive in STEP_MARKS:
            x, y, _ = step.robot
            what = step.object or (step.message.split(",")[-1].rstrip(")") if step.message else "")
            text = STEP_MARKS[step.primitive] + (what if step.primitive in MESSAGE_PRIMITIVES else "")
            labels.append(Label(x, y, text, {"fontsize": 8, "color": colour, "weight": "bold"}))
    return labels


def save_plan_png(scene: Scene, plans: PlanSet | None, path: str | Path, *, title: str | None = None) -> None:
    """Draw and write a PNG atomically."""
    plt = _pyplot()
    fig = draw_plan(scene, plans, title=title)
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=110)
    plt.close(fig)
    write_atomic(path, buffer.getvalue())
