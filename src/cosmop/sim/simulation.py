"""Executing plans: a multi-robot world with messages, people and a safety monitor.

Every robot executes its ``cosmop.plan/1`` plan step by step, all robots in lock step with one
control cycle :math:`\\varepsilon` (the scenario's ``dynamics.cycle``):

``GoTo``
    drives with the passive-safe dynamic window (:mod:`cosmop.control.dwa`) along a global path
    (:mod:`cosmop.control.paths`) to the step's waypoint.  A waypoint followed by another
    ``GoTo`` is passed within ``pass_tolerance`` (where the next ones continue the same straight
    segment, as the team's cuts at shared places do, the window aims past it, up to where the
    robot must stop); the last one of a run is reached within
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
    them (:mod:`cosmop.team.safe_plans`).

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

Robots may be delayed (``SimSettings.delays``, :mod:`cosmop.sim.delays`): every simulated
second each robot still executing its plan stops, with some probability, for a random time.
A stopped robot brakes and stands, and then carries on; the messages keep the order between
the robots whatever their speed.

The code is split along those jobs; :func:`simulate` runs one control cycle after the other:

0. delays end and strike (:func:`_delays`);
1. every robot decides what to do for its current step (:func:`cosmop.sim.execute.decide`,
   one executor per primitive, the motion in :mod:`cosmop.sim.motion`; a stalled robot
   replans, :func:`cosmop.sim.replan.replan_stalled`);
2. the dynamic window gives the robots that drive their speeds, all at once;
3. the robots move (:func:`cosmop.sim.unicycle.integrate`), the people walk
   (:mod:`cosmop.sim.humans`), the clock ticks;
4. the monitor logs contacts (:func:`cosmop.sim.monitor.monitor`), and a gripper lets go of
   the object it dropped once the robot has crept off it (:func:`cosmop.sim.execute.let_go`);
5. the frame is recorded (:mod:`cosmop.sim.recording`);
6. the run stops once every robot has finished and stands, or at ``max_time``.

The world's state is in :mod:`cosmop.sim.world`, the result types in :mod:`cosmop.sim.result`.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from cosmop.control.dwa import Drivers, Obstacles, dwa_commands
from cosmop.control.neighbourhood import dwa_commands_near
from cosmop.planning.plan_types import Itinerary, PlanSet, Pose
from cosmop.scene import Scenario
from cosmop.sim.execute import decide, let_go
from cosmop.sim.monitor import footprint_overlaps, monitor
from cosmop.sim.realised_times import step_times
from cosmop.sim.recording import Recorder
from cosmop.sim.result import DEFAULT_TIME_LIMIT, SIM_FORMAT, Contact, Message, SimResult, SimSettings
from cosmop.sim.unicycle import integrate
from cosmop.sim.world import World
from cosmop.team.timing import itinerary
from cosmop.traces import TRACE_FORMAT

__all__ = [
    "SIM_FORMAT",
    "TRACE_FORMAT",
    "Contact",
    "Message",
    "SimResult",
    "SimSettings",
    "advance",
    "footprint_overlaps",
    "simulate",
    "time_limit",
]

_EPS = 1e-9  # s: the clock, summed from its cycles, may fall a hair short of a stop's end


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
        Seeds the people's random walks and the delays (``settings.delays``), each with a
        generator of its own; the run is deterministic given the seed.
    settings : SimSettings, optional
    on_cycle : callable, optional
        Called every cycle with ``(t, robots done, robots)`` (the CLI's progress bar).

    Returns
    -------
    SimResult

    Raises
    ------
    ValueError
        For an infeasible plan set, or robots with different control cycles.
    """
    settings = settings or SimSettings()
    if not plans.feasible:
        raise ValueError(f"the plan set is infeasible: {plans.reason}")
    wall0 = time.perf_counter()
    world = World(plans.extend(scenario), plans, seed, settings)  # with the places of added tasks
    planned = _planned_times(world.scenario, plans)  # for the time limit and the summary
    robots = len(world.robot_ids)
    recorder = Recorder()
    recorder.record(world)
    completed = False
    cycles = 0
    for _ in range(math.ceil(_time_limit(settings, planned) / world.dt)):
        advance(world)
        cycles += 1
        recorder.record(world)
        done = sum(a.done for a in world.agents)
        if on_cycle is not None:
            on_cycle(world.t, done, robots)
        if done == robots and not world.v.any():  # finished, and standing
            completed = True
            break
    return _result(world, scenario, plans, planned, recorder.frames(world), completed, cycles, wall0)


