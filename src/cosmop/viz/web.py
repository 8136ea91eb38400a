"""A self-contained web page of a scene, its plans and a simulated run (``cosmop view``).

One HTML file with the data, the style and the script inline (no network needed to open it):
an SVG of the walls, workspaces, objects, robots and planned paths, a legend, and with a trace
a time slider and a play button that move the robots (labelled, with what they carry, ``?``
while waiting for an answer, ``!`` after sending one) and people, and draw each message as an
arrow from sender to receiver with its time for :data:`MESSAGE_SHOWN_S` seconds, beside a log of
all messages. The page shows lengths in metres; the data inside are the trace's mm and degrees.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping, Sequence
from importlib import resources
from typing import Any

from cosmop.io import write_atomic
from cosmop.planning.plan import PlanSet
from cosmop.scenario import Scene
from cosmop.traces import message_label
from cosmop.viz.palette import robot_colours, to_hex

__all__ = ["MESSAGE_SHOWN_S", "render_html", "save_html"]

MESSAGE_SHOWN_S = 2.0
"""Seconds (simulated) a message's arrow stays on the page after it was sent."""

_MARKS = {"PickUp": "P", "DropOff": "D", "Req": "?", "Res": "!"}
_LEGEND = [
    ('<span class="swatch" style="background:#111;height:3px"></span>', "wall"),
    ('<span class="swatch" style="background:#d9d9d9"></span>', "workspace"),
    (
        '<span class="swatch" style="background:#8b4513;width:8px;height:8px"></span>',
        "object (on a robot: carried)",
    ),
    ('<span class="swatch" style="background:orange;border-radius:6px"></span>', "person"),
    ('<span class="swatch" style="border-style:dashed"></span>', "planned path; P pick up, D drop off"),
    ("<b>?</b>", "waiting for an answer (request, Req)"),
    ("<b>!</b>", "just answered (response, Res)"),
    ("<b>&rarr;</b>", "message from sender to receiver, with its time"),
]


