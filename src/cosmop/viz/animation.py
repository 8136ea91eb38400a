"""Animate a simulation trace like the paper's figures: a GIF or an MP4 of the robots at work.

A trace (:class:`cosmop.traces.Trace`, or its ``cosmop.trace/1`` JSON) records every simulation
cycle: times, the robots' poses, what they carry and whether they wait, the people's and
objects' positions, and the messages.  Coordinates are mm, headings degrees, times seconds.
:func:`save_animation` draws the walls, workspaces, objects, robots (with their trails, planned
paths, carried objects, a ``?`` while waiting for an answer and a ``!`` just after sending a
message, and in plain words why a robot stands, :mod:`cosmop.viz.explain`) and humans, frame
by frame, and writes the file atomically.  A robot that replans has its planned path redrawn
from that moment. matplotlib is imported
lazily (``pip install 'cosmop[viz]'``, Agg backend); MP4 also needs the ffmpeg binary of
``imageio-ffmpeg`` (``pip install 'cosmop[video]'``).
"""

from __future__ import annotations

import bisect
import contextlib
import importlib.util
import itertools
import math
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any, cast

import numpy as np

from cosmop.io import atomic_path
from cosmop.planning.plan_types import PlanSet
from cosmop.scene import Scene
from cosmop.traces import RobotState, Trace, as_trace, message_label
from cosmop.viz.explain import Explainer, waiting_words
from cosmop.viz.labels import text_marker
from cosmop.viz.scene_drawing import (
    ANIMATION_STYLE,
    DEFAULT_OBJECT_SIZE,
    DEFAULT_ROBOT_SIZE,
    SceneArtists,
    draw_scene,
    ids_with_trace,
    planned_path,
    replanned_path,
    scene_legend,
)

__all__ = ["draw_frame", "save_animation", "video_available"]

_SUFFIXES = (".gif", ".mp4")
_MAX_FPS = 20.0
_MESSAGE_SHOWN = 2.0  # seconds (simulated) a '!' and the message's arrow stay after it was sent
_TARGET_LENGTH = 45.0  # seconds of animation by default: speed max(1, duration / 45)
_LEGEND_WIDTH = 1.9  # inches added on the right of the animation for the legend


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
    return cast(str, imageio_ffmpeg.get_ffmpeg_exe())


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
    trace: Trace, max_frames: int, fps: float | None, speed: float | None
) -> tuple[list[int], int, float]:
    """The frames to draw, their stride and the frame rate for a playback at `speed`.

    Without `fps`, the stride is grown until ``speed / (dt * stride) <= 20`` and the rate is
    exactly ``speed / (dt * stride)``; `speed` defaults to ``max(1, duration / 45)``.
    """
    times = trace.t.tolist()
    dt = _cycle(trace)
    if speed is None:
        speed = max(1.0, (times[-1] - times[0]) / _TARGET_LENGTH)
    indices, stride = _frame_indices(len(times), max_frames)
    if fps is not None:
        return indices, stride, fps
    if dt is None:
        return indices, stride, _MAX_FPS
    least = math.ceil(speed / (dt * _MAX_FPS) - 1e-9)
    if least > stride:  # fewer frames, so that the rate stays at most 20 per second
        stride = least
        indices = list(range(0, len(times), stride))
        if indices[-1] != len(times) - 1:
            indices.append(len(times) - 1)
    return indices, stride, speed / (dt * stride)


