"""The ``cosmop`` command line.

The library is silent; this module is the friendly layer. Errors in the user's input
(:class:`~cosmop.errors.CosmopInputError`) are printed as one line, ``error: <message>``, on
standard error, and the command exits with status 2 -- the same status as a usage error. Other
exit statuses: 0 for success, 1 for a well-formed problem without a solution (e.g. an infeasible
scenario).

To add a command, write a thin function decorated with ``@app.command()`` that loads its input
with :func:`_load` and leaves the work to the library; input errors need no handling there.
"""

from __future__ import annotations

import json
import sys
from enum import StrEnum
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.console import Console
from rich.table import Table
from rich.text import Text
from typer.core import TyperGroup

from cosmop import __version__
from cosmop.automata import DFA
from cosmop.cli_words import decompose_verdict, plan_verdict
from cosmop.errors import CosmopInputError, EventSyntaxError
from cosmop.io import check_writable, uninterrupted, write_atomic
from cosmop.missions.decomposition import decompose as run_decompose
from cosmop.missions.mission import GlobalMission, sequence_of
from cosmop.missions.team import verify_team
from cosmop.missions.verification import verify as run_verify
from cosmop.planning.checker import check_plan
from cosmop.planning.plan import MAX_STEPS, load_plan
from cosmop.scenario import Scenario, load_scenario

__all__ = ["EXIT_INPUT_ERROR", "app", "main"]

EXIT_INPUT_ERROR = 2
"""Exit status for bad input (also the status of command-line usage errors)."""


class _Group(TyperGroup):
    """Command group that turns input errors into one line on stderr and exit status 2.

    Input errors are :class:`~cosmop.errors.CosmopInputError` (bad files) and
    :class:`~cosmop.errors.EventSyntaxError` (an event typed on the command line); a file the
    system refuses to write (:class:`OSError`, e.g. a full disk) is reported the same way.
    Ctrl-C ends with one line and status 130 (128 + SIGINT), as shells expect.
    """

    def invoke(self, ctx: typer.Context) -> Any:
        try:
            return super().invoke(ctx)
        except (CosmopInputError, EventSyntaxError) as err:
            # plain echo, not rich: field paths such as tasks.R1[0] must not be read as markup
            typer.echo(f"error: {err}", err=True)
            raise typer.Exit(EXIT_INPUT_ERROR) from None
        except OSError as err:
            where = f"{err.filename}: " if err.filename else ""
            typer.echo(f"error: {where}{err.strerror or err}", err=True)
            raise typer.Exit(EXIT_INPUT_ERROR) from None
        except KeyboardInterrupt:
            typer.echo("interrupted", err=True)
            raise typer.Exit(130) from None


app = typer.Typer(
    cls=_Group,
    name="cosmop",
    help="Cooperative multi-robot mission and motion planning with formal guarantees.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_show_locals=False,
)


def _version_callback(value: bool) -> None:
    if value:
        typer.echo(f"cosmop {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: Annotated[
        bool,
        typer.Option(
            "--version", callback=_version_callback, is_eager=True, help="Print the version and exit."
        ),
    ] = False,
) -> None:
    """Cooperative multi-robot mission and motion planning with formal guarantees."""


def _stdout() -> Console:
    """A console on the current standard output (looked up late, so test runners can capture it)."""
    return Console(file=sys.stdout, highlight=False)


def _load(path: Path) -> Scenario:
    """Load a scenario for a command; a bad file raises ScenarioError, reported by the group."""
    return load_scenario(path)


ScenarioArgument = Annotated[
    Path, typer.Argument(metavar="SCENARIO", help="Scenario file (YAML).", show_default=False)
]


@app.command()
def validate(scenario: ScenarioArgument) -> None:
    """Check a scenario file and summarise it."""
    loaded = _load(scenario)
    console = _stdout()
    console.print(_summary_table(loaded))
    console.print(Text(f"{scenario}: valid", style="green"))


