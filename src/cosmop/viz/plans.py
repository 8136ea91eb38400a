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
from cosmop.planning.plan import PlanSet
from cosmop.scenario import Scene
from cosmop.viz.labels import Label, place_labels
from cosmop.viz.palette import robot_colours

_LABELS = {"PickUp": "P", "DropOff": "D", "Req": "?", "Res": "!"}
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
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    def marker(symbol: str, text: str) -> Line2D:
        return Line2D([], [], ls="none", marker=f"${symbol}$", color="black", ms=8, label=text)

    handles = [
        Line2D([], [], color="black", lw=2, label="wall"),
        Patch(color="lightgrey", label="workspace"),
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
    from matplotlib.patches import Rectangle

    fig, ax = plt.subplots(figsize=(9, 7))
    for wall in scene.obstacles:
        ax.plot([wall.start[0], wall.end[0]], [wall.start[1], wall.end[1]], color="black", lw=2)
    labels: list[Label] = []
    for wid, ws in scene.workspaces.items():
        if ws.point is not None:
            ax.plot(*ws.point, marker="x", color="grey", ms=8)
        else:
            ax.add_patch(
                Rectangle(
                    (ws.x[0], ws.y[0]), ws.x[1] - ws.x[0], ws.y[1] - ws.y[0], color="lightgrey", alpha=0.7
                )
            )
        labels.append(Label(*ws.center, wid, {"fontsize": 8, "color": "dimgrey"}, center=not ws.is_point))
    for oid, obj in scene.objects.items():
        h = obj.size / 2
        ax.add_patch(
            Rectangle((obj.position[0] - h, obj.position[1] - h), obj.size, obj.size, color="saddlebrown")
        )
        labels.append(Label(*obj.position, oid, {"fontsize": 7}))
    colours = dict(zip(scene.robots, robot_colours(len(scene.robots)), strict=True))
    squares = [(*o.position, o.size) for o in scene.objects.values()]
    for rid, robot in scene.robots.items():
        colour = colours[rid]
        h = robot.size / 2
        x0, y0, _ = robot.pose
        ax.add_patch(Rectangle((x0 - h, y0 - h), robot.size, robot.size, fill=False, ec=colour, lw=1.5))
        labels.insert(0, Label(x0, y0, rid, {"fontsize": 8, "color": colour, "weight": "bold"}, center=True))
        plan = plans.robots.get(rid) if plans is not None else None
        if plan is None:
            continue
        xs, ys = [x0], [y0]
        for step in plan.steps:
            x, y, _ = step.robot
            if step.primitive == "GoTo":
                xs.append(x)
                ys.append(y)
            elif step.primitive in _LABELS:
                what = step.object or (step.message.split(",")[-1].rstrip(")") if step.message else "")
                text = _LABELS[step.primitive] + (what if step.primitive in ("Req", "Res") else "")
                labels.append(Label(x, y, text, {"fontsize": 8, "color": colour, "weight": "bold"}))
        ax.plot(xs, ys, color=colour, lw=1.2, marker="o", ms=3)
        squares += [(x, y, 0) for x, y in zip(xs, ys, strict=True)]
    if plans is not None:
        labels += _coordination(ax, plans, colours)
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    _legend(ax, plans, colours)
    ax.set_title(title or (plans.scenario if plans is not None else ""))
    fig.tight_layout()
    ax.autoscale_view()
    ax.set_xlim(ax.get_xlim())
    ax.set_ylim(ax.get_ylim())  # fixed before placing labels in pixels
    obstacles = [(x0 - 3, y0 - 3, x1 + 3, y1 + 3) for x0, y0, x1, y1 in _boxes(ax, squares)]
    place_labels(ax, labels, obstacles=obstacles)
    return fig


def save_plan_png(scene: Scene, plans: PlanSet | None, path: str | Path, *, title: str | None = None) -> None:
    """Draw and write a PNG atomically."""
    plt = _pyplot()
    fig = draw_plan(scene, plans, title=title)
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=110)
    plt.close(fig)
    write_atomic(path, buffer.getvalue())
