"""Building a :class:`~cosmop.scene.Scenario` from a parsed scenario file, with every check
that names the file, the field and what was expected (structure, references, units, grid,
physically possible bodies, reachable mission states)."""

from __future__ import annotations

import math
import os
import re
from collections import Counter
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import replace
from fractions import Fraction
from pathlib import Path
from typing import Any, NoReturn

from pydantic import BaseModel, ValidationError
from pydantic_core import ErrorDetails

from cosmop.errors import EventSyntaxError, InputWarning, ScenarioError
from cosmop.events import ID_PATTERN, MESSAGE_KINDS, Event, parse_event
from cosmop.io import read_text
from cosmop.reading import UNPRINTABLE, FieldPath, Marks, Structure, format_path, load_yaml, lookup, show
from cosmop.scenario.plausible import implausible, out_of_range
from cosmop.scenario.schema import (
    EXPECTED,
    MAX_DFA_STATES,
    RANGE,
    SCENARIO_VERSION,
    DeliveryModel,
    DfaModel,
    HumanModel,
    MissionModel,
    OrderModel,
    OrdersFileModel,
    ScenarioModel,
    SceneModel,
    WorkspaceModel,
    show_points,
)
from cosmop.scene import (
    LENGTH_GRID,
    MAX_LENGTH,
    MAX_TASK_EVENTS,
    Delivery,
    DfaSpec,
    Dynamics,
    Human,
    Mission,
    MovableObject,
    Order,
    Robot,
    Scenario,
    Scene,
    Wall,
    Workspace,
)
from cosmop.team.handover import handovers
from cosmop.units import (
    UnitSystem,
    default_dynamics,
    localize,
    plain,
    scene_to_internal,
    show_length,
    shown,
)


