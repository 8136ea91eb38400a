"""``cosmop`` commands that connect cosmop to the robotics ecosystem: grid maps, ROS 2 bags, a web viewer.

They are registered by :mod:`cosmop.cli` on its one app and follow its
rules: thin functions, input errors reported by the command group as one line with exit status 2.
"""

from __future__ import annotations

from collections.abc import Mapping
from enum import StrEnum
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.text import Text

from cosmop.cli._app import finite, load, stdout
from cosmop.io import check_writable, write_atomic

if TYPE_CHECKING:
    from cosmop.planning.plan_types import PlanSet
    from cosmop.scene import Scenario, Scene
    from cosmop.traces import Trace

__all__ = ["check_bag_target", "export", "import_map", "view", "write_bag_and_report"]


class _Unknown(StrEnum):
    blocked = "blocked"
    free = "free"


class _Walls(StrEnum):
    boundary = "boundary"
    rectangles = "rectangles"


class _Units(StrEnum):
    mm = "mm"
    m = "m"


def import_map(
    map_file: Annotated[
        Path,
        typer.Argument(
            metavar="MAP", help="A MovingAI .map file or a ROS map_server .yaml file.", show_default=False
        ),
    ],
    output: Annotated[
        Path, typer.Option("-o", "--output", help="Scenario YAML to write.", show_default=False)
    ],
    cell_size: Annotated[
        float | None,
        typer.Option(help="Side of a cell in mm \\[default: 1000 for .map, the YAML's resolution]", min=1e-9),
    ] = None,
    origin: Annotated[
        tuple[float, float] | None,
        typer.Option(help="The map's lower-left corner X Y in mm \\[default: 0 0, or the ROS origin]"),
    ] = None,
    unknown: Annotated[_Unknown, typer.Option(help="ROS maps: what unknown cells are.")] = _Unknown.blocked,
    walls: Annotated[
        _Walls,
        typer.Option(help="boundary: only edges between free and blocked cells; rectangles: every outline."),
    ] = _Walls.boundary,
    units: Annotated[
        _Units | None, typer.Option(help="Units to write: mm (and degrees) or m (and radians).")
    ] = None,
    template: Annotated[
        Path | None,
        typer.Option(
            help="A scenario to keep, comments and all; only its walls are replaced.",
            show_default=False,
        ),
    ] = None,
    name: Annotated[str | None, typer.Option(help="The scenario's name.", show_default=False)] = None,
) -> None:
    """Turn a grid map into scenario walls: blocked cells merged into rectangles and walled in.

    Without --template it writes the scene's walls only (add robots, objects, workspaces and a
    mission); with one, a whole scenario, which is validated before it is written: the template
    as it was (comments, key order, one-line lists) with its walls replaced. Exit status 0
    written, 2 bad input (nothing written).

    Parameters
    ----------
    map_file : pathlib.Path
        The map: a MovingAI ``.map`` file or a ROS ``map_server`` ``.yaml`` file.
    output : pathlib.Path
        ``-o``: the scenario YAML to write.
    cell_size : float or None
        ``--cell-size``: side of a cell, mm (None: 1000 for ``.map``, the YAML's resolution).
    origin : tuple of float or None
        ``--origin``: the map's lower-left corner ``(x, y)``, mm (None: ``(0, 0)``, or the ROS
        map's origin).
    unknown : {"blocked", "free"}
        ``--unknown``: what the unknown cells of a ROS map are.
    walls : {"boundary", "rectangles"}
        ``--walls``: only the edges between free and blocked cells, or every rectangle's outline.
    units : {"mm", "m"} or None
        ``--units``: the units to write (None: the template's, else mm).
    template : pathlib.Path or None
        ``--template``: a scenario to keep, comments and all, with only its walls replaced.
    name : str or None
        ``--name``: the scenario's name (None: the template's, else the map file's stem).
    """
    from cosmop.maps import import_map as read_map
    from cosmop.maps import scenario_text
    from cosmop.scenario import load_scenario

    check_writable(output, "-o")
    imported = read_map(
        map_file,
        cell_size=cell_size,
        origin=origin,
        unknown=unknown.value,
        walls=walls.value,
    )
    text = scenario_text(imported, name=name, units=None if units is None else units.value, template=template)
    if template is not None:  # a whole scenario: it must load before it is written
        import tempfile

        with tempfile.TemporaryDirectory() as tmp:
            check = Path(tmp) / output.name
            check.write_text(text, encoding="utf-8")
            try:
                load_scenario(check)
            except Exception as err:  # report it against the file the user will get
                typer.echo(f"error: {output} (from {template}): {getattr(err, 'expected', err)}", err=True)
                raise typer.Exit(2) from None
    write_atomic(output, text)
    grid = imported.grid
    rows, cols = grid.shape
    stdout().print(
        Text(
            f"wrote {output}: {cols} x {rows} cells of {grid.cell_size:g} mm, {int(grid.blocked.sum())} "
            f"blocked cells in {len(imported.rectangles)} rectangles, {len(imported.walls)} walls "
            f"({imported.outline_walls} as rectangle outlines)",
            style="green",
        )
    )


