"""``cosmop simulate``: execute the plans in the scenario's world and say how the run went."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.table import Table
from rich.text import Text

from cosmop.cli._app import EXIT_INPUT_ERROR, ScenarioArgument, finite, load, stderr, stdout
from cosmop.cli.ecosystem import check_bag_target, write_bag_and_report
from cosmop.cli.plan import SchedulerOption, WorkersOption, check_engine, plan_with_progress
from cosmop.io import check_writable, uninterrupted
from cosmop.planning.plan_file import load_plan
from cosmop.planning.plan_types import PlanSet
from cosmop.scene import Scenario
from cosmop.sim import Delays, SimResult, SimSettings, StepTimes
from cosmop.team.plan_set_checker import check_plan

if TYPE_CHECKING:
    from cosmop.traces import Trace

__all__ = ["simulate"]


def parse_delays(text: str) -> Delays:
    """``--delays P:MIN:MAX``: the delays, or a usage error naming the option (exit 2).

    Parameters
    ----------
    text : str
        The option's value: a probability per robot and simulated second, then the shortest and
        longest stop in seconds, separated by colons.
    """
    try:
        return Delays.parse(text)
    except ValueError as err:
        raise typer.BadParameter(str(err)) from None


def simulate(
    scenario: ScenarioArgument,
    plan_file: Annotated[
        Path | None,
        typer.Option(
            "--plan",
            help="Plan file to execute (cosmop.plan/1); planned first if absent.",
            show_default=False,
        ),
    ] = None,
    seed: Annotated[
        int, typer.Option(help="Seed of the people's random walks and of the delays (0 or more).", min=0)
    ] = 0,
    delays: Annotated[
        Delays | None,
        typer.Option(
            parser=parse_delays,
            metavar="P:MIN:MAX",
            help="Every simulated second each robot stops with probability P for MIN to MAX s "
            "(e.g. 0.01:2:10).",
            show_default=False,
        ),
    ] = None,
    summary: Annotated[
        Path | None, typer.Option(help="Write the summary (cosmop.sim/1 JSON) here.", show_default=False)
    ] = None,
    trace: Annotated[
        Path | None,
        typer.Option(help="Write the trace, every cycle (cosmop.trace/1 JSON).", show_default=False),
    ] = None,
    html: Annotated[
        Path | None,
        typer.Option(
            help="Write a web page of the run: scene, plans, robots moving, why they wait (cosmop view).",
            show_default=False,
        ),
    ] = None,
    gif: Annotated[Path | None, typer.Option(help="Write an animation (GIF).", show_default=False)] = None,
    mp4: Annotated[Path | None, typer.Option(help="Write an animation (MP4).", show_default=False)] = None,
    speed: Annotated[
        float | None,
        typer.Option(
            help="Animation: simulated seconds per second \\[default: the run lasts at most 45 s]", min=1e-3
        ),
    ] = None,
    size: Annotated[
        int | None, typer.Option(help="Animation width in pixels \\[default: about 790]", min=100)
    ] = None,
    bag: Annotated[
        Path | None,
        typer.Option(help="Write a ROS 2 bag DIRECTORY (MCAP; the ros extra).", show_default=False),
    ] = None,
    max_time: Annotated[
        float | None,
        typer.Option(
            help="Simulated seconds before giving up \\[default: three times the planned makespan, "
            "at least 900 s]",
            min=1.0,
            callback=finite,
        ),
    ] = None,
    replan: Annotated[bool, typer.Option(help="Stalled robots replan their remaining mission.")] = True,
    workers: WorkersOption = None,
    scheduler: SchedulerOption = None,
) -> None:
    """Execute the plans: passive-safe DWA, docking, messages, people walking through.

    Every cycle each robot drives (GoTo), docks (PickUp, DropOff), waits for an answer (Req) or
    sends one (Res); a monitor records every contact and whether the robot was moving then.
    With ``--delays`` robots stop at random for a while, and the messages keep their order.
    Without ``--plan`` the team is planned first, as ``cosmop plan`` does (``--workers``,
    ``--scheduler``).  Exit status 0 when every robot finished with no contact while moving, 1
    otherwise, 2 on bad input.

    Parameters
    ----------
    scenario : pathlib.Path
        The scenario file (YAML).
    plan_file : pathlib.Path or None
        ``--plan``: the plan file to execute (``cosmop.plan/1``); None: plan the team first.
    seed : int
        ``--seed``: seeds the people's random walks and the delays.
    delays : Delays or None
        ``--delays P:MIN:MAX``: every simulated second each robot stops with probability P for
        MIN to MAX s (None: no delays).
    summary : pathlib.Path or None
        ``--summary``: write the summary (``cosmop.sim/1`` JSON) here.
    trace : pathlib.Path or None
        ``--trace``: write the trace, every cycle (``cosmop.trace/1`` JSON), here.
    html : pathlib.Path or None
        ``--html``: write a web page of the run here (as ``cosmop view`` does).
    gif, mp4 : pathlib.Path or None
        ``--gif``, ``--mp4``: write an animation of the run here.
    speed : float or None
        ``--speed``: the animations' simulated seconds per second (None: they last at most 45 s).
    size : int or None
        ``--size``: the animations' width, pixels (None: about 790).
    bag : pathlib.Path or None
        ``--bag``: write a ROS 2 bag directory (MCAP) of the run here.
    max_time : float or None
        ``--max-time``: simulated seconds before giving up (None: three times the planned
        makespan, at least 900 s).
    replan : bool
        ``--replan/--no-replan``: whether stalled robots replan their remaining mission.
    workers : int or None
        ``--workers``: local processes for the syntheses when the team is planned first.
    scheduler : str or None
        ``--scheduler``: a Dask scheduler's address for those syntheses.
    """
    check_engine(workers, scheduler)
    loaded = load(scenario)
    _check_outputs(summary=summary, trace=trace, gif=gif, mp4=mp4, bag=bag)
    check_writable(html, "--html")
    plans = _plans_to_run(loaded, plan_file, workers, scheduler)
    settings = SimSettings(max_time=max_time, replan=replan, delays=delays)
    result = _run_with_progress(loaded, plans, seed, settings)
    # one Trace for the file, the bag and the animations, made only when one of them is asked for
    run = result.trace() if any(p is not None for p in (trace, bag, gif, mp4, html)) else None
    with uninterrupted():  # the trace and its summary: both or neither
        if trace is not None:
            assert run is not None  # made whenever a trace is asked for
            run.save(trace)
        if summary is not None:
            result.save_summary(summary)
    if bag is not None:
        assert run is not None
        write_bag_and_report(loaded.scene, run, bag, plans, None, 5.0)
    for path in (gif, mp4):
        if path is not None:
            assert run is not None
            _animate(loaded, run, plans, path, speed, size)
    if html is not None:
        from cosmop.viz.web import save_html

        save_html(loaded.scene, html, plans=plans, trace=run, title=loaded.name)
    console = stdout()
    console.print(_robots_table(loaded, result, seed))
    ok = result.completed and result.contacts_while_moving == 0
    console.print(Text(_verdict(loaded, result, plans), style="green" if ok else "red"))
    for path, what in ((html, "open it in a browser"), (gif, "the animation"), (mp4, "the animation")):
        if path is not None:
            # not wrapped: a path cut in two cannot be copied or clicked
            console.print(Text(f"wrote {path}: {what}, {path.resolve().as_uri()}"), soft_wrap=True)
    raise typer.Exit(0 if ok else 1)


def _check_outputs(
    summary: Path | None, trace: Path | None, gif: Path | None, mp4: Path | None, bag: Path | None
) -> None:
    """Before any work: every output can be written and the extras it needs are installed."""
    for option, path in (("--summary", summary), ("--trace", trace), ("--gif", gif), ("--mp4", mp4)):
        check_writable(path, option)
    for path, check_video in ((gif, False), (mp4, True)):
        if path is None:
            continue
        from cosmop.viz import available, video_available

        if not available() or (check_video and not video_available()):
            extra = "video" if check_video else "viz"
            typer.echo(f"error: --{path.suffix[1:]} needs pip install 'cosmop[{extra}]'", err=True)
            raise typer.Exit(EXIT_INPUT_ERROR)
    if bag is not None:
        check_bag_target(bag)


def _plans_to_run(
    loaded: Scenario, plan_file: Path | None, workers: int | None, scheduler: str | None
) -> PlanSet:
    """The plan file, checked exactly against the scenario (else exit 2), or a plan made now."""
    if plan_file is not None:
        plans = load_plan(plan_file)
        report = check_plan(loaded, plans)
        if not plans.feasible or not report.ok:
            why = plans.reason if not plans.feasible else report.violations[0].message
            typer.echo(
                f"error: {plan_file}: expected a feasible plan valid for {loaded.name}: {why}", err=True
            )
            raise typer.Exit(EXIT_INPUT_ERROR)
        return plans
    plans = plan_with_progress(loaded, workers=workers, scheduler=scheduler).plans
    if not plans.feasible:
        stdout().print(Text(f"infeasible: {plans.reason}", style="red"))
        raise typer.Exit(1)
    return plans


def _run_with_progress(loaded: Scenario, plans: PlanSet, seed: int, settings: SimSettings) -> SimResult:
    """:func:`cosmop.sim.simulate` under a bar of simulated time and robots done."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    from cosmop.sim import simulate as run_simulate
    from cosmop.sim import time_limit

    columns = (
        TextColumn("simulating"),
        BarColumn(),
        TextColumn("{task.fields[done]}/{task.fields[robots]} robots done, t = {task.completed:.0f} s"),
        TimeElapsedColumn(),
    )
    with Progress(*columns, console=stderr(), transient=True) as progress:
        limit = time_limit(loaded, plans, settings)
        task = progress.add_task("simulating", total=limit, done=0, robots=len(loaded.scene.robots))
        return run_simulate(
            loaded,
            plans,
            seed=seed,
            settings=settings,
            on_cycle=lambda t, done, robots: progress.update(task, completed=t, done=done),
        )