class _Builder:
    """Validates one scenario mapping and builds the :class:`Scenario`."""

    MODEL: type[BaseModel] = ScenarioModel  # the structure of the file's top level
    STRUCTURE = Structure(ScenarioModel, EXPECTED, ScenarioError)  # its fields in words
    TOP_LEVEL = "a mapping with keys name, scene, mission at the top level"

    def __init__(self, data: Any, file: str | None, marks: Marks | None) -> None:
        self.data = data
        self.file = file
        self.marks = marks or {}
        units = data.get("units") if isinstance(data, Mapping) else None
        self.units: UnitSystem = "m" if units == "m" else "mm"  # the words of its messages

    def position(self, path: FieldPath) -> tuple[int | None, int | None]:
        """The line and column of `path` in the file (of its nearest written parent), if known."""
        for length in range(len(path), 0, -1):
            if path[:length] in self.marks:
                return self.marks[path[:length]]
        return None, None

    def fail(self, path: FieldPath, expected: str, *, in_file_units: bool = False) -> NoReturn:
        """Raise the error at `path`; `expected` names units the internal way (mm, degrees)
        unless `in_file_units` says it is written in the file's units already."""
        line, column = self.position(path)
        raise ScenarioError(
            expected if in_file_units else localize(expected, self.units),
            file=self.file,
            field=format_path(path) if path else None,
            line=line,
            column=column,
        )

    def warning(self, path: FieldPath, problem: str) -> InputWarning:
        line, column = self.position(path)
        return InputWarning(problem, file=self.file, field=format_path(path), line=line, column=column)

    # -- structure ----------------------------------------------------------------------------

    def validate_structure(self) -> Any:
        """The file's top level as :attr:`MODEL`; the first wrong field (by line) fails."""
        if not isinstance(self.data, Mapping):
            what = (
                "the file is empty"
                if self.data is None
                else f"got {type(self.data).__name__} {show(self.data)}"
            )
            self.fail((), f"expected {self.TOP_LEVEL}; {what}")
        try:
            return self.MODEL.model_validate(self.data)
        except ValidationError as exc:
            errors = exc.errors(include_url=False)
            first = min(
                enumerate(errors),
                key=lambda item: (self._line_of(tuple(item[1]["loc"])), item[0]),
            )[1]
            self._structure_error(first)

    def _line_of(self, loc: FieldPath) -> float:
        for length in range(len(loc), 0, -1):
            if loc[:length] in self.marks:
                return self.marks[loc[:length]][0]
        return math.inf

    def _structure_error(self, error: ErrorDetails) -> NoReturn:
        loc: FieldPath = tuple(error["loc"])
        if "[key]" in loc and error["type"] != UNPRINTABLE:  # a mapping's key that is not text
            cut = loc.index("[key]")
            self.fail(loc[: cut - 1], f"keys here must be ids (text), got {show(loc[cut - 1])}")
        path, problem = self.STRUCTURE.problem(error, self.data)
        self.fail(path, problem)

    # -- semantics ----------------------------------------------------------------------------

    def build(self, source: Path | None) -> Scenario:
        model = self.validate_structure()
        if model.version is not None and model.version != SCENARIO_VERSION:
            self.fail(("version",), f"expected {EXPECTED[('version',)]}, got {model.version}")
        written = self.build_scene(model.scene)  # in the file's units
        if (problem := out_of_range(written, self.units)) is not None:
            self.fail(*problem, in_file_units=True)
        scene = scene_to_internal(written, self.units)
        self.check_precision(scene)
        self.check_headings(scene)
        self.check_bodies(scene)
        if model.mission is None and model.orders is None:
            self.fail(
                ("mission",),
                "missing required key 'mission': expected a mission (tasks, dfa or deliveries), "
                "or orders released over time (a lifelong run)",
            )
        mission = self.build_mission(model.mission, scene) if model.mission is not None else None
        orders = self.build_orders(model.orders, scene) if model.orders is not None else ()
        warnings = tuple(self.warning(path, problem) for path, problem in implausible(written, self.units))
        return Scenario(
            name=model.name, scene=scene, mission=mission, source=source, warnings=warnings, orders=orders
        )

    def build_orders(self, models: list[OrderModel], scene: Scene) -> tuple[Order, ...]:
        """The orders with their ids checked against the scene, listed by release time.

        A stream is written in the order it is released: a time that goes backwards is more
        likely a typing slip than a wish, so it is refused rather than sorted.
        """
        out: list[Order] = []
        first: dict[str, int] = {}
        for index, model in enumerate(models):
            path = ("orders", index)
            if out and float(model.at) < out[-1].at:
                self.fail(
                    (*path, "at"),
                    f"expected a release time >= {out[-1].at:g} s, the time of orders[{index - 1}] "
                    f"before it (orders are listed as they are released), got {model.at:g}",
                )
            if model.object not in scene.objects:
                self.fail(
                    (*path, "object"), f"unknown object {model.object!r}; {_known('objects', scene.objects)}"
                )
            if model.object in first:  # goods are delivered once: they leave the world then
                self.fail(
                    (*path, "object"), f"{model.object} is already ordered by orders[{first[model.object]}]"
                )
            first[model.object] = index
            for k, ws in enumerate(model.to):
                if ws not in scene.workspaces:
                    self.fail(
                        (*path, "to", k),
                        f"unknown workspace {ws!r}; {_known('workspaces', scene.workspaces)}",
                    )
            for k, robot in enumerate(model.by or ()):
                if robot not in scene.robots:
                    self.fail((*path, "by", k), f"unknown robot {robot!r}; {_known('robots', scene.robots)}")
            by = tuple(dict.fromkeys(model.by)) if model.by else tuple(scene.robots)
            out.append(Order(float(model.at), model.object, tuple(dict.fromkeys(model.to)), by))
        return tuple(out)

    def build_scene(self, model: SceneModel) -> Scene:
        owner_of_id: dict[str, tuple[str, str, str]] = {}  # id -> ("scene", group, id)
        kinds = {
            "robots": "a robot",
            "objects": "an object",
            "workspaces": "a workspace",
            "humans": "a human",
        }
        for group in kinds:
            for ident in getattr(model, group):
                path = ("scene", group, ident)
                if not re.fullmatch(ID_PATTERN, ident):
                    self.fail(path, f"expected an id matching {ID_PATTERN}, got {ident!r}")
                if ident in owner_of_id:
                    other = owner_of_id[ident]
                    self.fail(
                        path,
                        f"id {ident!r} is already used by {kinds[other[1]]} ({format_path(other)}); "
                        "ids must be unique across robots, objects, workspaces and humans",
                    )
                owner_of_id[ident] = path

        walls = []
        for index, (start, end) in enumerate(model.obstacles):
            if start == end:
                self.fail(
                    ("scene", "obstacles", index),
                    f"expected a wall with two distinct end points, got {show_points(start, end)}",
                )
            walls.append(Wall(start, end))

        base = default_dynamics(self.units)  # the defaults in the file's units
        dynamics = base if model.dynamics is None else replace(base, **model.dynamics.overrides())
        robots = {
            ident: Robot(
                ident,
                r.size,
                r.pose,
                dynamics if r.dynamics is None else replace(dynamics, **r.dynamics.overrides()),
            )
            for ident, r in model.robots.items()
        }
        self.check_cycles(robots, dynamics)
        objects = {
            ident: MovableObject(ident, o.size, o.position, tuple(o.sides))
            for ident, o in model.objects.items()
        }
        workspaces = {ident: self.build_workspace(ident, w) for ident, w in model.workspaces.items()}
        humans = {ident: self.build_human(ident, h) for ident, h in model.humans.items()}
        return Scene(
            obstacles=tuple(walls),
            robots=robots,
            objects=objects,
            workspaces=workspaces,
            humans=humans,
            dynamics=dynamics,
        )

    def check_precision(self, scene: Scene) -> None:
        """Every length the planner uses lies on the :data:`LENGTH_GRID` and within :data:`MAX_LENGTH`,
        and every heading is a finite number of degrees (a metres file's 1e308 radians is not)."""
        for rid, robot in scene.robots.items():
            if not math.isfinite(robot.pose[2]):
                path: FieldPath = ("scene", "robots", rid, "pose", 2)
                written = _written(lookup(self.data, path)[1])
                self.fail(
                    path, f"expected a finite heading (degrees), got {written}: beyond the range of numbers"
                )
        grid = f"{shown(float(LENGTH_GRID), self.units):f}".rstrip("0") + (
            " m" if self.units == "m" else " mm"
        )
        for path, value in _planned_lengths(scene):
            if not abs(value) <= MAX_LENGTH:  # inf too: a metres file's 1e308 overflows in mm
                written = _written(lookup(self.data, path)[1])  # as the file wrote it
                self.fail(
                    path, f"expected a length of at most {show_length(MAX_LENGTH, self.units)}, got {written}"
                )
            if (Fraction(repr(float(value))) / LENGTH_GRID).denominator != 1:
                shown_value = f"{shown(value, self.units):.12g}"
                self.fail(
                    path,
                    f"expected a multiple of {grid} (plans are exact to a micrometre), got {shown_value}",
                )

    def check_headings(self, scene: Scene) -> None:
        """Every heading is still a finite number of degrees (a huge one in radians overflows)."""
        for rid, robot in scene.robots.items():
            if not math.isfinite(robot.pose[2]):
                given = lookup(self.data, ("scene", "robots", rid, "pose", 2))[1]
                self.fail(
                    ("scene", "robots", rid, "pose", 2),
                    f"expected a heading that stays finite in the planner's angle unit, got {given!r}",
                )

    def check_bodies(self, scene: Scene) -> None:
        """A physically possible scene: no body overlaps a wall or another body at the start."""
        from cosmop.scenario.overlaps import overlaps

        found = overlaps(scene, units=self.units)
        if found:
            self.fail(found[0].field, found[0].describe())

    def check_cycles(self, robots: Mapping[str, Robot], default: Dynamics) -> None:
        """All robots share one control cycle: report the first robot off the most common one."""
        counts = Counter(robot.dynamics.cycle for robot in robots.values())
        if len(counts) <= 1:
            return
        # the cycle most robots use; on a tie the scene-wide one, else the first in file order
        common = max(counts, key=lambda cycle: (counts[cycle], cycle == default.cycle))
        odd = next(robot for robot in robots.values() if robot.dynamics.cycle != common)
        users = [robot.id for robot in robots.values() if robot.dynamics.cycle == common]
        if len(users) == len(robots) - 1:
            others = "the others use"
        elif len(users) == 1:
            others = f"{users[0]} uses"
        else:
            shown = ", ".join(users[:3]) + (f" and {len(users) - 3} more" if len(users) > 3 else "")
            others = f"{shown} use"
        self.fail(
            ("scene", "robots", odd.id, "dynamics", "cycle"),
            "every robot must share one control cycle (the simulation steps all robots with one "
            f"clock); this robot's is {odd.dynamics.cycle:g} s, {others} {common:g} s",
        )

    def build_human(self, ident: str, model: HumanModel) -> Human:
        path = ("scene", "humans", ident)
        for index, point in enumerate(model.path):
            if len(point) == 3 and point[2] < 0:
                self.fail(
                    (*path, "path", index, 2), f"expected a dwell time >= 0 (seconds), got {point[2]:g}"
                )
        if len(model.path) < 2 and model.walk is None:
            self.fail(
                (*path, "path"),
                "expected at least two waypoints to walk between, or a walk area "
                "{x: [lo, hi], y: [lo, hi]} to roam in from the start point; got one point",
            )
        walk = None
        if model.walk is not None:
            for axis in ("x", "y"):
                lo, hi = getattr(model.walk, axis)
                if lo > hi:
                    self.fail((*path, "walk", axis), f"expected {RANGE}, got lo = {lo:g} > hi = {hi:g}")
            walk = (model.walk.x, model.walk.y)
        points = tuple((p[0], p[1], p[2] if len(p) == 3 else 0.0) for p in model.path)
        return Human(ident, model.size, model.speed, points, loop=model.loop, walk=walk)

    def build_workspace(self, ident: str, model: WorkspaceModel) -> Workspace:
        path = ("scene", "workspaces", ident)
        if model.point is not None:
            if model.x is not None or model.y is not None:
                self.fail(path, "expected either {x: [lo, hi], y: [lo, hi]} or {point: [x, y]}, not both")
            return Workspace(ident, point=model.point)
        if model.x is None and model.y is None:
            self.fail(path, "expected {x: [lo, hi], y: [lo, hi]} or {point: [x, y]}, got neither")
        for axis in ("x", "y"):
            bounds = getattr(model, axis)
            if bounds is None:
                self.fail((*path, axis), f"missing required key {axis!r}: expected {RANGE}")
            if bounds[0] > bounds[1]:
                self.fail((*path, axis), f"expected {RANGE}, got lo = {bounds[0]:g} > hi = {bounds[1]:g}")
        return Workspace(ident, x=model.x, y=model.y)

    def build_mission(self, model: MissionModel, scene: Scene) -> Mission:
        given = [k for k in ("tasks", "dfa", "deliveries") if getattr(model, k) is not None]
        if len(given) != 1:
            got = " and ".join(given) if given else "none"
            expected = "expected exactly one of 'tasks', 'dfa' or 'deliveries'"
            self.fail(("mission",), f"{expected}, got {got}")
        if model.returns is not None and model.deliveries is None:
            self.fail(
                ("mission", "return"), "'return' goes with 'deliveries' (tasks and DFAs say it by events)"
            )
        if model.tasks is not None:
            return Mission(tasks=self.build_tasks(model.tasks, scene))
        if model.dfa is not None:
            return Mission(dfa=self.build_dfa(model.dfa, scene))
        assert model.deliveries is not None  # exactly one of the three is given (checked above)
        return Mission(deliveries=self.build_deliveries(model.deliveries, scene), returns=bool(model.returns))

    def build_deliveries(self, models: list[DeliveryModel], scene: Scene) -> tuple[Delivery, ...]:
        out: list[Delivery] = []
        first: dict[str, int] = {}
        for index, model in enumerate(models):
            path = ("mission", "deliveries", index)
            obj = model.object
            if obj not in scene.objects:
                self.fail((*path, "object"), f"unknown object {obj!r}; {_known('objects', scene.objects)}")
            if obj in first:
                self.fail((*path, "object"), f"{obj} is already delivered by deliveries[{first[obj]}]")
            first[obj] = index
            for k, ws in enumerate(model.to):
                if ws not in scene.workspaces:
                    known = _known("workspaces", scene.workspaces)
                    self.fail((*path, "to", k), f"unknown workspace {ws!r}; {known}")
                self.check_holds((*path, "to", k), scene.objects[obj], ws, scene)
            by = tuple(model.by) if model.by is not None else tuple(scene.robots)
            for k, robot in enumerate(by):
                if robot not in scene.robots:
                    self.fail((*path, "by", k), f"unknown robot {robot!r}; {_known('robots', scene.robots)}")
            out.append(Delivery(model.object, tuple(dict.fromkeys(model.to)), tuple(dict.fromkeys(by))))
        return tuple(out)

    def build_tasks(self, tasks: Mapping[str, list[str]], scene: Scene) -> dict[str, tuple[Event, ...]]:
        if not tasks:
            self.fail(("mission", "tasks"), "expected a task list for at least one robot, got none")
        result = {}
        for robot, steps in tasks.items():
            if robot not in scene.robots:
                self.fail(
                    ("mission", "tasks", robot), f"unknown robot {robot!r}; {_known('robots', scene.robots)}"
                )
            events = []
            for index, text in enumerate(steps):
                path = ("mission", "tasks", robot, index)
                event = self.parse(path, text, robot)
                if robot not in event.owners:
                    owners = " and ".join(sorted(event.owners))
                    self.fail(
                        path,
                        f"expected an event of robot {robot}, got {event.name}, which belongs to {owners}",
                    )
                self.check_references(path, event, scene)
                events.append(event)
            tasks_given = sum(1 for event in events if event.kind not in MESSAGE_KINDS)
            if tasks_given > MAX_TASK_EVENTS:
                self.fail(
                    ("mission", "tasks", robot),
                    f"a task list of {tasks_given} tasks (pick, drop, return); at most {MAX_TASK_EVENTS} "
                    "per robot are planned (split the mission into several runs)",
                )
            result[robot] = tuple(events)
        if not any(result.values()):
            self.fail(
                ("mission", "tasks"),
                "expected at least one task, got only empty task lists: the mission is empty",
            )
        self.check_messages(result)
        self.check_relays(result)
        return result

    def check_messages(self, tasks: Mapping[str, tuple[Event, ...]]) -> None:
        """Every message of the task lists is in its sender's list and its receiver's, once each:
        a message sent that nobody awaits (or awaited that nobody sends) matches nothing."""
        where: dict[Event, dict[str, list[int]]] = {}
        for robot, events in tasks.items():
            for index, event in enumerate(events):
                if event.kind in MESSAGE_KINDS:
                    where.setdefault(event, {}).setdefault(robot, []).append(index)
        for event, places in where.items():
            for robot, indices in places.items():
                if len(indices) > 1:
                    first = format_path(("mission", "tasks", robot, indices[0]))
                    self.fail(
                        ("mission", "tasks", robot, indices[1]),
                        f"{event.name} is already in {robot}'s task list ({first}); every message is sent "
                        "once and awaited once",
                    )
            for party in (event.sender, event.receiver):
                if party not in places:
                    other = next(iter(places))
                    role = "sent" if other == event.sender else "awaited"
                    does = "awaits" if party == event.receiver else "sends"
                    self.fail(
                        ("mission", "tasks", other, places[other][0]),
                        f"{event.name} is {role} by {other}, but {party}'s task list never {does} it; a "
                        "message is listed by both its sender and its receiver, once each",
                    )

    def check_relays(self, tasks: Mapping[str, tuple[Event, ...]]) -> None:
        """Goods in two robots' task lists are a relay: messages in the lists must order every
        handling of them, and a robot meets them again only where it left them."""
        relays = handovers(tasks)
        for obj, (r1, i1), (r2, i2) in relays.unordered:
            first, then = ("mission", "tasks", r1, i1), ("mission", "tasks", r2, i2)
            self.fail(
                then,
                f"{obj} is moved by {r1} ({format_path(first)}) and by {r2} with no order between "
                f"them; a relay needs a message: put msg({r1},{r2},TAG) in {r1}'s list after its drop "
                f"and in {r2}'s list before its pick (or write the mission as a dfa)",
            )
        for why in relays.refused:
            self.fail(
                ("mission", "tasks"), f"expected each robot to meet goods only where it left them: {why}"
            )

    def build_dfa(self, model: DfaModel, scene: Scene) -> DfaSpec:
        base = ("mission", "dfa")
        listed = self.unique_states((*base, "states"), model.states) if model.states is not None else None

        def known(path: FieldPath, state: str, role: str) -> None:
            if listed is not None and state not in listed:
                self.fail(path, f"unknown {role} state {state!r}; it is not in mission.dfa.states")

        known((*base, "initial"), model.initial, "initial")
        order: dict[str, None] = dict.fromkeys(listed if listed is not None else [model.initial])
        first_transition: dict[tuple[str, Event], tuple[int, str]] = {}
        transitions = []
        for index, (source, text, target) in enumerate(model.transitions):
            path = (*base, "transitions", index)
            known((*path, 0), source, "source")
            known((*path, 2), target, "target")
            event = self.parse((*path, 1), text, None)
            self.check_references((*path, 1), event, scene)
            if (source, event) in first_transition:
                other, other_target = first_transition[(source, event)]
                if other_target == target:
                    problem = f"repeats transitions[{other}] ({source} --{event.name}--> {target})"
                else:
                    problem = (
                        f"nondeterministic: from state {source!r}, event {event.name} leads to "
                        f"{other_target!r} (transitions[{other}]) and to {target!r}"
                    )
                self.fail(path, f"{problem}; expected at most one transition per state and event")
            first_transition[(source, event)] = (index, target)
            order.setdefault(source)
            order.setdefault(target)
            transitions.append((source, event, target))
        states = tuple(order)
        self.check_start(model.initial, transitions, listed is not None)
        if len(states) > MAX_DFA_STATES:
            self.fail(
                base,
                f"a DFA of {len(states):,} states; at most {MAX_DFA_STATES:,} are read "
                "(write a large mission as tasks or deliveries: they are composed, not listed)",
            )

        if model.marked is None:
            marked = states
        else:
            marked = self.unique_states((*base, "marked"), model.marked)
            for index, state in enumerate(marked):
                if state not in order:
                    where = "mission.dfa.states" if listed is not None else "the transitions or initial"
                    self.fail(
                        (*base, "marked", index), f"unknown marked state {state!r}; it is not in {where}"
                    )
        spec = DfaSpec(
            states=states,
            initial=model.initial,
            marked=tuple(marked),
            transitions=tuple(transitions),
            marked_given=model.marked is not None,
        )
        reachable = _reachable(model.initial, transitions)
        if not any(q in reachable for q in spec.complete_states):
            where = "marked" if spec.marked_given else "without an outgoing transition"
            listed_states = ", ".join(spec.complete_states) or "none"
            self.fail(
                base,
                f"the mission can never be complete: no complete state ({where}: {listed_states}) "
                f"can be reached from the initial state {model.initial!r}; expected at least one",
            )
        return spec

    def check_start(self, initial: str, transitions: list[tuple[str, Event, str]], listed: bool) -> None:
        """Some event can happen from the initial state: else the mission is empty (nothing to
        plan), most often because the initial state's name has a typo."""
        base = ("mission", "dfa")
        if not transitions:
            self.fail(
                (*base, "transitions"), "expected at least one transition, got none: the mission is empty"
            )
        sources = list(dict.fromkeys(source for source, _, _ in transitions))
        if initial in sources:
            return
        shown = ", ".join(sources[:5]) + (f" and {len(sources) - 5} more" if len(sources) > 5 else "")
        if not listed and all(initial != target for _, _, target in transitions):
            problem = f"unknown initial state {initial!r}: no transition starts or ends there"
        else:
            problem = f"no transition leaves the initial state {initial!r}: the mission is empty"
        self.fail((*base, "initial"), f"{problem}; expected a state that a transition leaves ({shown})")

    def unique_states(self, path: FieldPath, states: list[str]) -> tuple[str, ...]:
        seen: dict[str, int] = {}
        for index, state in enumerate(states):
            if state in seen:
                self.fail((*path, index), f"duplicate state {state!r} (already at index {seen[state]})")
            seen[state] = index
        return tuple(states)

    def parse(self, path: FieldPath, text: str, robot: str | None) -> Event:
        try:
            return parse_event(text, robot=robot)
        except EventSyntaxError as err:
            self.fail(path, str(err))

    def check_references(self, path: FieldPath, event: Event, scene: Scene) -> None:
        for robot in sorted(event.owners):
            if robot not in scene.robots:
                self.fail(path, f"unknown robot {robot!r} in {event.name}; {_known('robots', scene.robots)}")
        if event.obj is not None and event.obj not in scene.objects:
            self.fail(
                path, f"unknown object {event.obj!r} in {event.name}; {_known('objects', scene.objects)}"
            )
        if event.workspace is not None and event.workspace not in scene.workspaces:
            self.fail(
                path,
                f"unknown workspace {event.workspace!r} in {event.name}; "
                f"{_known('workspaces', scene.workspaces)}",
            )
        if event.kind == "drop":
            assert event.obj is not None and event.workspace is not None  # a drop names both
            self.check_holds(path, scene.objects[event.obj], event.workspace, scene)

    def check_holds(self, path: FieldPath, obj: MovableObject, workspace: str, scene: Scene) -> None:
        """A drop's workspace can hold the object: as wide and as deep, with a place clear of walls."""
        ws, size = scene.workspaces[workspace], show_length(obj.size, self.units)
        x_range, y_range = ws.ranges
        if not ws.is_point and min(x_range[1] - x_range[0], y_range[1] - y_range[0]) < obj.size:
            width, depth = (show_length(hi - lo, self.units) for lo, hi in (x_range, y_range))
            self.fail(
                path,
                f"workspace {workspace} ({width} x {depth}) cannot hold {obj.id} (a {size} square); "
                "expected a workspace at least as wide and deep as its goods",
            )
        if not _fits(scene, obj, ws):
            self.fail(
                path,
                f"workspace {workspace} is too small for {obj.id} ({size}): no drop position "
                "in it keeps the object clear of the walls",
            )