def _warn_if_other_scenario(loaded: Scenario, trace: Trace | None, plans: PlanSet | None) -> None:
    """A trace or plan made for another scenario (by name) is drawn anyway, with a warning."""
    for what, name in (
        ("trace", getattr(trace, "scenario", None)),
        ("plan", getattr(plans, "scenario", None)),
    ):
        if name is not None and name != loaded.name:
            typer.echo(f"warning: the {what} is of scenario {name!r}, not {loaded.name!r}", err=True)


def check_bag_target(bag: Path) -> None:
    """Before any work: the ``ros`` extra is installed and the bag directory is new (else exit 2).

    Parameters
    ----------
    bag : pathlib.Path
        The bag directory to create (``--bag``).
    """
    from cosmop.export import ros_available

    if not ros_available():
        typer.echo("error: --bag needs rosbags: pip install 'cosmop[ros]'", err=True)
        raise typer.Exit(2)
    if bag.exists():
        typer.echo(
            f"error: {bag}: exists; expected a new directory for the bag (never overwritten)", err=True
        )
        raise typer.Exit(2)
    check_writable(bag, "--bag", folder=True)  # its folder exists and is writable


def write_bag_and_report(
    scene: Scene,
    trace: Trace | Mapping[str, Any],
    bag: Path,
    plans: PlanSet | None,
    rate: float | None,
    scene_rate: float,
) -> None:
    """Write the bag and print one line: where, how many messages on how many topics, how big.

    Parameters
    ----------
    scene : Scene
        The run's scene (mm).
    trace : Trace or Mapping
        The run (or its ``cosmop.trace/1`` JSON).
    bag : pathlib.Path
        The bag directory to create.
    plans : PlanSet or None
        The plans executed, published as each robot's ``/<robot>/plan``.
    rate : float or None
        Poses and ``/tf`` per second, Hz (None: every frame of the trace).
    scene_rate : float
        ``/scene`` marker arrays per second, Hz.
    """
    from cosmop.export import write_bag

    summary = write_bag(scene, trace, bag, plans=plans, rate=rate, scene_rate=scene_rate)
    stdout().print(
        Text(
            f"wrote ROS 2 bag {bag} (MCAP, metres and radians, frame 'map'): "
            f"{sum(summary.counts.values())} messages on {len(summary.counts)} topics, "
            f"{summary.start_s:.1f} s to {summary.end_s:.1f} s, {summary.size_bytes / 1e6:.2f} MB",
            style="green",
        )
    )


RateOption = Annotated[
    float | None,
    typer.Option(
        help="Poses and /tf per second (Hz) \\[default: every frame of the trace]", min=1e-6, callback=finite
    ),
]
SceneRateOption = Annotated[
    float, typer.Option(help="/scene marker arrays per second (Hz).", min=1e-6, callback=finite)
]


