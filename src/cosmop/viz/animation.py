"""Animate a simulation trace like the paper's figures: a GIF or an MP4 of the robots at work.

A trace (format ``cosmop.trace/1``) records every simulation cycle::

    {"format": "cosmop.trace/1", "scenario": "warehouse-2x2", "dt": 0.1,
     "frames": [{"t": 0.0,
                 "robots": {"R1": {"pose": [-2000, -1000, 0], "v": 0, "w": 0, "carrying": null,
                                   "primitive": "GoTo", "waiting": false}},
                 "humans": {"H1": [0, 1000]},
                 "objects": {"O1": [2000, -1000]}}, ...],
     "messages": [{"t": 4.2, "from": "R2", "to": "R1", "object": "O2", "event": "away(O2,R1,R2)"}]}

Coordinates are mm, headings degrees, times seconds. :func:`save_animation` draws the walls,
workspaces, objects, robots (with their trails, planned paths, carried objects, a ``?`` while
waiting for an answer and a ``!`` just after sending a message) and humans, frame by frame, and
writes the file atomically. matplotlib is imported lazily (``pip install 'cosmop[viz]'``, Agg
backend); MP4 also needs the ffmpeg binary of ``imageio-ffmpeg`` (``pip install 'cosmop[video]'``).
"""

from __future__ import annotations

import bisect
import contextlib
import importlib.util
import itertools
import math
import os
import secrets
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from cosmop.planning.plan import PlanSet
from cosmop.scenario import Scene
from cosmop.traces import message_label
from cosmop.viz.palette import robot_colours

__all__ = ["TRACE_FORMAT", "save_animation", "video_available"]

TRACE_FORMAT = "cosmop.trace/1"
"""The value of the ``format`` field of the simulation traces this module reads."""

_SUFFIXES = (".gif", ".mp4")
_MAX_FPS = 20.0
_MESSAGE_SHOWN = 2.0  # seconds (simulated) a '!' and the message's arrow stay after it was sent
_TARGET_LENGTH = 45.0  # seconds of animation by default: speed max(1, duration / 45)
_DEFAULT_ROBOT_SIZE = 400.0  # mm, for robots in the trace but not in the scene
_DEFAULT_OBJECT_SIZE = 100.0  # mm
_DEFAULT_HUMAN_SIZE = 500.0  # mm


def video_available() -> bool:
    """Whether MP4 output is possible: ``imageio_ffmpeg`` (the ``video`` extra) can be imported.

    Returns
    -------
    bool
    """
    return importlib.util.find_spec("imageio_ffmpeg") is not None


def _matplotlib() -> Any:
    try:
        import matplotlib
        import matplotlib.animation
    except ImportError as exc:  # pragma: no cover - depends on the installation
        raise ImportError("animations need matplotlib: pip install 'cosmop[viz]'") from exc
    return matplotlib


def _ffmpeg_exe() -> str:
    try:
        import imageio_ffmpeg
    except ImportError as exc:
        raise ImportError("MP4 animations need imageio-ffmpeg: pip install 'cosmop[video]'") from exc
    return imageio_ffmpeg.get_ffmpeg_exe()


# ----------------------------------------------------------------------------------------------
# Frames and timing
# ----------------------------------------------------------------------------------------------


def _frame_indices(n: int, max_frames: int) -> tuple[list[int], int]:
    """Every ``stride``-th frame index of ``range(n)``, plus the last, at most `max_frames` of them."""
    if n <= max_frames:
        return list(range(n)), 1
    if max_frames == 1:
        return [n - 1], n
    stride = math.ceil((n - 1) / (max_frames - 1))
    indices = list(range(0, n, stride))
    if indices[-1] != n - 1:
        indices.append(n - 1)
    return indices, stride


def _timing(
    trace: Mapping[str, Any],
    frames: Sequence[Mapping[str, Any]],
    max_frames: int,
    fps: float | None,
    speed: float | None,
) -> tuple[list[int], int, float]:
    """The frames to draw, their stride and the frame rate for a playback at `speed`.

    Without `fps`, the stride is grown until ``speed / (dt * stride) <= 20`` and the rate is
    exactly ``speed / (dt * stride)``; `speed` defaults to ``max(1, duration / 45)``.
    """
    times = [float(frame["t"]) for frame in frames]
    dt = _cycle(trace, times)
    if speed is None:
        speed = max(1.0, (times[-1] - times[0]) / _TARGET_LENGTH)
    indices, stride = _frame_indices(len(frames), max_frames)
    if fps is not None:
        return indices, stride, fps
    if dt is None:
        return indices, stride, _MAX_FPS
    least = math.ceil(speed / (dt * _MAX_FPS) - 1e-9)
    if least > stride:  # fewer frames, so that the rate stays at most 20 per second
        stride = least
        indices = list(range(0, len(frames), stride))
        if indices[-1] != len(frames) - 1:
            indices.append(len(frames) - 1)
    return indices, stride, speed / (dt * stride)