def _written(value: Any) -> str:
    """A value as the file wrote it, for a message: numbers in full (``1e+308``, ``800000``)."""
    if isinstance(value, int | float) and not isinstance(value, bool):
        return plain(value)
    return show(value)


def _known(group: str, ids: Mapping[str, Any]) -> str:
    if not ids:
        return f"the scene has no {group}"
    return f"the scene's {group} are " + ", ".join(ids)


def _planned_lengths(scene: Scene) -> Iterator[tuple[FieldPath, float]]:
    """``(field path, length in mm)`` of every coordinate and size the planner encodes."""
    for i, wall in enumerate(scene.obstacles):
        for j, point in enumerate((wall.start, wall.end)):
            for k in (0, 1):
                yield ("scene", "obstacles", i, j, k), point[k]
    for rid, robot in scene.robots.items():
        yield ("scene", "robots", rid, "size"), robot.size
        for k in (0, 1):
            yield ("scene", "robots", rid, "pose", k), robot.pose[k]
    for oid, obj in scene.objects.items():
        yield ("scene", "objects", oid, "size"), obj.size
        for k in (0, 1):
            yield ("scene", "objects", oid, "position", k), obj.position[k]
    for wid, ws in scene.workspaces.items():
        for key in ("x", "y", "point"):
            for k, value in enumerate(getattr(ws, key) or ()):
                yield ("scene", "workspaces", wid, key, k), value


