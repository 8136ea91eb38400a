"""The exact plan checker: is a plan sound for its scene and mission?

This module checks a :class:`~cosmop.planning.plan_types.PlanSet` against the scenario with exact
geometry (shapely 2 predicates on the double coordinates), independently of any SMT encoding,
so that a synthesised plan can be trusted -- or a hand-made plan debugged.

Let :math:`l` be the robot's side, :math:`b` an object's side and :math:`d = (l + b)/2`
(mm). Robots and objects are axis-aligned squares; a heading never changes a footprint.
*Overlap* always means that the interiors intersect: touching is allowed. For every instant
:math:`k = 1, \\dots, K` the transition from state :math:`k-1` to state :math:`k` by the
primitive of step :math:`k` must satisfy (state 0 is the scenario: the robot at its initial
pose, every object at its scenario position, neither carried nor away):

``GoTo``
    No object's position, carried or away flag changes. The swept area -- the convex hull of
    the robot's squares at the two positions -- overlaps no wall segment and no square of an
    object that is neither carried nor away in state :math:`k-1`.
``PickUp(O)``
    The pose is unchanged, the heading :math:`h` is one of O's docking headings (0°, 90°, 180°
    or 270°: it stands on O's west, south, east or north side, those O allows) and the robot
    faces O, touching it: :math:`(x, y) = (O.x, O.y) - d\\,(\\cos h, \\sin h)`. Before, nothing
    is carried and O is not away; after, O and only O is carried. Positions and away flags are
    unchanged. The gripper does not reach through a wall: no wall overlaps the union of the
    robot's and O's squares.
``DropOff(O)``
    The pose is unchanged and the heading :math:`h` is one of O's docking headings. Before, O
    is the only carried object; after, nothing is carried and O lies in front,
    at :math:`(x, y) + d\\,(\\cos h, \\sin h)`. Other positions and all away flags
    are unchanged. O's square overlaps no wall and no other object that is neither carried
    nor away, and the gripper does not reach through a wall (as for ``PickUp``).
``Req(O)``
    The pose, positions and carried flags are unchanged; O's away flag goes from false to
    true, the others are unchanged. The requester leaves room for whoever picks O, from any
    side O allows: its square overlaps none of the squares of side :math:`l` centred at the
    poses that pick O.
``Res(O)``
    Nothing changes, and O is carried before and after.

Positions change only on ``DropOff`` (the paper's :math:`\\phi_{carry}`): a carried object
keeps the position where it was picked up. Numbers are compared with a tolerance of
:data:`TOLERANCE` (mm or degrees); headings modulo 360°.

The plan's ``mission`` must be realised in order: there are instants
:math:`0 \\le i_1 < i_2 < \\dots` with event *m* holding at :math:`i_m` -- ``pick(R,O)``: step
*i* is ``PickUp(O)``; ``drop(R,O,W)``: step *i* is ``DropOff(O)`` and O's square in state *i*
lies wholly in W (a point W: O's centre is that point); ``return(R)``: the pose in state *i*
is the initial pose; ``away(O,A,B)``: step *i* is ``Req(O)`` for the requester A, ``Res(O)``
for the responder B.

:func:`cosmop.team.plan_set_checker.check_plan` checks a whole plan set: each robot's plan
with :func:`check_robot_plan`, then the rules that involve several robots.
"""

from __future__ import annotations

from collections.abc import Collection, Iterable
from typing import Any

import numpy as np
from shapely.geometry import LineString
from shapely.geometry.base import BaseGeometry

from cosmop.control.geometry import segment_array, segment_bounds
from cosmop.docking import DOCKING_HEADINGS, docking_pose, in_front
from cosmop.events import Event, Primitive, realising_step
from cosmop.planning.plan_types import RobotPlan, State, Step
from cosmop.planning.primitive_effects import initial_state
from cosmop.planning.realisation import TOLERANCE, angles_equal, at_pose, event_instants, holds_at
from cosmop.planning.report import RULES, CheckReport, Violation
from cosmop.scene import Scene, Wall
from cosmop.squares import square, swept_square
from cosmop.units import UnitSystem, show_angle, show_length, show_number, show_point, show_pose