def _cycle(trace: Mapping[str, Any], times: Sequence[float]) -> float | None:
    """The simulation cycle in seconds: ``trace["dt"]``, else the median spacing of the frames."""
    dt = trace.get("dt")
    if isinstance(dt, int | float) and not isinstance(dt, bool) and math.isfinite(dt) and dt > 0:
        return float(dt)
    gaps = sorted(b - a for a, b in itertools.pairwise(times) if b > a)
    return gaps[len(gaps) // 2] if gaps else None


def _check_trace(trace: Any) -> list[Mapping[str, Any]]:
    if not isinstance(trace, Mapping):
        raise ValueError(f"a trace must be a mapping ({TRACE_FORMAT}), got {type(trace).__name__}")
    fmt = trace.get("format", TRACE_FORMAT)
    if fmt != TRACE_FORMAT:
        raise ValueError(f"unsupported trace format {fmt!r}; expected {TRACE_FORMAT!r}")
    frames = trace.get("frames")
    if not isinstance(frames, Sequence) or isinstance(frames, str | bytes) or not frames:
        raise ValueError("a trace needs a non-empty list of frames")
    for k, frame in enumerate(frames):
        if not isinstance(frame, Mapping) or "t" not in frame:
            raise ValueError(f"trace frame {k} must be a mapping with a time 't' (s)")
    return list(frames)


# ----------------------------------------------------------------------------------------------
# Atomic output through a file name
# ----------------------------------------------------------------------------------------------


def _temp_beside(target: Path) -> Path:
    """Create a new, empty file beside `target` with the same suffix (the writers pick the format by it)."""
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0)
    for _ in range(100):
        candidate = target.with_name(f".{target.stem}.{secrets.token_hex(6)}.tmp{target.suffix}")
        try:
            os.close(os.open(candidate, flags, 0o666))
        except FileExistsError:
            continue
        return candidate
    raise FileExistsError(f"could not create a temporary file in {target.parent}")


def _publish(tmp: Path, target: Path) -> None:
    """fsync `tmp` and move it onto `target` (keeping an existing target's permission bits)."""
    fd = os.open(tmp, os.O_RDONLY | getattr(os, "O_BINARY", 0))
    try:
        os.fsync(fd)
    finally:
        os.close(fd)
    with contextlib.suppress(OSError):
        if target.exists():
            os.chmod(tmp, target.stat().st_mode & 0o7777)
    os.replace(tmp, target)


# ----------------------------------------------------------------------------------------------
# Drawing
# ----------------------------------------------------------------------------------------------


def _limits(scene: Scene, frames: Sequence[Mapping[str, Any]]) -> tuple[float, float, float, float]:
    """``(x0, x1, y0, y1)`` in mm: the walls' extent (or everything's, without walls) plus a margin."""
    xs: list[float] = []
    ys: list[float] = []
    for wall in scene.obstacles:
        xs += [wall.start[0], wall.end[0]]
        ys += [wall.start[1], wall.end[1]]
    if not xs:
        for robot in scene.robots.values():
            xs.append(robot.pose[0])
            ys.append(robot.pose[1])
        for obj in scene.objects.values():
            xs.append(obj.position[0])
            ys.append(obj.position[1])
        for ws in scene.workspaces.values():
            xs += [ws.point[0]] if ws.point is not None else list(ws.x)
            ys += [ws.point[1]] if ws.point is not None else list(ws.y)
        for frame in frames:
            for state in (frame.get("robots") or {}).values():
                xs.append(float(state["pose"][0]))
                ys.append(float(state["pose"][1]))
            for group in ("humans", "objects"):
                for point in (frame.get(group) or {}).values():
                    xs.append(float(point[0]))
                    ys.append(float(point[1]))
    if not xs:
        return -1000.0, 1000.0, -1000.0, 1000.0
    sizes = [r.size for r in scene.robots.values()] or [_DEFAULT_ROBOT_SIZE]
    span = max(max(xs) - min(xs), max(ys) - min(ys), 1.0)
    margin = max(0.03 * span, 0.5 * max(sizes))
    return min(xs) - margin, max(xs) + margin, min(ys) - margin, max(ys) + margin