def _cycle(trace: Trace) -> float | None:
    """The simulation cycle in seconds: the trace's ``dt``, else the median spacing of its frames."""
    if trace.dt is not None:
        return float(trace.dt)
    gaps = sorted(b - a for a, b in itertools.pairwise(trace.t.tolist()) if b > a)
    return gaps[len(gaps) // 2] if gaps else None


# ----------------------------------------------------------------------------------------------
# Drawing
# ----------------------------------------------------------------------------------------------


def _limits(scene: Scene, trace: Trace) -> tuple[float, float, float, float]:
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
            xs += [ws.point[0]] if ws.point is not None else list(ws.ranges[0])
            ys += [ws.point[1]] if ws.point is not None else list(ws.ranges[1])
        for group in ("robots", "humans", "objects"):
            points = trace.seen(group)
            xs += points[:, 0].tolist()
            ys += points[:, 1].tolist()
    if not xs:
        return -1000.0, 1000.0, -1000.0, 1000.0
    sizes = [r.size for r in scene.robots.values()] or [DEFAULT_ROBOT_SIZE]
    span = max(max(xs) - min(xs), max(ys) - min(ys), 1.0)
    margin = max(0.03 * span, 0.5 * max(sizes))
    return min(xs) - margin, max(xs) + margin, min(ys) - margin, max(ys) + margin


def _figure(limits: tuple[float, float, float, float], dpi: float) -> tuple[Any, Any]:
    """A figure of the scene's shape with room for the legend, and its axes over `limits` (mm)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    x0, x1, y0, y1 = limits
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
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal")
    ax.set_autoscale_on(False)
    ax.set_xlabel("x [mm]", fontsize=8)
    ax.set_ylabel("y [mm]", fontsize=8)
    ax.tick_params(labelsize=7)
    return fig, ax


def _trail(trace: Trace, rid: str) -> tuple[list[float], list[float]]:
    """Robot `rid`'s position in every frame (mm); NaN where it is absent, which breaks the line."""
    if rid not in trace.robot_ids:  # a robot of the scene that the trace does not follow
        return [math.nan] * len(trace.t), [math.nan] * len(trace.t)
    i = trace.robot_ids.index(rid)
    return trace.poses[:, i, 0].tolist(), trace.poses[:, i, 1].tolist()


def _sent_times(messages: Sequence[Any], robot_ids: Sequence[str]) -> dict[str, list[float]]:
    """When each robot sent a message (s, in order): it shows a '!' for a while after each."""
    sent: dict[str, list[float]] = {rid: [] for rid in robot_ids}
    for message in messages:
        sender = message.get("from") if isinstance(message, Mapping) else None
        if sender in sent and isinstance(message.get("t"), int | float):
            sent[sender].append(float(message["t"]))
    for times in sent.values():
        times.sort()
    return sent


class _Animator:
    """The figure and its moving artists; :meth:`update` shows one frame of the trace.

    `trace` is a :class:`~cosmop.traces.Trace` or its JSON.
    """

    def __init__(
        self,
        scene: Scene,
        trace: Trace | Mapping[str, Any],
        plans: PlanSet | None,
        title: str | None,
        dpi: float,
        shown: float = _MESSAGE_SHOWN,
    ) -> None:
        self.trace = trace = as_trace(trace)
        self.shown = shown  # seconds a message stays drawn (at least about one frame's time step)
        self.fig, self.ax = _figure(_limits(scene, trace), dpi)
        self.prefix = title if title is not None else str(trace.scenario or "")
        self.title = self.ax.set_title(self.prefix, fontsize=9)
        drawn = draw_scene(
            self.ax,
            scene,
            style=ANIMATION_STYLE,
            robots=ids_with_trace(scene.robots, trace, "robots"),
            objects=ids_with_trace(scene.objects, trace, "objects"),
            humans=ids_with_trace(scene.humans, trace, "humans"),
        )
        self._take_pieces(scene, drawn)
        self.explainer = Explainer(scene, plans)
        self.words = waiting_words(scene, plans)
        self.plan_lines = self._draw_plans(scene, plans, drawn.colours)
        self._add_robot_marks(drawn.colours)
        messages = trace.messages
        self.sent = _sent_times(messages, self.robot_ids)
        self.arrows = self._message_arrows(messages, drawn.colours)
        # GIF colours: few keep files small; each robot's colour needs its own shades
        self.palette_size = min(256, 48 + 4 * len(self.robot_ids))
        _legend(self.ax)
        self.fig.tight_layout()
        self.mm_per_pt = _mm_per_point(self.ax)
        self.spots: dict[tuple[tuple[str, tuple[float, float]], ...], dict[str, tuple[float, float]]] = {}
        self.moving = self._moving_artists()
        self.background: Any = None

    def _take_pieces(self, scene: Scene, drawn: SceneArtists) -> None:
        """Keep the scene's moving pieces, and where each object was last seen (mm)."""
        self.robots, self.objects, self.humans = drawn.robots, drawn.objects, drawn.humans
        self.robot_ids, self.object_ids = list(self.robots), list(self.objects)
        self.object_size = {oid: piece.size for oid, piece in self.objects.items()}
        self.object_at: dict[str, tuple[float, float] | None] = {
            oid: (scene.objects[oid].position[0], scene.objects[oid].position[1])
            if oid in scene.objects
            else None
            for oid in self.object_ids
        }
        self.object_patch = {oid: piece.patch for oid, piece in self.objects.items()}
        self.object_label: dict[str, Any] = {oid: piece.label for oid, piece in self.objects.items()}
        self.human_artists = {hid: (piece.patch, piece.label) for hid, piece in self.humans.items()}

    def _draw_plans(
        self, scene: Scene, plans: PlanSet | None, colours: Mapping[str, Any]
    ) -> dict[str, list[tuple[float, Any]]]:
        """Each robot's planned path, dashed in its colour; the paths of its replans too, each
        from its time on.  Returns the lines of the robots that replan, with their start
        times (s): they move; the others' stay in the still background."""
        paths: dict[str, list[tuple[float, list[tuple[float, float]]]]] = {}
        for rid in self.robot_ids:
            plan = plans.robots.get(rid) if plans is not None else None
            if plan is not None and rid in scene.robots:
                paths[rid] = [(-math.inf, planned_path(scene.robots[rid], plan))]
        for replan in self.trace.replans:
            if replan["robot"] in self.robot_ids:
                paths.setdefault(replan["robot"], []).append(
                    (float(replan["t"]), replanned_path(replan["route"]))
                )
        lines: dict[str, list[tuple[float, Any]]] = {}
        for rid, versions in paths.items():
            for k, (t, path) in enumerate(versions):
                (line,) = self.ax.plot(
                    *zip(*path, strict=True), color=colours[rid], lw=0.8, ls="--", alpha=0.8, zorder=1,
                    visible=k == 0 and t == -math.inf,
                )  # fmt: skip
                if len(versions) > 1 or t > -math.inf:  # it changes during the run
                    lines.setdefault(rid, []).append((t, line))
        return lines

    def _add_robot_marks(self, colours: Mapping[str, Any]) -> None:
        """Per robot, beside its square and id: trail, heading tick, cargo, '?' and '!'."""
        from matplotlib.patches import Rectangle

        ax = self.ax
        self.trail_x: dict[str, list[float]] = {}
        self.trail_y: dict[str, list[float]] = {}
        self.artists: dict[str, dict[str, Any]] = {}
        for rid in self.robot_ids:
            colour = colours[rid]
            self.trail_x[rid], self.trail_y[rid] = _trail(self.trace, rid)
            (trail,) = ax.plot([], [], color=colour, lw=1.0, alpha=0.9, zorder=2)
            (tick,) = ax.plot([], [], color=colour, lw=2, solid_capstyle="butt", zorder=5)
            cargo = ax.add_patch(Rectangle((0, 0), 1, 1, color="saddlebrown", zorder=6, visible=False))
            self.artists[rid] = {
                "trail": trail,
                "body": self.robots[rid].patch,
                "tick": tick,
                "label": self.robots[rid].label,
                "cargo": cargo,
                "question": text_marker(ax, "?", colour, 14, weight="bold", va="bottom", zorder=7),
                "bang": text_marker(ax, "!", colour, 14, weight="bold", va="bottom", zorder=7),
                "why": ax.text(
                    0, 0, "", fontsize=6, style="italic", color="black", ha="center", va="top", zorder=7,
                    visible=False,
                    bbox={"boxstyle": "round,pad=0.1", "fc": "white", "ec": "none", "alpha": 0.75},
                ),
            }  # fmt: skip

    def _moving_artists(self) -> list[Any]:
        """Everything that moves, in drawing order: drawn over a background rendered once (blitting)."""
        moving: list[Any] = [self.title]
        moving += list(self.object_patch.values()) + list(self.object_label.values())
        for a in self.artists.values():
            moving += a.values()
        for disc, label in self.human_artists.values():
            moving += [disc, label]
        for arrow, text, _ in self.arrows:
            moving += [arrow, text]
        moving += [line for versions in self.plan_lines.values() for _, line in versions]
        return sorted(moving, key=lambda artist: artist.get_zorder())

    def _message_arrows(
        self, messages: Sequence[Any], colours: Mapping[str, Any]
    ) -> list[tuple[Any, Any, Mapping[str, Any]]]:
        """One hidden arrow and time label per message between two robots of the trace."""
        from matplotlib.patches import FancyArrowPatch

        out = []
        for message in messages:
            if not (isinstance(message, Mapping) and isinstance(message.get("t"), int | float)):
                continue
            if message.get("from") not in self.artists or message.get("to") not in self.artists:
                continue
            colour = colours[message["from"]]
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

    def _show_messages(self, t: float, robots: Mapping[str, RobotState]) -> None:
        """Arrows from sender to receiver for the messages sent in the last ``shown`` seconds."""
        for arrow, text, message in self.arrows:
            age = t - float(message["t"])
            sender, receiver = robots.get(message["from"]), robots.get(message["to"])
            on = 0 <= age < self.shown and sender is not None and receiver is not None
            arrow.set_visible(on)
            text.set_visible(on)
            if on and sender is not None and receiver is not None:
                (x1, y1), (x2, y2) = sender.pose[:2], receiver.pose[:2]
                arrow.set_positions((x1, y1), (x2, y2))
                text.set_position(((x1 + x2) / 2, (y1 + y2) / 2))

    def _object_spots(self, carried: set[str]) -> dict[str, tuple[float, float]]:
        """Where the ids of the objects on the ground go: near each, not over another id or object."""
        visible = tuple(
            (oid, at) for oid in self.object_ids if (at := self.object_at[oid]) and oid not in carried
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
        return cast(memoryview, canvas.buffer_rgba())

    def _message_recent(self, rid: str, t: float) -> bool:
        times = self.sent[rid]
        k = bisect.bisect_right(times, t)
        return k > 0 and t - times[k - 1] < self.shown

    def update(self, index: int) -> None:
        """Move the artists to frame `index` of the trace (an index into all its frames)."""
        trace = self.trace
        t = float(trace.t[index])
        text = f"t = {t:.1f} s"
        self.title.set_text(f"{self.prefix}    {text}" if self.prefix else text)
        robots = trace.robots_at(index)
        for rid in self.robot_ids:
            self._show_robot(rid, robots.get(rid), index, t)
            self._show_why(rid, robots.get(rid), index)
        for versions in self.plan_lines.values():
            now = max((k for k, (start, _) in enumerate(versions) if start <= t), default=-1)
            for k, (_, line) in enumerate(versions):
                line.set_visible(k == now)
        self._show_objects(trace.points_at("objects", index), set(trace.carried_at(index)))
        self._show_messages(t, robots)
        humans = trace.points_at("humans", index)
        for hid, piece in self.humans.items():
            where = humans.get(hid)
            piece.show(where is not None)
            if where is not None:
                piece.move(float(where[0]), float(where[1]))

    def _show_robot(self, rid: str, state: RobotState | None, index: int, t: float) -> None:
        """Robot `rid` in `state` at time `t` (s) with its trail up to frame `index`."""
        a = self.artists[rid]
        a["trail"].set_data(self.trail_x[rid][: index + 1], self.trail_y[rid][: index + 1])
        visible = state is not None
        for key in ("body", "tick", "label"):
            a[key].set_visible(visible)
        if state is None:
            for key in ("cargo", "question", "bang"):
                a[key].set_visible(False)
            return
        x, y, heading = state.pose
        self.robots[rid].move(x, y)
        size = self.robots[rid].size
        rad = math.radians(heading)
        a["tick"].set_data([x, x + 0.8 * size * math.cos(rad)], [y, y + 0.8 * size * math.sin(rad)])
        oid = state.carrying
        if oid:
            s = self.object_size.get(oid, DEFAULT_OBJECT_SIZE)
            a["cargo"].set_bounds(x - s / 2, y - s / 2, s, s)
        a["cargo"].set_visible(bool(oid))
        waiting = state.waiting
        recent = self._message_recent(rid, t)
        h = size / 2
        shift = 0.35 * h if waiting and recent else 0.0  # both marks: side by side
        a["question"].set_visible(waiting)
        a["question"].set_data([x - shift], [y + 1.1 * h])
        a["bang"].set_visible(recent)
        a["bang"].set_data([x + shift], [y + 1.1 * h])

    def _show_why(self, rid: str, state: RobotState | None, index: int) -> None:
        """Under robot `rid`'s id, why it stands in frame `index`, in plain words (if it does)."""
        text = self.artists[rid]["why"]
        words = self._reason(rid, index) if state is not None else ""
        text.set_visible(bool(words))
        if words and state is not None:
            x, y, _ = state.pose
            below = 1.1 * self.robots[rid].size / 2 + 9 * self.mm_per_pt  # under the id
            text.set_position((x, y - below))
            if text.get_text() != words:
                text.set_text(words)

    def _reason(self, rid: str, index: int) -> str:
        """Why robot `rid` stands in frame `index` ("" when it does not)."""
        trace = self.trace
        if rid not in trace.robot_ids:
            return ""
        i = trace.robot_ids.index(rid)
        awaited = trace.awaits[index, i] if trace.awaits is not None else None
        if awaited is not None:
            return self.words.get(awaited) or self.explainer.awaits(awaited)
        who = trace.yields_to[index, i] if trace.yields_to is not None else None
        if who is not None:
            return self.explainer.yields(who)
        if trace.delayed is not None and trace.delayed[index, i]:
            return "stopped by a delay"
        return ""

    def _show_objects(self, objects: Mapping[str, tuple[float, float]], carried: set[str]) -> None:
        """The objects on the ground where the frame (or an earlier one) puts them, with their ids."""
        for oid, piece in self.objects.items():
            if oid in objects:
                self.object_at[oid] = objects[oid]
            where = self.object_at[oid]
            shown = where is not None and oid not in carried
            piece.show(shown)
            if shown and where is not None:
                piece.move(*where)
        for oid, (x, y) in self._object_spots(carried).items():
            self.object_label[oid].set_data([x], [y])


def draw_frame(
    scene: Scene,
    trace: Trace | Mapping[str, Any],
    index: int = -1,
    *,
    plans: PlanSet | None = None,
    title: str | None = None,
    dpi: float = 100.0,
) -> Any:
    """One frame of a run as a matplotlib figure, drawn as the animation draws it.

    The robots where frame `index` has them, each with the path it drove so far (the whole run
    for the last frame), its planned path (a replan's from its time on), what it carries, why it
    stands, the messages of the last two seconds, the people; the title gives the time.

    Parameters
    ----------
    scene : Scene
    trace : Trace or Mapping
        The run (:class:`~cosmop.traces.Trace` or its ``cosmop.trace/1`` JSON).
    index : int
        The frame; negative counts from the end (default: the last).
    plans : PlanSet, optional
        The planned paths to draw, dashed.
    title : str, optional
        Default: the trace's scenario name.
    dpi : float

    Returns
    -------
    matplotlib.figure.Figure
        Made without pyplot: nothing to close, the user's backend untouched.
    """
    animator = _Animator(scene, trace, plans, title, dpi)
    animator.update(range(len(animator.trace.t))[index])
    return animator.fig


def _legend(ax: Any) -> None:
    """What the markers of an animation mean, on the right of the axes."""
    from matplotlib.lines import Line2D

    def symbol(text: str, label: str) -> Line2D:
        return Line2D([], [], ls="none", marker=f"${text}$", color="black", ms=7, label=label)

    handles = [
        *scene_legend(),
        Line2D(
            [], [], ls="none", marker="s", color="saddlebrown", ms=4, label="object (on a robot: carried)"
        ),
        Line2D([], [], ls="none", marker="s", mfc="none", mec="black", ms=8, label="robot, heading tick, id"),
        Line2D([], [], color="grey", lw=1, label="path driven"),
        Line2D([], [], color="grey", lw=0.8, ls="--", label="path planned"),
        Line2D([], [], ls="none", marker="o", color="orange", ms=6, label="person"),
        symbol("?", "waits for an answer (Req)"),
        symbol("!", "sent an answer (Res)"),
        Line2D([], [], ls="none", marker="$abc$", color="black", ms=9, label="why a robot stands"),
        Line2D([], [], color="grey", lw=1.5, marker=">", ms=4, label="message → receiver, time"),
    ]
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=6, frameon=False)


def _mm_per_point(ax: Any) -> float:
    """Data units (mm) per typographic point, with the axes' final layout (equal aspect)."""
    ax.apply_aspect()
    (x0, _), (x1, _) = ax.transData.transform([(0.0, 0.0), (1000.0, 0.0)])
    px_per_mm = abs(x1 - x0) / 1000.0 or 1.0
    return cast(float, ax.figure.dpi / 72.0 / px_per_mm)


def _writer(animation: Any, suffix: str, fps: float, animator: _Animator) -> Any:
    """A PillowWriter (GIF) or FFMpegWriter (H.264 MP4) that takes the animator's canvas as it is.

    The stock writers re-render the whole figure for every frame with ``savefig``; these take the
    blitted canvas instead (and quantise GIF frames at once, to keep memory low), falling back on
    ``savefig`` if the canvas does not have the frame size.
    """
    if suffix == ".gif":
        from PIL import Image

        class GifWriter(animation.PillowWriter):  # type: ignore[misc]  # `animation` is matplotlib's, passed in
            def grab_frame(self, **savefig_kwargs: Any) -> None:
                pixels = animator.rgba(self.frame_size)
                frames = getattr(self, "_frames", None)
                if pixels is None or not isinstance(frames, list):
                    super().grab_frame(**savefig_kwargs)
                    return
                # as an array (the buffer protocol, no copy): what PIL's types accept
                image = Image.frombuffer(
                    "RGBA", self.frame_size, np.frombuffer(pixels, np.uint8), "raw", "RGBA", 0, 1
                )
                frames.append(
                    image.convert("RGB").quantize(animator.palette_size, method=Image.Quantize.FASTOCTREE)
                )

        return GifWriter(fps=fps)

    class Mp4Writer(animation.FFMpegWriter):  # type: ignore[misc]  # `animation` is matplotlib's, passed in
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
    trace: Trace | Mapping[str, Any],
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

    Every frame is the scene as :func:`cosmop.viz.scene_drawing.draw_scene` draws it at that time
    (a carried object on its carrier), each robot's trail so far, the planned paths (dashed),
    a ``?`` above a robot waiting for a message and a ``!`` for 1 s after it sent one; the title
    shows the simulated time. Axes in mm, equal aspect, fixed limits. The file is replaced
    atomically (:func:`cosmop.io.atomic_path`): nothing is left behind on failure.

    Parameters
    ----------
    scene : Scene
        The scene simulated: walls, workspaces, robot and object sizes (mm), and optionally
        ``scene.humans`` (only their ``size``, mm, is used).
    trace : Trace or Mapping
        The run (:class:`cosmop.traces.Trace`, or its ``cosmop.trace/1`` JSON): ``dt`` (s),
        times (s), robot poses (mm, mm, degrees), what they carry and whether they wait, human
        and object positions (mm) and messages (``t`` in s, ``from``, ``to``, ...).
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
        If the suffix is neither ``.gif`` nor ``.mp4``, the trace is malformed (a
        :class:`cosmop.traces.TraceError`, naming the field), or `fps` or `max_frames` are not
        positive.
    ImportError
        If matplotlib (``pip install 'cosmop[viz]'``) or, for MP4, imageio-ffmpeg
        (``pip install 'cosmop[video]'``) is missing.
    """
    suffix = _check_options(path, max_frames=max_frames, fps=fps, dpi=dpi, speed=speed, size=size)
    trace = as_trace(trace)
    matplotlib = _matplotlib()
    ffmpeg = _ffmpeg_exe() if suffix == ".mp4" else None

    indices, stride, fps = _timing(trace, max_frames, fps, speed)
    dt = _cycle(trace) or 0.0
    animator = _Animator(scene, trace, plans, title, dpi, max(_MESSAGE_SHOWN, 1.5 * stride * dt))
    if size is not None:
        dpi = size / animator.fig.get_figwidth()
        animator.fig.set_dpi(dpi)
    _render(matplotlib, animator, path, suffix, fps, indices, dpi, ffmpeg)
    return len(indices)


def _render(
    matplotlib: Any,
    animator: _Animator,
    path: str | os.PathLike[str],
    suffix: str,
    fps: float,
    indices: Sequence[int],
    dpi: float,
    ffmpeg: str | None,
) -> None:
    """Write the frames `indices` through the format's writer to `path`, atomically."""
    rc: dict[str, Any] = {"savefig.bbox": None}  # the writers need frames of a fixed size
    if ffmpeg is not None:
        rc["animation.ffmpeg_path"] = ffmpeg
    with matplotlib.rc_context(rc), atomic_path(path) as tmp:
        writer = _writer(matplotlib.animation, suffix, fps, animator)
        _write_frames(writer, animator, indices, tmp, dpi)


def _check_options(
    path: str | os.PathLike[str],
    *,
    max_frames: Any,
    fps: Any,
    dpi: Any,
    speed: Any,
    size: Any,
) -> str:
    """The output's suffix (``.gif`` or ``.mp4``), once the options of :func:`save_animation` are checked.

    Raises
    ------
    ValueError
        Naming the first option out of its range.
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
    return suffix


def _write_frames(writer: Any, animator: _Animator, indices: Sequence[int], path: Path, dpi: float) -> None:
    """Draw the frames `indices` and have `writer` write them to `path`; on a failure or Ctrl-C,
    abandon the file (:func:`_abandon`), which the staging folder's removal then takes away."""
    writer.setup(animator.fig, os.fspath(path), dpi)
    try:
        for index in indices:
            animator.draw(index)
            writer.grab_frame()
    except BaseException:
        _abandon(writer)
        raise
    writer.finish()


def _abandon(writer: Any) -> None:
    """Stop `writer` without finishing its file: ffmpeg (MP4) is killed and reaped, a GIF's
    frames are dropped.  Finishing would encode every frame drawn so far (Pillow writes a GIF's
    frames all at once, seconds for a few hundred) only to throw the file away, and would keep
    Ctrl-C waiting that long."""
    proc = getattr(writer, "_proc", None)
    if proc is not None:
        with contextlib.suppress(OSError):
            proc.kill()
            proc.communicate()