__all__ = [
    "RULES",
    "TOLERANCE",
    "CheckReport",
    "Violation",
    "check_robot_plan",
    "overlaps",
    "square",
    "swept_square",
]

# ----------------------------------------------------------------------------------------------
# Geometry
# ----------------------------------------------------------------------------------------------


def overlaps(a: BaseGeometry, b: BaseGeometry) -> bool:
    """Whether the interiors of `a` and `b` intersect (touching does not count).

    For a segment against a polygon this is ``seg.intersects(poly) and not seg.touches(poly)``:
    a segment running along the boundary, or ending on it, only touches.

    Parameters
    ----------
    a, b : shapely geometry
        The two shapes (mm).
    """
    return a.intersects(b) and not a.touches(b)


def _wall_line(wall: Wall) -> LineString:
    return LineString([wall.start, wall.end])


def _wall_text(wall: Wall, units: UnitSystem) -> str:
    """A wall as the scenario file writes it, in its units: ``[[-2.5,0],[2.5,0]]``."""
    (x1, y1), (x2, y2) = ((show_number(v, units) for v in end) for end in (wall.start, wall.end))
    return f"[[{x1},{y1}],[{x2},{y2}]]"


# ----------------------------------------------------------------------------------------------
# Small predicates
# ----------------------------------------------------------------------------------------------


def _eq(a: float, b: float) -> bool:
    return abs(a - b) <= TOLERANCE


def _points_eq(p: Iterable[float], q: Iterable[float]) -> bool:
    return all(_eq(a, b) for a, b in zip(p, q, strict=True))


def _or(words: Iterable[str]) -> str:
    """``a``, ``a or b``, ``a, b or c``."""
    words = list(words)
    return words[0] if len(words) == 1 else f"{', '.join(words[:-1])} or {words[-1]}"


def _docking_heading(heading: float) -> int | None:
    """The docking heading (:data:`~cosmop.docking.DOCKING_HEADINGS`) `heading` equals, or ``None``."""
    return next((h for h in DOCKING_HEADINGS if angles_equal(heading, h)), None)


def _yes(flag: bool) -> str:
    return "true" if flag else "false"


def _nth(n: int) -> str:
    suffix = "th" if 10 <= n % 100 <= 20 else {1: "st", 2: "nd", 3: "rd"}.get(n % 10, "th")
    return f"{n}{suffix}"


# ----------------------------------------------------------------------------------------------
# One robot's plan
# ----------------------------------------------------------------------------------------------


