"""One drawing of a scene for every figure: walls, workspaces, objects, robots, people and ids.

:func:`draw_scene` draws a scene on matplotlib axes as it is declared (robots at their initial
poses, objects at their positions) and returns the pieces that can move, so that the plan plot
(:mod:`.plans`) leaves them where they are and the animation (:mod:`.animation`) moves them
frame by frame. The two figures differ only in their look, a :class:`SceneStyle`:
:data:`PLAN_STYLE` and :data:`ANIMATION_STYLE`. Lengths are mm (data units), font and marker
sizes points. matplotlib is imported when drawing, not with this module.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, cast

from cosmop.events import Primitive
from cosmop.planning.plan_types import RobotPlan
from cosmop.scene import Robot, Scene, Workspace
from cosmop.traces import Trace
from cosmop.viz.labels import Label, text_marker
from cosmop.viz.palette import robot_colours

__all__ = [
    "ANIMATION_STYLE",
    "DEFAULT_HUMAN_SIZE",
    "DEFAULT_OBJECT_SIZE",
    "DEFAULT_ROBOT_SIZE",
    "PLAN_STYLE",
    "STEP_MARKS",
    "Piece",
    "SceneArtists",
    "SceneStyle",
    "draw_scene",
    "ids_with_trace",
    "planned_path",
    "replanned_path",
    "scene_legend",
]

DEFAULT_ROBOT_SIZE = 400.0
"""Side (mm) of a robot that a trace names but the scene does not declare."""
DEFAULT_OBJECT_SIZE = 100.0
"""Side (mm) of an object that a trace names but the scene does not declare."""
DEFAULT_HUMAN_SIZE = 500.0
"""Diameter (mm) of a person that a trace names but the scene does not declare."""

STEP_MARKS = {Primitive.PICKUP: "P", Primitive.DROPOFF: "D", Primitive.REQ: "?", Primitive.RES: "!"}
"""The letter drawn at a plan step that is not a GoTo, in every picture (``?`` waits, ``!`` sends)."""

_WALL_LAYER = 2  # matplotlib's layer of lines, in every style

Rgb = tuple[float, float, float]  # a colour, each component in [0, 1]


@dataclass(frozen=True)
class SceneStyle:
    """How one kind of figure draws a scene.

    Attributes
    ----------
    font : float
        Font size of the ids of workspaces, robots and people, pt; objects' ids are 1 pt smaller.
    cross : float
        Size of the ``x`` that marks a point workspace, pt.
    wall_caps : str
        Cap style of the wall segments: ``"projecting"`` (half a line width beyond the end
        points, closing corners) or ``"butt"``.
    area_layer, mark_layer, object_layer, robot_layer, id_layer : float
        matplotlib zorders of: workspace rectangles; crosses and fixed workspace ids; objects
        and their ids; robots and people; the ids of robots and people.
    robot_fill : float or None
        Opacity of a robot's square filled in its colour; None: an outline only.
    people : bool
        Whether people are drawn.
    placed_ids : bool
        True: the ids are returned as :class:`~cosmop.viz.labels.Label` objects, to be placed
        clear of each other by :func:`~cosmop.viz.labels.place_labels` once the axes' limits
        are final. False: they are drawn at once, those of pieces that move as
        :func:`~cosmop.viz.labels.text_marker` objects that move with them.
    """

    font: float
    cross: float
    wall_caps: str
    area_layer: float
    mark_layer: float
    object_layer: float
    robot_layer: float
    id_layer: float
    robot_fill: float | None
    people: bool
    placed_ids: bool


PLAN_STYLE = SceneStyle(
    font=8,
    cross=8,
    wall_caps="projecting",
    area_layer=1,  # matplotlib's default layers of patches (1) and lines (2)
    mark_layer=2,
    object_layer=1,
    robot_layer=1,
    id_layer=5,
    robot_fill=None,  # outlines: the planned paths start inside the squares
    people=False,  # a plan does not say where people will be
    placed_ids=True,
)
"""The still plot of a scene and its plans (:func:`cosmop.viz.draw_plan`)."""

ANIMATION_STYLE = SceneStyle(
    font=7,
    cross=7,
    wall_caps="butt",
    area_layer=0,
    mark_layer=1,
    object_layer=3,  # over the trails (2), under the robots that carry them (4)
    robot_layer=4,
    id_layer=6,
    robot_fill=0.3,
    people=True,
    placed_ids=False,
)
"""The frames of an animation (:func:`cosmop.viz.save_animation`)."""


@dataclass
class Piece:
    """A piece of the scene that can move: a square (robot, object) or disc (person), and its id.

    Attributes
    ----------
    patch : matplotlib.patches.Rectangle or matplotlib.patches.Circle
    label : matplotlib.lines.Line2D or None
        The id as a text marker, or None where the ids are placed as labels.
    size : float
        Side of the square or diameter of the disc, mm.
    label_offset : float or None
        How far above its centre the piece's id goes, mm (negative: below); None: the caller
        places the id.
    """

    patch: Any
    label: Any | None
    size: float
    label_offset: float | None = 0.0

    def move(self, x: float, y: float) -> None:
        """Centre the piece, and its id unless the caller places it, on ``(x, y)`` (mm).

        Parameters
        ----------
        x, y : float
            The new centre, mm.
        """
        if hasattr(self.patch, "set_center"):  # a disc is placed by its centre, a square by a corner
            self.patch.set_center((x, y))
        else:
            h = self.size / 2
            self.patch.set_xy((x - h, y - h))
        if self.label is not None and self.label_offset is not None:
            self.label.set_data([x], [y + self.label_offset])

    def show(self, visible: bool) -> None:
        """Show or hide the piece with its id.

        Parameters
        ----------
        visible : bool
            True to show it, False to hide it.
        """
        self.patch.set_visible(visible)
        if self.label is not None:
            self.label.set_visible(visible)


@dataclass
class SceneArtists:
    """What :func:`draw_scene` drew that a figure may move or still has to place.

    Attributes
    ----------
    colours : dict of str to (float, float, float)
        Each robot's colour, RGB in [0, 1] (:func:`~cosmop.viz.palette.robot_colours`).
    robots, objects, humans : dict of str to Piece
        The pieces by id, in drawing order.
    labels : list of Label
        The ids to place (styles with ``placed_ids``; empty otherwise), most important first:
        robots', workspaces', objects'.
    """

    colours: dict[str, Rgb]
    robots: dict[str, Piece] = field(default_factory=dict)
    objects: dict[str, Piece] = field(default_factory=dict)
    humans: dict[str, Piece] = field(default_factory=dict)
    labels: list[Label] = field(default_factory=list)


def draw_scene(
    ax: Any,
    scene: Scene,
    *,
    style: SceneStyle = PLAN_STYLE,
    robots: Sequence[str] | None = None,
    objects: Sequence[str] | None = None,
    humans: Sequence[str] | None = None,
) -> SceneArtists:
    """Draw the walls, workspaces, objects, robots and people of `scene` on `ax`, with their ids.

    Walls are black lines, workspaces light grey rectangles (or grey crosses for points),
    objects brown squares at their positions, robots squares of their size in their colour at
    their initial poses, people orange discs. Every piece has its id: beside it, placed later
    (``style.placed_ids``), or as a marker that moves with it. People have no place in a scene
    (they walk): they are drawn hidden, and so is any robot or object the scene does not
    declare; the caller shows them where a trace says (:meth:`Piece.move`).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Axes in mm.
    scene : Scene
        Only ``size`` is read of the people.
    style : SceneStyle, optional
        :data:`PLAN_STYLE` (default) or :data:`ANIMATION_STYLE`.
    robots, objects, humans : sequence of str, optional
        The ids to draw, in order; by default the scene's. An id the scene does not declare
        gets a default size (:data:`DEFAULT_ROBOT_SIZE`, :data:`DEFAULT_OBJECT_SIZE`,
        :data:`DEFAULT_HUMAN_SIZE`, mm). Robots are coloured in this order.

    Returns
    -------
    SceneArtists
    """
    robot_ids = list(scene.robots if robots is None else robots)
    drawn = SceneArtists(dict(zip(robot_ids, robot_colours(len(robot_ids)), strict=True)))
    _draw_walls(ax, scene, style)
    workspace_labels = _draw_workspaces(ax, scene.workspaces, style)
    object_labels: list[Label] = []
    for oid in scene.objects if objects is None else objects:
        drawn.objects[oid] = _draw_object(ax, oid, scene, style, object_labels)
    robot_labels: list[Label] = []
    for rid in robot_ids:
        drawn.robots[rid] = _draw_robot(ax, rid, scene, drawn.colours[rid], style, robot_labels)
    if style.people:
        for hid in scene.humans if humans is None else humans:
            drawn.humans[hid] = _draw_person(ax, hid, scene, style)
    # The robots' ids get the best spots (the last robot's first, as the plan plot always had it).
    drawn.labels = [*reversed(robot_labels), *workspace_labels, *object_labels]
    return drawn


def _draw_walls(ax: Any, scene: Scene, style: SceneStyle) -> None:
    """The walls, black segments 2 pt wide, in one collection."""
    from matplotlib.collections import LineCollection

    if scene.obstacles:
        segments = [[w.start, w.end] for w in scene.obstacles]
        walls = LineCollection(
            segments, colors="black", linewidths=2, capstyle=style.wall_caps, zorder=_WALL_LAYER
        )
        ax.add_collection(walls)


def _draw_workspaces(ax: Any, workspaces: Mapping[str, Workspace], style: SceneStyle) -> list[Label]:
    """Rectangles or crosses with their ids; the ids to place, if the style places them."""
    from matplotlib.patches import Rectangle

    labels = []
    for wid, ws in workspaces.items():
        if ws.point is not None:
            ax.plot(*ws.point, marker="x", color="grey", ms=style.cross, zorder=style.mark_layer)
        else:
            x, y = ws.ranges
            width, height = x[1] - x[0], y[1] - y[0]
            area = Rectangle(
                (x[0], y[0]), width, height, color="lightgrey", alpha=0.7, zorder=style.area_layer
            )
            ax.add_patch(area)
        if style.placed_ids:
            text = {"fontsize": style.font, "color": "dimgrey"}
            labels.append(Label(*ws.center, wid, text, center=not ws.is_point))
        elif ws.point is not None:  # beside the cross, which it must not hide
            ax.annotate(
                wid, ws.point, textcoords="offset points", xytext=(4, 4), color="grey", fontsize=style.font
            )
        else:
            ax.text(
                *ws.center, wid, ha="center", va="center", color="dimgrey", fontsize=style.font,
                zorder=style.mark_layer,
            )  # fmt: skip
    return labels


def _draw_object(ax: Any, oid: str, scene: Scene, style: SceneStyle, labels: list[Label]) -> Piece:
    """A brown square at the object's position, hidden if the scene does not declare it."""
    from matplotlib.patches import Rectangle

    declared = scene.objects.get(oid)
    size = float(declared.size) if declared is not None else DEFAULT_OBJECT_SIZE
    patch = ax.add_patch(Rectangle((0, 0), size, size, color="saddlebrown", zorder=style.object_layer))
    marker = None
    if not style.placed_ids:  # placed by the caller: near the object, clear of its neighbours
        marker = text_marker(ax, oid, "black", style.font - 1, zorder=style.object_layer)
    piece = Piece(patch, marker, size, label_offset=None)
    if declared is None:
        piece.show(False)
        return piece
    piece.move(*declared.position)
    if style.placed_ids:
        labels.append(Label(*declared.position, oid, {"fontsize": style.font - 1}))
    return piece


