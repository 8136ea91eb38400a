"""``cosmop run``: a fleet that keeps working while orders stream in (a lifelong run)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table
from rich.text import Text

from cosmop.cli._app import EXIT_INPUT_ERROR, ScenarioArgument, finite, load, stderr, stdout
from cosmop.cli.simulate import parse_delays
from cosmop.io import check_writable, interrupt_at_safe_points, uninterrupted
from cosmop.lifelong import Failure, FleetInterrupted, FleetResult, FleetSettings, run_fleet
from cosmop.scenario import load_orders
from cosmop.scene import Order, Scenario
from cosmop.sim import Delays, SimSettings

__all__ = ["run"]


def _parse_failure(text: str) -> Failure:
    """``--fail R3@600``: the failure, or a usage error naming the option (exit 2)."""
    try:
        return Failure.parse(text)
    except ValueError as err:
        raise typer.BadParameter(str(err)) from None


def run(
    scenario: ScenarioArgument,
    until: Annotated[float, typer.Option(help="Simulated seconds the run lasts.", min=1.0, callback=finite)],
    orders: Annotated[
        Path | None,
        typer.Option(
            help="An orders file (orders: as in a scenario); default: the scenario's.", show_default=False
        ),
    ] = None,
    seed: Annotated[int, typer.Option(help="Seed of the people's walks and of the delays.", min=0)] = 0,
    fail: Annotated[
        list[Failure] | None,
        typer.Option(
            parser=_parse_failure,
            metavar="ROBOT@SECONDS",
            help="A robot stops for good at that time (repeat the option for several).",
            show_default=False,
        ),
    ] = None,
    delays: Annotated[
        Delays | None,
        typer.Option(
            parser=parse_delays,
            metavar="P:MIN:MAX",
            help="Every simulated second each robot stops with probability P for MIN to MAX s.",
            show_default=False,
        ),
    ] = None,
    reorder_after: Annotated[
        float,
        typer.Option(
            help="Order again the conflicts of a robot that has waited this long for a message "
            "another will send only later (s; 0: keep orders as handed over).",
            min=0.0,
            callback=finite,
        ),
    ] = 15.0,
    reveal: Annotated[
        float,
        typer.Option(
            help="Orders per robot the dispatcher chooses among, oldest first: each idle robot "
            "takes the one of least work (0: each order in turn, oldest first).",
            min=0.0,
            callback=finite,
        ),
    ] = 1.0,
    summary: Annotated[
        Path | None, typer.Option(help="Write the summary (cosmop.run/1 JSON) here.", show_default=False)
    ] = None,
    trace: Annotated[
        Path | None, typer.Option(help="Write the trace (cosmop.trace/1 JSON).", show_default=False)
    ] = None,
    plot: Annotated[
        Path | None,
        typer.Option(
            help="Write a PNG of the orders released and delivered over time (the viz extra).",
            show_default=False,
        ),
    ] = None,
) -> None:
    """Run the fleet while orders arrive: each goes to an idle robot, planned and ordered with
    the others' committed plans while they keep moving.

    Prints a live progress line, a table per robot and the totals (deliveries per hour, each
    order's wait, contacts, whether each delivery did what its order asked).  Exit status 0 when
    no contact happened while a robot moved, no order was lost and every delivered order's
    events are a word of its delivery mission, 1 otherwise, 2 on bad input.

    Parameters
    ----------
    scenario : pathlib.Path
        The scenario file (YAML).
    until : float
        ``--until``: simulated seconds the run lasts.
    orders : pathlib.Path or None
        ``--orders``: an orders file (``orders:`` as in a scenario); None: the scenario's orders.
    seed : int
        ``--seed``: seeds the people's walks and the delays.
    fail : list of Failure or None
        ``--fail ROBOT@SECONDS``, repeatable: robots that stop for good at those times.
    delays : Delays or None
        ``--delays P:MIN:MAX``: every simulated second each robot stops with probability P for
        MIN to MAX s (None: no delays).
    reorder_after : float
        ``--reorder-after``: seconds a robot waits for a message before its conflicts are
        ordered again (``FleetSettings.reorder_after``; 0: never).
    reveal : float
        ``--reveal``: orders per robot the dispatcher chooses among (``FleetSettings.reveal``).
    summary : pathlib.Path or None
        ``--summary``: write the summary (``cosmop.run/1`` JSON) here.
    trace : pathlib.Path or None
        ``--trace``: write the trace (``cosmop.trace/1`` JSON) here.
    plot : pathlib.Path or None
        ``--plot``: write a PNG of the orders released and delivered over time here.
    """
    loaded = load(scenario, mission=False)
    stream = load_orders(orders, loaded) if orders is not None else loaded.orders
    if not stream:
        typer.echo(f"error: {scenario}: orders: expected orders in the scenario or --orders FILE", err=True)
        raise typer.Exit(EXIT_INPUT_ERROR)
    for option, path in (("--summary", summary), ("--trace", trace), ("--plot", plot)):
        check_writable(path, option)
    if plot is not None:
        from cosmop.viz import available

        if not available():
            typer.echo("error: --plot needs pip install 'cosmop[viz]'", err=True)
            raise typer.Exit(EXIT_INPUT_ERROR)
    for failure in fail or ():
        if failure.robot not in loaded.scene.robots:
            typer.echo(f"error: --fail: {failure.robot} is not a robot of {loaded.name}", err=True)
            raise typer.Exit(EXIT_INPUT_ERROR)
    settings = SimSettings(delays=delays)
    try:
        fleet = FleetSettings(until=until, reorder_after=reorder_after or None, reveal=reveal)
        result = _run_with_progress(loaded, stream, fleet, seed, settings, tuple(fail or ()))
    except FleetInterrupted as stop:  # Ctrl-C: what was delivered so far, written whole
        _save(stop.result, summary, trace)
        raise KeyboardInterrupt from None
    _save(result, summary, trace)
    if plot is not None:
        result.save_plot(plot)
    console = stdout()
    console.print(_robots_table(result))
    ok = result.contacts_while_moving == 0 and result.lost == 0 and not result.not_as_ordered
    console.print(Text(_verdict(result), style="green" if ok else "red"))
    for line in _undelivered(result):
        console.print(Text(line), soft_wrap=True)
    for path in (summary, trace, plot):
        if path is not None:
            console.print(Text(f"wrote {path}"), soft_wrap=True)
    raise typer.Exit(0 if ok else 1)


def _save(result: FleetResult, summary: Path | None, trace: Path | None) -> None:
    """The summary and its trace: both or neither, whatever Ctrl-C does meanwhile."""
    with uninterrupted():
        if trace is not None:
            result.trace().save(trace)
        if summary is not None:
            result.save_summary(summary)


def _run_with_progress(
    loaded: Scenario,
    stream: Sequence[Order],
    fleet: FleetSettings,
    seed: int,
    settings: SimSettings,
    failures: Sequence[Failure],
) -> FleetResult:
    """:func:`cosmop.lifelong.run_fleet` under a live line: time, released, delivered."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    columns = (
        TextColumn("running"),
        BarColumn(),
        TextColumn(
            "t = {task.completed:.0f} s, {task.fields[released]} released, {task.fields[delivered]} delivered"
        ),
        TimeElapsedColumn(),
    )
    # Ctrl-C is answered between two cycles, where the run can say what it did so far
    with (
        interrupt_at_safe_points() as safe_point,
        Progress(*columns, console=stderr(), transient=True) as progress,
    ):
        task = progress.add_task("running", total=fleet.until, released=0, delivered=0)

        def on_cycle(t: float, delivered: int, released: int) -> None:
            progress.update(task, completed=t, delivered=delivered, released=released)
            safe_point()

        return run_fleet(
            loaded,
            stream,
            fleet=fleet,
            seed=seed,
            settings=settings,
            failures=failures,
            on_cycle=on_cycle,
        )