def _fits(scene: Scene, obj: MovableObject, workspace: Workspace) -> bool:
    """Whether some position in `workspace` holds `obj`'s square clear of every wall (touching allowed)."""
    from cosmop.squares import rectangle  # shapely: loaded only when a drop is checked

    places = rectangle(*workspace.centres(obj.size).ranges)
    return not places.difference(scene.blocked(obj.size / 2.0, within=places.bounds)).is_empty


def _reachable(initial: str, transitions: Iterable[tuple[str, Event, str]]) -> set[str]:
    """The states reachable from `initial` along `transitions` ``(source, event, target)``."""
    successors: dict[str, list[str]] = {}
    for source, _, target in transitions:
        successors.setdefault(source, []).append(target)
    seen, todo = {initial}, [initial]
    while todo:
        for nxt in successors.get(todo.pop(), ()):
            if nxt not in seen:
                seen.add(nxt)
                todo.append(nxt)
    return seen


def parse_scenario(data: Mapping[str, Any], source: str | os.PathLike[str] | None = None) -> Scenario:
    """Validate a scenario given as a mapping (e.g. already-parsed YAML or JSON).

    Parameters
    ----------
    data : Mapping
        The scenario, with the structure of a version-1 scenario file.
    source : str or os.PathLike, optional
        Where the data came from; used in error messages and kept as ``Scenario.source``.

    Returns
    -------
    Scenario
        The validated scenario.

    Raises
    ------
    ScenarioError
        If the data are not a valid scenario; the error names the field and what was expected.
    """
    file = None if source is None else os.fspath(source)
    return _Builder(data, file, None).build(None if source is None else Path(source))