def _ids(declared: Mapping[str, Any], frames: Sequence[Mapping[str, Any]], group: str) -> list[str]:
    """The scene's ids in order, then any others that appear in the trace."""
    ids = dict.fromkeys(declared)
    for frame in frames:
        ids.update(dict.fromkeys(frame.get(group) or {}))
    return list(ids)


def _plan_polyline(scene: Scene, plans: PlanSet | None, rid: str) -> tuple[list[float], list[float]] | None:
    plan = plans.robots.get(rid) if plans is not None else None
    robot = scene.robots.get(rid)
    if plan is None or robot is None:
        return None
    xs, ys = [robot.pose[0]], [robot.pose[1]]
    for step in plan.steps:
        if step.primitive == "GoTo":
            xs.append(step.robot[0])
            ys.append(step.robot[1])
    return xs, ys


def _text_marker(
    ax: Any,
    text: str,
    colour: Any,
    fontsize: float,
    *,
    weight: str = "normal",
    va: str = "center",
    zorder: float = 5,
    visible: bool = True,
) -> Any:
    """A moving label: `text` as a marker (a glyph outline), horizontally centred on its point.

    Markers are drawn much faster than :class:`~matplotlib.text.Text` (no layout per frame).
    `va` is ``"top"``, ``"bottom"`` or ``"center"``: which edge of the text sits at the point.
    Move it with ``set_data([x], [y])`` (mm).
    """
    from matplotlib.font_manager import FontProperties
    from matplotlib.markers import MarkerStyle
    from matplotlib.path import Path as MplPath
    from matplotlib.textpath import TextPath

    glyphs = TextPath((0, 0), text, size=fontsize, prop=FontProperties(weight=weight))
    box = glyphs.get_extents()
    dy = {"top": -box.y1, "bottom": -box.y0}.get(va, -(box.y0 + box.y1) / 2)
    vertices = np.asarray(glyphs.vertices) + np.array([-(box.x0 + box.x1) / 2, dy])
    extent = float(np.abs(vertices).max()) or 1.0  # the marker is scaled to this half-size, in points
    marker = MarkerStyle(MplPath(vertices, glyphs.codes))
    (line,) = ax.plot(
        [],
        [],
        linestyle="none",
        marker=marker,
        markersize=2 * extent,
        markerfacecolor=colour,
        markeredgewidth=0,
        zorder=zorder,
        visible=visible,
    )
    return line