def _bounds(scene: Scene, frames: Sequence[Mapping[str, Any]]) -> list[float]:
    xs = [p[0] for w in scene.obstacles for p in (w.start, w.end)]
    ys = [p[1] for w in scene.obstacles for p in (w.start, w.end)]
    xs += [r.pose[0] for r in scene.robots.values()] + [o.position[0] for o in scene.objects.values()]
    ys += [r.pose[1] for r in scene.robots.values()] + [o.position[1] for o in scene.objects.values()]
    for frame in frames[:: max(1, len(frames) // 200)]:
        for state in (frame.get("robots") or {}).values():
            xs.append(state["pose"][0])
            ys.append(state["pose"][1])
    span = max(max(xs) - min(xs), max(ys) - min(ys), 1000.0)
    margin = 0.04 * span + 400
    return [min(xs) - margin, max(xs) + margin, min(ys) - margin - 0.04 * span, max(ys) + margin]


def _plans(scene: Scene, plans: PlanSet | None) -> dict[str, Any]:
    out = {}
    for rid, plan in (plans.robots if plans is not None else {}).items():
        if rid not in scene.robots:
            continue
        x0, y0, _ = scene.robots[rid].pose
        path, marks = [[x0, y0]], []
        for step in plan.steps:
            x, y, _ = step.robot
            if step.primitive == "GoTo":
                path.append([x, y])
            else:
                marks.append([x, y, _MARKS[step.primitive] + (step.object or "")])
        out[rid] = {"path": path, "marks": marks}
    return out


def _column(values: list[float], digits: int = 0) -> list[float]:
    return [round(v, digits) if digits else round(v) for v in values]


def _trace(trace: Mapping[str, Any], object_ids: list[str], max_frames: int) -> dict[str, Any]:
    """The trace as columns (one list per robot and coordinate), at most `max_frames` frames."""
    frames = trace["frames"]
    stride = max(1, -(-len(frames) // max_frames))
    picked = frames[::stride] if (len(frames) - 1) % stride == 0 else [*frames[::stride], frames[-1]]
    index = {oid: k for k, oid in enumerate(object_ids)}
    robots: dict[str, dict[str, list]] = {}
    points: dict[str, dict[str, dict[str, list]]] = {"humans": {}, "objects": {}}
    for frame in picked:
        for rid, state in (frame.get("robots") or {}).items():
            r = robots.setdefault(rid, {"x": [], "y": [], "h": [], "carrying": [], "waiting": []})
            r["x"].append(state["pose"][0])
            r["y"].append(state["pose"][1])
            r["h"].append(state["pose"][2])
            r["carrying"].append(index.get(state.get("carrying")))
            r["waiting"].append(bool(state.get("waiting")))
        for group in points:
            for ident, (x, y) in (frame.get(group) or {}).items():
                p = points[group].setdefault(ident, {"x": [], "y": []})
                p["x"].append(x)
                p["y"].append(y)
    for r in robots.values():
        r["x"], r["y"], r["h"] = _column(r["x"]), _column(r["y"]), _column(r["h"], 1)
    for group in points.values():
        for p in group.values():
            p["x"], p["y"] = _column(p["x"]), _column(p["y"])
    return {"t": [round(float(f["t"]), 3) for f in picked], "robots": robots, **points}


def render_html(
    scene: Scene,
    *,
    plans: PlanSet | None = None,
    trace: Mapping[str, Any] | None = None,
    title: str | None = None,
    max_frames: int = 3000,
) -> str:
    """The viewer page as one HTML string (see the module's description).

    Parameters
    ----------
    scene : Scene
        Walls, workspaces, objects, robots and people (mm).
    plans : PlanSet, optional
        Drawn as dashed paths with their primitives (P, D, ?O, !O).
    trace : Mapping, optional
        A ``cosmop.trace/1`` trace; without it the page shows the initial scene and the plans.
    title : str, optional
        Default: the plans' or trace's scenario name.
    max_frames : int, optional
        At most this many frames are kept (uniformly; the last always), to bound the file size.

    Returns
    -------
    str
    """
    frames = list(trace["frames"]) if trace is not None else []
    robot_ids = list(dict.fromkeys([*scene.robots, *(r for f in frames for r in f.get("robots") or {})]))
    colours = dict(zip(robot_ids, map(to_hex, robot_colours(len(robot_ids))), strict=True))
    steps = {rid: plan.horizon for rid, plan in (plans.robots if plans is not None else {}).items()}
    object_ids = list(scene.objects)
    name = (
        title or (plans.scenario if plans is not None else None) or (trace or {}).get("scenario") or "cosmop"
    )
    data = {
        "title": name,
        "units_text": "lengths in m on the page (the files: mm and degrees); times in s",
        "bounds": _bounds(scene, frames),
        "walls": [[*w.start, *w.end] for w in scene.obstacles],
        "workspaces": {
            wid: {"point": list(w.point)} if w.is_point else {"x": list(w.x), "y": list(w.y)}
            for wid, w in scene.workspaces.items()
        },
        "objects": {oid: {"size": o.size, "position": list(o.position)} for oid, o in scene.objects.items()},
        "object_ids": object_ids,
        "humans": {hid: {"size": h.size} for hid, h in scene.humans.items()},
        "robots": {
            rid: {
                "size": scene.robots[rid].size if rid in scene.robots else 400.0,
                "pose": list(scene.robots[rid].pose) if rid in scene.robots else [0.0, 0.0, 0.0],
                "colour": colours[rid],
                "steps": steps.get(rid),
            }
            for rid in robot_ids
        },
        "plans": _plans(scene, plans),
        "trace": _trace(trace, object_ids, max_frames) if trace is not None else None,
        "messages": sorted(
            (
                {"t": float(m["t"]), "from": m["from"], "to": m["to"], "label": message_label(m)}
                for m in (trace or {}).get("messages") or []
            ),
            key=lambda m: m["t"],
        ),
        "message_shown_s": MESSAGE_SHOWN_S,
        "legend": _LEGEND,
    }
    # "</" must not appear inside the script element; JSON allows "<\/" for it.
    payload = json.dumps(data, separators=(",", ":")).replace("</", "<\\/")
    template = resources.files("cosmop.viz").joinpath("viewer.html").read_text(encoding="utf-8")
    html_title = name.replace("&", "&amp;").replace("<", "&lt;")
    return template.replace("__TITLE__", html_title).replace("__DATA__", payload)


def save_html(
    scene: Scene,
    path: str | os.PathLike[str],
    *,
    plans: PlanSet | None = None,
    trace: Mapping[str, Any] | None = None,
    title: str | None = None,
) -> int:
    """Write :func:`render_html` to `path` atomically; return the number of bytes written."""
    text = render_html(scene, plans=plans, trace=trace, title=title)
    write_atomic(path, text)
    return len(text.encode("utf-8"))