def _animate(
    loaded: Scenario, run: Trace, plans: PlanSet, path: Path, speed: float | None, size: int | None
) -> None:
    """Draw the run's trace into a GIF or MP4 under a spinner."""
    from rich.progress import Progress, TextColumn, TimeElapsedColumn

    from cosmop.viz import save_animation

    with Progress(
        TextColumn(f"drawing {path.name}"), TimeElapsedColumn(), console=stderr(), transient=True
    ) as p:
        p.add_task("drawing", total=None)
        save_animation(loaded.scene, run, path, plans=plans, speed=speed, size=size)


def _robots_table(loaded: Scenario, result: SimResult, seed: int) -> Table:
    """One row per robot: where it ended, how far it drove, whether and when it finished."""
    delays = result.delays
    title = f"simulation of {loaded.name} (seed {seed}" + (f"; delays {delays.show()})" if delays else ")")
    table = Table(title=Text(title), header_style="bold")
    metres = loaded.units == "m"  # the scenario file's units: metres and radians, or mm and degrees
    pose_column = "pose [m, rad]" if metres else "pose [mm, deg]"
    columns = ["robot", pose_column, "distance", "finished", "done at (planned)"]
    for column in columns + (["stopped by delays"] if delays else []):
        table.add_column(Text(column))  # Text: "[mm, deg]" is not markup
    finished = result.finished
    for rid, (pose, dist) in result.robots.items():
        x, y, heading = pose
        row = [
            rid,
            f"{x / 1000:.3f}, {y / 1000:.3f}, {math.radians(heading):.2f}"
            if metres
            else f"{x:.0f}, {y:.0f}, {heading:.0f}",
            f"{dist / 1000:.2f} m" if metres else f"{dist:.0f} mm",
            "yes" if finished[rid] else Text("no", style="red"),
            _done_at(result.steps.get(rid, ()), finished[rid]),
        ]
        if delays:
            row.append(_stopped(result.stops.get(rid, ())))
        table.add_row(*row)
    return table