class Method(StrEnum):
    """How ``decompose`` verifies the local missions."""

    auto = "auto"
    assume_guarantee = "assume-guarantee"
    direct = "direct"


def _sequence_text(dfa: DFA) -> str:
    """A local mission as ``a -> b -> c`` when it is one sequence, else its size."""
    seq = sequence_of(dfa)
    if seq is None:
        return f"{dfa.n_states} states, {dfa.n_transitions} transitions"
    return " -> ".join(seq) if seq else "(no events)"


@app.command()
def decompose(
    scenario: ScenarioArgument,
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object instead of tables.")] = False,
    method: Annotated[
        Method, typer.Option(help="Verification: assume-guarantee with L*, direct inclusion, or auto.")
    ] = Method.auto,
    dot: Annotated[
        Path | None,
        typer.Option(
            help="Also write each local mission as Graphviz DOT into this DIRECTORY.", show_default=False
        ),
    ] = None,
    verbose: Annotated[
        bool, typer.Option("--verbose", "-v", help="Also print the verification's statistics.")
    ] = False,
) -> None:
    """Decompose the global mission into local missions and verify them (paper, Section III).

    Exit status 0 when the mission is separable and the local missions are proven to satisfy it,
    1 when it is not (the counterexample and the re-synthesised local missions are shown), 2 on
    bad input.
    """
    loaded = _load(scenario)
    check_writable(dot, "--dot", folder=True)
    err = Console(file=sys.stderr, highlight=False)
    if loaded.mission.deliveries is not None:
        # any allowed robot may move each good: no split into robots exists before a choice
        _stdout().print(
            Text(
                "not separable as written: a deliveries mission leaves open which robot moves each good; "
                f"`cosmop plan {scenario}` chooses, then decomposes and verifies the chosen missions",
                style="yellow",
            )
        )
        raise typer.Exit(1)
    mission = GlobalMission.from_scenario(loaded)
    team = None
    with err.status("decomposing by natural projection ...", spinner="dots") as status:
        result = run_decompose(mission)
        status.update("verifying (assume-guarantee) ...")
        if result.messaging is not None:  # the robots ordered by messages: verify them with their messages
            team = verify_team(mission, result.messaging.words, method=method.value)
            verification = (
                team.safety if team.safety is not None else run_verify(mission, result.local_missions)
            )
        else:
            verification = run_verify(mission, result.local_missions, method=method.value)
    if dot is not None:
        dot.mkdir(parents=True, exist_ok=True)
        for robot, dfa in result.local_missions.items():
            write_atomic(dot / f"{robot}.dot", dfa.to_dot(f"K_{robot}"))
        names = ", ".join(f"{robot}.dot" for robot in result.local_missions)
        if as_json:  # stdout is the JSON alone
            typer.echo(f"wrote the local missions as Graphviz DOT to {dot}/: {names}", err=True)
    holds = team.holds if team is not None else verification.holds
    ok = (result.separable or result.messaging is not None) and holds
    if as_json:
        checked = verification.to_dict() | {"holds": holds}
        if team is not None:
            checked |= {
                "deadlock_free": team.blocking is None,
                "complete": None if team.completion is None else team.completion.to_dict(),
                "counterexample": None if team.counterexample is None else list(team.counterexample),
            }
        data = result.to_dict() | {"verification": checked}
        typer.echo(json.dumps(data, indent=2))
        raise typer.Exit(0 if ok else 1)
    console = _stdout()
    verdict, good = decompose_verdict(result, verification, holds)
    console.print(Text(verdict, style="green" if good else "red"))
    table = Table(title=Text(f"local missions of {loaded.name}"), header_style="bold")
    for column in ("robot", "events", "states", "local mission K_i = P_i(K)"):
        table.add_column(column)
    for robot, dfa in result.local_missions.items():
        table.add_row(robot, str(len(result.alphabets[robot])), str(dfa.n_states), Text(_sequence_text(dfa)))
    console.print(table)
    stats = result.stats
    details = (
        f"   (largest automaton {stats.largest_automaton} states, {stats.total_s:.3f} s)" if verbose else ""
    )
    console.print(Text(f"formally: separable: {'yes' if result.separable else 'no'} (||_i K_i = K){details}"))
    if result.counterexample is not None:
        console.print(Text(f"counterexample: {' '.join(result.counterexample)}", style="red"))
    if result.messaging is not None:
        console.print(
            Text(f"ordered by {len(result.messaging.messages)} message(s) instead of removing tasks:")
        )
        for entry in result.messaging.to_dict():
            console.print(
                Text(
                    f"  {entry['event']}: {entry['receiver']} waits before {entry['before']} "
                    f"until {entry['sender']} has done {entry['after']}"
                )
            )
    if result.resynthesis is not None:
        rs = result.resynthesis
        console.print(
            Text(
                f"re-synthesis: {'sound' if rs.converged else 'did not converge'} after {rs.iterations} "
                f"counterexample(s)"
            )
        )
        for robot, events in rs.lost_events.items():
            if events:
                console.print(Text(f"  {robot} can no longer perform: {', '.join(events)}", style="yellow"))
    v = verification
    sizes = ", ".join(str(a.assumption.n_states if a.assumption else 0) for a in v.assumptions) or "-"
    details = (
        f"; {v.membership_queries} membership / {v.equivalence_queries} equivalence queries; "
        f"assumption sizes {sizes}; largest automaton {v.largest_automaton}; {v.time_s:.3f} s"
        if verbose
        else ""
    )
    console.print(
        Text(
            f"verification: {'holds' if holds else 'fails'} ({v.method}{details})",
            style="green" if holds else "red",
        )
    )
    violation = team.reason() if team is not None else None
    if violation is None and v.counterexample is not None:
        violation = " ".join(v.counterexample)
    if violation is not None:
        console.print(Text(f"violation: {violation}", style="red"))
    if dot is not None:
        console.print(Text(f"wrote the local missions as Graphviz DOT to {dot}/: {names}"))
    raise typer.Exit(0 if ok else 1)


