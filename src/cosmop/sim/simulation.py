"""Executing plans: a multi-robot world with messages, people and a safety monitor.

Every robot executes its ``cosmop.plan/1`` plan step by step, all robots in lock step with one
control cycle :math:`\\varepsilon` (the scenario's ``dynamics.cycle``):

``GoTo``
    drives with the passive-safe dynamic window (:mod:`cosmop.control.dwa`) along a global path
    (:mod:`cosmop.control.paths`) to the step's waypoint.  A waypoint followed by another
    ``GoTo`` is passed within ``pass_tolerance``; the last one of a run is reached within
    ``goal_tolerance`` and turned to its heading within ``heading_tolerance``, and so is one
    from which the plan approaches a pose that touches something (not turned).  A plan may
    start or end a motion touching a wall or resting object (never slide along one:
    :data:`cosmop.planning.specification.MOTION_MARGIN`); the robot first creeps straight out
    to ``leave_gap``, and the last few millimetres onto a final pose that touches something
    are crept, with the docking controller.
``PickUp`` / ``DropOff``
    dock: the docking pose (facing the object from the plan's side, touching it:
    :func:`cosmop.docking.docking_pose`; the plan's pose for a drop) is closed at
    ``dock_speed`` by the docking controller (a fine alignment of at most ``dock_tolerance``,
    which the unicycle model abstracts), then the gripper works for ``handling_time``.  After
    a drop the robot stays where the plan has it (a robot that waits there keeps the
    clearances the plan was ordered with) and creeps out when it next drives, so that it never
    drives along the object it touches.
    A carried object rides on its robot, inside the robot's square, as in the plan model where
    a carried object takes no room.
``Req``
    stops and waits for its message (the answer ``away(O, A, B)`` to a request, or a
    ``msg``); ``Res`` stops and sends it.  The message bus logs every message.  Plans are
    executed exactly as written: the messages that keep robots apart sit where the plan put
    them (:mod:`cosmop.planning.teamsafety`).

Robots are unicycles: each cycle the robot holds a turn rate in :math:`[-\\Omega, \\Omega]` and
speeds up at most at :math:`A` or brakes at :math:`-b` until it has the speed it was given.
The footprint is the scenario's axis-aligned square, so a turn on the spot moves no part of
it; *moving* means a translational speed above zero.

The safety monitor records every contact -- a robot's square touching a wall, a resting
object, another robot or a person -- and whether the robot was moving then.  Passive safety
guarantees that it never is (a person may walk into a standing robot).  A robot that makes no
progress for ``stall_time`` replans its remaining mission from where it is, with the robots and
people it senses added to the scene (:mod:`cosmop.sim.replan`).  Units: mm, mm/s, degrees at
the interfaces, seconds.
"""

from __future__ import annotations

import json
import math
import os
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from cosmop.control.dwa import DwaSettings, dwa_commands, robot_gaps
from cosmop.control.geometry import box_gaps, point_segment_linf, segment_array
from cosmop.control.paths import GlobalPath, plan_path, straight_path
from cosmop.control.safety import is_safe, obstacle_speed, stopping_horizon, stopping_margin
from cosmop.docking import docking_pose, in_front
from cosmop.io import write_atomic
from cosmop.missions.events import Event, parse_event
from cosmop.planning.plan import Itinerary, ObjectState, PlanSet, RobotPlan, State, Step, initial_state
from cosmop.planning.realisation import event_instants
from cosmop.planning.timing import itinerary
from cosmop.scenario import Scenario
from cosmop.sim.humans import Walker
from cosmop.sim.recoordinate import Remaining, recoordinate
from cosmop.sim.replan import replan
from cosmop.sim.timing import StepTimes, carry_instants, step_times
from cosmop.units import INTERNAL_UNITS

__all__ = [
    "SIM_FORMAT",
    "TRACE_FORMAT",
    "Contact",
    "Message",
    "SimResult",
    "SimSettings",
    "footprint_overlaps",
    "simulate",
]

SIM_FORMAT = "cosmop.sim/1"
"""The ``format`` of a simulation summary (``summary.json``)."""

TRACE_FORMAT = "cosmop.trace/1"
"""The ``format`` of a simulation trace (``trace.json``)."""

_PRIMITIVES = (None, "GoTo", "PickUp", "DropOff", "Req", "Res")
_TOUCH = 1e-6  # mm: squares closer than this touch
_GRAZE = 1.0  # mm: a straight way closer than this to an obstacle is not trusted off the plan


@dataclass(frozen=True)
class SimSettings:
    """How the simulation runs (the robots' limits come from the scenario's ``dynamics``).

    Attributes
    ----------
    max_time : float
        Simulated seconds after which an unfinished run stops (``completed`` false).
    goal_tolerance, pass_tolerance : float
        Distance (mm) within which a final / intermediate GoTo waypoint counts as reached.
    heading_tolerance : float
        Degrees within which a final waypoint's heading counts as reached.
    dock_tolerance : float
        Largest offset (mm) from a docking pose that the docking controller closes; farther
        away, the robot first drives there.
    dock_speed : float
        Speed of the docking controller, mm/s (at most one cycle's braking, :math:`b\\varepsilon`).
    reach : float
        How far (mm) the gripper reaches: a pick-up whose docking is blocked closer than this
        to its pose still picks the object up.  A drop waits for the exact pose: the object
        goes exactly where the plan puts it (in its workspace).
    handling_time : float
        Seconds the gripper needs to pick up or drop off.
    leave_gap : float
        Gap (mm) to walls and resting objects that a robot creeps out to, straight, before it
        drives off a pose that touches them (a plan's motion leaves such a pose to at least
        :data:`~cosmop.planning.specification.MOTION_MARGIN`).
    detour_time : float
        Seconds without progress after which a driving robot plans its global path again,
        around the robots that block it and have the right of way (less path left).
    stall_time : float
        Seconds without ``stall_progress`` mm of progress after which a driving robot replans.
    stall_progress : float
        Progress (mm of path) that resets the stall clock.
    replan : bool
        Whether stalled robots replan (else they keep trying).
    sense_range : float
        Robots and people within this gap (mm) of a stalled robot are added to its scene.
    max_horizon, rlimit : int
        Bounds of the solver when replanning.
    dwa : DwaSettings
        The dynamic window's search.
    """

    max_time: float = 900.0
    goal_tolerance: float = 15.0
    pass_tolerance: float = 150.0
    heading_tolerance: float = 2.0
    dock_tolerance: float = 80.0
    dock_speed: float = 50.0
    reach: float = 20.0
    handling_time: float = 1.0
    leave_gap: float = 10.0
    detour_time: float = 3.0
    stall_time: float = 12.0
    stall_progress: float = 50.0
    replan: bool = True
    sense_range: float = 800.0
    max_horizon: int = 12
    rlimit: int = 10_000_000
    dwa: DwaSettings = field(default_factory=DwaSettings)


@dataclass(frozen=True)
class Message:
    """A message on the bus: ``event`` from ``sender`` to ``receiver`` at time ``t`` (s).

    ``object`` is the object of an ``away`` answer (``None`` for a ``msg``).
    """

    t: float
    sender: str
    receiver: str
    object: str | None
    event: str

    def to_dict(self) -> dict[str, Any]:
        return {
            "t": self.t,
            "from": self.sender,
            "to": self.receiver,
            "object": self.object,
            "event": self.event,
        }


@dataclass(frozen=True)
class Contact:
    """A contact episode: `robot`'s square touched `other` from time `t` on.

    ``moving`` is true if the robot had a translational speed above zero at any cycle of the
    episode -- what passive safety rules out.
    """

    t: float
    robot: str
    other: str
    moving: bool

    def to_dict(self) -> dict[str, Any]:
        return {"t": self.t, "robot": self.robot, "other": self.other, "moving": self.moving}