def _robots_table(result: FleetResult) -> Table:
    """One row per robot: deliveries made, share of the run serving orders, failure."""
    table = Table(
        title=Text(f"lifelong run of {result.scenario} ({result.until:.0f} s)"), header_style="bold"
    )
    for column in ("robot", "delivered", "busy", "failed"):
        table.add_column(column)
    done: dict[str, int] = {}
    for order in result.orders:
        if order.delivered is not None and order.robot is not None:
            done[order.robot] = done.get(order.robot, 0) + 1
    for rid in result.robot_ids:
        failure = result.failures.get(rid)
        failed = (
            f"at {failure['t']:.0f} s"
            + (f", carrying {', '.join(failure['carrying'])}" if failure["carrying"] else "")
            if failure
            else "-"
        )
        table.add_row(rid, str(done.get(rid, 0)), f"{100 * result.utilisation[rid]:.0f} %", Text(failed))
    return table


def _undelivered(result: FleetResult, shown: int = 5) -> list[str]:
    """The orders lost, and those still waiting after a refusal, each with its reason (the
    first `shown`; the summary has them all)."""
    lines = [
        f"{o.object} (released at {o.at:g} s) "
        + (f"lost: {o.lost}" if o.lost else f"not delivered: {o.refused}")
        for o in result.orders
        if o.delivered is None and (o.lost or o.refused)
    ]
    more = len(lines) - shown
    return lines[:shown] + ([f"... and {more} more orders (see --summary)"] if more > 0 else [])


def _verdict(result: FleetResult) -> str:
    """The closing line: throughput, waits, lost orders, safety."""
    wait = result.wait_s()
    waits = (
        f"wait p50 {wait['p50']:.1f} s, p95 {wait['p95']:.1f} s, max {wait['max']:.1f} s"
        if wait["p50"] is not None
        else "no order delivered"
    )
    pending = result.released - result.delivered - result.lost
    handing = result.handover_wall_s()
    handovers = (
        f"; a hand-over took {handing['p50']:.2f} s of wall time (median, p95 {handing['p95']:.2f} s)"
        if handing["p50"] is not None
        else ""
    )
    return (
        f"{result.delivered} of {result.released} orders delivered "
        f"({result.deliveries_per_hour:.1f} per hour; "
        f"{pending} pending, {result.lost} lost); {waits}; contacts {len(result.contacts)}, while moving "
        f"{result.contacts_while_moving}; messages {len(result.messages)}; replans {result.replans}"
        f"{_reordered(result)}{handovers}; {_as_ordered(result)}"
    )


def _as_ordered(result: FleetResult) -> str:
    """Whether every delivery did what its order asked (its events a word of its mission)."""
    broken = result.not_as_ordered
    if not broken:
        return f"all {result.delivered} deliveries as ordered (each a word of its delivery mission)"
    words = "; ".join(f"{o.object}: {' '.join(e.name for e in o.word)}" for o in broken[:3])
    return f"{len(broken)} of {result.delivered} deliveries NOT as ordered ({words})"


def _reordered(result: FleetResult) -> str:
    """How many robots that stood long for a message had their conflicts ordered again."""
    if not result.reorders:
        return ""
    turned = sum(1 for r in result.reorders if r["accepted"])
    return f"; waits re-ordered {turned} of {len(result.reorders)} tried"
