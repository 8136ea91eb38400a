"""``cosmop plan`` and ``cosmop check``: plan, coordinate and verify the team; check a plan file."""

from __future__ import annotations

import json
from concurrent.futures import Executor
from contextlib import AbstractContextManager
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.console import Console
from rich.table import Table
from rich.text import Text

from cosmop.cli._app import EXIT_INPUT_ERROR, ScenarioArgument, finite, load, stderr, stdout
from cosmop.cli.words import plan_verdict
from cosmop.io import check_writable
from cosmop.planning.plan_file import load_plan
from cosmop.planning.plan_types import MAX_STEPS
from cosmop.scene import Scenario
from cosmop.team.plan_set_checker import check_plan

if TYPE_CHECKING:
    from cosmop.team.loop import TeamResult

__all__ = [
    "SchedulerOption",
    "WorkersOption",
    "check",
    "check_engine",
    "default_budget",
    "plan",
    "plan_with_progress",
]

WorkersOption = Annotated[
    int | None,
    typer.Option(
        "--workers",
        min=1,
        help="Local processes for the robots' syntheses \\[default: one per core, at most one per robot]",
        show_default=False,
    ),
]
SchedulerOption = Annotated[
    str | None,
    typer.Option(
        "--scheduler",
        metavar="ADDRESS",
        help="Run the syntheses on a Dask cluster, e.g. tcp://host:8786 (pip install 'cosmop\\[cluster]').",
        show_default=False,
    ),
]


def check(
    scenario: ScenarioArgument,
    plan: Annotated[
        Path, typer.Argument(metavar="PLAN", help="Plan file (cosmop.plan/1 JSON).", show_default=False)
    ],
    as_json: Annotated[bool, typer.Option("--json", help="Print the report as one JSON object.")] = False,
) -> None:
    """Check a plan file against its scenario with exact geometry (walls, poses, flags, mission).

    Exit status 0 when the plan is valid, 1 when it breaks a rule (every violation is listed),
    2 on bad input.

    Parameters
    ----------
    scenario : pathlib.Path
        The scenario file (YAML).
    plan : pathlib.Path
        The plan file to check (``cosmop.plan/1`` JSON).
    as_json : bool
        ``--json``: print the report as one JSON object instead of a table.
    """
    loaded = load(scenario)
    plans = load_plan(plan)
    report = check_plan(loaded, plans)
    if as_json:
        typer.echo(json.dumps(report.to_dict(), indent=2))
        raise typer.Exit(0 if report.ok else 1)
    console = stdout()
    if not plans.feasible:
        console.print(Text(f"the plan file marks the scenario infeasible: {plans.reason}", style="yellow"))
    if report.ok:
        console.print(Text(f"plan valid: {report.checked_steps} steps checked", style="green"))
        raise typer.Exit(0)
    table = Table(title=Text(f"violations of {plan.name}"), header_style="bold")
    for column in ("robot", "instant", "rule", "problem"):
        table.add_column(column)
    for v in report.violations:
        instant = "-" if v.instant is None else str(v.instant)
        table.add_row(Text(v.robot or "-"), instant, Text(v.rule), Text(v.message))
    console.print(table)
    count = len(report.violations)
    noun = "violation" if count == 1 else "violations"
    console.print(Text(f"plan invalid: {count} {noun} in {report.checked_steps} steps checked", style="red"))
    raise typer.Exit(1)