@dataclass(frozen=True)
class SimResult:
    """The outcome of :func:`simulate`: status, statistics, and the whole trace.

    Attributes
    ----------
    scenario : str
    completed : bool
        Every robot executed its whole plan before ``max_time``.
    sim_time_s, wall_time_s : float
        Simulated and real seconds.
    cycles : int
    dt : float
        The control cycle, s.
    contacts : tuple of Contact
    replans, replan_attempts : int
        Successful replans and all attempts.
    messages : tuple of Message
    objects : Mapping[str, tuple]
        Final ``(position (x, y), carried_by or None)`` of every object.
    robots : Mapping[str, tuple]
        Final ``(pose (x, y, heading deg), distance_mm)`` of every robot.
    finished : Mapping[str, bool]
        Whether each robot executed its whole plan.
    frames : Mapping[str, ndarray]
        Per cycle arrays: ``t`` (n,), ``pose`` (n, R, 3; degrees), ``v`` (n, R), ``w``
        (n, R; deg/s), ``carrying`` (n, R; object index or -1), ``primitive`` (n, R; index in
        ``(None, GoTo, PickUp, DropOff, Req, Res)``), ``waiting`` (n, R), ``humans`` (n, H, 2),
        ``objects`` (n, O, 2).
    robot_ids, human_ids, object_ids : tuple of str
    replan_log : tuple of dict
        Every replan attempt: ``t``, ``robot``, ``accepted`` (its new plan was ordered with the
        others' again, :mod:`cosmop.sim.recoordinate`), ``why`` not, and the ``messages`` added.
    events : tuple of (float, str, str)
        ``(t, robot, event)``: the mission events and messages as the robots realised them --
        a pick when the gripper closes, a drop when the object lies in its workspace, a return
        when the robot ends its plan at home, a message when it is sent (and again when it is
        received).
    added : tuple of str
        The events of the tasks the planner added (:attr:`PlanSet.added
        <cosmop.planning.plan.PlanSet.added>`): goods moved out of a robot's way.
    steps : Mapping[str, tuple of StepTimes]
        Every robot's steps with their planned (the plan set's itinerary) and realised start
        and end (:mod:`cosmop.sim.timing`).
    """

    scenario: str
    completed: bool
    sim_time_s: float
    wall_time_s: float
    cycles: int
    dt: float
    contacts: tuple[Contact, ...]
    replans: int
    replan_attempts: int
    messages: tuple[Message, ...]
    objects: Mapping[str, tuple]
    robots: Mapping[str, tuple]
    frames: Mapping[str, np.ndarray] = field(repr=False)
    finished: Mapping[str, bool] = field(default_factory=dict)
    robot_ids: tuple[str, ...] = ()
    human_ids: tuple[str, ...] = ()
    object_ids: tuple[str, ...] = ()
    events: tuple[tuple[float, str, str], ...] = ()
    added: tuple[str, ...] = ()
    replan_log: tuple[dict[str, Any], ...] = ()
    steps: Mapping[str, tuple[StepTimes, ...]] = field(default_factory=dict)

    def executed_word(self) -> tuple[str, ...]:
        """The mission events the run realised, in time order (messages and the events of tasks
        the planner added, :attr:`added`, left out: no mission names them)."""
        skip = set(self.added)
        return tuple(
            name
            for _, _, name in sorted(self.events)
            if not name.startswith(("msg(", "away(")) and name not in skip
        )

    @property
    def makespan(self) -> dict[str, float | None]:
        """When the team was expected to be done (``planned``, s) and was (``realised``; ``None``
        for a run that did not complete)."""
        planned = [r.planned[1] for rows in self.steps.values() for r in rows if r.planned is not None]
        realised = [r.realised[1] for rows in self.steps.values() for r in rows if r.realised is not None]
        return {
            "planned": round(max(planned), 3) if planned else None,
            "realised": round(max(realised, default=0.0), 3) if self.completed else None,
        }

    @property
    def contacts_while_moving(self) -> int:
        """Contact episodes in which the robot was moving (0 under passive safety)."""
        return sum(1 for c in self.contacts if c.moving)

    def summary(self) -> dict[str, Any]:
        """The ``cosmop.sim/1`` summary (what ``--summary`` writes)."""
        return {
            "format": SIM_FORMAT,
            "scenario": self.scenario,
            "units": dict(INTERNAL_UNITS),
            "completed": self.completed,
            "sim_time_s": round(self.sim_time_s, 6),
            "wall_time_s": round(self.wall_time_s, 6),
            "cycles": self.cycles,
            "contacts": len(self.contacts),
            "contacts_while_moving": self.contacts_while_moving,
            "replans": self.replans,
            "replan_attempts": self.replan_attempts,
            "messages": [m.to_dict() for m in self.messages],
            "events": [{"t": t, "robot": r, "event": e} for t, r, e in self.events],
            "replan_log": list(self.replan_log),
            "makespan": self.makespan,
            "itinerary": {rid: [row.to_dict() for row in rows] for rid, rows in self.steps.items()},
            "objects": {
                oid: {"position": [round(p[0], 3), round(p[1], 3)], "carried_by": by}
                for oid, (p, by) in self.objects.items()
            },
            "robots": {
                rid: {"pose": [round(v, 3) for v in pose], "distance_mm": round(dist, 3)}
                for rid, (pose, dist) in self.robots.items()
            },
            "contact_log": [c.to_dict() for c in self.contacts],
        }

    def trace(self) -> dict[str, Any]:
        """The ``cosmop.trace/1`` trace: one frame per cycle (what ``--trace`` writes)."""
        f = self.frames
        frames = []
        for n in range(len(f["t"])):
            robots = {}
            for i, rid in enumerate(self.robot_ids):
                carry = int(f["carrying"][n, i])
                robots[rid] = {
                    "pose": [round(float(x), 3) for x in f["pose"][n, i]],
                    "v": round(float(f["v"][n, i]), 3),
                    "w": round(float(f["w"][n, i]), 3),
                    "carrying": self.object_ids[carry] if carry >= 0 else None,
                    "primitive": _PRIMITIVES[int(f["primitive"][n, i])],
                    "waiting": bool(f["waiting"][n, i]),
                }
            frames.append(
                {
                    "t": round(float(f["t"][n]), 6),
                    "robots": robots,
                    "humans": {
                        hid: [round(float(x), 3) for x in f["humans"][n, j]]
                        for j, hid in enumerate(self.human_ids)
                    },
                    "objects": {
                        oid: [round(float(x), 3) for x in f["objects"][n, j]]
                        for j, oid in enumerate(self.object_ids)
                    },
                }
            )
        return {
            "format": TRACE_FORMAT,
            "scenario": self.scenario,
            "units": dict(INTERNAL_UNITS),
            "dt": self.dt,
            "frames": frames,
            "messages": [m.to_dict() for m in self.messages],
        }

    def save_summary(self, path: str | os.PathLike[str]) -> None:
        """Write :meth:`summary` as JSON, atomically."""
        write_atomic(path, json.dumps(self.summary(), indent=2) + "\n")

    def save_trace(self, path: str | os.PathLike[str]) -> None:
        """Write :meth:`trace` as JSON, atomically."""
        write_atomic(path, json.dumps(self.trace(), separators=(",", ":")) + "\n")

    def objects_in_workspaces(self, scenario: Scenario, plans: PlanSet) -> dict[str, bool]:
        """For every drop event of the plans' missions: is its object in its workspace now?"""
        scenario = plans.extend(scenario)
        out = {}
        for plan in plans.robots.values():
            for event in plan.events:
                if event.kind == "drop":
                    (x, y), by = self.objects[event.obj]
                    size = scenario.scene.objects[event.obj].size
                    out[event.obj] = by is None and scenario.scene.workspaces[event.workspace].holds(
                        x, y, size, 1e-6
                    )
        return out


# ----------------------------------------------------------------------------------------------
# The world
# ----------------------------------------------------------------------------------------------


class _Agent:
    """One robot's executor: where it is in its plan and what it is doing (mutable)."""

    def __init__(self, rid: str, index: int, steps: tuple[Step, ...], mission: tuple[Event, ...]) -> None:
        self.id = rid
        self.index = index
        self.steps = list(steps)
        self.mission = list(mission)
        self.k = 0  # the step being executed
        self.instants: list[int | None] = list(range(1, len(self.steps) + 1))  # in the plan file
        self.began = 0.0  # when the current step started, s
        self.log: list[tuple[int | None, str, float, float]] = []  # the steps done: instant, label, times
        self.phase = "start"  # of driving: start, drive, turn
        self.stage: str | None = None  # of docking: approach, dock, handle
        self.path: GlobalPath | None = None
        self.seat: tuple[float, float] | None = None  # the plan's segment start to creep back to
        self.anchor: tuple[int, tuple] | None = None  # (step, pose): where a replan starts that step
        self.goal: tuple[float, float, float] | None = None
        self.timer = 0.0
        self.grip: int | None = None  # object index touched by the gripper
        self.best = math.inf  # path left at the last progress
        self.room = math.inf  # clearance of the current goal
        self.left = 0.0  # path left while driving (0 otherwise: the right of way)
        self.detour_until = 0.0
        self.since = 0.0  # time of the last progress
        self.waiting = False
        self.answered: dict[str, int] = {}  # Res sent per object
        self.exit: tuple[float, float] | bool | None = None  # where it creeps out of touch (False: none)

    @property
    def done(self) -> bool:
        return self.k >= len(self.steps)

    @property
    def step(self) -> Step:
        return self.steps[self.k]