class _RobotChecker:
    """Checks one robot's plan; collects violations."""

    def __init__(
        self,
        scene: Scene,
        robot_id: str,
        plan: RobotPlan,
        start: State | None = None,
        moved: Collection[str] | None = None,
    ) -> None:
        self.scene = scene
        self.robot_id = robot_id
        self.plan = plan
        self.side = scene.robots[robot_id].size
        self.initial = initial_state(scene, robot_id, plan, moved) if start is None else start
        self.home = scene.robots[robot_id].pose
        self.states: list[State] = [self.initial, *(step.state for step in plan.steps)]
        # each wall's bounding box, to test exactly only the walls a shape's box meets: a
        # warehouse has hundreds of walls and thousands of goods, and a step meets a few
        walls = segment_array((w.start, w.end) for w in scene.obstacles)
        self._wall_lo, self._wall_hi = segment_bounds(walls)
        self._lines: dict[int, LineString] = {}
        self.violations: list[Violation] = []

    # -- reporting ---------------------------------------------------------------------------

    def add(self, k: int | None, rule: str, message: str, labelled: bool = False) -> None:
        """Record a violation; the message is prefixed with the robot, instant and primitive.

        `labelled` messages already start with the primitive (``GoTo from ...``).
        """
        if k is None:
            prefix = f"{self.robot_id}: "
        elif labelled:
            prefix = f"{self.robot_id} at instant {k}: "
        else:
            prefix = f"{self.robot_id} at instant {k}, {self.plan.steps[k - 1].label}: "
        self.violations.append(Violation(self.robot_id, k, rule, prefix + message))

    # -- words, in the units of the scenario file ----------------------------------------------

    def point(self, point: Iterable[float]) -> str:
        return show_point(point, self.scene.units)

    def pose(self, pose: Iterable[float]) -> str:
        return show_pose(tuple(pose), self.scene.units)

    def length(self, mm: float) -> str:
        return show_length(mm, self.scene.units)

    def angle(self, degrees: float) -> str:
        return show_angle(degrees, self.scene.units)

    def gap(self, oid: str) -> float:
        """d = (l + b)/2 for this robot and object `oid`."""
        return (self.side + self.scene.objects[oid].size) / 2.0

    # -- driver ------------------------------------------------------------------------------

    def run(self) -> list[Violation]:
        scene_objects = list(self.scene.objects)
        wanted = set(scene_objects)
        complete = [True]  # instant 0 (the scenario) is complete
        for k, step in enumerate(self.plan.steps, 1):
            listed = set(step.objects)
            ok = True
            if listed != wanted:
                missing = [o for o in scene_objects if o not in listed]
                extra = [o for o in step.objects if o not in wanted]
                parts = []
                if missing:
                    parts.append(f"missing {', '.join(missing)}")
                if extra:
                    parts.append(f"{', '.join(extra)} not in the scene")
                self.add(
                    k,
                    "objects",
                    f"every step must list every object of the scene ({', '.join(scene_objects) or 'none'}); "
                    + "; ".join(parts),
                )
                ok = False
            if step.object is not None and step.object not in wanted:
                self.add(
                    k,
                    "objects",
                    f"{step.object} is not an object of the scene ({', '.join(scene_objects) or 'none'})",
                )
                ok = False
            complete.append(ok)
        for k, step in enumerate(self.plan.steps, 1):
            if complete[k - 1] and complete[k]:
                self.transition(k, step, self.states[k - 1], self.states[k])
        self.mission()
        # by instant, plan-wide (mission) violations last; stable within an instant
        return sorted(self.violations, key=lambda v: (v.instant is None, v.instant or 0))

    def transition(self, k: int, step: Step, prev: State, cur: State) -> None:
        if step.message is not None:
            self.message(k, step, prev, cur)
        elif step.primitive == Primitive.GOTO:
            self.goto(k, step, prev, cur)
        elif step.primitive == Primitive.PICKUP:
            self.pickup(k, step, prev, cur)
        elif step.primitive == Primitive.DROPOFF:
            self.dropoff(k, step, prev, cur)
        elif step.primitive == Primitive.REQ:
            self.req(k, step, prev, cur)
        else:
            self.res(k, step, prev, cur)

    # -- frame conditions --------------------------------------------------------------------

    def robot_static(self, k: int, prev: State, cur: State) -> None:
        if not at_pose(prev.robot, cur.robot):
            self.add(
                k,
                "robot-static",
                f"the robot moves from {self.pose(prev.robot)} to {self.pose(cur.robot)}; "
                f"only GoTo moves the robot, so keep the pose of instant {k - 1}",
            )

    def positions_static(self, k: int, prev: State, cur: State, moved: str | None = None) -> None:
        for oid, before in prev.objects.items():
            if oid == moved:
                continue
            after = cur.objects[oid].position
            if not _points_eq(before.position, after):
                carried = " (a carried object stays where it was picked up)" if before.carried else ""
                self.add(
                    k,
                    "position",
                    f"{oid} moves from {self.point(before.position)} to {self.point(after)}; "
                    f"objects move only when dropped off{carried}",
                )

    def flags_static(self, k: int, prev: State, cur: State, flag: str, changed: str | None = None) -> None:
        for oid, before in prev.objects.items():
            if oid == changed:
                continue
            old, new = getattr(before, flag), getattr(cur.objects[oid], flag)
            if old != new:
                why = (
                    "only PickUp and DropOff change what is carried"
                    if flag == "carried"
                    else "only Req marks an object as moved away"
                )
                self.add(k, flag, f"the {flag} flag of {oid} changes from {_yes(old)} to {_yes(new)}; {why}")

    def docking(self, k: int, cur: State, oid: str, rule: str, verb: str) -> int | None:
        """The docking heading of the robot at instant `k`; a violation and ``None`` if it has none."""
        heading = _docking_heading(cur.robot[2])
        allowed = self.scene.objects[oid].headings
        if heading is None or heading not in allowed:
            sides = self.scene.objects[oid].sides
            self.add(
                k,
                rule,
                f"the robot's heading is {self.angle(cur.robot[2])}, but {oid} is {verb} facing one of its "
                f"sides {', '.join(sides)}: at heading {_or(self.angle(h) for h in allowed)}",
            )
            return None
        return heading

    def walls_meeting(self, shape: BaseGeometry) -> Iterable[tuple[Wall, LineString]]:
        """The walls, in the scene's order, whose bounding box meets `shape`'s (closed boxes:
        a wall whose box does not meet it cannot meet the shape), each with its segment."""
        x0, y0, x1, y1 = shape.bounds
        near = np.all((self._wall_lo <= (x1, y1)) & (self._wall_hi >= (x0, y0)), axis=1)
        for i in np.flatnonzero(near).tolist():
            line = self._lines.get(i)
            if line is None:
                line = self._lines[i] = _wall_line(self.scene.obstacles[i])
            yield self.scene.obstacles[i], line

    def resting(
        self, state: State, exclude: str | None = None, near: BaseGeometry | None = None
    ) -> Iterable[tuple[str, Any]]:
        """Objects neither carried nor away in `state`, with their squares; with `near`, only
        those whose square's box (grown by a millimetre, for rounding) meets its box."""
        x0, y0, x1, y1 = near.bounds if near is not None else (-np.inf, -np.inf, np.inf, np.inf)
        for oid, obj in state.objects.items():
            if oid != exclude and not obj.carried and not obj.away:
                x, y = obj.position
                half = self.scene.objects[oid].size / 2.0 + 1.0
                if x - half <= x1 and x + half >= x0 and y - half <= y1 and y + half >= y0:
                    yield oid, square(x, y, self.scene.objects[oid].size)

    # -- primitives --------------------------------------------------------------------------

    def goto(self, k: int, step: Step, prev: State, cur: State) -> None:
        self.positions_static(k, prev, cur)
        self.flags_static(k, prev, cur, "carried")
        self.flags_static(k, prev, cur, "away")
        area = swept_square(prev.robot, cur.robot, self.side)
        (x0, y0, _), (x1, y1, _) = prev.robot, cur.robot
        if _eq(x0, x1) and _eq(y0, y1):
            motion, verb_wall, verb_obj = f"GoTo staying at {self.point((x0, y0))}", "overlaps", "overlaps"
        else:
            motion, verb_wall, verb_obj = (
                f"GoTo from {self.point((x0, y0))} to {self.point((x1, y1))}",
                "crosses",
                "sweeps over",
            )
        for wall, line in self.walls_meeting(area):
            if overlaps(line, area):
                self.add(
                    k,
                    "wall",
                    f"{motion} {verb_wall} wall {_wall_text(wall, self.scene.units)}; "
                    "add a waypoint (another GoTo) to go around it",
                    labelled=True,
                )
        for oid, shape in self.resting(prev, near=area):
            if overlaps(shape, area):
                position = prev.objects[oid].position
                self.add(
                    k,
                    "object-collision",
                    f"{motion} {verb_obj} {oid}, resting at {self.point(position)} "
                    f"(size {self.length(self.scene.objects[oid].size)}); go around it or request it away "
                    f"with Req({oid})",
                    labelled=True,
                )

    def reach(
        self, k: int, oid: str, robot: State, where: tuple[float, float], skip: Iterable[Wall] = ()
    ) -> None:
        """The gripper must not reach through a wall: robot and object squares on its two sides."""
        x, y, _ = robot.robot
        reach = square(x, y, self.side).union(square(*where, self.scene.objects[oid].size))
        skipped = set(skip)
        for wall, line in self.walls_meeting(reach):
            if wall not in skipped and overlaps(line, reach):
                self.add(
                    k,
                    "wall",
                    f"the robot at {self.point((x, y))} and {oid} at {self.point(where)} are on the two "
                    f"sides of wall {_wall_text(wall, self.scene.units)}; "
                    "the gripper cannot reach through it",
                )

    def pickup(self, k: int, step: Step, prev: State, cur: State) -> None:
        oid = step.object
        assert oid is not None  # Step requires the object of a primitive without a message
        self.robot_static(k, prev, cur)
        heading = self.docking(k, cur, oid, "pick-pose", "picked up")
        ox, oy = prev.objects[oid].position
        d = self.gap(oid)
        x, y, _ = cur.robot
        pose = None if heading is None else docking_pose((ox, oy), d, heading)
        if pose is not None and not _points_eq((x, y), pose):
            assert heading is not None  # the pose is found only for a docking heading
            self.add(
                k,
                "pick-pose",
                f"the robot is at {self.point((x, y))}, but picking {oid} at {self.point((ox, oy))} at "
                f"heading {self.angle(heading)} requires standing in front of it at {self.point(pose)} "
                f"(d = {self.length(d)})",
            )
        elif pose is not None:
            self.reach(k, oid, cur, (ox, oy))
        carried_before = [o for o, s in prev.objects.items() if s.carried]
        if carried_before:
            self.add(
                k,
                "carried",
                f"the robot already carries {', '.join(carried_before)} at instant {k - 1}; "
                "drop it off before picking up another object",
            )
        if prev.objects[oid].away:
            self.add(
                k,
                "away",
                f"{oid} has been moved away by another robot (away at instant {k - 1}); it cannot be picked",
            )
        if not cur.objects[oid].carried:
            self.add(k, "carried", f"{oid} is not marked carried after PickUp({oid})")
        others = [o for o, s in cur.objects.items() if s.carried and o != oid]
        if others:
            self.add(
                k, "carried", f"after PickUp({oid}) only {oid} may be carried, but {', '.join(others)} is too"
            )
        self.positions_static(k, prev, cur)
        self.flags_static(k, prev, cur, "away")

    def dropoff(self, k: int, step: Step, prev: State, cur: State) -> None:
        oid = step.object
        assert oid is not None  # Step requires the object of a primitive without a message
        self.robot_static(k, prev, cur)
        heading = self.docking(k, cur, oid, "drop-pose", "dropped off")
        if not prev.objects[oid].carried:
            self.add(
                k, "carried", f"{oid} is not carried at instant {k - 1}, so there is nothing to drop off"
            )
        others = [o for o, s in prev.objects.items() if s.carried and o != oid]
        if others:
            self.add(
                k, "carried", f"the robot carries {', '.join(others)} as well as {oid} at instant {k - 1}"
            )
        still = [o for o, s in cur.objects.items() if s.carried]
        if still:
            self.add(k, "carried", f"{', '.join(still)} is still marked carried after DropOff({oid})")
        d = self.gap(oid)
        x, y, _ = cur.robot
        where = cur.objects[oid].position
        front = None if heading is None else in_front((x, y), d, heading)
        placed = front is not None and _points_eq(where, front)
        if front is not None and not placed:
            assert heading is not None  # the front is found only for a docking heading
            self.add(
                k,
                "drop-pose",
                f"{oid} is put at {self.point(where)}, but a robot at {self.point((x, y))} facing "
                f"{self.angle(heading)} puts it in front of itself at {self.point(front)} "
                f"(d = {self.length(d)})",
            )
        self.positions_static(k, prev, cur, moved=oid)
        self.flags_static(k, prev, cur, "away")
        shape = square(where[0], where[1], self.scene.objects[oid].size)
        crossed = []
        for wall, line in self.walls_meeting(shape):
            if overlaps(line, shape):
                crossed.append(wall)
                self.add(
                    k,
                    "wall",
                    f"{oid} dropped at {self.point(where)} overlaps wall "
                    f"{_wall_text(wall, self.scene.units)}; drop it elsewhere",
                )
        if placed:
            self.reach(k, oid, cur, where, skip=crossed)
        for other, other_shape in self.resting(cur, exclude=oid, near=shape):
            if overlaps(other_shape, shape):
                self.add(
                    k,
                    "object-collision",
                    f"{oid} dropped at {self.point(where)} overlaps {other}, resting at "
                    f"{self.point(cur.objects[other].position)}; drop it elsewhere",
                )

    def req(self, k: int, step: Step, prev: State, cur: State) -> None:
        oid = step.object
        assert oid is not None  # Step requires the object of a primitive without a message
        self.robot_static(k, prev, cur)
        self.positions_static(k, prev, cur)
        self.flags_static(k, prev, cur, "carried")
        self.flags_static(k, prev, cur, "away", changed=oid)
        if prev.objects[oid].away:
            self.add(k, "away", f"{oid} is already away at instant {k - 1}; request it only once")
        if not cur.objects[oid].away:
            self.add(k, "away", f"{oid} is not marked away after Req({oid})")
        ox, oy = prev.objects[oid].position
        d = self.gap(oid)
        x, y, _ = cur.robot
        poses = [(h, docking_pose((ox, oy), d, h)) for h in self.scene.objects[oid].headings]
        blocked = [(h, p) for h, p in poses if overlaps(square(x, y, self.side), square(*p, self.side))]
        if blocked:
            where = ", ".join(f"{self.point(p)} (heading {self.angle(h)})" for h, p in blocked)
            self.add(
                k,
                "req-room",
                f"the requester at {self.point((x, y))} stands in the way of a robot picking {oid} from "
                f"{where}; request from a pose that leaves the pick pose on each of its sides free",
            )

    def res(self, k: int, step: Step, prev: State, cur: State) -> None:
        oid = step.object
        assert oid is not None  # Step requires the object of a primitive without a message
        self.robot_static(k, prev, cur)
        self.positions_static(k, prev, cur)
        self.flags_static(k, prev, cur, "carried")
        self.flags_static(k, prev, cur, "away")
        if not prev.objects[oid].carried or not cur.objects[oid].carried:
            self.add(
                k,
                "carried",
                f"Res({oid}) tells the requester that {oid} has been moved away, so the robot must carry "
                f"{oid} at instants {k - 1} and {k}; pick it up first",
            )

    def message(self, k: int, step: Step, prev: State, cur: State) -> None:
        """A ``Req`` (wait) or ``Res`` (send) of a ``msg``: nothing moves, the robot is its party."""
        self.robot_static(k, prev, cur)
        self.positions_static(k, prev, cur)
        self.flags_static(k, prev, cur, "carried")
        self.flags_static(k, prev, cur, "away")
        assert step.message is not None  # (transition sends only steps with a message here)
        event = step.message
        role, robot = (
            ("receiver", event.receiver) if step.primitive == Primitive.REQ else ("sender", event.sender)
        )
        if robot != self.robot_id:
            self.add(
                k,
                "message",
                f"{event.name} is {'awaited' if role == 'receiver' else 'sent'} by its {role} {robot}, "
                f"not by {self.robot_id}",
            )

    # -- mission -----------------------------------------------------------------------------

    def mission(self) -> None:
        events: list[Event] = []
        for event in self.plan.mission:
            if self.robot_id not in event.owners:
                self.add(
                    None,
                    "mission",
                    f"the mission lists {event.name}, an event of {' and '.join(sorted(event.owners))}; "
                    "a robot's plan realises only its own events",
                )
                return
            if event.kind == "drop" and event.workspace not in self.scene.workspaces:
                self.add(
                    None,
                    "mission",
                    f"{event.name} names workspace {event.workspace}, which is not in the scene "
                    f"({', '.join(self.scene.workspaces) or 'none'})",
                )
                return
            events.append(event)
        instants = event_instants(self.plan, self.robot_id, self.scene, events, self.initial)
        for n, (event, found) in enumerate(zip(events, instants, strict=True), 1):
            if found is None:
                last = instants[n - 2] if n > 1 else None
                self.add(None, "mission", self.unmatched(event, n, len(events), last, events))
                return

    def holds(self, event: Event, i: int) -> bool:
        return holds_at(event, self.robot_id, self.plan, self.states, self.scene, i)

    def expectation(self, event: Event) -> str:
        if event.kind == "pick":
            return f"PickUp({event.obj})"
        if event.kind == "drop":
            return f"DropOff({event.obj}) that leaves {event.obj} in {event.workspace}"
        realised = realising_step(event, self.robot_id)
        assert realised is not None  # an away or msg here (a return is never asked): it has a step
        primitive, obj, sent = realised
        return f"{primitive}({obj or (sent.name if sent is not None else None)})"

    def unmatched(self, event: Event, n: int, total: int, last: int | None, events: list[Event]) -> str:
        after = "anywhere in the plan" if last is None else f"after instant {last} ({events[n - 2].name})"
        head = f"mission event {event.name} ({_nth(n)} of {total}) is not realised"
        if event.kind == "return":
            text = f"{head}: the robot is never at its initial pose {self.pose(self.home)} {after}"
        else:
            text = f"{head}: there is no {self.expectation(event)} {after}"
        earlier = []
        if last is not None and event.kind != "return":  # a return holds trivially at instant 0
            earlier = [i for i in range(last + 1) if self.holds(event, i)]
        if earlier:
            text += (
                f"; it holds only at instant {', '.join(map(str, earlier))}, before {events[n - 2].name}: "
                "the events are out of order"
            )
        elif event.kind == "drop":
            assert event.obj is not None and event.workspace is not None  # a drop names both
            for i in range(1 if last is None else last + 1, self.plan.horizon + 1):
                step = self.plan.steps[i - 1]
                if (
                    step.primitive == Primitive.DROPOFF
                    and step.object == event.obj
                    and event.obj in step.objects
                ):
                    text += (
                        f"; DropOff({event.obj}) at instant {i} leaves it at "
                        f"{self.point(step.objects[event.obj].position)}, "
                        f"{_outside(self.scene, event.obj, event.workspace)}"
                    )
        elif event.kind == "return" and self.plan.horizon:
            final = self.pose(self.states[-1].robot)
            text += f"; the last pose is {final}: add a GoTo back to the initial pose"
        remaining = [e.name for e in events[n:]]
        if remaining:
            text += f" (so {', '.join(remaining)} cannot be matched either)"
        return text