def plan(
    scenario: ScenarioArgument,
    output: Annotated[
        Path,
        typer.Option("-o", "--output", help="Plan file to write (cosmop.plan/1 JSON).", show_default=False),
    ],
    png: Annotated[
        Path | None, typer.Option(help="Also draw the scene and the plans into this PNG.", show_default=False)
    ] = None,
    full_map: Annotated[
        bool,
        typer.Option(
            "--full-map",
            help="Draw the whole map in the --png picture \\[default: where the team works, and a margin]",
        ),
    ] = False,
    max_horizon: Annotated[
        int | None,
        typer.Option(
            help="Longest plan tried per robot (steps) \\[default: 16, or 3 per mission event + 6 if more]",
            min=0,
            max=MAX_STEPS,
            show_default=False,
        ),
    ] = None,
    workers: WorkersOption = None,
    scheduler: SchedulerOption = None,
    budget: Annotated[
        float | None,
        typer.Option(
            help="Seconds the planning may take before it gives up on a team it has not planned "
            "yet, saying so \\[default: 60 + 10 per robot]",
            min=1.0,
            show_default=False,
            callback=finite,
        ),
    ] = None,
) -> None:
    """Plan, coordinate and verify the team (paper, Fig. "Overall framework").

    Each robot's shortest safe sequence of motion primitives is synthesised; every request
    (Req) becomes an ``away(O, requester, responder)`` pair placed so that the team cannot
    deadlock; the robots whose missions changed are re-planned; the coordinated missions are
    verified against the global mission, and every plan passes the exact checker before it is
    written.  The file is written even when infeasible (``"feasible": false`` and a reason).
    The syntheses run in local processes, or on a Dask cluster with ``--scheduler``; the plans
    are the same.  The PNG shows where the team works (``--full-map``: the whole map) and says
    in its title whether the plans are feasible, and if not why.  Exit status 0 feasible,
    1 infeasible, 2 bad input (an unreachable scheduler included).

    Parameters
    ----------
    scenario : pathlib.Path
        The scenario file (YAML).
    output : pathlib.Path
        ``-o``: the plan file to write (``cosmop.plan/1`` JSON).
    png : pathlib.Path or None
        ``--png``: also draw the scene and the plans into this PNG.
    full_map : bool
        ``--full-map``: draw the whole map in the PNG, not only where the team works.
    max_horizon : int or None
        ``--max-horizon``: the longest plan tried per robot, steps (None: the planner's default).
    workers : int or None
        ``--workers``: local processes for the robots' syntheses (None: one per core, at most
        one per robot).
    scheduler : str or None
        ``--scheduler``: the address of a Dask scheduler to run the syntheses on (None: local).
    budget : float or None
        ``--budget``: seconds the planning may take (None: :func:`default_budget`).
    """
    check_engine(workers, scheduler)
    loaded = load(scenario)
    check_writable(output, "-o")
    check_writable(png, "--png")
    if png is not None:
        _need_viz()
    budget = default_budget(loaded) if budget is None else budget
    result = plan_with_progress(loaded, max_horizon, workers, scheduler, budget)
    result.plans.save(output)
    if png is not None:
        from cosmop.viz import save_plan_png

        save_plan_png(loaded.scene, result.plans, png, full_map=full_map)
    console = stdout()
    console.print(_plan_table(loaded, result))
    if result.plans.feasible:
        console.print(Text(plan_verdict(result.plans, result.verification, loaded.units), style="green"))
    if result.verification is not None:
        _print_coordination(console, result)
    if result.allocation is not None and result.allocation.alternative is not None:
        _print_allocation(console, result)
    if result.plans.feasible:
        checked = result.report.checked_steps
        console.print(Text(f"{checked} steps checked, all valid; written to {output}", style="green"))
    else:
        console.print(Text(f"infeasible: {result.plans.reason}; written to {output}", style="red"))
    raise typer.Exit(0 if result.plans.feasible else 1)


def _need_viz() -> None:
    """Say that ``--png`` needs matplotlib before any work is done or anything is written."""
    from cosmop.viz import available

    if not available():
        typer.echo("error: --png needs matplotlib: pip install 'cosmop[viz]'", err=True)
        raise typer.Exit(EXIT_INPUT_ERROR)


def check_engine(workers: int | None, scheduler: str | None) -> None:
    """``--workers`` counts local processes; a cluster has its own workers (usage error, 2).

    Parameters
    ----------
    workers : int or None
        ``--workers``: local processes for the robots' syntheses (None: one per core, at most
        one per robot).
    scheduler : str or None
        ``--scheduler``: the address of a Dask scheduler to run the syntheses on (None: local).
    """
    if workers is not None and scheduler is not None:
        raise typer.BadParameter(
            "local worker processes and a Dask scheduler exclude each other: "
            "the cluster's workers run the syntheses (set them with dask worker --nworkers)",
            param_hint="'--workers'",
        )


def default_budget(loaded: Scenario) -> float:
    """The planning budget of ``cosmop plan`` when none is given: 60 s and 10 s per robot (s).

    A team is planned well within it (50 robots of the MovingAI warehouse map, the largest
    benchmark, take about 300 s of its 560 s on a 2-core machine); it bounds the time spent on
    a team that cannot be planned.

    Parameters
    ----------
    loaded : Scenario
        The scenario planned.
    """
    return 60.0 + 10.0 * len(loaded.scene.robots)