class _World:
    """The state of a running simulation; :func:`simulate` drives it."""

    def __init__(self, scenario: Scenario, plans: PlanSet, seed: int, settings: SimSettings) -> None:
        scene = scenario.scene
        self.scenario = scenario
        self.settings = settings
        self.rids = tuple(scene.robots)
        self.oids = tuple(scene.objects)
        humans = getattr(scene, "humans", {})
        self.hids = tuple(humans)
        R = len(self.rids)
        self.walls = segment_array([(w.start, w.end) for w in scene.obstacles])
        robots = [scene.robots[r] for r in self.rids]
        self.half = np.array([r.size / 2.0 for r in robots])
        dyn = [r.dynamics for r in robots]
        self.dynamics = dyn
        cycles = {d.cycle for d in dyn}
        if len(cycles) != 1:
            raise ValueError("every robot must share one control cycle")
        self.dt = cycles.pop()
        self.limits = np.array(
            [[d.max_speed, d.acceleration, d.braking, math.radians(d.turn_rate), d.cycle] for d in dyn]
        ).reshape(R, 5)
        self.pose = np.array([[r.pose[0], r.pose[1], math.radians(r.pose[2])] for r in robots]).reshape(R, 3)
        self.v = np.zeros(R)
        self.w = np.zeros(R)
        self.distance = np.zeros(R)
        self.obj_pos = np.array([scene.objects[o].position for o in self.oids], dtype=float).reshape(-1, 2)
        self.obj_half = np.array([scene.objects[o].size / 2.0 for o in self.oids])
        self.carried_by = np.full(len(self.oids), -1)
        rng = np.random.default_rng(seed)
        self.walkers = [Walker(humans[h], self.walls, rng) for h in self.hids]
        self.human_half = np.array([w.half for w in self.walkers])
        self.human_speed = np.array([humans[h].speed for h in self.hids])
        self.robot_speed = self.limits[:, 0].copy()
        self.agents = []
        for i, rid in enumerate(self.rids):
            plan = plans.robots.get(rid)
            steps = plan.steps if plan is not None else ()
            events = plan.events if plan is not None else ()
            self.agents.append(_Agent(rid, i, steps, events))
        self.inbox: set[str] = set()  # the message events sent
        self.events: list[tuple[float, str, str]] = [  # (t, robot, event) as the robots do them
            (0.0, a.id, f"return({a.id})")
            for a in self.agents
            if a.done and any(e.kind == "return" for e in a.mission)
        ]
        self.messages: list[Message] = []
        self.contacts: list[Contact] = []
        self.touching: dict[tuple[int, str], int] = {}  # pair -> index in contacts
        self.replans = 0
        self.replan_attempts = 0
        self.replan_log: list[dict[str, Any]] = []  # every replan: time, robot, accepted, messages
        self.conflict_names = {m.event for m in plans.messages if m.kind == "conflict"}
        self.used_names = {
            name for p in plans.robots.values() for name in p.mission if name.startswith("msg(")
        }
        self.detours = 0
        self.t = 0.0

    # -- obstacles ---------------------------------------------------------------------------

    def boxes(self) -> tuple[np.ndarray, np.ndarray, list[str]]:
        """Resting objects, robots and people as boxes ``x, y, half``, their speed bounds, names."""
        resting = np.flatnonzero(self.carried_by < 0)
        parts = [
            np.column_stack([self.obj_pos[resting], self.obj_half[resting]]),
            np.column_stack([self.pose[:, :2], self.half]),
        ]
        speeds = [np.zeros(len(resting)), np.where(self.parked(), 0.0, self.robot_speed)]
        names = [self.oids[j] for j in resting] + list(self.rids)
        if self.walkers:
            parts.append(np.column_stack([np.array([w.position for w in self.walkers]), self.human_half]))
            speeds.append(self.human_speed)
            names += list(self.hids)
        return np.vstack(parts).reshape(-1, 3), np.concatenate(speeds), names

    def parked(self) -> np.ndarray:
        """Which robots are parked: standing and promising not to move (their V is 0).

        A robot that has finished, waits for a message or lets its gripper work stands still,
        and it leaves that state only when no other robot is within the standoff
        (:meth:`crowded`).  The others may therefore treat it like a wall: come close, dock
        beside it, and leave again -- two robots that touch could otherwise never part.
        """
        return np.array(
            [(a.done or a.waiting or a.stage == "handle") and self.v[a.index] == 0 for a in self.agents],
            dtype=bool,
        )

    def crowded(self, i: int) -> bool:
        """Whether robot `i` must stay parked: another robot that may still move is within its
        standoff.  A robot that has finished never moves again and does not count; of two parked
        robots close together the one listed first may leave (the other keeps its promise), so
        that two waiting robots never hold each other for ever."""
        gaps = box_gaps(self.pose[i, :2], self.half[i], np.column_stack([self.pose[:, :2], self.half]))
        gaps[i] = np.inf
        parked = self.parked()
        for agent in self.agents:
            if agent.done or (parked[agent.index] and agent.index > i):
                gaps[agent.index] = np.inf
        return bool((gaps < self.settings.dwa.standoff).any())

    def box_velocity(self, names: list[str]) -> np.ndarray:
        """Current velocities (mm/s) of the boxes of :meth:`boxes`: sensed, for prediction only."""
        vel = np.zeros((len(names), 2))
        n_obj = len(names) - len(self.rids) - len(self.walkers)
        heading = self.pose[:, 2]
        vel[n_obj : n_obj + len(self.rids)] = np.column_stack(
            [self.v * np.cos(heading), self.v * np.sin(heading)]
        )
        for k, walker in enumerate(self.walkers):
            vel[n_obj + len(self.rids) + k] = walker.velocity
        return vel

    def box_accel(self, names: list[str]) -> np.ndarray:
        """Acceleration limits of the boxes of :meth:`boxes` (objects 0, people unknown: inf)."""
        acc = np.zeros(len(names))
        n_obj = len(names) - len(self.rids) - len(self.walkers)
        acc[n_obj : n_obj + len(self.rids)] = np.where(self.parked(), 0.0, self.limits[:, 1])
        acc[n_obj + len(self.rids) :] = np.inf
        return acc

    def static_gaps(self, points: np.ndarray, half: float) -> np.ndarray:
        """L-infinity gaps (mm) of squares of half side `half` at `points` to walls and resting objects."""
        points = np.asarray(points, dtype=float).reshape(-1, 2)
        gap = np.full(len(points), np.inf)
        if len(self.walls):
            gap = np.minimum(gap, (point_segment_linf(points, self.walls) - half).min(axis=1))
        keep = self.carried_by < 0
        if keep.any():
            boxes = np.column_stack([self.obj_pos[keep], self.obj_half[keep]])
            gap = np.minimum(gap, box_gaps(points, half, boxes).min(axis=1))
        return gap

    def static_boxes(self, robot: int, goal: tuple[float, ...] | None = None) -> np.ndarray:
        """What the global path of robot `robot` avoids: resting objects and parked robots.

        A robot that waits for a message, docks, handles an object or has finished stands
        still for a while, so the others plan around it instead of queueing behind it.
        """
        keep = self.carried_by < 0
        boxes = [np.column_stack([self.obj_pos[keep], self.obj_half[keep]])]
        parked = [
            a.index
            for a in self.agents
            if a.index != robot and (a.done or a.waiting or a.stage is not None) and self.v[a.index] == 0
        ]
        if parked:
            half = self.half[parked].copy()
            if goal is not None:
                # A parked robot stops up to the goal tolerance from its own goal, so a goal
                # planned right beside it may lie a little inside: shrink that one, so that
                # the goal stays reachable (the path is a guide; the dynamic window keeps the
                # real distance).
                reach = np.abs(self.pose[parked, :2] - np.asarray(goal[:2])).max(axis=1)
                inside = reach < half + self.half[robot]
                half[inside] = np.minimum(half[inside], np.maximum(reach[inside] - self.half[robot], 1.0))
            boxes.append(np.column_stack([self.pose[parked, :2], half]))
        return np.vstack(boxes).reshape(-1, 3)

    # -- messages ----------------------------------------------------------------------------

    def send(self, agent: _Agent, step: Step) -> None:
        """Send the message of a ``Res`` step: its ``msg``, or the next ``away`` answer about its
        object (the k-th Res(O) answers the k-th away(O, *, sender) of the mission)."""
        if step.message is not None:
            event = parse_event(step.message)
        else:
            answers = [
                e for e in agent.mission if e.kind == "away" and e.obj == step.object and e.sender == agent.id
            ]
            sent = agent.answered.get(step.object, 0)
            agent.answered[step.object] = sent + 1
            event = answers[min(sent, len(answers) - 1)]
        self.messages.append(Message(round(self.t, 6), agent.id, event.receiver, event.obj, event.name))
        self.inbox.add(event.name)
        self.events.append((round(self.t, 6), agent.id, event.name))

    def record(self, agent: _Agent, step: Step) -> None:
        """Log the mission events a finished step realises (the executed word of the run)."""
        done = {name for _, robot, name in self.events if robot == agent.id}
        if step.primitive == "PickUp":
            wanted = [e for e in agent.mission if e.kind == "pick" and e.obj == step.object]
        elif step.primitive == "DropOff":
            x, y = self.obj_pos[self.oids.index(step.object)]
            scene = self.scenario.scene
            size = scene.objects[step.object].size
            wanted = [
                e
                for e in agent.mission
                if e.kind == "drop"
                and e.obj == step.object
                and scene.workspaces[e.workspace].holds(x, y, size, 1e-6)
            ]
        elif step.primitive == "Req":
            wanted = [e for e in agent.mission if e.name in self.inbox and e.receiver == agent.id]
            wanted = [
                e for e in wanted if step.message == e.name or (step.message is None and e.obj == step.object)
            ]
        else:
            wanted = []
        event = next((e for e in wanted if e.name not in done), None)
        if event is not None:
            self.events.append((round(self.t, 6), agent.id, event.name))
            done.add(event.name)
        # ``return`` holds as soon as the robot is home with the events before it done (as in
        # the plan: messages it sends from home come after it)
        pending = next((e for e in agent.mission if e.name not in done), None)
        if pending is not None and pending.kind == "return":
            home = self.scenario.scene.robots[agent.id].pose
            if math.dist(self.pose[agent.index, :2], home[:2]) <= self.settings.goal_tolerance + 1e-6:
                self.events.append((round(self.t, 6), agent.id, pending.name))

    def received(self, agent: _Agent, step: Step) -> bool:
        """Whether the message a ``Req`` step waits for has been sent."""
        if step.message is not None:
            return step.message in self.inbox
        return any(
            e.name in self.inbox
            for e in agent.mission
            if e.kind == "away" and e.obj == step.object and e.receiver == agent.id
        )