def _outside(scene: Scene, oid: str, wid: str) -> str:
    """Words for an object left where the drop's workspace does not hold it."""
    if scene.workspaces[wid].is_point:
        return f"not on {_workspace_text(scene, wid)}"
    size = show_length(scene.objects[oid].size, scene.units)
    return f"not wholly inside {_workspace_text(scene, wid)} (size {size})"


def _workspace_text(scene: Scene, wid: str) -> str:
    ws = scene.workspaces[wid]
    if ws.point is not None:
        return f"{wid} (the point {show_point(ws.point, scene.units)})"
    assert ws.x is not None and ws.y is not None  # a rectangle
    (x0, x1), (y0, y1) = ((show_number(v, scene.units) for v in axis) for axis in (ws.x, ws.y))
    return f"{wid} (x in [{x0}, {x1}], y in [{y0}, {y1}])"


def check_robot_plan(
    scene: Scene,
    robot_id: str,
    plan: RobotPlan,
    start: State | None = None,
    moved: Collection[str] | None = None,
) -> list[Violation]:
    """Check one robot's plan against the scene: every transition, and the plan's own mission.

    Parameters
    ----------
    scene : Scene
        Walls, robots, objects and workspaces (mm, degrees).
    robot_id : str
        The robot whose plan it is; instant 0 is its initial pose and the scenario's objects.
    plan : RobotPlan
        The plan.
    start : State, optional
        Instant 0 when it is not the scenario (a plan made mid-mission, :mod:`cosmop.sim`);
        ``return`` still means the scenario's initial pose.
    moved : collection of str, optional
        Goods the team moves: the plan may know them elsewhere than the scenario at instant 0
        (:func:`~cosmop.planning.primitive_effects.initial_state`; the team's checker verifies where they
        really are).  By default the goods the plan picks up.

    Returns
    -------
    list of Violation
        Empty if the plan is sound: first the transitions' violations by instant, then the
        first mission event that cannot be matched (if any).
    """
    if robot_id not in scene.robots:
        return [
            Violation(
                robot_id,
                None,
                "robot",
                f"{robot_id}: there is no robot {robot_id} in the scene "
                f"({', '.join(scene.robots) or 'none'})",
            )
        ]
    return _RobotChecker(scene, robot_id, plan, start, moved).run()