def time_limit(scenario: Scenario, plans: PlanSet, settings: SimSettings | None = None) -> float:
    """When a run of `plans` stops unfinished, simulated s: ``settings.max_time``, or by
    default three times the plans' expected makespan and at least 900 s (:class:`SimSettings`).

    Parameters
    ----------
    scenario : Scenario
        The scenario the plans are for.
    plans : PlanSet
        The plans to run.
    settings : SimSettings, optional
        The run's settings (default: the defaults).
    """
    settings = settings or SimSettings()
    planned = None if settings.max_time is not None else _planned_times(plans.extend(scenario), plans)
    return _time_limit(settings, planned)


def _time_limit(settings: SimSettings, planned: Itinerary | None) -> float:
    """:func:`time_limit` with the plans' itinerary `planned` (None: none, or not needed)."""
    if settings.max_time is not None:
        return settings.max_time
    return max(DEFAULT_TIME_LIMIT, 3.0 * (planned.makespan if planned is not None else 0.0))


def advance(world: World) -> None:
    """One control cycle of the whole world (the module docstring's steps 0 to 4); a lifelong
    run (:mod:`cosmop.lifelong`) drives the world with it between its dispatches.

    Parameters
    ----------
    world : World
        The running simulation, changed in place.
    """
    _delays(world)
    # the dynamic window senses the world as it was when the cycle began: an object picked
    # up or dropped during the decisions is sensed next cycle
    sensed = world.obstacles()
    commands = _gather_commands(world)
    _dynamic_window(world, sensed, commands)
    moving = integrate(world, commands.v, commands.w, commands.docks)
    for walker in world.walkers:
        walker.step(world.dt)
    world.t += world.dt
    monitor(world, moving)
    let_go(world)


def _delays(world: World) -> None:
    """The robots' delays (:mod:`cosmop.sim.delays`): the stops that are over end, then the
    draws due now strike the robots that still execute their plan and are not stopped."""
    if world.delay_draws is None:
        return
    for agent in world.agents:
        if agent.stopped_until is not None and world.t >= agent.stopped_until - _EPS:
            agent.resume(world.t)
    for i, seconds in world.delay_draws.due(world.t):
        agent = world.agents[i]
        if not agent.done and agent.stopped_until is None:
            agent.stop_for(world.t, seconds)


@dataclass
class _Commands:
    """This cycle's commands: speed `v` (mm/s) and turn rate `w` (rad/s) per robot, the docking
    poses of the robots that creep, and the targets of those that drive with the window."""

    v: np.ndarray
    w: np.ndarray
    docks: dict[int, Pose] = field(default_factory=dict)  # robot -> pose (x, y, heading deg)
    driving: list[int] = field(default_factory=list)  # robots for the dynamic window
    targets: list[tuple[float, float]] = field(default_factory=list)  # their lookahead points, mm
    stops: list[float] = field(default_factory=list)  # path left to a final goal (inf: none), mm
    rooms: list[float] = field(default_factory=list)  # their goals' clearance, mm