def _wrap(angle: np.ndarray | float) -> np.ndarray | float:
    return (np.asarray(angle) + math.pi) % (2 * math.pi) - math.pi


# ----------------------------------------------------------------------------------------------
# The executor: one cycle's decision per robot
# ----------------------------------------------------------------------------------------------


def _decide(world: _World, agent: _Agent) -> tuple[str, Any]:
    """What `agent` does this cycle: ``("drive", (target, stop))``, ``("move", (v, w))`` or
    ``("dock", pose)``."""
    i = agent.index
    brake = _brake(world, i)
    while not agent.done:
        step = agent.step
        prim = step.primitive
        if prim == "GoTo":
            action = _goto(world, agent, step)
        elif prim in ("PickUp", "DropOff"):
            action = _handle(world, agent, step)
        elif prim == "Req":
            agent.waiting = True
            if world.v[i] > 0:
                return brake
            if world.received(agent, step) and not world.crowded(i):
                agent.waiting = False
                action = None
            else:
                return brake
        else:  # Res
            if world.v[i] > 0:
                return brake
            world.send(agent, step)
            action = None
        if action is not None:
            return action
        agent.log.append((agent.instants[agent.k], step.label, agent.began, world.t))
        agent.began = world.t
        agent.k += 1  # the step is done
        world.record(agent, step)
        agent.left = 0.0
        agent.phase = "start"
        agent.stage = None
        agent.waiting = False
        agent.path = None
        agent.exit = None
    return brake


def _brake(world: _World, i: int) -> tuple[str, Any]:
    """Robot `i`'s command to brake with :math:`-b` (the always-safe choice), not turning."""
    return ("move", (max(0.0, world.v[i] - world.limits[i, 2] * world.dt), 0.0))


def _goto(world: _World, agent: _Agent, step: Step) -> tuple[str, Any] | None:
    last = agent.k + 1 >= len(agent.steps) or agent.steps[agent.k + 1].primitive != "GoTo"
    goal = step.robot
    # a waypoint from which the plan approaches a pose that touches something is reached, not
    # passed: cutting its corner would cut into what that pose touches
    stop = last or bool(
        world.static_gaps(agent.steps[agent.k + 1].robot[:2], world.half[agent.index])[0]
        < world.settings.leave_gap
    )
    if agent.anchor is not None and agent.anchor[0] == agent.k:  # a replan's first step
        origin = agent.anchor[1]
    else:
        origin = agent.steps[agent.k - 1].robot if agent.k > 0 else None
    if agent.exit is not False:  # at the start, and after creeping back onto the plan's segment
        action = _get_out(world, agent, goal)
        if action is not None:
            return action
    return _drive(world, agent, goal, stop, heading=last, origin=origin)


def _route(world: _World, i: int, goal: tuple, origin: tuple | None) -> tuple[GlobalPath, tuple | None]:
    """The global path to `goal` (the plan's own segment where the robot can follow it), and
    the segment's start when the path goes back to it first (``None`` otherwise).

    Straight from where the robot is, unless that is blocked or only grazes an obstacle; else
    back onto the plan's segment at its `origin` (an intermediate waypoint passed within the
    tolerance, or a replan's rounded start, leaves the robot beside it) and along it; else
    around what now stands in the way (:func:`cosmop.control.paths.plan_path`).
    """
    xy = world.pose[i, :2]
    here, boxes = (float(xy[0]), float(xy[1])), world.static_boxes(i, goal)
    half, target = float(world.half[i]), (goal[0], goal[1])
    path = straight_path(here, target, half, world.walls, boxes)
    # a way from here that only grazes an obstacle (margin under a millimetre) may in truth cut
    # into it by a fraction of one: the plan's own segment is proved free, so go by it
    tight = path is None or path.margin < _GRAZE
    if tight and origin is not None and math.dist(here, origin[:2]) > 1e-9:
        back = straight_path(here, (origin[0], origin[1]), half, world.walls, boxes)
        on = straight_path((origin[0], origin[1]), target, half, world.walls, boxes)
        if back is not None and on is not None:
            start = (origin[0], origin[1])
            return GlobalPath((here, start, target), min(back.margin, on.margin)), start
    path = path or plan_path(here, target, half, world.walls, boxes) or GlobalPath((here, target), 0.0)
    return path, None


def _reseat(world: _World, agent: _Agent) -> tuple[str, Any] | None:
    """Creep straight back onto the start of the plan's segment, turned along it; ``None`` once there.

    A robot stops within a tolerance of its waypoint, and the plan's next segment may touch a
    wall (the plan allows touching): a few millimetres off it, or turned a few degrees towards
    the wall, the robot's first move along that segment runs into the corner, and the
    controller, aiming along the path, never finds the sideways move out.  The docking creep
    is that move: straight, slow, exact at the end.
    """
    i = agent.index
    (sx, sy), (tx, ty) = agent.seat, agent.path.points[-1]
    heading = math.atan2(ty - sy, tx - sx)
    if math.dist(world.pose[i, :2], (sx, sy)) <= 1e-9 and abs(_wrap(heading - world.pose[i, 2])) <= 1e-9:
        agent.seat = None
        agent.exit = None  # the segment's start may touch what the segment leaves: creep out first
        agent.path = GlobalPath(agent.path.points[1:], agent.path.margin)
        agent.since = world.t
        return None
    return _creep(world, agent, (sx, sy), heading)