def export(
    scenario: Annotated[
        Path, typer.Argument(metavar="SCENARIO", help="Scenario file (YAML).", show_default=False)
    ],
    trace: Annotated[
        Path,
        typer.Option(
            help="The run: a trace from cosmop simulate --trace (cosmop.trace/1).", show_default=False
        ),
    ],
    bag: Annotated[
        Path, typer.Option(help="ROS 2 bag DIRECTORY to create (MCAP storage).", show_default=False)
    ],
    plan_file: Annotated[
        Path | None,
        typer.Option(
            "--plan", help="The plan file executed: each robot's /<robot>/plan.", show_default=False
        ),
    ] = None,
    rate: RateOption = None,
    scene_rate: SceneRateOption = 5.0,
) -> None:
    """Write a run as a ROS 2 bag for Foxglove, RViz and ros2 bag play (REP 103: map frame, metres, radians).

    Topics: /tf, /<robot>/pose (PoseStamped), /<robot>/plan (Path), /scene (MarkerArray: walls,
    workspaces, objects, people, robots and what they carry, message arrows) and /coordination
    (String, one JSON object per message). Exit status 0 written, 2 bad input (nothing written).

    Parameters
    ----------
    scenario : pathlib.Path
        The scenario file (YAML).
    trace : pathlib.Path
        ``--trace``: the run, a trace from ``cosmop simulate --trace`` (``cosmop.trace/1``).
    bag : pathlib.Path
        ``--bag``: the bag directory to create (MCAP storage).
    plan_file : pathlib.Path or None
        ``--plan``: the plan file executed, published as each robot's ``/<robot>/plan``.
    rate : float or None
        ``--rate``: poses and ``/tf`` per second, Hz (None: every frame of the trace).
    scene_rate : float
        ``--scene-rate``: ``/scene`` marker arrays per second, Hz.
    """
    from cosmop.planning.plan_file import load_plan
    from cosmop.traces import load_trace

    loaded = load(scenario, mission=False)
    data = load_trace(trace)
    plans = load_plan(plan_file) if plan_file is not None else None
    check_bag_target(bag)
    _warn_if_other_scenario(loaded, data, plans)
    write_bag_and_report(loaded.scene, data, bag, plans, rate, scene_rate)


def view(
    scenario: Annotated[
        Path, typer.Argument(metavar="SCENARIO", help="Scenario file (YAML).", show_default=False)
    ],
    output: Annotated[Path, typer.Option("-o", "--output", help="HTML file to write.", show_default=False)],
    plan_file: Annotated[
        Path | None, typer.Option("--plan", help="Plan file (cosmop.plan/1) to draw.", show_default=False)
    ] = None,
    trace: Annotated[
        Path | None,
        typer.Option(help="A run (cosmop.trace/1) to play with a time slider.", show_default=False),
    ] = None,
) -> None:
    """Write one self-contained web page of the scene, the plans and the run (no network needed).

    Open it in any browser: a time slider and a play button move the robots (labelled, with
    what they carry) and draw each message as an arrow with its time. Exit status 0 written,
    2 bad input (nothing written).

    Parameters
    ----------
    scenario : pathlib.Path
        The scenario file (YAML).
    output : pathlib.Path
        ``-o``: the HTML file to write.
    plan_file : pathlib.Path or None
        ``--plan``: a plan file (``cosmop.plan/1``) to draw.
    trace : pathlib.Path or None
        ``--trace``: a run (``cosmop.trace/1``) to play with a time slider.
    """
    from cosmop.planning.plan_file import load_plan
    from cosmop.traces import load_trace
    from cosmop.viz.web import save_html

    loaded = load(scenario, mission=False)
    check_writable(output, "-o")
    plans = load_plan(plan_file) if plan_file is not None else None
    data = load_trace(trace) if trace is not None else None
    _warn_if_other_scenario(loaded, data, plans)
    size = save_html(loaded.scene, output, plans=plans, trace=data, title=loaded.name)
    frames = len(data.t) if data is not None else 0
    stdout().print(
        Text(f"wrote {output} ({size / 1e6:.2f} MB, {frames} frames); open it in a browser", style="green")
    )