class _Animator:
    """The figure and its moving artists; :meth:`update` shows one trace frame."""

    def __init__(
        self,
        scene: Scene,
        trace: Mapping[str, Any],
        frames: list[Mapping[str, Any]],
        plans: PlanSet | None,
        title: str | None,
        dpi: float,
        shown: float = _MESSAGE_SHOWN,
    ) -> None:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.collections import LineCollection
        from matplotlib.figure import Figure
        from matplotlib.patches import Circle, Rectangle

        self.frames = frames
        self.shown = shown  # seconds a message stays drawn (at least about one frame's time step)
        x0, x1, y0, y1 = _limits(scene, frames)
        width, height = x1 - x0, y1 - y0
        base = 6.0
        if width >= height:
            figsize = (base + _LEGEND_WIDTH, max(2.5, base * height / width) + 0.5)
        else:
            figsize = (max(2.5, base * width / height) + 0.5 + _LEGEND_WIDTH, base)
        # A figure outside pyplot (drawn with Agg): nothing to close, the user's backend untouched.
        fig = Figure(figsize=figsize, dpi=dpi)
        FigureCanvasAgg(fig)
        ax = fig.add_subplot()
        self.fig, self.ax = fig, ax
        ax.set_xlim(x0, x1)
        ax.set_ylim(y0, y1)
        ax.set_aspect("equal")
        ax.set_autoscale_on(False)
        ax.set_xlabel("x [mm]", fontsize=8)
        ax.set_ylabel("y [mm]", fontsize=8)
        ax.tick_params(labelsize=7)
        self.prefix = title if title is not None else str(trace.get("scenario") or "")
        self.title = ax.set_title(self.prefix, fontsize=9)

        # The static background: walls, workspaces, planned paths.
        if scene.obstacles:
            segments = [[w.start, w.end] for w in scene.obstacles]
            ax.add_collection(LineCollection(segments, colors="black", linewidths=2, zorder=2))
        for wid, ws in scene.workspaces.items():
            if ws.point is not None:
                ax.plot(*ws.point, marker="x", color="grey", ms=7, zorder=1)
                ax.annotate(
                    wid, ws.point, textcoords="offset points", xytext=(4, 4), color="grey", fontsize=7
                )
            else:
                ax.add_patch(
                    Rectangle(
                        (ws.x[0], ws.y[0]),
                        ws.x[1] - ws.x[0],
                        ws.y[1] - ws.y[0],
                        color="lightgrey",
                        alpha=0.7,
                        zorder=0,
                    )
                )
                ax.text(*ws.center, wid, ha="center", va="center", color="dimgrey", fontsize=7, zorder=1)

        self.robot_ids = _ids(scene.robots, frames, "robots")
        colours = robot_colours(len(self.robot_ids))
        self.object_ids = _ids(scene.objects, frames, "objects")
        self.human_ids = _ids(getattr(scene, "humans", None) or {}, frames, "humans")
        humans = getattr(scene, "humans", None) or {}

        # Objects on the ground (a carried one is hidden here and drawn on its carrier).
        self.object_size = {
            oid: float(scene.objects[oid].size) if oid in scene.objects else _DEFAULT_OBJECT_SIZE
            for oid in self.object_ids
        }
        self.object_at: dict[str, tuple[float, float] | None] = {
            oid: tuple(scene.objects[oid].position) if oid in scene.objects else None
            for oid in self.object_ids
        }
        self.object_patch = {}
        self.object_label = {}
        for oid in self.object_ids:
            s = self.object_size[oid]
            self.object_patch[oid] = ax.add_patch(
                Rectangle((0, 0), s, s, color="saddlebrown", zorder=3, visible=False)
            )
            self.object_label[oid] = _text_marker(ax, oid, "black", 6, zorder=3, visible=False)

        # Robots: trail, planned path, body, heading tick, id, cargo, '?' and '!'.
        self.robot_size = {}
        self.trail_x: dict[str, list[float]] = {}
        self.trail_y: dict[str, list[float]] = {}
        self.artists: dict[str, dict[str, Any]] = {}
        messages = trace.get("messages") or []
        self.sent: dict[str, list[float]] = {rid: [] for rid in self.robot_ids}
        for message in messages:
            sender = message.get("from") if isinstance(message, Mapping) else None
            if sender in self.sent and isinstance(message.get("t"), int | float):
                self.sent[sender].append(float(message["t"]))
        for times in self.sent.values():
            times.sort()
        for i, rid in enumerate(self.robot_ids):
            colour = colours[i]
            size = float(scene.robots[rid].size) if rid in scene.robots else _DEFAULT_ROBOT_SIZE
            self.robot_size[rid] = size
            planned = _plan_polyline(scene, plans, rid)
            if planned is not None:
                ax.plot(*planned, color=colour, lw=0.8, ls="--", alpha=0.8, zorder=1)
            xs, ys = [], []
            for frame in frames:
                state = (frame.get("robots") or {}).get(rid)
                xs.append(float(state["pose"][0]) if state else math.nan)
                ys.append(float(state["pose"][1]) if state else math.nan)
            self.trail_x[rid], self.trail_y[rid] = xs, ys
            (trail,) = ax.plot([], [], color=colour, lw=1.0, alpha=0.9, zorder=2)
            body = ax.add_patch(
                Rectangle((0, 0), size, size, fc=(*colour[:3], 0.3), ec=colour, lw=1.5, zorder=4)
            )
            (tick,) = ax.plot([], [], color=colour, lw=2, solid_capstyle="butt", zorder=5)
            label = _text_marker(ax, rid, colour, 7, weight="bold", va="top", zorder=6)
            cargo = ax.add_patch(Rectangle((0, 0), 1, 1, color="saddlebrown", zorder=6, visible=False))
            question = _text_marker(ax, "?", colour, 14, weight="bold", va="bottom", zorder=7)
            bang = _text_marker(ax, "!", colour, 14, weight="bold", va="bottom", zorder=7)
            self.artists[rid] = {
                "trail": trail,
                "body": body,
                "tick": tick,
                "label": label,
                "cargo": cargo,
                "question": question,
                "bang": bang,
            }

        # Humans: orange discs of their size.
        self.human_artists = {}
        for hid in self.human_ids:
            size = float(getattr(humans.get(hid), "size", _DEFAULT_HUMAN_SIZE) or _DEFAULT_HUMAN_SIZE)
            disc = ax.add_patch(
                Circle((0, 0), size / 2, fc="orange", ec="darkorange", alpha=0.85, zorder=4, visible=False)
            )
            label = _text_marker(ax, hid, "black", 7, va="center", zorder=6, visible=False)
            self.human_artists[hid] = (disc, label)
        self.arrows = self._message_arrows(messages, colours)
        # GIF colours: few keep files small; each robot's colour needs its own shades
        self.palette_size = min(256, 48 + 4 * len(self.robot_ids))
        _legend(ax)
        fig.tight_layout()
        self.mm_per_pt = _mm_per_point(ax)
        self.spots: dict[tuple, dict[str, tuple[float, float]]] = {}

        # Everything that moves is drawn over a background rendered once (blitting).
        moving: list[Any] = [self.title]
        moving += list(self.object_patch.values()) + list(self.object_label.values())
        for a in self.artists.values():
            moving += a.values()
        for disc, label in self.human_artists.values():
            moving += [disc, label]
        for arrow, text, _ in self.arrows:
            moving += [arrow, text]
        self.moving = sorted(moving, key=lambda artist: artist.get_zorder())
        self.background: Any = None

    def _message_arrows(self, messages: Sequence[Any], colours: list) -> list[tuple[Any, Any, Mapping]]:
        """One hidden arrow and time label per message between two robots of the trace."""
        from matplotlib.patches import FancyArrowPatch

        out = []
        for message in messages:
            if not (isinstance(message, Mapping) and isinstance(message.get("t"), int | float)):
                continue
            if message.get("from") not in self.artists or message.get("to") not in self.artists:
                continue
            colour = colours[self.robot_ids.index(message["from"])]
            arrow = self.ax.add_patch(
                FancyArrowPatch(
                    (0, 0),
                    (1, 1),
                    arrowstyle="-|>",
                    mutation_scale=12,
                    lw=1.5,
                    color=colour,
                    zorder=8,
                    visible=False,
                )
            )
            text = self.ax.text(
                0, 0, f"{message_label(message)} @ {float(message['t']):.1f} s", fontsize=7, color=colour,
                ha="center", va="bottom", zorder=8, visible=False,
                bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.8},
            )  # fmt: skip
            out.append((arrow, text, message))
        return out

    def _show_messages(self, t: float, robots: Mapping[str, Any]) -> None:
        """Arrows from sender to receiver for the messages sent in the last ``shown`` seconds."""
        for arrow, text, message in self.arrows:
            age = t - float(message["t"])
            sender, receiver = robots.get(message["from"]), robots.get(message["to"])
            on = 0 <= age < self.shown and sender is not None and receiver is not None
            arrow.set_visible(on)
            text.set_visible(on)
            if on:
                a, b = (float(v) for v in sender["pose"][:2]), (float(v) for v in receiver["pose"][:2])
                (x1, y1), (x2, y2) = tuple(a), tuple(b)
                arrow.set_positions((x1, y1), (x2, y2))
                text.set_position(((x1 + x2) / 2, (y1 + y2) / 2))

    def _object_spots(self, carried: set[str]) -> dict[str, tuple[float, float]]:
        """Where the ids of the objects on the ground go: near each, not over another id or object."""
        visible = tuple(
            (oid, self.object_at[oid])
            for oid in self.object_ids
            if self.object_at[oid] and oid not in carried
        )
        if visible not in self.spots:
            boxes = [
                (x - self.object_size[o] / 2, y - self.object_size[o] / 2, x + self.object_size[o] / 2,
                 y + self.object_size[o] / 2)
                for o, (x, y) in visible
            ]  # fmt: skip
            spots = {}
            for oid, (x, y) in visible:
                w = (0.7 * 6 * len(oid) + 2) * self.mm_per_pt
                h = 1.3 * 6 * self.mm_per_pt
                s = self.object_size[oid] / 2
                candidates = [(0, -(s + h / 2)), (0, s + h / 2), (s + w / 2, 0), (-(s + w / 2), 0)]
                candidates += [(dx * (s + w / 2), dy * (s + h / 2)) for dx in (1, -1) for dy in (-1, 1)]
                for dx, dy in candidates:
                    box = (x + dx - w / 2, y + dy - h / 2, x + dx + w / 2, y + dy + h / 2)
                    if not any(
                        b[0] < box[2] and box[0] < b[2] and b[1] < box[3] and box[1] < b[3] for b in boxes
                    ):
                        break
                else:
                    dx, dy = candidates[0]
                    box = (x + dx - w / 2, y + dy - h / 2, x + dx + w / 2, y + dy + h / 2)
                boxes.append(box)
                spots[oid] = (x + dx, y + dy)
            self.spots = {visible: spots}  # objects move rarely: keep the last placement only
        return self.spots[visible]

    def draw(self, index: int) -> None:
        """Show frame `index` of the trace (an index into the full list of frames) on the canvas."""
        self.update(index)
        canvas = self.fig.canvas
        if self.background is None:
            for artist in self.moving:
                artist.set_animated(True)
            canvas.draw()
            self.background = canvas.copy_from_bbox(self.fig.bbox)
        canvas.restore_region(self.background)
        for artist in self.moving:
            if artist.get_visible():
                self.ax.draw_artist(artist)

    def rgba(self, frame_size: tuple[int, int]) -> memoryview | None:
        """The canvas's RGBA pixels, or None if they do not have the writer's `frame_size`."""
        canvas = self.fig.canvas
        if self.background is None or tuple(canvas.get_width_height(physical=True)) != tuple(frame_size):
            return None
        return canvas.buffer_rgba()

    def _message_recent(self, rid: str, t: float) -> bool:
        times = self.sent[rid]
        k = bisect.bisect_right(times, t)
        return k > 0 and t - times[k - 1] < self.shown

    def update(self, index: int) -> None:
        """Move the artists to frame `index` of the trace (an index into the full list of frames)."""
        frame = self.frames[index]
        t = float(frame["t"])
        text = f"t = {t:.1f} s"
        self.title.set_text(f"{self.prefix}    {text}" if self.prefix else text)
        robots = frame.get("robots") or {}
        carried: set[str] = set()

        for rid in self.robot_ids:
            a = self.artists[rid]
            state = robots.get(rid)
            a["trail"].set_data(self.trail_x[rid][: index + 1], self.trail_y[rid][: index + 1])
            visible = state is not None
            for key in ("body", "tick", "label"):
                a[key].set_visible(visible)
            if not visible:
                for key in ("cargo", "question", "bang"):
                    a[key].set_visible(False)
                continue
            x, y, heading = (float(v) for v in state["pose"][:3])
            size = self.robot_size[rid]
            h = size / 2
            a["body"].set_xy((x - h, y - h))
            rad = math.radians(heading)
            a["tick"].set_data([x, x + 0.8 * size * math.cos(rad)], [y, y + 0.8 * size * math.sin(rad)])
            a["label"].set_data([x], [y - 1.1 * h])
            oid = state.get("carrying")
            if oid:
                carried.add(oid)
                s = self.object_size.get(oid, _DEFAULT_OBJECT_SIZE)
                a["cargo"].set_bounds(x - s / 2, y - s / 2, s, s)
            a["cargo"].set_visible(bool(oid))
            waiting = bool(state.get("waiting"))
            recent = self._message_recent(rid, t)
            shift = 0.35 * h if waiting and recent else 0.0
            a["question"].set_visible(waiting)
            a["question"].set_data([x - shift], [y + 1.1 * h])
            a["bang"].set_visible(recent)
            a["bang"].set_data([x + shift], [y + 1.1 * h])

        objects = frame.get("objects") or {}
        for oid in self.object_ids:
            if oid in objects:
                self.object_at[oid] = (float(objects[oid][0]), float(objects[oid][1]))
            where = self.object_at[oid]
            shown = where is not None and oid not in carried
            self.object_patch[oid].set_visible(shown)
            self.object_label[oid].set_visible(shown)
            if shown:
                s = self.object_size[oid]
                self.object_patch[oid].set_xy((where[0] - s / 2, where[1] - s / 2))
        spots = self._object_spots(carried)
        for oid, (x, y) in spots.items():
            self.object_label[oid].set_data([x], [y])

        self._show_messages(t, robots)
        humans = frame.get("humans") or {}
        for hid, (disc, label) in self.human_artists.items():
            where = humans.get(hid)
            disc.set_visible(where is not None)
            label.set_visible(where is not None)
            if where is not None:
                disc.set_center((float(where[0]), float(where[1])))
                label.set_data([float(where[0])], [float(where[1])])


