"""Labels that do not collide: a greedy placement of short texts around their points.

Each label goes to the first of a fixed list of offsets around its point (below, above, right,
left, the diagonals, then twice and three times as far) whose text box lies inside the axes
and overlaps neither a label already placed nor any of the given obstacles (marker boxes), all
in display pixels. A label that finds no free spot is dropped: a crowded picture loses its
least important labels instead of piling them up. Only the labels marked ``keep`` (robots' ids)
are always written, on the spot that overlaps the fewest others. The
boxes are estimated from the font size (0.7 em per character, 1.3 em high), which covers the
DejaVu Sans glyphs of short ids, bold too, so placement needs no rendering pass.

Labels that move (in animations) are made by :func:`text_marker` instead: the glyph outline
of the text drawn as a marker, which matplotlib draws much faster than a text.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["Label", "Placement", "place_labels", "text_marker"]

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
    keep : bool
        Always written, even where no free spot is left (robots' ids); other labels are
        dropped there.
    """

    x: float
    y: float
    text: str
    style: dict[str, Any]
    center: bool = False
    keep: bool = False


def _overlaps(a: Box, b: Box) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def _box(cx: float, cy: float, w: float, h: float) -> Box:
    return (cx - w / 2, cy - h / 2, cx + w / 2, cy + h / 2)


def _within(box: Box, frame: Box) -> bool:
    return frame[0] <= box[0] and box[2] <= frame[2] and frame[1] <= box[1] and box[3] <= frame[3]


@dataclass
class Placement:
    """What :func:`place_labels` wrote and what it left out.

    Attributes
    ----------
    annotations : list of matplotlib.text.Annotation
        The labels written, in the order given.
    dropped : list of Label
        Labels that found no free spot inside the axes and were left out rather than piled
        on others (never a label with ``keep``).
    outside : list of Label
        Labels whose point lies outside the axes' view (a cropped picture): nothing to point at.
    """

    annotations: list[Any] = field(default_factory=list)
    dropped: list[Label] = field(default_factory=list)
    outside: list[Label] = field(default_factory=list)


def _candidates(
    label: Label, px: float, py: float, w: float, h: float, gap: float
) -> Iterator[tuple[float, float, int]]:
    """Spots for a label's centre around its point ``(px, py)``, nearest first, with their scale
    (1: beside the point; 2 and 3: farther, drawn with a leader line)."""
    for scale in (1, 2, 3):
        for dx, dy in ((0, 0), *_DIRECTIONS) if label.center and scale == 1 else _DIRECTIONS:
            cx = px + dx * (w / 2 + gap * scale + (scale - 1) * w / 2)
            cy = py + dy * (h / 2 + gap * scale + (scale - 1) * h)
            yield cx, cy, scale


def _spot(
    label: Label,
    point: tuple[float, float],
    size: tuple[float, float],
    placed: list[Box],
    frame: Box,
    gap: float,
) -> tuple[float, float, bool] | None:
    """The centre of the first free spot inside `frame` and whether it needs a leader line; for
    a label to keep, the spot inside with the fewest overlaps when none is free; else None."""
    w, h = size
    best, fewest = None, None
    for cx, cy, scale in _candidates(label, *point, w, h, gap):
        box = _box(cx, cy, w, h)
        if not _within(box, frame):
            continue
        overlaps = sum(_overlaps(box, other) for other in placed)
        if overlaps == 0:
            return cx, cy, scale > 1
        if fewest is None or overlaps < fewest:
            best, fewest = (cx, cy, scale > 1), overlaps
    if not label.keep:
        return None
    if best is None:  # no spot fits inside at all (a tiny axes): the first one, pushed inside
        cx, cy, _ = next(_candidates(label, *point, w, h, gap))
        cx = min(max(cx, frame[0] + w / 2), frame[2] - w / 2)
        cy = min(max(cy, frame[1] + h / 2), frame[3] - h / 2)
        best = (cx, cy, True)
    return best


def place_labels(
    ax: Any, labels: Sequence[Label], *, obstacles: Sequence[Box] = (), gap: float = 4.0, inset: float = 3.0
) -> Placement:
    """Annotate `ax` with `labels`, inside the axes, none overlapping another or an obstacle.

    Call it after the axes' limits are final (the placement is done in display pixels). A
    label goes only where its whole box lies inside the axes, `inset` pixels clear of the
    spines (so never on the ticks or outside the map), and overlaps nothing placed before it.
    A label that finds no such spot is dropped, the picture is thinned rather than piled up;
    only labels with ``keep`` (robots' ids) are always written, on the spot inside the axes
    with the fewest overlaps. Labels whose point is outside the view are not written.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    labels : sequence of Label
        In order of priority: earlier labels get the nearer spots, later ones are dropped first.
    obstacles : sequence of (x0, y0, x1, y1)
        Display boxes (pixels) that labels must not cover, e.g. markers.
    gap : float
        Pixels between a point and its label's nearest edge.
    inset : float
        Pixels between a label's box and the axes' edges.

    Returns
    -------
    Placement
        The annotations written, and the labels dropped or outside the view.
    """
    fig = ax.figure
    fig.canvas.draw_idle()
    ax.apply_aspect()  # the axes' box shrinks to the data's aspect: its final pixels
    to_px = fig.dpi / 72.0
    x0, y0, x1, y1 = ax.bbox.extents
    frame = (x0 + inset, y0 + inset, x1 - inset, y1 - inset)
    placed: list[Box] = list(obstacles)
    result = Placement()
    for label in labels:
        size = float(label.style.get("fontsize", 8)) * to_px
        w, h = 0.7 * size * max(len(label.text), 1) + 2, 1.3 * size
        px, py = ax.transData.transform((label.x, label.y))
        if not (x0 <= px <= x1 and y0 <= py <= y1):
            result.outside.append(label)
            continue
        spot = _spot(label, (px, py), (w, h), placed, frame, gap)
        if spot is None:
            result.dropped.append(label)
            continue
        cx, cy, leader = spot
        placed.append(_box(cx, cy, w, h))
        result.annotations.append(_annotate(ax, label, (cx - px) / to_px, (cy - py) / to_px, leader))
    return result


def _annotate(ax: Any, label: Label, dx: float, dy: float, leader: bool) -> Any:
    """Write `label` `dx`, `dy` points from its point, with a thin grey leader line if asked."""
    arrow = {"arrowprops": {"arrowstyle": "-", "lw": 0.5, "color": "grey"}} if leader else {}
    style = {"zorder": 5, "bbox": {"boxstyle": "round,pad=0.1", "fc": "white", "ec": "none", "alpha": 0.75}}
    style.update(label.style)  # a white backing keeps a label readable over lines
    return ax.annotate(
        label.text,
        (label.x, label.y),
        xytext=(dx, dy),
        textcoords="offset points",
        ha="center",
        va="center",
        **arrow,
        **style,
    )


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
