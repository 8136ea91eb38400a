"""Labels that do not collide: a greedy placement of short texts around their points.

Each label goes to the first of a fixed list of offsets around its point (below, above, right,
left, the diagonals, then twice and three times as far) whose text box overlaps neither a label
already placed nor any of the given obstacles (marker boxes), all in display pixels. A label
that finds no free spot takes the farthest candidate with a thin leader line to its point. The
boxes are estimated from the font size (0.7 em per character, 1.3 em high), which covers the
DejaVu Sans glyphs of short ids, bold too, so placement needs no rendering pass.

Labels that move (in animations) are made by :func:`text_marker` instead: the glyph outline
of the text drawn as a marker, which matplotlib draws much faster than a text.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["Label", "place_labels", "text_marker"]

_DIRECTIONS = ((0, -1), (0, 1), (1, 0), (-1, 0), (1, -1), (-1, -1), (1, 1), (-1, 1))
Box = tuple[float, float, float, float]  # x0, y0, x1, y1 in display pixels


@dataclass
class Label:
    """A text to place near a data point.

    Attributes
    ----------
    x, y : float
        The data point.
    text : str
    style : dict
        Extra keyword arguments for matplotlib's ``annotate``.
    center : bool
        Try the point itself first (ids inside workspaces and robots).
    """

    x: float
    y: float
    text: str
    style: dict[str, Any]
    center: bool = False


def _overlaps(a: Box, b: Box) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def _box(cx: float, cy: float, w: float, h: float) -> Box:
    return (cx - w / 2, cy - h / 2, cx + w / 2, cy + h / 2)


def place_labels(
    ax: Any, labels: Sequence[Label], *, obstacles: Sequence[Box] = (), gap: float = 4.0
) -> list[Any]:
    """Annotate `ax` with `labels`, none overlapping another or an obstacle where a free spot exists.

    Call it after the axes' limits are final (the placement is done in display pixels).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    labels : sequence of Label
        In order of priority: earlier labels get the nearer spots.
    obstacles : sequence of (x0, y0, x1, y1)
        Display boxes (pixels) that labels must not cover, e.g. markers.
    gap : float
        Pixels between a point and its label's nearest edge.

    Returns
    -------
    list of matplotlib.text.Annotation
    """
    fig = ax.figure
    fig.canvas.draw_idle()
    to_px = fig.dpi / 72.0
    placed: list[Box] = list(obstacles)
    out = []
    for label in labels:
        size = float(label.style.get("fontsize", 8)) * to_px
        w, h = 0.7 * size * max(len(label.text), 1) + 2, 1.3 * size
        px, py = ax.transData.transform((label.x, label.y))
        choice, leader = None, False
        for scale in (1, 2, 3):
            for dx, dy in ((0, 0), *_DIRECTIONS) if label.center and scale == 1 else _DIRECTIONS:
                cx = px + dx * (w / 2 + gap * scale + (scale - 1) * w / 2)
                cy = py + dy * (h / 2 + gap * scale + (scale - 1) * h)
                box = _box(cx, cy, w, h)
                if not any(_overlaps(box, other) for other in placed):
                    choice = (cx, cy, box)
                    break
            if choice is not None:
                leader = scale > 1
                break
        if choice is None:  # crowded: the farthest spot below, with a leader line
            cx, cy = px, py - (h / 2 + 3 * gap + 2 * h)
            choice, leader = (cx, cy, _box(cx, cy, w, h)), True
        cx, cy, box = choice
        placed.append(box)
        arrow = {"arrowprops": {"arrowstyle": "-", "lw": 0.5, "color": "grey"}} if leader else {}
        style = {
            "zorder": 5,
            "bbox": {"boxstyle": "round,pad=0.1", "fc": "white", "ec": "none", "alpha": 0.75},
        }
        style.update(label.style)  # a white backing keeps a label readable over lines
        out.append(
            ax.annotate(
                label.text,
                (label.x, label.y),
                xytext=((cx - px) / to_px, (cy - py) / to_px),
                textcoords="offset points",
                ha="center",
                va="center",
                **arrow,
                **style,
            )
        )
    return out


def text_marker(
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

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    text : str
    colour : matplotlib colour
    fontsize : float
        Points.
    weight : str
        Font weight, ``"normal"`` or ``"bold"``.
    va : str
        ``"top"``, ``"bottom"`` or ``"center"``: which edge of the text sits at the point.
    zorder : float
    visible : bool

    Returns
    -------
    matplotlib.lines.Line2D
        Without a point yet; move it with ``set_data([x], [y])`` (data units, mm).
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
