"""``cosmop validate``: check a scenario file and summarise it in a table."""

from __future__ import annotations

from rich.table import Table
from rich.text import Text

from cosmop.cli._app import ScenarioArgument, load, stdout
from cosmop.scene import Scenario
from cosmop.units import show_length

__all__ = ["validate"]


def validate(scenario: ScenarioArgument) -> None:
    """Check a scenario file and summarise it."""
    loaded = load(scenario)
    console = stdout()
    console.print(_summary_table(loaded))
    console.print(Text(f"{scenario}: valid", style="green"))


def _summary_table(scenario: Scenario) -> Table:
    """A table with one row per part of the scenario."""
    scene, mission = scenario.scene, scenario.mission
    table = Table(title=Text(f"scenario {scenario.name}"), show_header=True, header_style="bold")
    table.add_column("part")
    table.add_column("count", justify="right")
    table.add_column("details")

    def row(part: str, count: int, details: str) -> None:
        table.add_row(part, str(count), Text(details))  # Text: ids are data, never markup

    sizes = (f"{r.id} (size {show_length(r.size, scenario.units)})" for r in scene.robots.values())
    row("robots", len(scene.robots), ", ".join(sizes))
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