_LEGEND_WIDTH = 1.9  # inches added on the right of the animation for the legend


def _legend(ax: Any) -> None:
    """What the markers of an animation mean, on the right of the axes."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    def symbol(text: str, label: str) -> Line2D:
        return Line2D([], [], ls="none", marker=f"${text}$", color="black", ms=7, label=label)

    handles = [
        Line2D([], [], color="black", lw=2, label="wall"),
        Patch(color="lightgrey", label="workspace"),
        Line2D(
            [], [], ls="none", marker="s", color="saddlebrown", ms=4, label="object (on a robot: carried)"
        ),
        Line2D([], [], ls="none", marker="s", mfc="none", mec="black", ms=8, label="robot, heading tick, id"),
        Line2D([], [], color="grey", lw=1, label="path driven"),
        Line2D([], [], color="grey", lw=0.8, ls="--", label="path planned"),
        Line2D([], [], ls="none", marker="o", color="orange", ms=6, label="person"),
        symbol("?", "waits for an answer (Req)"),
        symbol("!", "sent an answer (Res)"),
        Line2D([], [], color="grey", lw=1.5, marker=">", ms=4, label="message → receiver, time"),
    ]
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=6, frameon=False)


def _mm_per_point(ax: Any) -> float:
    """Data units (mm) per typographic point, with the axes' final layout (equal aspect)."""
    ax.apply_aspect()
    (x0, _), (x1, _) = ax.transData.transform([(0.0, 0.0), (1000.0, 0.0)])
    px_per_mm = abs(x1 - x0) / 1000.0 or 1.0
    return ax.figure.dpi / 72.0 / px_per_mm


