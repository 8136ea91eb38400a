"""``cosmop decompose``: local missions by natural projection, and the proof that they add up."""

from __future__ import annotations

import json
from enum import StrEnum
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.console import Console
from rich.table import Table
from rich.text import Text

from cosmop.automata import DFA
from cosmop.cli._app import ScenarioArgument, load, stderr, stdout
from cosmop.cli.words import decompose_verdict
from cosmop.io import check_writable, write_atomic
from cosmop.missions.decomposition import Decomposition, Resynthesis
from cosmop.missions.decomposition import decompose as run_decompose
from cosmop.missions.mission import GlobalMission, sequence_of
from cosmop.missions.verification import Verification
from cosmop.missions.verification import verify as run_verify
from cosmop.scene import Scenario
from cosmop.team.mission_proof import TeamVerdict, verify_team

__all__ = ["Method", "decompose"]


class Method(StrEnum):
    """How ``decompose`` verifies the local missions."""

    auto = "auto"
    assume_guarantee = "assume-guarantee"
    direct = "direct"


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

    Parameters
    ----------
    scenario : pathlib.Path
        The scenario file (YAML).
    as_json : bool
        ``--json``: print one JSON object instead of tables.
    method : Method
        ``--method``: verify by assume-guarantee reasoning with L*, by direct inclusion, or
        choose automatically.
    dot : pathlib.Path or None
        ``--dot``: also write each local mission as Graphviz DOT into this directory.
    verbose : bool
        ``--verbose``: also print the verification's statistics.
    """
    loaded = load(scenario)
    assert loaded.mission is not None  # load() refuses a file without one
    check_writable(dot, "--dot", folder=True)
    if loaded.mission.deliveries is not None:
        _refuse_deliveries(scenario)
    result, verification, team = _decompose_and_verify(GlobalMission.from_scenario(loaded), method)
    names = _write_dot(dot, result, tell_stderr=as_json) if dot is not None else ""
    holds = team.holds if team is not None else verification.holds
    ok = (result.separable or result.messaging is not None) and holds
    if as_json:
        typer.echo(json.dumps(_as_json(result, verification, team, holds), indent=2))
        raise typer.Exit(0 if ok else 1)
    console = stdout()
    verdict, good = decompose_verdict(result, verification, holds)
    console.print(Text(verdict, style="green" if good else "red"))
    _print_local_missions(console, loaded, result, verbose)
    _print_verification(console, verification, team, holds, verbose)
    if dot is not None:
        console.print(Text(f"wrote the local missions as Graphviz DOT to {dot}/: {names}"))
    raise typer.Exit(0 if ok else 1)


def _refuse_deliveries(scenario: Path) -> None:
    """A deliveries mission leaves open which robot moves each good: no split exists before a choice."""
    stdout().print(
        Text(
            "not separable as written: a deliveries mission leaves open which robot moves each good; "
            f"`cosmop plan {scenario}` chooses, then decomposes and verifies the chosen missions",
            style="yellow",
        )
    )
    raise typer.Exit(1)


def _decompose_and_verify(
    mission: GlobalMission, method: Method
) -> tuple[Decomposition, Verification, TeamVerdict | None]:
    """The decomposition, its verification and, for robots ordered by messages, the team's proof."""
    team = None
    with stderr().status("decomposing by natural projection ...", spinner="dots") as status:
        result = run_decompose(mission)
        status.update("verifying (assume-guarantee) ...")
        if result.messaging is not None:  # the robots ordered by messages: verify them with their messages
            team = verify_team(mission, result.messaging.words, method=method.value)
            verification = (
                team.safety if team.safety is not None else run_verify(mission, result.local_missions)
            )
        else:
            verification = run_verify(mission, result.local_missions, method=method.value)
    return result, verification, team


def _write_dot(dot: Path, result: Decomposition, tell_stderr: bool) -> str:
    """Write each local mission as ``<robot>.dot``; the file names, for the closing line."""
    dot.mkdir(parents=True, exist_ok=True)
    for robot, dfa in result.local_missions.items():
        write_atomic(dot / f"{robot}.dot", dfa.to_dot(f"K_{robot}"))
    names = ", ".join(f"{robot}.dot" for robot in result.local_missions)
    if tell_stderr:  # with --json, stdout is the JSON alone
        typer.echo(f"wrote the local missions as Graphviz DOT to {dot}/: {names}", err=True)
    return names


def _as_json(
    result: Decomposition, verification: Verification, team: TeamVerdict | None, holds: bool
) -> dict[str, Any]:
    """The ``--json`` answer: the decomposition with its verification (and the team's proof)."""
    checked = verification.to_dict() | {"holds": holds}
    if team is not None:
        checked |= {
            "deadlock_free": team.blocking is None,
            "complete": None if team.completion is None else team.completion.to_dict(),
            "counterexample": None if team.counterexample is None else list(team.counterexample),
        }
    return result.to_dict() | {"verification": checked}


def _sequence_text(dfa: DFA) -> str:
    """A local mission as ``a -> b -> c`` when it is one sequence, else its size."""
    seq = sequence_of(dfa)
    if seq is None:
        return f"{dfa.n_states} states, {dfa.n_transitions} transitions"
    return " -> ".join(seq) if seq else "(no events)"


def _print_local_missions(console: Console, loaded: Scenario, result: Decomposition, verbose: bool) -> None:
    """The table of local missions, separability, and what ordering or re-synthesis changed."""
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
        _print_resynthesis(console, result.resynthesis)


def _print_resynthesis(console: Console, rs: Resynthesis) -> None:
    """Whether the paper's re-synthesis converged, and each robot's lost events."""
    console.print(
        Text(
            f"re-synthesis: {'sound' if rs.converged else 'did not converge'} after {rs.iterations} "
            f"counterexample(s)"
        )
    )
    for robot, events in rs.lost_events.items():
        if events:
            console.print(Text(f"  {robot} can no longer perform: {', '.join(events)}", style="yellow"))


def _print_verification(
    console: Console, v: Verification, team: TeamVerdict | None, holds: bool, verbose: bool
) -> None:
    """The verification's verdict (statistics with ``--verbose``) and the violation, if any."""
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