def _drive(
    world: _World,
    agent: _Agent,
    goal: tuple[float, float, float],
    final: bool,
    heading: bool,
    origin: tuple | None = None,
) -> tuple[str, Any] | None:
    """Drive towards `goal`; ``None`` once it is reached (and turned to, if `heading`)."""
    s = world.settings
    i = agent.index
    xy = world.pose[i, :2]
    fresh = agent.phase == "start" or agent.path is None
    if fresh:
        agent.path, back = _route(world, i, goal, origin)
        near = back is not None and math.dist(xy, back) <= s.pass_tolerance + s.goal_tolerance
        agent.seat = back if near else None
        agent.phase = "drive"
        agent.room = float(world.static_gaps(goal[:2], world.half[i])[0])
        agent.best = math.inf
        agent.since = world.t
    dist = math.hypot(goal[0] - xy[0], goal[1] - xy[1])
    tolerance = s.goal_tolerance if final else s.pass_tolerance
    if final and agent.phase == "drive" and dist > tolerance:
        action = _get_in(world, agent, goal, dist)
        if action is not None:
            return action
    if agent.phase == "drive" and dist <= tolerance:
        if not final:
            return None
        agent.phase = "turn"
    if agent.phase == "turn":
        if world.v[i] > 0:
            return _brake(world, i)
        if not heading:
            return None
        error = float(_wrap(math.radians(goal[2]) - world.pose[i, 2]))
        if abs(math.degrees(error)) <= s.heading_tolerance:
            return None
        w = max(-world.limits[i, 3], min(world.limits[i, 3], error / world.dt))
        return ("move", (0.0, w))
    if agent.seat is not None:
        action = _reseat(world, agent)
        if action is not None:  # (waiting for someone to pass counts towards a stall)
            waited = action[0] == "move" and world.t - agent.since > s.stall_time
            return (_stall(world, agent) or action) if waited else action
    target, left = agent.path.lookahead((float(xy[0]), float(xy[1])), s.dwa.lookahead)
    agent.left = left
    if left < agent.best - s.stall_progress:
        agent.best = left
        agent.since = world.t
    elif world.t - agent.since > s.detour_time and world.t >= agent.detour_until:
        _detour(world, agent, goal)
    elif world.t - agent.since > s.stall_time:
        action = _stall(world, agent)
        if action is not None:
            return action
    stop = left if final else math.inf
    return ("drive", (target, stop, agent.room))


def _stall(world: _World, agent: _Agent) -> tuple[str, Any] | None:
    """No progress for ``stall_time``: replan (:func:`_stalled`); a new plan's first decision."""
    _stalled(world, agent)
    agent.since = world.t
    agent.best = math.inf
    return _decide(world, agent) if agent.phase == "start" else None


def _get_in(world: _World, agent: _Agent, goal: tuple[float, ...], dist: float) -> tuple[str, Any] | None:
    """The last few millimetres onto a final pose beside a wall or resting object: creep there.

    The dynamic window stops a braking distance short of what it approaches, and a pose that
    touches something (a docking pose, a home against a wall) lies right there; within
    ``dock_tolerance`` of it the docking creep, straight and exact, takes over when its way is
    clear (``None`` otherwise: the window drives on).
    """
    s = world.settings
    i = agent.index
    if dist > s.dock_tolerance or float(world.static_gaps(goal[:2], world.half[i])[0]) >= s.leave_gap:
        return None
    pose = (goal[0], goal[1], math.degrees(float(world.pose[i, 2])))
    if not _dock_safe(world, i, agent, pose):
        return None
    return _brake(world, i) if world.v[i] > 0 else ("dock", pose)


def _detour(world: _World, agent: _Agent, goal: tuple[float, float, float]) -> None:
    """Plan the global path again, around the robots that block this one and have the right of way.

    Two driving robots can block each other for ever, each waiting for the other to clear
    its path.  The one with more path left yields: it plans its global path around the other
    (as if that one stood still) for a while.  Ties go to the robot listed first.  Without
    such blockers the path is simply planned again (parked robots come and go).
    """
    s = world.settings
    i = agent.index
    agent.detour_until = world.t + s.detour_time
    gaps = box_gaps(world.pose[i, :2], world.half[i], np.column_stack([world.pose[:, :2], world.half]))
    parked = world.parked()  # (already in the static boxes)
    blockers = [
        j
        for j, other in enumerate(world.agents)
        if j != i
        and not parked[j]
        and gaps[j] < s.sense_range
        and (other.left < agent.left or (other.left == agent.left and j < i))
    ]
    xy = (float(world.pose[i, 0]), float(world.pose[i, 1]))
    boxes = np.vstack(
        [world.static_boxes(i, goal), np.column_stack([world.pose[blockers, :2], world.half[blockers]])]
    )
    path = plan_path(xy, (goal[0], goal[1]), float(world.half[i]), world.walls, boxes)
    if path is None:
        return
    world.detours += int(bool(blockers))
    agent.path, agent.seat = path, None
    agent.best = path.length


def _handle(world: _World, agent: _Agent, step: Step) -> tuple[str, Any] | None:
    """PickUp or DropOff: dock, then let the gripper work."""
    s = world.settings
    i = agent.index
    j = world.oids.index(step.object)
    gap = world.half[i] + world.obj_half[j]
    heading = float(step.robot[2]) % 360.0
    if step.primitive == "PickUp":  # where the object is now, from the side the plan faces
        dock = (*map(float, docking_pose(world.obj_pos[j], gap, heading)), heading)
    else:
        dock = (float(step.robot[0]), float(step.robot[1]), heading)
    if agent.stage is None:
        offset = math.hypot(dock[0] - world.pose[i, 0], dock[1] - world.pose[i, 1])
        agent.stage = "dock" if offset <= s.dock_tolerance else "approach"
    if agent.stage == "approach":  # not where the plan said: drive to the docking pose first
        action = _drive(world, agent, dock, final=True, heading=True)
        if action is not None:
            return action
        agent.stage = "dock"
    if agent.stage == "dock":
        if step.primitive == "PickUp":
            agent.grip = j
        if world.v[i] > 0:
            return _brake(world, i)
        offset = math.hypot(dock[0] - world.pose[i, 0], dock[1] - world.pose[i, 1])
        error = abs(float(_wrap(math.radians(heading) - world.pose[i, 2])))
        there = offset < 1e-9 and error < 1e-9
        if not there and _dock_safe(world, i, agent, dock):
            return ("dock", dock)
        reach = s.reach if step.primitive == "PickUp" else 0.0  # a drop goes exactly where planned
        if not there and (offset > reach or error > math.radians(s.heading_tolerance)):
            return ("move", (0.0, 0.0))  # blocked: wait (the gripper cannot reach from here)
        if step.primitive == "DropOff" and not _drop_clear(world, i, j, _drop_spot(world, agent, step, j)):
            return ("move", (0.0, 0.0))
        agent.stage = "handle"
        agent.timer = s.handling_time
    if agent.stage == "handle":
        agent.timer -= world.dt
        if agent.timer > 1e-9 or world.crowded(i):
            return ("move", (0.0, 0.0))
        if step.primitive == "PickUp":
            world.carried_by[j] = i
            agent.grip = None
            return None
        world.obj_pos[j] = _drop_spot(world, agent, step, j)
        world.carried_by[j] = -1
        agent.grip = j  # touching it where the plan stands, until it creeps out (_get_out)
        return None
    return ("move", (0.0, 0.0))


_EXIT_HEADINGS = np.radians(np.arange(0.0, 360.0, 5.0))
_EXIT_REACH = 80  # mm: how far a way out is looked for