def _writer(animation: Any, suffix: str, fps: float, animator: _Animator) -> Any:
    """A PillowWriter (GIF) or FFMpegWriter (H.264 MP4) that takes the animator's canvas as it is.

    The stock writers re-render the whole figure for every frame with ``savefig``; these take the
    blitted canvas instead (and quantise GIF frames at once, to keep memory low), falling back on
    ``savefig`` if the canvas does not have the frame size.
    """
    if suffix == ".gif":
        from PIL import Image

        class GifWriter(animation.PillowWriter):  # type: ignore[misc, valid-type]
            def grab_frame(self, **savefig_kwargs: Any) -> None:
                pixels = animator.rgba(self.frame_size)
                frames = getattr(self, "_frames", None)
                if pixels is None or not isinstance(frames, list):
                    super().grab_frame(**savefig_kwargs)
                    return
                image = Image.frombuffer("RGBA", self.frame_size, pixels, "raw", "RGBA", 0, 1)
                frames.append(
                    image.convert("RGB").quantize(animator.palette_size, method=Image.Quantize.FASTOCTREE)
                )

        return GifWriter(fps=fps)

    class Mp4Writer(animation.FFMpegWriter):  # type: ignore[misc, valid-type]
        def grab_frame(self, **savefig_kwargs: Any) -> None:
            pixels = animator.rgba(self.frame_size)
            proc = getattr(self, "_proc", None)
            if pixels is None or proc is None or self.frame_format != "rgba":
                super().grab_frame(**savefig_kwargs)
                return
            proc.stdin.write(pixels)

    return Mp4Writer(fps=fps, codec="h264")