@app.command()
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
    """
    loaded = _load(scenario)
    plans = load_plan(plan)
    report = check_plan(loaded, plans)
    if as_json:
        typer.echo(json.dumps(report.to_dict(), indent=2))
        raise typer.Exit(0 if report.ok else 1)
    console = _stdout()
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


@app.command()
def plan(
    scenario: ScenarioArgument,
    output: Annotated[
        Path,
        typer.Option("-o", "--output", help="Plan file to write (cosmop.plan/1 JSON).", show_default=False),
    ],
    png: Annotated[
        Path | None, typer.Option(help="Also draw the scene and the plans into this PNG.", show_default=False)
    ] = None,
    max_horizon: Annotated[
        int | None,
        typer.Option(
            help="Longest plan tried per robot (steps) [default: 16, or 3 per mission event + 6 if more]",
            min=0,
            max=MAX_STEPS,
            show_default=False,
        ),
    ] = None,
) -> None:
    """Plan, coordinate and verify the team (paper, Fig. "Overall framework").

    Each robot's shortest safe sequence of motion primitives is synthesised; every request
    (Req) becomes an ``away(O, requester, responder)`` pair placed so that the team cannot
    deadlock; the robots whose missions changed are re-planned; the coordinated missions are
    verified against the global mission, and every plan passes the exact checker before it is
    written.  The file is written even when infeasible (``"feasible": false`` and a reason).
    Exit status 0 feasible, 1 infeasible, 2 bad input.
    """
    from rich.progress import Progress, SpinnerColumn, TextColumn, TimeElapsedColumn

    from cosmop.pipeline import plan_team

    loaded = _load(scenario)
    check_writable(output, "-o")
    check_writable(png, "--png")
    if png is not None:
        from cosmop.viz import available

        if not available():  # say so before any work is done or anything is written
            typer.echo("error: --png needs matplotlib: pip install 'cosmop[viz]'", err=True)
            raise typer.Exit(EXIT_INPUT_ERROR)
    err = Console(file=sys.stderr, highlight=False)
    with Progress(
        SpinnerColumn(),
        TextColumn("{task.description}"),
        TimeElapsedColumn(),
        console=err,
        transient=True,
    ) as progress:
        task = progress.add_task("planning", total=None)
        result = plan_team(
            loaded,
            max_horizon=max_horizon,
            on_robot=lambda robot, res: progress.update(
                task, description=f"planned {robot} ({res.horizon} steps)"
            ),
        )
    result.plans.save(output)
    if png is not None:
        from cosmop.viz import save_plan_png

        save_plan_png(loaded.scene, result.plans, png)
    console = _stdout()
    console.print(_plan_table(loaded, result))
    if result.plans.feasible:
        console.print(Text(plan_verdict(result.plans, result.verification), style="green"))
    if result.verification is not None:
        v = result.verification
        safety = result.safety
        ordered = f"{safety.conflicts} conflict(s) between plans, " if safety is not None else ""
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
    if result.allocation is not None and result.allocation.alternative is not None:
        choice = result.allocation
        moved = ", ".join(f"{o} by {r}" for o, r in result.plans.allocation.items()) or "nothing moved"
        proof = "the best" if choice.exhaustive else "the best found within the search bound"
        console.print(
            Text(
                f"allocation: {moved}; cost: longest {choice.makespan} steps, {choice.total} in all "
                f"({proof}; {choice.method}, {choice.considered} compared)"
            )
        )
    if result.plans.feasible:
        console.print(
            Text(
                f"{result.report.checked_steps} steps checked, all valid; written to {output}", style="green"
            )
        )
    else:
        console.print(Text(f"infeasible: {result.plans.reason}; written to {output}", style="red"))
    raise typer.Exit(0 if result.plans.feasible else 1)


@app.command()
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
    seed: Annotated[int, typer.Option(help="Seed of the people's random walks.")] = 0,
    summary: Annotated[
        Path | None, typer.Option(help="Write the summary (cosmop.sim/1 JSON) here.", show_default=False)
    ] = None,
    trace: Annotated[
        Path | None,
        typer.Option(help="Write the trace, every cycle (cosmop.trace/1 JSON).", show_default=False),
    ] = None,
    gif: Annotated[Path | None, typer.Option(help="Write an animation (GIF).", show_default=False)] = None,
    mp4: Annotated[Path | None, typer.Option(help="Write an animation (MP4).", show_default=False)] = None,
    speed: Annotated[
        float | None,
        typer.Option(
            help="Animation: simulated seconds per second [default: the run lasts at most 45 s]", min=1e-3
        ),
    ] = None,
    size: Annotated[
        int | None, typer.Option(help="Animation width in pixels [default: about 790]", min=100)
    ] = None,
    bag: Annotated[
        Path | None,
        typer.Option(help="Write a ROS 2 bag DIRECTORY (MCAP; the ros extra).", show_default=False),
    ] = None,
    max_time: Annotated[float, typer.Option(help="Simulated seconds before giving up.", min=1.0)] = 900.0,
    replan: Annotated[bool, typer.Option(help="Stalled robots replan their remaining mission.")] = True,
) -> None:
    """Execute the plans: passive-safe DWA, docking, messages, people walking through.

    Every cycle each robot drives (GoTo), docks (PickUp, DropOff), waits for an answer (Req) or
    sends one (Res); a monitor records every contact and whether the robot was moving then.
    Exit status 0 when every robot finished with no contact while moving, 1 otherwise, 2 on bad
    input.
    """
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    from cosmop.planning.plan import PlanSet
    from cosmop.sim import SimSettings
    from cosmop.sim import simulate as run_simulate

    loaded = _load(scenario)
    for option, path in (("--summary", summary), ("--trace", trace), ("--gif", gif), ("--mp4", mp4)):
        check_writable(path, option)
    for path, check_video in ((gif, False), (mp4, True)):
        if path is None:
            continue
        from cosmop.viz import available, video_available

        if not available() or (check_video and not video_available()):  # before any work
            extra = "video" if check_video else "viz"
            typer.echo(f"error: --{path.suffix[1:]} needs pip install 'cosmop[{extra}]'", err=True)
            raise typer.Exit(EXIT_INPUT_ERROR)
    if bag is not None:
        _cli_ecosystem.check_bag_target(bag)  # before any work
    err = Console(file=sys.stderr, highlight=False)
    if plan_file is not None:
        plans: PlanSet = load_plan(plan_file)
        report = check_plan(loaded, plans)
        if not plans.feasible or not report.ok:
            why = plans.reason if not plans.feasible else report.violations[0].message
            typer.echo(
                f"error: {plan_file}: expected a feasible plan valid for {loaded.name}: {why}", err=True
            )
            raise typer.Exit(EXIT_INPUT_ERROR)
    else:
        from cosmop.pipeline import plan_team

        with Progress(TextColumn("planning"), TimeElapsedColumn(), console=err, transient=True) as progress:
            progress.add_task("planning", total=None)
            plans = plan_team(loaded).plans
        if not plans.feasible:
            _stdout().print(Text(f"infeasible: {plans.reason}", style="red"))
            raise typer.Exit(1)
    settings = SimSettings(max_time=max_time, replan=replan)
    with Progress(
        TextColumn("simulating"),
        BarColumn(),
        TextColumn("{task.fields[done]}/{task.fields[robots]} robots done, t = {task.completed:.0f} s"),
        TimeElapsedColumn(),
        console=err,
        transient=True,
    ) as progress:
        task = progress.add_task("simulating", total=max_time, done=0, robots=len(loaded.scene.robots))
        result = run_simulate(
            loaded,
            plans,
            seed=seed,
            settings=settings,
            on_cycle=lambda t, done, robots: progress.update(task, completed=t, done=done),
        )
    with uninterrupted():  # the trace and its summary: both or neither
        if trace is not None:
            result.save_trace(trace)
        if summary is not None:
            result.save_summary(summary)
    if bag is not None:
        _cli_ecosystem.write_bag_and_report(loaded.scene, result.trace(), bag, plans, None, 5.0)
    for path in (gif, mp4):
        if path is not None:
            from cosmop.viz import save_animation

            with Progress(
                TextColumn(f"drawing {path.name}"), TimeElapsedColumn(), console=err, transient=True
            ) as p:
                p.add_task("drawing", total=None)
                save_animation(loaded.scene, result.trace(), path, plans=plans, speed=speed, size=size)
    console = _stdout()
    table = Table(title=Text(f"simulation of {loaded.name} (seed {seed})"), header_style="bold")
    for column in ("robot", "pose [mm, deg]", "distance", "finished", "done at (planned)"):
        table.add_column(column)
    finished = result.finished
    for rid, (pose, dist) in result.robots.items():
        table.add_row(
            rid,
            f"{pose[0]:.0f}, {pose[1]:.0f}, {pose[2]:.0f}",
            f"{dist / 1000:.1f} m",
            "yes" if finished[rid] else Text("no", style="red"),
            _done_at(result.steps.get(rid, ()), finished[rid]),
        )
    console.print(table)
    delivered = result.objects_in_workspaces(loaded, plans)
    ok = result.completed and result.contacts_while_moving == 0
    speed = result.sim_time_s / max(result.wall_time_s, 1e-9)
    planned = result.makespan["planned"]
    console.print(
        Text(
            f"{'completed' if result.completed else 'not completed'} in {result.sim_time_s:.1f} s simulated "
            + (f"(planned {planned:.1f} s; " if planned is not None else "(")
            + f"{result.wall_time_s:.1f} s, {speed:.0f}x real time); "
            f"objects in place {sum(delivered.values())}/{len(delivered)}; contacts {len(result.contacts)}, "
            f"while moving {result.contacts_while_moving}; messages {len(result.messages)}; "
            f"replans {result.replans}",
            style="green" if ok else "red",
        )
    )
    raise typer.Exit(0 if ok else 1)


def _done_at(rows, finished: bool) -> str:
    """When a robot ended its plan in the run, and when its itinerary expected it: ``64.7 s (46.1 s)``."""
    realised = rows[-1].realised[1] if finished and rows and rows[-1].realised else None
    planned = max((r.planned[1] for r in rows if r.planned is not None), default=None)
    done = f"{realised:.1f} s" if realised is not None else "-"
    return f"{done} ({planned:.1f} s)" if planned is not None else done


def _plan_table(scenario: Scenario, result) -> Table:
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


def _summary_table(scenario: Scenario) -> Table:
    """A table with one row per part of the scenario."""
    scene, mission = scenario.scene, scenario.mission
    table = Table(title=Text(f"scenario {scenario.name}"), show_header=True, header_style="bold")
    table.add_column("part")
    table.add_column("count", justify="right")
    table.add_column("details")

    def row(part: str, count: int, details: str) -> None:
        table.add_row(part, str(count), Text(details))  # Text: ids are data, never markup

    row("robots", len(scene.robots), ", ".join(f"{r.id} (size {r.size:g} mm)" for r in scene.robots.values()))
    row("objects", len(scene.objects), ", ".join(scene.objects) or "-")
    row(
        "workspaces",
        len(scene.workspaces),
        ", ".join(f"{w.id} ({'point' if w.is_point else 'rectangle'})" for w in scene.workspaces.values())
        or "-",
    )
    row("walls", len(scene.obstacles), "wall segments")
    events = mission.events
    if mission.tasks is not None:
        steps = sum(len(seq) for seq in mission.tasks.values())
        row(
            "mission",
            len(events),
            f"tasks: {steps} steps for {len(mission.tasks)} robots, {len(events)} events",
        )
    elif mission.dfa is not None:
        dfa = mission.dfa
        row(
            "mission",
            len(events),
            f"dfa: {len(dfa.states)} states, {len(dfa.transitions)} transitions, "
            f"{len(dfa.marked)} marked, {len(events)} events",
        )
    else:
        deliveries = mission.deliveries
        choices = sum(len(d.to) * len(d.by) for d in deliveries)
        movers = sorted({r for d in deliveries for r in d.by})
        row(
            "mission",
            len(events),
            f"deliveries: {len(deliveries)} objects, {choices} (robot, workspace) choices, "
            f"robots {', '.join(movers)}{', return' if mission.returns else ''}; {len(events)} events",
        )
    row("complete", *_completion(mission))
    return table


def _completion(mission) -> tuple[int, str]:
    """Where the mission is complete: the count and the words for the summary's row."""
    if mission.tasks is not None:
        return len(mission.tasks), "when every robot's task list is done"
    if mission.deliveries is not None:
        home = " and every robot that moved something is home" if mission.returns else ""
        return len(mission.deliveries), f"when every object is in one of its workspaces{home}"
    done = mission.dfa.complete_states
    why = "the marked states" if mission.dfa.marked_given else "the states with no outgoing event"
    return len(done), f"in {', '.join(done)} ({why})"


def main() -> None:
    """Run the command line (``python -m cosmop``), with the program name ``cosmop``."""
    app(prog_name="cosmop")


# The ecosystem commands (import-map, export, view) live in their own module and register on `app`.
from cosmop import cli_ecosystem as _cli_ecosystem  # noqa: E402