def _way_out(world: _World, i: int, toward: np.ndarray, gap: float) -> tuple[float, float] | None:
    """The nearest point straight out from robot `i` at `gap` (mm) from everything static, or ``None``.

    Headings every 5 degrees and distances every millimetre up to :data:`_EXIT_REACH` are
    tried; the way to the point must not touch a wall or resting object.  Of the points within
    2 mm of the nearest, the one most towards `toward` is taken.
    """
    xy, half = world.pose[i, :2], float(world.half[i])
    units = np.column_stack([np.cos(_EXIT_HEADINGS), np.sin(_EXIT_HEADINGS)])
    steps = np.arange(1.0, _EXIT_REACH + 1.0)
    points = xy[None, None, :] + steps[:, None, None] * units[None, :, :]  # (distance, heading, 2)
    flat = points.reshape(-1, 2)
    # never touching on the way (the first millimetre already opens every gap that is shut):
    # creeping along a face it touches would be a contact while moving
    gaps = world.static_gaps(flat, half).reshape(len(steps), len(units))
    good = np.logical_and.accumulate(gaps > _TOUCH, axis=0) & (gaps >= gap)
    if not good.any():
        return None
    first = np.where(good.any(axis=0), good.argmax(axis=0), len(steps))
    distance = np.where(first < len(steps), steps[np.minimum(first, len(steps) - 1)], np.inf)
    aim = np.asarray(toward, dtype=float) - xy
    towards = units @ (aim / max(float(np.hypot(*aim)), 1e-9))
    best = int(np.argmin(np.where(distance <= distance.min() + 2.0, -towards, np.inf)))
    x, y = points[first[best], best]
    return (float(x), float(y))


def _creep(
    world: _World, agent: _Agent, point: tuple[float, float], heading: float | None = None
) -> tuple[str, Any]:
    """The docking creep straight to `point`, turning to `heading` (rad; default: keep it);
    brake first, or wait while something passes."""
    i = agent.index
    if world.v[i] > 0:
        return _brake(world, i)
    turn = float(world.pose[i, 2]) if heading is None else heading
    pose = (point[0], point[1], math.degrees(turn))
    if _dock_safe(world, i, agent, pose):
        return ("dock", pose)
    return ("move", (0.0, 0.0))  # something passes: wait for it


def _get_out(world: _World, agent: _Agent, goal: tuple[float, float, float]) -> tuple[str, Any] | None:
    """Before driving off a pose that touches a wall or resting object, creep clear of it.

    A plan may start a motion touching what it then leaves (a docking pose, a home against a
    wall), and a controller cannot drive off along a face it touches: it first creeps straight
    out (:func:`_way_out`, towards the goal where it can) to ``leave_gap`` from everything
    static.  ``None`` when there is nothing to leave or once out.
    """
    s = world.settings
    i = agent.index
    half = world.half[i]
    if agent.exit is None:
        agent.exit = False
        if float(world.static_gaps(world.pose[i, :2], half)[0]) < s.leave_gap:
            agent.exit = _way_out(world, i, np.asarray(goal[:2]), s.leave_gap) or False
    if agent.exit is False or math.dist(world.pose[i, :2], agent.exit) <= 1e-9:
        agent.exit = False
        return None
    return _creep(world, agent, agent.exit)


def _drop_spot(world: _World, agent: _Agent, step: Step, j: int) -> np.ndarray:
    """Where the gripper puts object `j` down: where the plan puts it (within reach of the robot)."""
    planned = step.objects.get(world.oids[j])
    if planned is not None:
        return np.array(planned.position, dtype=float)
    i = agent.index
    front = in_front(world.pose[i], world.half[i] + world.obj_half[j], float(step.robot[2]) % 360.0)
    return np.array(front, dtype=float)


def _drop_clear(world: _World, i: int, j: int, spot: np.ndarray) -> bool:
    """Whether object `j` may be put at `spot` by robot `i` now.

    A new object must not appear inside another robot's stopping distance (that robot could
    no longer brake in time: passive safety assumes resting obstacles stay where they are) nor
    within the standoff of one that may move, nor on a parked robot or a person.  A parked robot
    does not move while this one is close, and sees the object once it does.
    """
    others = [k for k in range(len(world.rids)) if k != i]
    if others:
        gaps = box_gaps(
            world.pose[others, :2], world.half[others][:, None], np.array([[*spot, world.obj_half[j]]])
        )
        parked = world.parked()
        need = [
            _TOUCH
            if parked[k]
            else stopping_margin(world.v[k], 0.0, world.dynamics[k]) + world.settings.dwa.standoff
            for k in others
        ]
        if (gaps[:, 0] <= np.array(need)).any():
            return False
    if world.walkers:
        people = np.column_stack([np.array([w.position for w in world.walkers]), world.human_half])
        if (box_gaps(spot, world.obj_half[j], people) <= _TOUCH).any():
            return False
    return True


def _stalled(world: _World, agent: _Agent) -> None:
    """Receding horizon: replan the remaining mission with the sensed robots and people."""
    s = world.settings
    if not s.replan:
        return
    i = agent.index
    world.replan_attempts += 1
    boxes, _, names = world.boxes()
    gaps = box_gaps(world.pose[i, :2], world.half[i], boxes)
    # robots keep the clearance the team-safety layer checks, people a little room; a robot that
    # has finished stays where it is for good, however far
    finished = {a.id for a in world.agents if a.done}
    sensed = [
        (float(b[0]), float(b[1]), float(b[2]) + (s.dwa.standoff if n in world.rids else 10.0))
        for b, n, g in zip(boxes, names, gaps, strict=True)
        if n != agent.id and n not in world.oids and (g < s.sense_range or n in finished)
    ]
    done_steps = agent.steps[: agent.k]
    _, todo = _split_mission(world, agent)
    # the mission's own events and messages; messages that kept plans apart are ordered afresh
    remaining = [e for e in todo if e.name not in world.conflict_names and e.name not in world.inbox]
    objects = {}
    for j, oid in enumerate(world.oids):
        carried = world.carried_by[j] == i
        away = world.carried_by[j] >= 0 and not carried
        away = away or any(st.primitive == "Req" and st.object == oid for st in done_steps)
        pos = world.obj_pos[j]
        objects[oid] = ObjectState(
            (round(float(pos[0])), round(float(pos[1]))), carried=bool(carried), away=away
        )
    x, y, h = world.pose[i]
    start = State((round(float(x)), round(float(y)), round(math.degrees(float(h)))), objects)
    # A replan should not be much longer than what is left of the plan: bound the search there
    # (an infeasible replan -- a blocked doorway -- would otherwise search every horizon).
    horizon = min(s.max_horizon, len(agent.steps) - agent.k + 4)
    plan = replan(
        world.scenario.scene,
        agent.id,
        remaining,
        start,
        sensed,
        max_horizon=horizon,
        rlimit=s.rlimit,
    )
    if plan is None:
        world.replan_log.append(
            {"t": round(world.t, 6), "robot": agent.id, "accepted": False, "why": "no plan"}
        )
        return
    accepted, why, added = _recoordinate(world, agent, plan, start)
    world.replan_log.append(
        {
            "t": round(world.t, 6),
            "robot": agent.id,
            "accepted": accepted,
            "why": why or None,
            "messages": added,
        }
    )
    if accepted:
        world.replans += 1


def _split_mission(world: _World, agent: _Agent) -> tuple[list[Event], list[Event]]:
    """The agent's mission events done (by its completed steps) and those still to do."""
    plan = RobotPlan.from_steps([e.name for e in agent.mission], agent.steps)
    instants = event_instants(plan, agent.id, world.scenario.scene)
    done = [e for e, t in zip(agent.mission, instants, strict=True) if t is not None and t <= agent.k]
    return done, agent.mission[len(done) :]


def _state_now(world: _World, agent: _Agent) -> State:
    """Where the agent is (mm, degrees) and the objects as its plan sees them now."""
    i = agent.index
    if agent.k > 0:
        objects = agent.steps[agent.k - 1].objects
    else:
        objects = initial_state(world.scenario.scene, agent.id).objects
    x, y, h = world.pose[i]
    return State((float(x), float(y), math.degrees(float(h))), objects)