def _gather_commands(world: World) -> _Commands:
    """Every robot's decision for this cycle (:func:`cosmop.sim.execute.decide`), gathered."""
    commands = _Commands(v=world.v.copy(), w=np.zeros(len(world.robot_ids)))
    for agent in world.agents:
        kind, arg = decide(world, agent)
        i = agent.index
        if kind == "drive":
            commands.driving.append(i)
            commands.targets.append(arg[0])
            commands.stops.append(arg[1])
            commands.rooms.append(arg[2])
        elif kind == "dock":
            commands.docks[i] = arg
        else:
            commands.v[i], commands.w[i] = arg
    return commands


def _dynamic_window(world: World, sensed: Obstacles, commands: _Commands) -> None:
    """The speeds of the driving robots, from the passive-safe dynamic window, all at once.

    `sensed` is :meth:`~cosmop.sim.world.World.obstacles` at the start of the cycle; the
    boxes' motion is read again now (:meth:`~cosmop.sim.world.World.with_motion`).
    """
    if not commands.driving:
        return
    names = list(sensed.names)
    idx = np.array(commands.driving)
    grip = np.zeros((len(idx), len(names)), dtype=bool)  # the object each gripper touches
    for row, i in enumerate(commands.driving):
        g = world.agents[i].gripped
        if g is not None and world.object_ids[g] in names:  # (a drop this cycle is sensed next cycle)
            grip[row, names.index(world.object_ids[g])] = True
    drivers = Drivers(
        pose=world.pose[idx],
        v=world.v[idx],
        half=world.robot_half[idx],
        limits=world.limits[idx],
        target=np.array(commands.targets, dtype=float),
        stop_distance=np.array(commands.stops, dtype=float),
        room_cap=np.array(commands.rooms, dtype=float),
    )
    window = dwa_commands_near if world.settings.neighbourhood else dwa_commands
    cmd = window(
        drivers, world.with_motion(sensed), world.settings.dwa, ignore=world.own_boxes(sensed, idx), grip=grip
    )
    commands.v[idx] = cmd.v
    commands.w[idx] = cmd.w


def _result(
    world: World,
    scenario: Scenario,
    plans: PlanSet,
    planned: Itinerary | None,
    frames: dict[str, np.ndarray],
    completed: bool,
    cycles: int,
    wall0: float,
) -> SimResult:
    """The :class:`SimResult` of a finished run (`planned`: the plans' itinerary; `wall0`: the
    run's start, :func:`time.perf_counter`)."""
    positions = world.object_positions()
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
                tuple(float(x) for x in positions[j]),
                world.robot_ids[world.carried_by[j]] if world.carried_by[j] >= 0 else None,
            )
            for j, oid in enumerate(world.object_ids)
        },
        robots={
            rid: (
                (float(world.pose[i, 0]), float(world.pose[i, 1]), math.degrees(float(world.pose[i, 2]))),
                float(world.distance[i]),
            )
            for i, rid in enumerate(world.robot_ids)
        },
        frames=frames,
        finished={a.id: a.done for a in world.agents},
        robot_ids=world.robot_ids,
        human_ids=world.human_ids,
        object_ids=world.object_ids,
        events=tuple((t, robot, event.name) for t, robot, event in world.events),
        added=tuple(e.name for task in plans.added for e in task.events),
        replan_log=tuple(world.replan_log),
        delays=world.settings.delays,
        stops={a.id: tuple((t, min(seconds, world.t - t)) for t, seconds in a.stops) for a in world.agents},
        scene=scenario.scene,
        plans=plans,
        steps=step_times(
            {rid: [s.label for s in p.steps] for rid, p in plans.robots.items()},
            planned,
            {a.id: a.step_log for a in world.agents},
        ),
    )


def _planned_times(scenario: Scenario, plans: PlanSet) -> Itinerary | None:
    """The plan set's itinerary, or the expected one for a plan file without times (`scenario`
    with the places of the plans' added tasks)."""
    if plans.itinerary is not None:
        return plans.itinerary
    try:
        return itinerary(scenario.scene, plans.robots)
    except ValueError:  # messages that deadlock: no schedule to compare with
        return None
