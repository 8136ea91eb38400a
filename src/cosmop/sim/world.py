"""The state of a running simulation: every robot's executor state and the shared world.

:class:`World` holds what the robots, people and objects are doing (poses, speeds, who carries
what), the message bus and the safety monitor's log; :class:`Agent` is one robot's place in its
plan.  Both are mutable and owned by :func:`cosmop.sim.simulation.simulate`; the executors
(:mod:`cosmop.sim.execute`), the unicycles (:mod:`cosmop.sim.unicycle`) and the monitor
(:mod:`cosmop.sim.monitor`) read and change them.  Units: mm, mm/s and radians inside (poses
keep their heading in radians), seconds; degrees where a plan's pose is read.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cosmop.control.dwa import Obstacles
from cosmop.control.geometry import box_gaps, point_segment_linf, rect_gaps, segment_array, segment_bounds
from cosmop.control.paths import GlobalPath
from cosmop.control.safety import Limits
from cosmop.events import MESSAGE_KINDS, Event, Primitive, realising_step
from cosmop.planning.plan_types import PlanSet, Pose, RobotPlan, State, Step
from cosmop.planning.realisation import event_instants
from cosmop.scenario.overlaps import TOUCH  # the one tolerance under which two squares touch
from cosmop.scene import Scenario
from cosmop.sim.delays import DelayDraws
from cosmop.sim.humans import Walker
from cosmop.sim.result import Contact, Message, SimSettings, drop_holds
from cosmop.team.conflicts import ConflictSettings

__all__ = ["TOUCH", "Action", "Agent", "World", "wrap_angle"]

_NEAR = 1000.0  # mm: :meth:`World.static_gaps` measures the walls this near first
_MEMO = 4096  # static gaps remembered at most (cleared when full: old layouts are dead)
_MEMO_POINTS = 8  # only questions about this few points are remembered (waypoints, not fans)

Action = tuple[str, Any]
"""One cycle's command of a robot: ``("drive", (target, stop, room))`` for the dynamic window,
``("move", (v, w))`` (mm/s, rad/s) or ``("dock", (x, y, heading deg))`` for the docking creep."""


def wrap_angle(angle: NDArray[np.float64] | float) -> NDArray[np.float64]:
    """`angle` (radians) wrapped into :math:`[-\\pi, \\pi)`.

    Parameters
    ----------
    angle : float or ndarray
        Angles, rad.

    Returns
    -------
    ndarray
        The same shape as `angle` (0-d for a float).
    """
    return (np.asarray(angle) + math.pi) % (2 * math.pi) - math.pi


class Agent:
    """One robot's executor state: where it is in its plan and what it is doing (mutable)."""

    def __init__(self, rid: str, index: int, steps: tuple[Step, ...], mission: tuple[Event, ...]) -> None:
        self.id = rid
        self.index = index  # the robot's row in the world's arrays
        self.steps = list(steps)  # the plan being executed (a replan replaces the rest)
        self.mission = list(mission)  # the events those steps realise, messages included
        self.step_index = 0  # the step being executed (== len(steps): finished)
        # each step's instant in the plan the run started from (None: a replan added it)
        self.plan_instants: list[int | None] = list(range(1, len(self.steps) + 1))
        self.step_began = 0.0  # when the current step started, s
        self.step_log: list[tuple[int | None, str, float, float]] = []  # done: instant, label, start, end
        self.drive_phase = "start"  # of a drive: start (no path yet), drive, turn (onto the heading)
        # of a pick or drop: approach, dock, docked, handle (None: not begun)
        self.dock_stage: str | None = None
        self.path: GlobalPath | None = None  # the global path being followed
        self.reseat_point: tuple[float, float] | None = None  # the plan's segment start to creep back to
        self.replan_start: tuple[int, State] | None = None  # (step, state): where a replan starts that step
        self.handling_left = 0.0  # seconds of gripper work left
        self.gripped: int | None = None  # the object (index) the gripper touches, not carried
        self.best_path_left = math.inf  # path left (mm) at the last progress
        self.goal_clearance = math.inf  # gap (mm) of the current goal to everything static
        self.path_left = 0.0  # path left (mm) while driving, 0 otherwise: the right of way
        self.detour_until = 0.0  # no new detour before this time, s
        self.last_progress_t = 0.0  # time of the last progress, s
        self.waiting = False  # standing for a message
        self.through = False  # drove through its last waypoint: its messages there need no stop
        self.answers_sent: dict[str, int] = {}  # Res steps done per object
        # where it creeps out of touch before driving off: None not looked for yet, False none
        self.way_out: tuple[float, float] | Literal[False] | None = None
        self.stopped_until: float | None = None  # a delay holds it until then, s (None: not stopped)
        self.stops: list[tuple[float, float]] = []  # the delays that struck it: (time, seconds), s

    @property
    def mission(self) -> list[Event]:
        """The events the plan's steps realise, messages included (a replan replaces them)."""
        return self._mission

    @mission.setter
    def mission(self, events: Iterable[Event]) -> None:
        self._mission = list(events)
        self._realising: dict[tuple[Primitive, str | None], list[Event]] = {}

    def realising(self, primitive: Primitive, obj: str | None) -> list[Event]:
        """The mission's events that a step `primitive` about `obj` (no message) realises, in
        order (kept: a waiting robot asks every cycle).

        Parameters
        ----------
        primitive : Primitive
            The step's primitive.
        obj : str or None
            The object the step is about.
        """
        key = (primitive, obj)
        if key not in self._realising:
            self._realising[key] = [
                e for e in self._mission if realising_step(e, self.id) == (primitive, obj, None)
            ]
        return self._realising[key]

    @property
    def before(self) -> State | None:
        """Its plan's state before its current step: a replan's start at the replan's first
        step, else the previous step's pose and objects; ``None`` before the first step of the
        run (the robot stands at its start)."""
        k = self.step_index
        if self.replan_start is not None and self.replan_start[0] == k:
            return self.replan_start[1]
        return State(self.steps[k - 1].robot, self.steps[k - 1].objects) if k > 0 else None

    @property
    def origin(self) -> Pose | None:
        """Where its plan has the robot before its current step (mm, mm, degrees; :attr:`before`)."""
        before = self.before
        return None if before is None else before.robot

    @property
    def done(self) -> bool:
        """Whether the robot has executed its whole plan."""
        return self.step_index >= len(self.steps)

    @property
    def step(self) -> Step:
        """The step being executed."""
        return self.steps[self.step_index]

    def stop_for(self, t: float, seconds: float) -> None:
        """A delay strikes at time `t` (s): the robot stops for `seconds` (:mod:`cosmop.sim.delays`).

        Parameters
        ----------
        t : float
            Time now, s.
        seconds : float
            How long the delay holds the robot, s.
        """
        self.stopped_until = t + seconds
        self.stops.append((t, seconds))

    def resume(self, t: float) -> None:
        """The delay is over at time `t` (s).  The clocks of progress and of detours move on by
        the time the robot stood, so that its own stop is not taken for a stall.

        Parameters
        ----------
        t : float
            Time now, s.
        """
        stood = t - self.stops[-1][0]
        self.last_progress_t += stood
        self.detour_until += stood
        self.stopped_until = None

    def restart_step(self) -> None:
        """Forget how the current step was being executed: it starts afresh next cycle (a robot
        that waited for a message the new order no longer has is no longer parked)."""
        self.waiting = False
        self.drive_phase = "start"
        self.dock_stage = None
        self.path = None
        self.way_out = None

    def split_mission(self, scenario: Scenario) -> tuple[list[Event], list[Event]]:
        """The mission events done (by the completed steps) and those still to do.

        Parameters
        ----------
        scenario : Scenario
            The running scenario.
        """
        plan = RobotPlan.from_steps(self.mission, self.steps)
        instants = event_instants(plan, self.id, scenario.scene)
        done = [
            e for e, t in zip(self.mission, instants, strict=True) if t is not None and t <= self.step_index
        ]
        return done, self.mission[len(done) :]