def _recoordinate(world: _World, agent: _Agent, new: RobotPlan, start: State) -> tuple[bool, str, list[str]]:
    """Order the rest of every plan again around the agent's new one (:mod:`cosmop.sim.recoordinate`)."""
    rests = {}
    for other in world.agents:
        if other is agent:
            rests[other.id] = Remaining(new.steps, new.mission, start)
        else:
            _, todo = _split_mission(world, other)
            rests[other.id] = Remaining(
                tuple(other.steps[other.k :]), tuple(e.name for e in todo), _state_now(world, other)
            )
    positions = {
        oid: None if world.carried_by[j] >= 0 else tuple(float(v) for v in world.obj_pos[j])
        for j, oid in enumerate(world.oids)
    }
    result = recoordinate(
        world.scenario.scene,
        rests,
        agent.id,
        sent=world.inbox,
        conflict_messages=world.conflict_names,
        used=world.used_names,
        positions=positions,
    )
    if not result.accepted:
        return False, result.reason or "", []
    for other in world.agents:
        done, _ = (
            _split_mission(world, other) if other is not agent else (_split_mission(world, other)[0], None)
        )
        plan = result.plans[other.id]
        current = other.steps[other.k] if other.k < len(other.steps) else None
        kept = [] if other is agent else other.steps[other.k :]  # a new plan's steps were never planned
        carried = carry_instants(kept, other.instants[other.k :], plan.steps)
        other.instants = other.instants[: other.k] + carried
        other.steps = other.steps[: other.k] + list(plan.steps)
        other.mission = list(done) + [parse_event(e) for e in plan.mission]
        if other is agent or (other.k < len(other.steps) and other.steps[other.k] != current):
            other.phase, other.stage, other.path, other.exit = "start", None, None, None
        if other is agent:  # its new plan starts where it stood, rounded to the millimetre
            other.anchor = (other.k, start.robot)
    added = [m.event for m in result.messages]
    world.conflict_names |= set(added)
    return True, "", added


# ----------------------------------------------------------------------------------------------
# One cycle of physics and monitoring
# ----------------------------------------------------------------------------------------------


def _integrate(world: _World, v_cmd: np.ndarray, w_cmd: np.ndarray, docks: dict[int, tuple]) -> np.ndarray:
    """Move every robot for one cycle towards the speed `v_cmd`, turning at `w_cmd`.

    A robot slows down by braking at :math:`-b` until it reaches the commanded speed, then holds
    it (the control passive safety assumes: a stop from :math:`v < b\\varepsilon` takes
    :math:`v^2/2b`, not the :math:`v\\varepsilon/2` of a ramp spread over the cycle); it speeds
    up at a constant acceleration over the cycle (at most :math:`A`).  The distance of each
    sub-step is exact; its heading is the sub-step's midpoint heading.

    Returns each robot's translational speed at the end of the cycle, mm/s: what the monitor
    calls moving.  A docking creep is a stop-and-go no faster than one cycle's braking, so the
    robot is at rest at the start of every docking cycle and moving until it is on the pose.
    """
    dt = world.dt
    acc, brk = world.limits[:, 1], world.limits[:, 2]
    v0 = world.v
    v1 = np.clip(v_cmd, np.maximum(0.0, v0 - brk * dt), v0 + acc * dt)
    v1 = np.minimum(v1, world.limits[:, 0])
    slowing = v1 < v0
    reached = np.where(slowing, (v0 - v1) / np.maximum(brk, 1e-9), dt)  # when v1 is reached, s

    def covered(t: float) -> np.ndarray:
        """Distance (mm) from the cycle's start to time `t` within it."""
        ramp = v0 * t + (v1 - v0) * t * t / (2.0 * dt)
        tb = np.minimum(t, reached)
        braked = v0 * tb - brk * tb * tb / 2.0 + v1 * np.maximum(t - reached, 0.0)
        return np.where(slowing, braked, ramp)

    start = world.pose[:, :2].copy()
    n = 4
    for k in range(n):
        step = covered((k + 1) * dt / n) - covered(k * dt / n)
        theta = world.pose[:, 2] + w_cmd * dt / (2 * n)
        world.pose[:, 0] += step * np.cos(theta)
        world.pose[:, 1] += step * np.sin(theta)
        world.pose[:, 2] += w_cmd * dt / n
    world.pose[:, 2] = _wrap(world.pose[:, 2])
    world.v = v1
    world.w = w_cmd.copy()
    moving = v1.copy()
    for i, dock in docks.items():  # the docking controller: straight, slow, exact at the end
        x, y, h = world.pose[i]
        dx, dy = dock[0] - x, dock[1] - y
        dist = math.hypot(dx, dy)
        # Creep no faster than the robot can stop within one cycle: it halts exactly on the pose.
        step = min(world.settings.dock_speed, world.limits[i, 2] * dt) * dt
        if dist <= step:
            world.pose[i, 0], world.pose[i, 1] = dock[0], dock[1]
        else:
            world.pose[i, 0] += dx * step / dist
            world.pose[i, 1] += dy * step / dist
        error = float(_wrap(math.radians(dock[2]) - h))
        turn = world.limits[i, 3] * dt
        world.pose[i, 2] = math.radians(dock[2]) if abs(error) <= turn else h + math.copysign(turn, error)
        world.v[i] = 0.0
        world.w[i] = 0.0
        moving[i] = 0.0 if dist <= step else step / dt
    world.distance += np.hypot(*(world.pose[:, :2] - start).T)
    return moving


def _monitor(world: _World, moving_speed: np.ndarray) -> None:
    """Record contacts: new touching pairs, and whether the robot moves while touching."""
    boxes, _, names = world.boxes()
    wall_gap, box_gap = robot_gaps(world.pose[:, :2], world.half, world.walls, boxes, None)
    now: set[tuple[int, str]] = set()
    for i, agent in enumerate(world.agents):
        for w in np.flatnonzero(wall_gap[i] <= _TOUCH):
            now.add((i, f"wall {int(w)}"))
        for b in np.flatnonzero(box_gap[i] <= _TOUCH):
            name = names[b]
            if name == agent.id:
                continue
            gripped = agent.grip is not None and name == world.oids[agent.grip]
            if gripped and box_gap[i, b] >= -_TOUCH:
                continue  # the gripper's contact with its own object
            now.add((i, name))
        if agent.grip is not None and world.carried_by[agent.grip] < 0 and agent.stage is None:
            j = agent.grip
            sep = box_gaps(
                world.pose[i, :2], world.half[i], np.array([[*world.obj_pos[j], world.obj_half[j]]])
            )
            if float(sep[0]) > 1.0:
                agent.grip = None
    for pair in list(world.touching):
        if pair not in now:
            del world.touching[pair]
    for pair in now:
        moving = bool(moving_speed[pair[0]] > 0)
        if pair not in world.touching:
            world.touching[pair] = len(world.contacts)
            world.contacts.append(Contact(round(world.t, 6), world.rids[pair[0]], pair[1], moving))
        elif moving and not world.contacts[world.touching[pair]].moving:
            c = world.contacts[world.touching[pair]]
            world.contacts[world.touching[pair]] = Contact(c.t, c.robot, c.other, True)


# ----------------------------------------------------------------------------------------------
# The entry point
# ----------------------------------------------------------------------------------------------