def plan_with_progress(
    loaded: Scenario,
    max_horizon: int | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    budget: float | None = None,
) -> TeamResult:
    """:func:`cosmop.team.loop.plan_team` under a spinner that names each robot as it is planned;
    in local processes, or on the Dask cluster whose scheduler is at `scheduler`.

    Parameters
    ----------
    loaded : Scenario
        The scenario to plan.
    max_horizon : int or None
        The longest plan tried per robot, steps (None: the planner's default).
    workers : int or None
        Local processes for the syntheses (None: one per core, at most one per robot).
    scheduler : str or None
        The address of a Dask scheduler to run the syntheses on (None: local processes).
    budget : float or None
        Seconds the planning may take (:func:`cosmop.team.loop.plan_team`; None: no limit).

    Returns
    -------
    cosmop.team.loop.TeamResult
    """
    from contextlib import nullcontext

    from rich.progress import Progress, SpinnerColumn, TextColumn, TimeElapsedColumn

    from cosmop.team.loop import plan_team

    columns = (SpinnerColumn(), TextColumn("{task.description}"), TimeElapsedColumn())
    with Progress(*columns, console=stderr(), transient=True) as progress:
        task = progress.add_task("planning", total=None)
        engine: AbstractContextManager[Executor | None] = nullcontext(None)
        if scheduler is not None:
            from cosmop.team.cluster import dask_executor

            progress.update(task, description=f"connecting to the Dask scheduler at {scheduler}")
            engine = dask_executor(scheduler, field="--scheduler")
        with engine as executor:
            progress.update(task, description="planning")
            return plan_team(
                loaded,
                max_horizon=max_horizon,
                workers=workers,
                executor=executor,
                on_robot=lambda robot, res: progress.update(
                    task, description=f"planned {robot} ({res.horizon} steps)"
                ),
                budget=budget,
            )


def _print_coordination(console: Console, result: TeamResult) -> None:
    """The formal verdict: coordination pairs, messages, conflicts ordered, and the expected finish."""
    v, safety = result.verification, result.safety
    assert v is not None  # printed for a verified team only
    ordered = ""
    if safety is not None:
        ordered = f"{safety.conflicts} conflict(s) between plans"
        if safety.chosen:  # the orders that went against the robots' own itineraries
            ordered += f", {safety.flipped} of {safety.chosen} orders against the itinerary"
        ordered += ", "
    console.print(
        Text(
            f"formally: coordination: {len(result.plans.coordination)} pair(s), "
            f"{len(result.plans.messages)} message(s) ({ordered}deadlock-free); verification: "
            f"{'holds' if v.holds else 'fails'} ({v.method})",
            style="green" if v.holds else "red",
        )
    )
    itinerary = result.plans.itinerary
    if safety is not None and itinerary is not None and itinerary.makespan > 0:
        console.print(
            Text(
                f"expected time to finish: {itinerary.makespan:.0f} s (each robot alone: at most "
                f"{safety.makespan_alone:.0f} s); the plan file gives every step its expected "
                "start and end"
            )
        )


def _print_allocation(console: Console, result: TeamResult) -> None:
    """Which robot moves each good, and the cost of that choice."""
    choice = result.allocation
    assert choice is not None  # printed when the mission left a choice only
    moved = ", ".join(f"{o} by {r}" for o, r in result.plans.allocation.items()) or "nothing moved"
    proof = "the best" if choice.exhaustive else "the best found within the search bound"
    console.print(
        Text(
            f"allocation: {moved}; cost: longest {choice.makespan} steps, {choice.total} in all "
            f"({proof}; {choice.method}, {choice.considered} compared)"
        )
    )


def _plan_table(scenario: Scenario, result: TeamResult) -> Table:
    """One row per robot: its plan's steps, K (the shortest plan), requests, answers, messages."""
    table = Table(title=Text(f"plans for {scenario.name}"), header_style="bold")
    for column in ("robot", "feasible", "steps", "K", "requests", "answers", "msgs out/in", "solve"):
        table.add_column(column)
    for robot, res in result.results.items():
        plan = result.plans.robots.get(robot)
        answers = [c.object + " to " + c.requester for c in result.plans.coordination if c.responder == robot]
        sent = sum(1 for s in plan.steps if s.message is not None and s.primitive == "Res") if plan else 0
        awaited = sum(1 for s in plan.steps if s.message is not None and s.primitive == "Req") if plan else 0
        table.add_row(
            robot,
            "yes" if res.feasible else Text("no", style="red"),
            str(plan.horizon) if plan is not None else "-",
            str(res.horizon) if res.horizon is not None else "-",
            Text(", ".join(res.requests) or "-"),
            Text(", ".join(answers) or "-"),
            f"{sent}/{awaited}" if sent or awaited else "-",
            f"{res.solve_s:.2f} s",
        )
    return table