class World:
    """The state of a running simulation; :func:`~cosmop.sim.simulation.simulate` drives it.

    Robots are rows of the arrays ``pose`` (x, y mm, heading rad), ``v`` (mm/s), ``w`` (rad/s),
    ``robot_half`` and ``limits`` (:class:`~cosmop.control.safety.Limits`); objects rows of
    ``object_xy`` and ``object_half``.  An object
    carried by robot ``i`` has ``carried_by == i`` and rides at the robot's centre (its
    ``object_xy`` is stale then); a resting one has ``carried_by == -1``.
    """

    def __init__(self, scenario: Scenario, plans: PlanSet, seed: int, settings: SimSettings) -> None:
        scene = scenario.scene
        self.scenario = scenario
        self.settings = settings
        self.robot_ids = tuple(scene.robots)
        self.object_ids = tuple(scene.objects)
        humans = scene.humans
        self.human_ids = tuple(humans)
        self.walls = segment_array([(w.start, w.end) for w in scene.obstacles])
        self._wall_lo, self._wall_hi = segment_bounds(self.walls)  # each wall's box
        self._init_robots(scenario)
        objects = [scene.objects[o] for o in self.object_ids]
        self.object_xy = np.array([o.position for o in objects], dtype=float).reshape(-1, 2)  # resting ones
        self.object_half = np.array([o.size / 2.0 for o in objects])
        self.carried_by = np.full(len(self.object_ids), -1)  # robot index, -1: resting
        # goods a lifelong run has shipped: they left their dock and the world (cosmop.lifelong)
        self.shipped = np.zeros(len(self.object_ids), dtype=bool)
        # how re-coordination finds conflicts (None: the defaults; a lifelong run ships goods on drop)
        self.conflict_settings: ConflictSettings | None = None
        rng = np.random.default_rng(seed)  # the people's random walks
        self.walkers = [Walker(humans[h], self.walls, rng) for h in self.human_ids]
        self.human_half = np.array([w.half for w in self.walkers])
        self.human_speed = np.array([humans[h].speed for h in self.human_ids])  # at most, mm/s
        # the robots' delays: a generator of their own, so that the people walk the same without them
        delays = settings.delays
        self.delay_draws = None if delays is None else DelayDraws(delays, seed, len(self.robot_ids))
        self.agents = []
        for i, rid in enumerate(self.robot_ids):
            plan = plans.robots.get(rid)
            steps = plan.steps if plan is not None else ()
            events = plan.mission if plan is not None else ()
            self.agents.append(Agent(rid, i, steps, events))
        self.sent_messages: set[Event] = set()  # the message events sent so far
        self.events: list[tuple[float, str, Event]] = [  # (t, robot, event) as the robots do them
            (0.0, a.id, Event("return", a.id))
            for a in self.agents
            if a.done and any(e.kind == "return" for e in a.mission)
        ]
        self.messages: list[Message] = []  # the bus's log
        self.contacts: list[Contact] = []  # the monitor's log
        # (robot, what it touches) for the pairs touching now -> the episode's index in contacts
        self.open_contacts: dict[tuple[int, str], int] = {}
        self.replans = 0  # accepted replans
        self.replan_attempts = 0
        self.replan_log: list[dict[str, Any]] = []  # every replan: time, robot, accepted, messages
        # the messages that keep plans apart (re-ordered on a replan) and every message used
        self.conflict_messages = {m.event for m in plans.messages if m.kind == "conflict"}
        self.used_messages = {e for p in plans.robots.values() for e in p.mission if e.kind == "msg"}
        self.t = 0.0  # simulated time, s
        self._layout_key: tuple[bytes, bytes] | None = None  # what the sensed layout was made for
        self._static_memo: dict[
            tuple[bytes, float, bytes, bytes], NDArray[np.float64]
        ] = {}  # static_gaps by points, half and layout

    def _init_robots(self, scenario: Scenario) -> None:
        """The robots' arrays: sizes, limits, poses at rest."""
        robots = [scenario.scene.robots[r] for r in self.robot_ids]
        R = len(robots)
        self.robot_half = np.array([r.size / 2.0 for r in robots])
        cycles = {r.dynamics.cycle for r in robots}
        if len(cycles) != 1:
            raise ValueError("every robot must share one control cycle")
        self.dt = cycles.pop()  # the control cycle, s
        self.limits = Limits.of([r.dynamics for r in robots])  # the unicycle limits, arrays over robots
        self.pose = np.array([[r.pose[0], r.pose[1], math.radians(r.pose[2])] for r in robots]).reshape(R, 3)
        self.v = np.zeros(R)
        self.w = np.zeros(R)
        self.distance = np.zeros(R)  # driven so far, mm

    # -- what the robots sense -----------------------------------------------------------------

    def robot_boxes(self) -> np.ndarray:
        """Every robot as a box ``x, y, half side`` (mm)."""
        return np.concatenate([self.pose[:, :2], self.robot_half[:, None]], axis=1)

    def resting_boxes(self) -> np.ndarray:
        """Every resting (not carried) object as a box ``x, y, half side`` (mm)."""
        keep = self.resting()
        return np.column_stack([self.object_xy[keep], self.object_half[keep]])

    def resting(self) -> np.ndarray:
        """Which objects rest in the world: not carried, not shipped."""
        return (self.carried_by < 0) & ~self.shipped

    def ship(self, obj: str) -> None:
        """Goods delivered in a lifelong run leave the world: no longer sensed, drawn or planned.

        Parameters
        ----------
        obj : str
            The object's id.
        """
        self.shipped[self.object_ids.index(obj)] = True

    def people_boxes(self) -> np.ndarray:
        """Every person as a box ``x, y, half side`` (mm); call only with people."""
        return np.column_stack([np.array([w.position for w in self.walkers]), self.human_half])

    def obstacles(self) -> Obstacles:
        """What the robots sense now: the walls, and the resting objects, robots and people (in
        that order) as boxes with their speed bounds and ids; :meth:`with_motion` adds how they
        move (only the controllers need it, so the monitor does not pay for it)."""
        resting, names, agents = self._sensed_layout()
        speed = [np.zeros(len(resting)), np.where(self.parked(), 0.0, self.limits.max_speed)]
        if self.walkers:
            speed.append(self.human_speed)
        return Obstacles(
            self.walls, self._stacked(resting), np.concatenate(speed), agents=agents, names=names
        )

    def boxes(self) -> tuple[np.ndarray, tuple[str, ...]]:
        """The boxes of :meth:`obstacles` ``(n, 3)`` and their ids, without their speeds (the
        monitor's view)."""
        resting, names, _ = self._sensed_layout()
        return self._stacked(resting), names

    def _stacked(self, resting: np.ndarray) -> np.ndarray:
        """The resting objects' boxes `resting`, then the robots', then the people's, ``(n, 3)``."""
        boxes = [resting, self.robot_boxes()]
        if self.walkers:
            boxes.append(self.people_boxes())
        return np.concatenate([b.reshape(-1, 3) for b in boxes])

    def _sensed_layout(self) -> tuple[np.ndarray, tuple[str, ...], np.ndarray]:
        """The resting objects' boxes, every box's name and which boxes are robots or people, as
        :meth:`obstacles` lists them; they change only when an object is picked or dropped, so
        they are kept until then."""
        key = self._layout_now()
        if self._layout_key != key:
            resting = np.flatnonzero(self.resting())
            names = tuple(self.object_ids[j] for j in resting) + self.robot_ids + self.human_ids
            self._layout_key = key
            self._layout = (self.resting_boxes(), names, np.arange(len(names)) >= len(resting))
        return self._layout

    def _layout_now(self) -> tuple[bytes, bytes]:
        """Where the objects are and who carries them: the layout changes only when it does."""
        return self.carried_by.tobytes() + self.shipped.tobytes(), self.object_xy.tobytes()

    def first_robot_box(self, count: int) -> int:
        """Where the robots' boxes begin among `count` sensed boxes (:meth:`obstacles`,
        :meth:`boxes`): after the resting objects', before the people's, in robot order.

        Parameters
        ----------
        count : int
            The number of sensed boxes.
        """
        return count - len(self.robot_ids) - len(self.walkers)

    def with_motion(self, sensed: Obstacles) -> Obstacles:
        """`sensed` with the velocities (mm/s; sensed, for prediction only) and acceleration
        limits (mm/s^2) its boxes have now: resting objects and parked robots 0, people an
        unknown acceleration (``inf``).

        Parameters
        ----------
        sensed : Obstacles
            What :meth:`obstacles` returned this cycle.
        """
        first = self.first_robot_box(len(sensed.names))
        robots = slice(first, first + len(self.robot_ids))
        velocity = np.zeros((len(sensed.names), 2))
        heading = self.pose[:, 2]
        velocity[robots, 0], velocity[robots, 1] = self.v * np.cos(heading), self.v * np.sin(heading)
        for k, walker in enumerate(self.walkers):
            velocity[robots.stop + k] = walker.velocity
        acceleration = np.zeros(len(sensed.names))
        acceleration[robots] = np.where(self.parked(), 0.0, self.limits.acceleration)
        acceleration[robots.stop :] = np.inf
        # (built directly: dataclasses.replace costs more than the arrays, every cycle)
        return Obstacles(
            sensed.walls, sensed.boxes, sensed.speed, velocity, acceleration, sensed.agents, sensed.names
        )

    def own_boxes(self, sensed: Obstacles, robots: np.ndarray | None = None) -> np.ndarray:
        """Which box of `sensed` (of :meth:`obstacles`) is each robot itself, ``(R, n)``, or
        each of the robots `robots` only: the robots' boxes follow the resting objects', in
        robot order.

        Parameters
        ----------
        sensed : Obstacles
            What :meth:`obstacles` returned this cycle.
        robots : ndarray of int, optional
            Indices of the robots asked about (default: all).
        """
        rows = np.arange(len(self.robot_ids)) if robots is None else np.asarray(robots)
        first = self.first_robot_box(len(sensed.names))
        own = np.zeros((len(rows), len(sensed.names)), dtype=bool)
        own[np.arange(len(rows)), first + rows] = True
        return own

    def static_gaps(self, points: ArrayLike, half: float) -> NDArray[np.float64]:
        """L-infinity gaps (mm) of squares of half side `half` at `points` to walls and resting objects.

        Answers about a few points are remembered until an object is picked up or dropped: a
        driving robot asks about the same waypoints every cycle.

        Parameters
        ----------
        points : array_like, shape (n, 2)
            Centres of the squares, mm.
        half : float
            Their half side, mm.
        """
        points = np.asarray(points, dtype=float).reshape(-1, 2)
        if len(points) > _MEMO_POINTS:
            return self._measure_static_gaps(points, half)
        key = (points.tobytes(), float(half), *self._layout_now())
        gap = self._static_memo.get(key)
        if gap is None:
            if len(self._static_memo) >= _MEMO:
                self._static_memo.clear()
            gap = self._static_memo[key] = self._measure_static_gaps(points, half)
        return gap.copy()

    def _measure_static_gaps(self, points: np.ndarray, half: float) -> np.ndarray:
        """:meth:`static_gaps`, measured (`points` ``(n, 2)``)."""
        gap = np.full(len(points), np.inf)
        unsure = np.ones(len(points), dtype=bool)
        reach = _NEAR
        while len(self.walls) and unsure.any():
            # the walls within `reach` of the unsure points' box: a farther wall is more than
            # `reach` from each of them, so it cannot be the nearest of a point nearer than that
            # to one of them; the rest look again four times as far (rings, not every wall)
            todo = points[unsure]
            lo, hi = todo.min(axis=0), todo.max(axis=0)
            near = rect_gaps(lo, hi, self._wall_lo, self._wall_hi) <= reach
            if near.any():
                gap[unsure] = (point_segment_linf(todo, self.walls[near]) - half).min(axis=1)
            if near.all():
                break
            unsure &= gap > reach - half
            reach *= 4.0
        if self.resting().any():
            gap = np.minimum(gap, box_gaps(points, half, self.resting_boxes()).min(axis=1))
        return gap

    def static_boxes(self, robot: int, goal: Sequence[float] | None = None) -> np.ndarray:
        """What the global path of robot `robot` avoids: resting objects and parked robots.

        A robot that waits for a message, docks, handles an object or has finished stands
        still for a while, so the others plan around it instead of queueing behind it.

        Parameters
        ----------
        robot : int
            The robot's index.
        goal : sequence of float, optional
            The robot's goal ``x, y`` (mm; more entries are ignored).
        """
        boxes = [self.resting_boxes()]
        parked = [
            a.index
            for a in self.agents
            if a.index != robot and (a.done or a.waiting or a.dock_stage is not None) and self.v[a.index] == 0
        ]
        if parked:
            half = self.robot_half[parked].copy()
            if goal is not None:
                # A parked robot stops up to the goal tolerance from its own goal, so a goal
                # planned right beside it may lie a little inside: shrink that one, so that
                # the goal stays reachable (the path is a guide; the dynamic window keeps the
                # real distance).
                reach = np.abs(self.pose[parked, :2] - np.asarray(goal[:2])).max(axis=1)
                inside = reach < half + self.robot_half[robot]
                half[inside] = np.minimum(
                    half[inside], np.maximum(reach[inside] - self.robot_half[robot], 1.0)
                )
            boxes.append(np.column_stack([self.pose[parked, :2], half]))
        return np.concatenate([b.reshape(-1, 3) for b in boxes])

    def gaps_to_robots(self, i: int) -> np.ndarray:
        """L-infinity gaps (mm) of robot `i`'s square to every robot's (itself included).

        Parameters
        ----------
        i : int
            The robot's index.
        """
        return box_gaps(self.pose[i, :2], self.robot_half[i], self.robot_boxes())

    def object_positions(self) -> np.ndarray:
        """Where every object is now (a carried one at its robot's centre; NaN: shipped), (O, 2) mm."""
        positions = self.object_xy.copy()
        for j, r in enumerate(self.carried_by):
            if r >= 0:
                positions[j] = self.pose[r, :2]
        positions[self.shipped] = np.nan
        return positions

    def creep_speed(self, i: int) -> float:
        """Speed (mm/s) of robot `i`'s docking creep: at most ``dock_speed``, and no faster than
        the robot stops within one cycle (so it halts exactly on its pose).

        Parameters
        ----------
        i : int
            The robot's index.
        """
        speed: float = min(self.settings.dock_speed, self.limits.braking[i] * self.dt)
        return speed

    def heading_error(self, i: int, heading: float) -> float:
        """The turn (rad, wrapped) from robot `i`'s heading to `heading` (rad).

        Parameters
        ----------
        i : int
            The robot's index.
        heading : float
            The heading wanted, rad.
        """
        return float(wrap_angle(heading - self.pose[i, 2]))

    # -- who may move ----------------------------------------------------------------------------

    def parked(self) -> np.ndarray:
        """Which robots are parked: standing and promising not to move (their V is 0).

        A robot that has finished, waits for a message, stands docked on the pose it picks or
        drops from, or lets its gripper work stands still, and it leaves that state only when
        no other robot is within the standoff (:meth:`crowded`).  The others may therefore
        treat it like a wall: come close, dock beside it, and leave again -- two robots that
        touch could otherwise never part.
        """
        return np.array(
            [
                (a.done or a.waiting or a.dock_stage in ("docked", "handle")) and self.v[a.index] == 0
                for a in self.agents
            ],
            dtype=bool,
        )

    def crowded(self, i: int) -> bool:
        """Whether robot `i` must stay parked: another robot that may still move is within its
        standoff.  A robot that has finished never moves again and does not count, nor does a
        parked one whose message has not come (it cannot leave; were it to hold `i`, and its
        message wait on `i`, neither would ever move); of two other parked robots close
        together the one listed first may leave (the other keeps its promise), so that two
        waiting robots never hold each other for ever.

        Parameters
        ----------
        i : int
            The robot's index.
        """
        gaps = self.gaps_to_robots(i)
        gaps[i] = np.inf
        parked = self.parked()
        for agent in self.agents:
            if agent.done or (parked[agent.index] and (agent.index > i or self.held(agent))):
                gaps[agent.index] = np.inf
        return bool((gaps < self.settings.dwa.standoff).any())

    def held(self, agent: Agent) -> bool:
        """Whether `agent` waits for a message that has not been sent: it cannot move before.

        Parameters
        ----------
        agent : Agent
            A robot.
        """
        if not agent.waiting or agent.done:
            return False
        return agent.step.primitive == Primitive.REQ and not self.received(agent, agent.step)

    # -- messages and mission events ---------------------------------------------------------------

    def send(self, agent: Agent, step: Step) -> None:
        """Send the message of a ``Res`` step: its ``msg``, or the next ``away`` answer about its
        object (the k-th Res(O) answers the k-th away(O, *, sender) of the mission).

        Parameters
        ----------
        agent : Agent
            The sender.
        step : Step
            Its ``Res`` step.
        """
        if step.message is not None:
            event = step.message
        else:
            assert step.object is not None  # a Res without a message answers about its object
            answers = agent.realising(Primitive.RES, step.object)
            sent = agent.answers_sent.get(step.object, 0)
            agent.answers_sent[step.object] = sent + 1
            event = answers[min(sent, len(answers) - 1)]
        assert event.receiver is not None  # a message event
        self.messages.append(Message(round(self.t, 6), agent.id, event.receiver, event.obj, event.name))
        self.sent_messages.add(event)
        self.events.append((round(self.t, 6), agent.id, event))

    def awaited(self, agent: Agent, step: Step) -> Event | None:
        """The message a ``Req`` step waits for: its ``msg``, or the first ``away`` request about
        its object not yet answered (None when every one has been).

        Parameters
        ----------
        agent : Agent
            The waiting robot.
        step : Step
            Its ``Req`` step.
        """
        if step.message is not None:
            return step.message
        pending = [e for e in agent.realising(Primitive.REQ, step.object) if e not in self.sent_messages]
        return pending[0] if pending else None

    def received(self, agent: Agent, step: Step) -> bool:
        """Whether the message a ``Req`` step waits for has been sent.

        Parameters
        ----------
        agent : Agent
            The waiting robot.
        step : Step
            Its ``Req`` step.
        """
        if step.message is not None:
            return step.message in self.sent_messages
        return any(e in self.sent_messages for e in agent.realising(Primitive.REQ, step.object))

    def _happened(self, event: Event) -> bool:
        """Whether the step that realises `event` made it happen: a drop left its object in the
        workspace, an awaited message was sent."""
        if event.kind == "drop":
            xy = self.object_xy[self.object_ids.index(event.obj)]
            return drop_holds(self.scenario.scene, event, xy)
        if event.kind in MESSAGE_KINDS:
            return event in self.sent_messages
        return True

    def log_events(self, agent: Agent, step: Step) -> None:
        """Log the mission events a finished step realises (the executed word of the run).

        Parameters
        ----------
        agent : Agent
            The robot.
        step : Step
            The step it finished.
        """
        done = {event for _, robot, event in self.events if robot == agent.id}
        realised = (step.primitive, step.object, step.message)
        wanted = [
            e
            for e in agent.mission
            if step.primitive != Primitive.RES  # a message is logged when it is sent
            and realising_step(e, agent.id) == realised
            and self._happened(e)
        ]
        event = next((e for e in wanted if e not in done), None)
        if event is not None:
            self.events.append((round(self.t, 6), agent.id, event))
            done.add(event)
        # ``return`` holds as soon as the robot is home with the events before it done (as in
        # the plan: messages it sends from home come after it)
        pending = next((e for e in agent.mission if e not in done), None)
        if pending is not None and pending.kind == "return":
            home = self.scenario.scene.robots[agent.id].pose
            if math.dist(self.pose[agent.index, :2], home[:2]) <= self.settings.goal_tolerance + 1e-6:
                self.events.append((round(self.t, 6), agent.id, pending))