class _OrdersBuilder(_Builder):
    """Reads an order stream of its own file: the scenario's ``orders`` key, nothing else."""

    MODEL = OrdersFileModel
    STRUCTURE = Structure(OrdersFileModel, EXPECTED, ScenarioError)
    TOP_LEVEL = "a mapping with the key orders at the top level"


def load_orders(path: str | os.PathLike[str], scenario: Scenario) -> tuple[Order, ...]:
    """Read an order stream file (``orders:`` as in a scenario) for `scenario`'s scene.

    Parameters
    ----------
    path : str or os.PathLike
        A YAML file whose top-level key ``orders`` lists orders ``{at, object, to, by}``.
    scenario : Scenario
        Its objects, workspaces and robots are the ids the orders may name.

    Returns
    -------
    tuple of Order
        By release time.

    Raises
    ------
    ScenarioError
        Naming the file, the field and what was expected there.
    """
    file = os.fspath(path)
    text = read_text(path, ScenarioError, "an orders file")
    data, marks = load_yaml(text, file, ScenarioError)
    builder = _OrdersBuilder(data, file, marks)
    return builder.build_orders(builder.validate_structure().orders, scenario.scene)


def load_scenario(path: str | os.PathLike[str]) -> Scenario:
    """Load and validate a scenario file (YAML, format version 1).

    Parameters
    ----------
    path : str or os.PathLike
        The scenario file.

    Returns
    -------
    Scenario
        The validated scenario; ``source`` is `path`.

    Raises
    ------
    ScenarioError
        If the file cannot be read, is not valid YAML (the line is given), repeats a key, or is
        not a valid scenario; the error names the file, the field and what was expected.
    """
    file = os.fspath(path)
    text = read_text(path, ScenarioError, "a scenario file")
    data, marks = load_yaml(text, file, ScenarioError)
    return _Builder(data, file, marks).build(Path(path))
