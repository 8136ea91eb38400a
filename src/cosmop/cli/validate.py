"""``cosmop validate``: check a scenario file and summarise it in a table."""

from __future__ import annotations

from collections.abc import Iterable

from rich.table import Table
from rich.text import Text

from cosmop.cli._app import ScenarioArgument, load, stdout
from cosmop.scene import Dynamics, Human, Mission, Robot, Scenario
from cosmop.units import (
    UnitSystem,
    length_unit,
    plain,
    show_angle,
    show_length,
    show_number,
    show_point,
    show_speed,
)

__all__ = ["validate"]


def validate(scenario: ScenarioArgument) -> None:
    """Check a scenario file and summarise it: robots and their speed limits, objects,
    workspaces, walls, people walking through, the mission and when it is complete.

    Parameters
    ----------
    scenario : pathlib.Path
        The scenario file (YAML).
    """
    loaded = load(scenario, mission=False)
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

    def row(part: str, count: int | str, details: str) -> None:
        table.add_row(part, str(count), Text(details))  # Text: ids are data, never markup

    sizes = (f"{r.id} (size {show_length(r.size, scenario.units)})" for r in scene.robots.values())
    row("robots", len(scene.robots), ", ".join(sizes))
    row("dynamics", "", _dynamics(scene.robots.values(), scenario.units))
    row("objects", len(scene.objects), ", ".join(scene.objects) or "-")
    row(
        "workspaces",
        len(scene.workspaces),
        ", ".join(f"{w.id} ({'point' if w.is_point else 'rectangle'})" for w in scene.workspaces.values())
        or "-",
    )
    row("walls", len(scene.obstacles), "wall segments")
    people = [_person(h, scenario.units) for h in scene.humans.values()]
    row("people", len(people), "\n".join(people) or "no people")
    if scenario.orders:
        row("orders", len(scenario.orders), _orders(scenario))
    if mission is None:
        row("mission", "-", "none: the orders are served by a lifelong run (cosmop run)")
        return table
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
        assert deliveries is not None  # neither tasks nor a dfa: deliveries
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


def _orders(scenario: Scenario) -> str:
    """The order stream in a line: how many, over what time, for which goods and docks."""
    orders = scenario.orders
    first, last = orders[0].at, orders[-1].at
    docks = sorted({w for o in orders for w in o.to})
    return (
        f"released from {first:g} s to {last:g} s, {len({o.object for o in orders})} goods, "
        f"to {', '.join(docks)}"
    )


def _completion(mission: Mission) -> tuple[int, str]:
    """Where the mission is complete: the count and the words for the summary's row."""
    if mission.tasks is not None:
        return len(mission.tasks), "when every robot's task list is done"
    if mission.deliveries is not None:
        home = " and every robot that moved something is home" if mission.returns else ""
        return len(mission.deliveries), f"when every object is in one of its workspaces{home}"
    dfa = mission.dfa
    assert dfa is not None  # neither tasks nor deliveries: a dfa
    done = dfa.complete_states
    why = "the marked states" if dfa.marked_given else "the states with no outgoing event"
    return len(done), f"in {', '.join(done)} ({why})"


_LIMITS = (  # Dynamics field, its words
    ("max_speed", "top speed"),
    ("acceleration", "acceleration"),
    ("braking", "braking"),
    ("turn_rate", "turning"),
    ("cycle", "control cycle"),
)


def _limit(dynamics: Dynamics, field: str, units: UnitSystem) -> str:
    """One limit in the file's units: m/s, m/s^2 and rad/s for a metres file."""
    value = getattr(dynamics, field)
    if field == "max_speed":
        return show_speed(value, units)
    if field in ("acceleration", "braking"):
        return f"{show_speed(value, units)}^2"
    if field == "turn_rate":
        return f"{show_angle(value, units)}/s"
    return f"{plain(value)} s"


def _dynamics(robots: Iterable[Robot], units: UnitSystem) -> str:
    """The limits the robots drive by, one line per set of robots that share them.

    Parameters
    ----------
    robots : iterable of Robot
        With their limits in mm/s, mm/s^2, degrees/s and s (``Robot.dynamics``).
    units : {"mm", "m"}
        The file's units, which the limits are shown in.

    Returns
    -------
    str
        ``defaults: top speed 750 mm/s, ...`` when the file sets none; otherwise the limits
        the file sets first, then the defaults of the others; one line per set of robots
        that share their limits, each led by their ids, when they differ.
    """
    groups: dict[Dynamics, list[Robot]] = {}  # robots that share their limits share a line
    for robot in robots:
        groups.setdefault(robot.dynamics, []).append(robot)
    default = Dynamics()
    lines = []
    for dynamics, members in groups.items():
        # a limit equal to the default is shown as a default, whether or not the file wrote it
        parts: dict[bool, list[str]] = {True: [], False: []}
        for field, words in _LIMITS:
            given = getattr(dynamics, field) != getattr(default, field)
            parts[given].append(f"{words} {_limit(dynamics, field, units)}")
        text = f"defaults: {', '.join(parts[False])}"
        if parts[True]:
            text = f"{', '.join(parts[True])} (set in the file)" + (f"; {text}" if parts[False] else "")
        who = f"{', '.join(r.id for r in members)}: " if len(groups) > 1 else ""
        lines.append(who + text)
    return "\n".join(lines)


def _person(human: Human, units: UnitSystem) -> str:
    """How one person walks, in plain words.

    Parameters
    ----------
    human : Human
        Size in mm, speed in mm/s, path points in mm with dwell times in s.
    units : {"mm", "m"}
        The file's units, which lengths and speeds are shown in.

    Returns
    -------
    str
        ``H1, 400 mm wide, walks at 600 mm/s: a route of 3 points once, then ...``
    """
    head = f"{human.id}, {show_length(human.size, units)} wide, walks at {show_speed(human.speed, units)}"
    area = ""
    if human.walk is not None:
        (x0, x1), (y0, y1) = (tuple(show_number(v, units) for v in axis) for axis in human.walk)
        area = f"at random in x [{x0}, {x1}], y [{y0}, {y1}] {length_unit(units)}"
    if len(human.path) == 1:  # only a start point: the loader made sure a walk area is given
        return f"{head}: from {show_point(human.path[0][:2], units)} {area}"
    stops = [dwell for *_, dwell in human.path if dwell > 0]
    notes = []
    if len(stops) == 1:
        notes.append(f"stopping {plain(stops[0])} s")
    elif stops:
        notes.append(f"stopping at {len(stops)} of them, {plain(sum(stops))} s in all")
    if human.loop and area:  # a looping route never ends, so its walk area is never reached
        notes.append("its walk area is never used")
    route = f"a route of {len(human.path)} points {'over and over' if human.loop else 'once'}"
    route += f" ({'; '.join(notes)})" if notes else ""
    return f"{head}: {route}" if human.loop else f"{head}: {route}, then {area or 'stands at its end'}"