def save_animation(
    scene: Scene,
    trace: Mapping[str, Any],
    path: str | os.PathLike[str],
    *,
    plans: PlanSet | None = None,
    fps: float | None = None,
    max_frames: int = 400,
    title: str | None = None,
    dpi: float = 100,
    speed: float | None = None,
    size: int | None = None,
) -> int:
    """Render `trace` to `path` (.gif with Pillow, .mp4 with ffmpeg); return the number of frames written.

    Every drawn frame shows the walls (black), workspaces (grey rectangles, or crosses for
    points), objects (brown squares; a carried one on its carrier), the robots as squares of
    their size in their tab10 colour with a heading tick, their id and their trail so far, the
    planned paths (dashed, if `plans` is given), humans (orange discs of their size), a ``?``
    above a robot waiting for an answer and a ``!`` for 1 s (simulated) after it sent a message.
    The title shows the simulated time. Axes are in mm with equal aspect and fixed limits (the
    walls plus a margin). The file is replaced atomically: it is rendered to a temporary file
    beside `path` and moved onto it, and nothing is left behind on failure.

    Parameters
    ----------
    scene : Scene
        The scene simulated: walls, workspaces, robot and object sizes (mm), and optionally
        ``scene.humans`` (only their ``size``, mm, is used).
    trace : Mapping
        A ``cosmop.trace/1`` trace: ``dt`` (s), ``frames`` (``t`` in s, robot poses
        ``[x, y, heading]`` in mm and degrees, ``carrying``, ``waiting``; human and object
        positions in mm) and ``messages`` (``t`` in s, ``from``, ``to``, ...).
    path : str or os.PathLike
        The output file; its suffix picks the format: ``.gif`` or ``.mp4``. Its directory must
        exist.
    plans : PlanSet, optional
        If given, each robot's planned path (initial pose, then every GoTo pose) is drawn.
    fps : float, optional
        Frames per second of the output; overrides `speed`. By default ``speed / (dt * stride)``,
        with the stride grown so that it is at most 20.
    max_frames : int, optional
        At most this many frames are drawn (default 400): the trace is subsampled with a
        uniform stride; the last frame is always included.
    title : str, optional
        Text before the time in the title; by default the trace's scenario name.
    dpi : float, optional
        Resolution of the frames, dots per inch (default 100; the figure is about 7.7 in wide).
    speed : float, optional
        Simulated seconds per second of animation (> 0). By default ``max(1, duration / 45)``:
        real time for runs up to 45 s, and any longer run lasts 45 s.
    size : int, optional
        Width of the frames in pixels (overrides `dpi`); the height follows the scene's shape.

    Returns
    -------
    int
        The number of frames written.

    Raises
    ------
    ValueError
        If the suffix is neither ``.gif`` nor ``.mp4``, the trace is malformed, or `fps` or
        `max_frames` are not positive.
    ImportError
        If matplotlib (``pip install 'cosmop[viz]'``) or, for MP4, imageio-ffmpeg
        (``pip install 'cosmop[video]'``) is missing.
    """
    target = Path(path)
    suffix = target.suffix.lower()
    if suffix not in _SUFFIXES:
        raise ValueError(
            f"cannot write an animation to {os.fspath(path)!r}: unknown suffix "
            f"{target.suffix or '(none)'!r}; expected .gif (Pillow) or .mp4 (ffmpeg)"
        )
    if isinstance(max_frames, bool) or not isinstance(max_frames, int) or max_frames < 1:
        raise ValueError(f"max_frames must be a positive integer, got {max_frames!r}")
    if fps is not None and not (isinstance(fps, int | float) and math.isfinite(fps) and fps > 0):
        raise ValueError(f"fps must be a positive number of frames per second, got {fps!r}")
    if not (isinstance(dpi, int | float) and math.isfinite(dpi) and dpi > 0):
        raise ValueError(f"dpi must be a positive number, got {dpi!r}")
    if speed is not None and not (isinstance(speed, int | float) and math.isfinite(speed) and speed > 0):
        raise ValueError(f"speed must be a positive number (simulated seconds per second), got {speed!r}")
    if size is not None and (isinstance(size, bool) or not isinstance(size, int) or size < 100):
        raise ValueError(f"size must be a width of at least 100 pixels, got {size!r}")
    frames = _check_trace(trace)
    matplotlib = _matplotlib()
    ffmpeg = _ffmpeg_exe() if suffix == ".mp4" else None

    indices, stride, fps = _timing(trace, frames, max_frames, fps, speed)
    dt = _cycle(trace, [float(frame["t"]) for frame in frames]) or 0.0
    animator = _Animator(scene, trace, frames, plans, title, dpi, max(_MESSAGE_SHOWN, 1.5 * stride * dt))
    if size is not None:
        dpi = size / animator.fig.get_figwidth()
        animator.fig.set_dpi(dpi)
    rc: dict[str, Any] = {"savefig.bbox": None}  # the writers need frames of a fixed size
    if ffmpeg is not None:
        rc["animation.ffmpeg_path"] = ffmpeg
    tmp: Path | None = None
    try:
        with matplotlib.rc_context(rc):
            writer = _writer(matplotlib.animation, suffix, fps, animator)
            tmp = _temp_beside(target)
            writer.setup(animator.fig, os.fspath(tmp), dpi)
            try:
                for index in indices:
                    animator.draw(index)
                    writer.grab_frame()
            except BaseException:
                with contextlib.suppress(Exception):
                    writer.finish()  # reap ffmpeg; the partial file is removed below
                raise
            writer.finish()
        _publish(tmp, target)
        tmp = None
    finally:
        if tmp is not None:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
    return len(indices)