def _draw_robot(
    ax: Any, rid: str, scene: Scene, colour: Rgb, style: SceneStyle, labels: list[Label]
) -> Piece:
    """The robot's square at its initial pose, its id under it; hidden if the scene does not declare it."""
    from matplotlib.patches import Rectangle

    declared = scene.robots.get(rid)
    size = float(declared.size) if declared is not None else DEFAULT_ROBOT_SIZE
    fill: dict[str, Any] = (
        {"fill": False} if style.robot_fill is None else {"fc": (*colour[:3], style.robot_fill)}
    )
    body = Rectangle((0, 0), size, size, ec=colour, lw=1.5, zorder=style.robot_layer, **fill)
    marker = None
    if not style.placed_ids:
        marker = text_marker(ax, rid, colour, style.font, weight="bold", va="top", zorder=style.id_layer)
    piece = Piece(ax.add_patch(body), marker, size, label_offset=-1.1 * (size / 2))
    if declared is None:
        piece.show(False)
        return piece
    x, y, _ = declared.pose
    piece.move(x, y)
    if style.placed_ids:
        text = {"fontsize": style.font, "color": colour, "weight": "bold"}
        labels.append(Label(x, y, rid, text, center=True, keep=True))  # a robot's id always shows
    return piece


def _draw_person(ax: Any, hid: str, scene: Scene, style: SceneStyle) -> Piece:
    """An orange disc of the person's size with the id on it, hidden until the caller moves it."""
    from matplotlib.patches import Circle

    declared = scene.humans.get(hid)
    size = float(declared.size) if declared is not None else DEFAULT_HUMAN_SIZE
    disc = Circle((0, 0), size / 2, fc="orange", ec="darkorange", alpha=0.85, zorder=style.robot_layer)
    marker = text_marker(ax, hid, "black", style.font, va="center", zorder=style.id_layer)
    piece = Piece(ax.add_patch(disc), marker, size)
    piece.show(False)
    return piece