def _stopped(stops: Sequence[tuple[float, float]]) -> str:
    """How often and how long a delay stopped a robot: ``2 times, 12.3 s`` (``-``: never)."""
    if not stops:
        return "-"
    return f"{len(stops)} time{'s' if len(stops) > 1 else ''}, {sum(s for _, s in stops):.1f} s"


def _verdict(loaded: Scenario, result: SimResult, plans: PlanSet) -> str:
    """The closing line: completed or not, times, goods in place, contacts, messages, replans."""
    delivered = result.objects_in_workspaces(loaded, plans)
    speed = result.sim_time_s / max(result.wall_time_s, 1e-9)
    planned = result.makespan["planned"]
    return (
        f"{'completed' if result.completed else 'not completed'} in {result.sim_time_s:.1f} s simulated "
        + (f"(planned {planned:.1f} s; " if planned is not None else "(")
        + f"{result.wall_time_s:.1f} s, {speed:.0f}x real time); "
        f"objects in place {sum(delivered.values())}/{len(delivered)}; {_contacts_said(loaded, result)}; "
        f"messages {len(result.messages)}; "
        f"replans {result.replans}" + _delays_said(result)
    )


def _contacts_said(loaded: Scenario, result: SimResult) -> str:
    """The contacts in the closing line, with how many were people walking into a standing robot
    (passive safety keeps a robot from moving into anything, not people from walking into it)."""
    people = sum(1 for c in result.contacts if not c.moving and c.other in loaded.scene.humans)
    said = f"contacts {len(result.contacts)}, while moving {result.contacts_while_moving}"
    return said + (f" ({people} a person walking into a standing robot)" if people else "")


def _delays_said(result: SimResult) -> str:
    """The delays in the closing line: how often robots stopped and for how long in all."""
    report = result.delay_report()
    if report is None:
        return ""
    return f"; delays stopped robots {report['count']} times, {report['seconds']:.1f} s in all"


def _done_at(rows: Sequence[StepTimes], finished: bool) -> str:
    """When a robot ended its plan in the run, and when its itinerary expected it: ``64.7 s (46.1 s)``."""
    realised = rows[-1].realised[1] if finished and rows and rows[-1].realised else None
    planned = max((r.planned[1] for r in rows if r.planned is not None), default=None)
    done = f"{realised:.1f} s" if realised is not None else "-"
    return f"{done} ({planned:.1f} s)" if planned is not None else done
