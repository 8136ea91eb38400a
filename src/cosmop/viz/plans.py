"""Draw a scene and its plans like the paper's figures: walls, objects, workspaces, waypoints.

matplotlib is imported lazily (``pip install cosmop[viz]``); the non-interactive Agg backend is
used, so drawing works without a display.
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

from cosmop.io import write_atomic
from cosmop.planning.plan import PlanSet
from cosmop.scenario import Scene

_LABELS = {"PickUp": "P", "DropOff": "D", "Req": "?", "Res": "!"}


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


def draw_plan(scene: Scene, plans: PlanSet | None = None, *, title: str | None = None) -> Any:
    """A matplotlib figure of the scene and, if given, every robot's waypoints and primitives.

    Walls are black lines, workspaces grey (rectangles or crosses), objects small squares,
    robots their squares at the initial pose; each plan is a polyline through its waypoints
    with the primitives marked (P pick up, D drop off, ? request, ! response).  Units are mm.
    """
    plt = _pyplot()
    from matplotlib.patches import Rectangle

    fig, ax = plt.subplots(figsize=(7, 7))
    for wall in scene.obstacles:
        ax.plot([wall.start[0], wall.end[0]], [wall.start[1], wall.end[1]], color="black", lw=2)
    for wid, ws in scene.workspaces.items():
        if ws.point is not None:
            ax.plot(*ws.point, marker="x", color="grey", ms=8)
            ax.annotate(wid, ws.point, textcoords="offset points", xytext=(4, 4), color="grey")
        else:
            ax.add_patch(
                Rectangle(
                    (ws.x[0], ws.y[0]), ws.x[1] - ws.x[0], ws.y[1] - ws.y[0], color="lightgrey", alpha=0.7
                )
            )
            ax.annotate(wid, ws.center, ha="center", va="center", color="dimgrey")
    for oid, obj in scene.objects.items():
        h = obj.size / 2
        ax.add_patch(
            Rectangle((obj.position[0] - h, obj.position[1] - h), obj.size, obj.size, color="saddlebrown")
        )
        ax.annotate(oid, obj.position, textcoords="offset points", xytext=(0, -12), ha="center", fontsize=7)
    colours = plt.get_cmap("tab10")
    for i, (rid, robot) in enumerate(scene.robots.items()):
        colour = colours(i % 10)
        h = robot.size / 2
        x0, y0, _ = robot.pose
        ax.add_patch(Rectangle((x0 - h, y0 - h), robot.size, robot.size, fill=False, ec=colour, lw=1.5))
        ax.annotate(rid, (x0, y0), ha="center", va="center", color=colour, fontsize=8, weight="bold")
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
                ax.annotate(
                    _LABELS[step.primitive],
                    (x, y),
                    textcoords="offset points",
                    xytext=(6, 6),
                    color=colour,
                    weight="bold",
                )
        ax.plot(xs, ys, color=colour, lw=1.2, marker="o", ms=3, label=f"{rid}: {plan.horizon} steps")
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    if plans is not None and plans.robots:
        ax.legend(loc="upper left", fontsize=7, bbox_to_anchor=(1.0, 1.0))
    ax.set_title(title or (plans.scenario if plans is not None else ""))
    fig.tight_layout()
    return fig


def save_plan_png(scene: Scene, plans: PlanSet | None, path: str | Path, *, title: str | None = None) -> None:
    """Draw and write a PNG atomically."""
    plt = _pyplot()
    fig = draw_plan(scene, plans, title=title)
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=110)
    plt.close(fig)
    write_atomic(path, buffer.getvalue())
