"""A self-contained web page of a scene, its plans and a simulated run (``cosmop view``).

One HTML file with the data, the style and the script inline (no network needed to open it):
an SVG of the walls, workspaces, objects, robots and planned paths, a legend, and with a trace
a time slider and a play button that move the robots (labelled, with what they carry, ``?``
while waiting for an answer, ``!`` after sending one) and people, and draw each message as an
arrow from sender to receiver with its time for :data:`MESSAGE_SHOWN_S` seconds, beside a log of
all messages.  A robot that stands says why in plain words (:mod:`cosmop.viz.explain`), and a
robot that replans has its planned path redrawn from that moment.  The view zooms (wheel) and
pans (drag); it opens fitted to the robots when they use a small part of the map
(:data:`FIT_BELOW`).  Words are in the scenario file's units, the scale bar in metres; the data
inside are the trace's mm and degrees (:class:`cosmop.traces.Trace`).
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from importlib import resources
from typing import Any

import numpy as np

from cosmop.io import write_atomic
from cosmop.planning.plan_types import PlanSet
from cosmop.scene import Scene
from cosmop.traces import Trace, as_trace, message_label
from cosmop.units import UnitSystem
from cosmop.viz.explain import Explainer, waiting_words
from cosmop.viz.palette import robot_colours, to_hex
from cosmop.viz.scene_drawing import (
    DEFAULT_ROBOT_SIZE,
    STEP_MARKS,
    ids_with_trace,
    planned_path,
    replanned_path,
)

__all__ = ["FIT_BELOW", "MESSAGE_SHOWN_S", "render_html", "save_html"]

MESSAGE_SHOWN_S = 2.0
"""Seconds (simulated) a message's arrow stays on the page after it was sent."""

FIT_BELOW = 0.4
"""The page opens fitted to the robots when their activity covers less than this share of the
map's area (a big map with the work in one corner), else on the whole map."""

_LEGEND = [
    ('<span class="swatch" style="background:#111;height:3px"></span>', "wall"),
    ('<span class="swatch" style="background:#d9d9d9"></span>', "workspace"),
    (
        '<span class="swatch" style="background:#8b4513;width:8px;height:8px"></span>',
        "object (on a robot: carried)",
    ),
    ('<span class="swatch" style="background:orange;border-radius:6px"></span>', "person"),
    (
        '<span class="swatch" style="border-style:dashed"></span>',
        "planned path (redrawn when a robot replans); P pick up, D drop off",
    ),
    ("<b>?</b>", "waiting for an answer (request, Req)"),
    ("<b>!</b>", "just answered (response, Res)"),
    ("<b>&rarr;</b>", "message from sender to receiver, with its time"),
    ("<i>words</i>", "why a robot stands: what it waits for"),
]