def simulate(
    scenario: Scenario,
    plans: PlanSet,
    *,
    seed: int = 0,
    settings: SimSettings | None = None,
    on_cycle: Callable[[float, int, int], None] | None = None,
) -> SimResult:
    """Execute a plan set in the scenario's world with moving people; monitor safety.

    Parameters
    ----------
    scenario : Scenario
        The scene (walls, robots with their ``dynamics``, objects, workspaces, ``humans``).
    plans : PlanSet
        A feasible ``cosmop.plan/1`` plan set for the scenario (with its coordination pairs).
    seed : int
        Seeds the people's random walks; the run is deterministic given the seed.
    settings : SimSettings, optional
    on_cycle : callable, optional
        Called every cycle with ``(t, robots done, robots)`` (the CLI's progress bar).

    Returns
    -------
    SimResult
    """
    settings = settings or SimSettings()
    if not plans.feasible:
        raise ValueError(f"the plan set is infeasible: {plans.reason}")
    wall0 = time.perf_counter()
    world = _World(plans.extend(scenario), plans, seed, settings)  # with the places of added tasks
    R, H, n_obj = len(world.rids), len(world.walkers), len(world.oids)
    n_max = math.ceil(settings.max_time / world.dt)
    rec: dict[str, list] = {
        k: [] for k in ("t", "pose", "v", "w", "carrying", "primitive", "waiting", "humans", "objects")
    }
    completed = False
    cycles = 0
    self_mask = None
    _record(world, rec)
    for _ in range(n_max):
        boxes, speeds, names = world.boxes()
        if self_mask is None or self_mask.shape[1] != len(names):
            self_mask = np.array([[n == rid for n in names] for rid in world.rids]).reshape(R, len(names))
        v_cmd = world.v.copy()
        w_cmd = np.zeros(R)
        docks: dict[int, tuple] = {}
        driving, targets, stops, caps = [], [], [], []
        for agent in world.agents:
            kind, arg = _decide(world, agent)
            i = agent.index
            if kind == "drive":
                driving.append(i)
                targets.append(arg[0])
                stops.append(arg[1])
                caps.append(arg[2])
            elif kind == "dock":
                docks[i] = arg
            else:
                v_cmd[i], w_cmd[i] = arg
        if driving:
            idx = np.array(driving)
            grip = np.zeros((len(idx), len(names)), dtype=bool)
            for row, i in enumerate(driving):
                g = world.agents[i].grip
                if g is not None and world.oids[g] in names:  # (a drop this cycle is sensed next cycle)
                    grip[row, names.index(world.oids[g])] = True
            cmd = dwa_commands(
                world.pose[idx],
                world.v[idx],
                world.half[idx],
                world.limits[idx],
                np.array(targets, dtype=float),
                np.array(stops, dtype=float),
                world.walls,
                boxes,
                speeds,
                self_mask[idx],
                settings.dwa,
                grip=grip,
                box_velocity=world.box_velocity(names),
                room_cap=np.array(caps, dtype=float),
                box_accel=world.box_accel(names),
                w_now=world.w[idx],
                agents=np.array([n in world.rids or n in world.hids for n in names], dtype=bool),
            )
            v_cmd[idx] = cmd.v
            w_cmd[idx] = cmd.w
        moving = _integrate(world, v_cmd, w_cmd, docks)
        for walker in world.walkers:
            walker.step(world.dt)
        world.t += world.dt
        cycles += 1
        _monitor(world, moving)
        _record(world, rec)
        done = sum(a.done for a in world.agents)
        if on_cycle is not None:
            on_cycle(world.t, done, R)
        if done == R and not world.v.any():
            completed = True
            break
    frames = {k: np.array(v) for k, v in rec.items()}
    n = len(frames["t"])
    frames["pose"] = frames["pose"].reshape(n, R, 3)
    frames["humans"] = frames["humans"].reshape(n, H, 2)
    frames["objects"] = frames["objects"].reshape(n, n_obj, 2)
    return SimResult(
        scenario=scenario.name,
        completed=completed,
        sim_time_s=world.t,
        wall_time_s=time.perf_counter() - wall0,
        cycles=cycles,
        dt=world.dt,
        contacts=tuple(world.contacts),
        replans=world.replans,
        replan_attempts=world.replan_attempts,
        messages=tuple(world.messages),
        objects={
            oid: (
                tuple(float(x) for x in _object_position(world, j)),
                world.rids[world.carried_by[j]] if world.carried_by[j] >= 0 else None,
            )
            for j, oid in enumerate(world.oids)
        },
        robots={
            rid: (
                (float(world.pose[i, 0]), float(world.pose[i, 1]), math.degrees(float(world.pose[i, 2]))),
                float(world.distance[i]),
            )
            for i, rid in enumerate(world.rids)
        },
        frames=frames,
        finished={a.id: a.done for a in world.agents},
        robot_ids=world.rids,
        human_ids=world.hids,
        object_ids=world.oids,
        events=tuple(world.events),
        added=tuple(e.name for task in plans.added for e in task.events),
        replan_log=tuple(world.replan_log),
        steps=step_times(
            {rid: [s.label for s in p.steps] for rid, p in plans.robots.items()},
            _planned_times(world, plans),
            {a.id: a.log for a in world.agents},
        ),
    )


def _planned_times(world: _World, plans: PlanSet) -> Itinerary | None:
    """The plan set's itinerary, or the expected one for a plan file without times."""
    if plans.itinerary is not None:
        return plans.itinerary
    try:
        return itinerary(world.scenario.scene, plans.robots)
    except ValueError:  # messages that deadlock: no schedule to compare with
        return None


def footprint_overlaps(
    scene, result: SimResult, tolerance: float = 1e-6
) -> list[tuple[float, str, str, float]]:
    """Every recorded instant at which two robots' squares overlap (touching allowed).

    Returns ``(t, robot, other, depth)`` for the first instant of each overlapping pair and
    episode, depth in mm; an empty list for a run in which robots never overlap.
    """
    pose = result.frames["pose"]
    half = np.array([scene.robots[r].size / 2.0 for r in result.robot_ids])
    out = []
    for i in range(len(half)):
        for j in range(i + 1, len(half)):
            gap = np.abs(pose[:, i, :2] - pose[:, j, :2]).max(axis=1) - (half[i] + half[j])
            bad = gap < -tolerance
            starts = np.flatnonzero(bad & ~np.concatenate([[False], bad[:-1]]))
            for n in starts:
                out.append(
                    (float(result.frames["t"][n]), result.robot_ids[i], result.robot_ids[j], float(-gap[n]))
                )
    return sorted(out)


def _dock_safe(world: _World, i: int, agent: _Agent, target: tuple | None = None) -> bool:
    """Passive safety of a slow docking creep, with the gripper's object left out.

    Moving obstacles (robots, people) need the paper's ``safe`` at the creep speed.  Towards a
    docking `target` the creep is a straight move that stops exactly on it, so walls and
    resting objects only need to stay clear of that short segment (touching allowed: a
    docking pose may touch a wall, as the plan allows).
    """
    boxes, speeds, names = world.boxes()
    skip = {agent.id}
    if agent.grip is not None:
        skip.add(world.oids[agent.grip])
    movers = [
        b
        for b, n in enumerate(names)
        if n not in skip and (speeds[b] > 0 or n in world.rids or n in world.hids)
    ]
    still = [b for b, n in enumerate(names) if n not in skip and b not in movers]
    dyn = world.dynamics[i]
    speed = min(world.settings.dock_speed, world.limits[i, 2] * world.dt)
    xy = world.pose[i, :2]
    if movers:
        gaps = box_gaps(xy, world.half[i], boxes[movers])
        now = np.hypot(*world.box_velocity(names)[movers].T)
        bound = obstacle_speed(
            stopping_horizon(speed, dyn), speeds[movers], now, world.box_accel(names)[movers]
        )
        if not np.all(is_safe(gaps, speed, bound, dyn)):
            return False
    if target is None:
        if still and not np.all(is_safe(box_gaps(xy, world.half[i], boxes[still]), speed, 0.0, dyn)):
            return False
        if len(world.walls):
            return bool(np.all(is_safe(point_segment_linf(xy, world.walls) - world.half[i], speed, 0.0, dyn)))
        return True
    path = xy[None, :] + np.linspace(0.0, 1.0, 12)[:, None] * (np.asarray(target[:2]) - xy)[None, :]
    if still and (box_gaps(path, world.half[i], boxes[still]) < -1e-6).any():
        return False
    if len(world.walls):
        return bool((point_segment_linf(path, world.walls) - world.half[i] >= -1e-6).all())
    return True


def _object_position(world: _World, j: int) -> np.ndarray:
    carrier = world.carried_by[j]
    return world.pose[carrier, :2] if carrier >= 0 else world.obj_pos[j]


def _record(world: _World, rec: dict[str, list]) -> None:
    rec["t"].append(world.t)
    pose = world.pose.copy()
    pose[:, 2] = np.degrees(pose[:, 2])
    rec["pose"].append(pose)
    rec["v"].append(world.v.copy())
    rec["w"].append(np.degrees(world.w))
    carrying = np.full(len(world.rids), -1)
    for j, r in enumerate(world.carried_by):
        if r >= 0:
            carrying[r] = j
    rec["carrying"].append(carrying)
    rec["primitive"].append(
        np.array([0 if a.done else _PRIMITIVES.index(a.step.primitive) for a in world.agents])
    )
    rec["waiting"].append(np.array([a.waiting for a in world.agents]))
    rec["humans"].append(np.array([w.position for w in world.walkers]).reshape(-1, 2))
    positions = world.obj_pos.copy()
    for j, r in enumerate(world.carried_by):
        if r >= 0:
            positions[j] = world.pose[r, :2]
    rec["objects"].append(positions)