def scene_legend() -> list[Any]:
    """Legend entries for what every style draws alike: walls and workspaces."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    return [Line2D([], [], color="black", lw=2, label="wall"), Patch(color="lightgrey", label="workspace")]


def planned_path(robot: Robot, plan: RobotPlan) -> list[tuple[float, float]]:
    """The path a plan drives: the robot's initial position, then every GoTo's target (mm).

    Parameters
    ----------
    robot : Robot
        The robot, at its initial pose.
    plan : RobotPlan
        Its plan.

    Returns
    -------
    list of (float, float)
    """
    return [(robot.pose[0], robot.pose[1])] + [
        (s.robot[0], s.robot[1]) for s in plan.steps if s.primitive == "GoTo"
    ]


def replanned_path(route: Mapping[str, Any]) -> list[tuple[float, float]]:
    """The path a replan drives: where it went on from, then every GoTo's target (mm); `route`
    is a trace's ``replans[k].route`` (:attr:`cosmop.traces.Trace.replans`).

    Parameters
    ----------
    route : Mapping
        The route as the trace holds it: ``from`` (a pose) and ``steps`` (each with its
        ``primitive`` and ``pose``), poses in mm and degrees.

    Returns
    -------
    list of (float, float)
    """
    points = [tuple(route["from"][:2])] + [
        tuple(s["pose"][:2]) for s in route["steps"] if s["primitive"] == "GoTo"
    ]
    return cast(list[tuple[float, float]], points)  # the trace's JSON: pairs of numbers


def ids_with_trace(declared: Mapping[str, Any], trace: Trace | None, group: str) -> list[str]:
    """The ids of `declared` in order, then those only `trace` follows under `group`.

    Parameters
    ----------
    declared : Mapping
        The scene's robots, objects or people by id.
    trace : Trace or None
        The run (None: the scene's ids only).
    group : str
        ``"robots"``, ``"humans"`` or ``"objects"``.

    Returns
    -------
    list of str
    """
    return list(dict.fromkeys([*declared, *(trace.ids(group) if trace is not None else ())]))