def _bounds(scene: Scene, trace: Trace | None) -> list[float]:
    """``[x0, x1, y0, y1]`` (mm): the scene and the robots' trace (every 200th of it), with margins."""
    xs = [p[0] for w in scene.obstacles for p in (w.start, w.end)]
    ys = [p[1] for w in scene.obstacles for p in (w.start, w.end)]
    xs += [r.pose[0] for r in scene.robots.values()] + [o.position[0] for o in scene.objects.values()]
    ys += [r.pose[1] for r in scene.robots.values()] + [o.position[1] for o in scene.objects.values()]
    if trace is not None:
        points = trace.seen("robots", max(1, len(trace.t) // 200))
        xs += points[:, 0].tolist()
        ys += points[:, 1].tolist()
    return _with_margin(xs, ys, floor=400.0)


def _activity(scene: Scene, plans: PlanSet | None, trace: Trace | None) -> list[float]:
    """``[x0, x1, y0, y1]`` (mm): where the robots are, go and carry things (their start poses,
    planned paths and trace), with a margin of two robots or a tenth of the span."""
    xs = [r.pose[0] for r in scene.robots.values()]
    ys = [r.pose[1] for r in scene.robots.values()]
    for rid, plan in (plans.robots if plans is not None else {}).items():
        if rid in scene.robots:
            path = planned_path(scene.robots[rid], plan)
            xs += [p[0] for p in path]
            ys += [p[1] for p in path]
    if trace is not None:
        points = trace.seen("robots", max(1, len(trace.t) // 200))
        xs += points[:, 0].tolist()
        ys += points[:, 1].tolist()
    if not xs:
        return _bounds(scene, trace)
    size = max((r.size for r in scene.robots.values()), default=DEFAULT_ROBOT_SIZE)
    return _with_margin(xs, ys, floor=2 * size)


def _with_margin(xs: list[float], ys: list[float], *, floor: float) -> list[float]:
    """The box of the points with a margin of 4 % of its span plus `floor` mm (more below: the scale bar)."""
    span = max(max(xs) - min(xs), max(ys) - min(ys), 1000.0)
    margin = 0.04 * span + floor
    return [min(xs) - margin, max(xs) + margin, min(ys) - margin - 0.04 * span, max(ys) + margin]


def _opens_fitted(whole: list[float], activity: list[float]) -> bool:
    """Whether the robots' activity covers less than :data:`FIT_BELOW` of the map's area."""
    area = (whole[1] - whole[0]) * (whole[3] - whole[2])
    used = (activity[1] - activity[0]) * (activity[3] - activity[2])
    return area > 0 and used < FIT_BELOW * area


def _plans(scene: Scene, plans: PlanSet | None, trace: Trace | None) -> dict[str, list[dict[str, Any]]]:
    """Each robot's planned paths, mm: the plan's, then one from each replan on (``t``, s; the
    plan's is null), each with the marks of its other primitives (P, D, ?O, !O)."""
    out: dict[str, list[dict[str, Any]]] = {}
    for rid, plan in (plans.robots if plans is not None else {}).items():
        if rid not in scene.robots:
            continue
        path = [list(point) for point in planned_path(scene.robots[rid], plan)]
        marks = [
            [*step.robot[:2], STEP_MARKS[step.primitive] + (step.object or "")]
            for step in plan.steps
            if step.primitive != "GoTo"
        ]
        out[rid] = [{"t": None, "path": path, "marks": marks}]
    for replan in trace.replans if trace is not None else ():
        route = replan["route"]
        steps = route["steps"]
        path = [list(point) for point in replanned_path(route)]
        marks = [
            [
                *s["pose"][:2],
                STEP_MARKS.get(s["primitive"], "")
                + (s["about"] if s["primitive"] in ("PickUp", "DropOff") else ""),
            ]
            for s in steps
            if s["primitive"] != "GoTo"
        ]
        out.setdefault(replan["robot"], []).append({"t": replan["t"], "path": path, "marks": marks})
    return out


def _units_text(units: UnitSystem) -> str:
    """The page header's note on units: what the page shows and what each file uses."""
    if units == "m":
        return (
            "lengths in m, times in s; the scenario file: m and radians; "
            "the plan and trace files: mm and degrees"
        )
    return "scale in m; words, scenario, plan and trace files: mm and degrees; times in s"


def _column(values: np.ndarray, digits: int = 0) -> list[float | None]:
    """Values rounded for the page (to whole mm, or `digits` decimals); None where NaN (not shown)."""
    return [None if v != v else round(v, digits) if digits else round(v) for v in values.tolist()]


def _trace(trace: Trace, object_ids: list[str], max_frames: int) -> dict[str, Any]:
    """The trace as columns (one list per robot and coordinate), at most `max_frames` frames.

    Each column has an entry per frame kept; None where the trace does not show the robot,
    person or object then (a trace of another tool may leave it out of some frames).
    """
    n = len(trace.t)
    stride = max(1, -(-n // max_frames))
    picked = list(range(0, n, stride)) if (n - 1) % stride == 0 else [*range(0, n, stride), n - 1]
    points: dict[str, dict[str, dict[str, list[float | None]]]] = {"humans": {}, "objects": {}}
    for group, columns in points.items():
        xy = trace.positions(group)[picked]
        for j, pid in enumerate(trace.ids(group)):
            if not np.isnan(xy[:, j, 0]).all():
                columns[pid] = {"x": _column(xy[:, j, 0]), "y": _column(xy[:, j, 1])}
    return {
        "t": [round(t, 3) for t in trace.t[picked].tolist()],
        "robots": _robot_columns(trace, picked, object_ids),
        **points,
    }


def _robot_columns(trace: Trace, picked: list[int], object_ids: list[str]) -> dict[str, dict[str, list[Any]]]:
    """Per robot the trace shows in the frames `picked`: x, y (mm), h (degrees), carrying, waiting.

    ``carrying`` is an index into `object_ids` (the scene's objects; None: nothing, or an object
    the scene does not declare).
    """
    index = {oid: k for k, oid in enumerate(object_ids)}
    robots: dict[str, dict[str, list[Any]]] = {}  # the page's JSON: a column per key
    for i, rid in enumerate(trace.robot_ids):
        x, y, h = trace.poses[picked, i].T
        shown = (~np.isnan(x)).tolist()
        if not any(shown):
            continue
        carrying = trace.carrying[picked, i].tolist() if trace.carrying is not None else [-1] * len(picked)
        waiting = trace.waiting[picked, i].tolist() if trace.waiting is not None else [False] * len(picked)
        why = _why_columns(trace, picked, i)
        robots[rid] = {
            "x": _column(x),
            "y": _column(y),
            "h": _column(h, 1),
            "carrying": [
                index.get(trace.object_ids[c]) if on and c >= 0 else None
                for c, on in zip(carrying, shown, strict=True)
            ],
            "waiting": [w if on else None for w, on in zip(waiting, shown, strict=True)],
            **why,
        }
    return robots


def _why_columns(trace: Trace, picked: list[int], i: int) -> dict[str, list[Any]]:
    """Robot `i`'s reasons to stand in the frames `picked`: ``awaits`` (a message name),
    ``yields`` (the robot or person it gives way to) and ``delayed`` (true/false), None when not."""
    out = {}
    for key, array in (("awaits", trace.awaits), ("yields", trace.yields_to), ("delayed", trace.delayed)):
        if array is not None:
            out[key] = [None if v is None or v is False else v for v in array[picked, i].tolist()]
    return out


def _scene_data(scene: Scene, plans: PlanSet | None, robot_ids: list[str]) -> dict[str, Any]:
    """Walls, workspaces, objects, people and robots (with colour and plan length) for the page."""
    colours = dict(zip(robot_ids, map(to_hex, robot_colours(len(robot_ids))), strict=True))
    steps = {rid: plan.horizon for rid, plan in (plans.robots if plans is not None else {}).items()}
    return {
        "walls": [[*w.start, *w.end] for w in scene.obstacles],
        "workspaces": {
            wid: {"point": list(w.point)}
            if w.point is not None
            else {"x": list(w.ranges[0]), "y": list(w.ranges[1])}
            for wid, w in scene.workspaces.items()
        },
        "objects": {oid: {"size": o.size, "position": list(o.position)} for oid, o in scene.objects.items()},
        "object_ids": list(scene.objects),
        "humans": {hid: {"size": h.size} for hid, h in scene.humans.items()},
        "robots": {
            rid: {
                "size": scene.robots[rid].size if rid in scene.robots else DEFAULT_ROBOT_SIZE,
                "pose": list(scene.robots[rid].pose) if rid in scene.robots else [0.0, 0.0, 0.0],
                "colour": colours[rid],
                "steps": steps.get(rid),
            }
            for rid in robot_ids
        },
    }


def _waits(scene: Scene, plans: PlanSet | None, trace: Trace | None, explainer: Explainer) -> dict[str, str]:
    """Plain words for every message a robot waits for in the plans or the trace."""
    words = waiting_words(scene, plans)
    if trace is not None and trace.awaits is not None:
        for name in {v for v in trace.awaits.ravel().tolist() if v is not None} - words.keys():
            words[name] = explainer.awaits(name)
    return words


def _messages(trace: Trace | None, waits: dict[str, str]) -> list[dict[str, Any]]:
    """The trace's messages in time order: time (s), sender, receiver, a short label and, when
    known, why the receiver waited for it (``why``, plain words)."""
    out = []
    for m in trace.messages if trace is not None else ():
        entry = {"t": float(m["t"]), "from": m["from"], "to": m["to"], "label": message_label(m)}
        if isinstance(m.get("event"), str) and m["event"] in waits:
            entry["why"] = f"{m['to']} {waits[m['event']]}"
        out.append(entry)
    return sorted(out, key=lambda m: m["t"])


def render_html(
    scene: Scene,
    *,
    plans: PlanSet | None = None,
    trace: Trace | Mapping[str, Any] | None = None,
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
    trace : Trace or Mapping, optional
        The run (:class:`cosmop.traces.Trace`, or its ``cosmop.trace/1`` JSON); without it the
        page shows the initial scene and the plans.
    title : str, optional
        Default: the plans' or trace's scenario name.
    max_frames : int, optional
        At most this many frames are kept (uniformly; the last always), to bound the file size.

    Returns
    -------
    str
    """
    trace = as_trace(trace) if trace is not None else None
    explainer = Explainer(scene, plans)
    robot_ids = ids_with_trace(scene.robots, trace, "robots")
    whole, activity = _bounds(scene, trace), _activity(scene, plans, trace)
    name = (
        title
        or (plans.scenario if plans is not None else None)
        or (trace.scenario if trace is not None else None)
        or "cosmop"
    )
    waits = _waits(scene, plans, trace, explainer)
    data = {
        "title": name,
        "units_text": _units_text(scene.units),
        "bounds": whole,
        "activity": activity,
        "opens_fitted": _opens_fitted(whole, activity),
        **_scene_data(scene, plans, robot_ids),
        "plans": _plans(scene, plans, trace),
        "waits": waits,
        "yields": {
            who: explainer.yields(who)
            for who in [*robot_ids, *scene.humans, *(trace.human_ids if trace else ())]
        },
        "trace": _trace(trace, list(scene.objects), max_frames) if trace is not None else None,
        "messages": _messages(trace, waits),
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
    trace: Trace | Mapping[str, Any] | None = None,
    title: str | None = None,
) -> int:
    """Write :func:`render_html` to `path` atomically; return the number of bytes written.

    Parameters
    ----------
    scene : Scene
        Walls, workspaces, objects, robots and people (mm).
    path : str or os.PathLike
        The HTML file to write.
    plans : PlanSet, optional
        Drawn as dashed paths with their primitives.
    trace : Trace or Mapping, optional
        The run (a :class:`cosmop.traces.Trace` or its ``cosmop.trace/1`` JSON).
    title : str, optional
        Default: the plans' or trace's scenario name.

    Returns
    -------
    int
        The size of the file, bytes.
    """
    text = render_html(scene, plans=plans, trace=trace, title=title)
    write_atomic(path, text)
    return len(text.encode("utf-8"))
