"""Driving to a pose: the global path, the dynamic window's target, and the docking creep.

A robot drives with the passive-safe dynamic window (:mod:`cosmop.control.dwa`) along a global
path (:mod:`cosmop.control.paths`).  A plan may start or end a motion touching a wall or resting
object (never slide along one: :data:`cosmop.planning.specification.MOTION_MARGIN`), which a
controller that keeps its distance cannot do; there the robot *creeps* instead -- straight,
slowly, stopping exactly on its pose (:func:`creep_to`): out of touch before it drives off
(:func:`creep_out`), onto a final pose that touches something (:func:`creep_onto_goal`), and
back onto the plan's segment where it stopped beside it (:func:`back_onto_segment`).  A robot
that makes no progress plans its path again around whoever blocks it (:func:`detour`), and
at last replans its mission (:func:`cosmop.sim.replan.replan_stalled`).

Each function returns the robot's :data:`~cosmop.sim.world.Action` for this cycle, or
``None`` once its part is done.  Units: mm, mm/s, seconds; plan poses in degrees.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cosmop.control.geometry import box_gaps, point_segment_linf, swept_box_gaps, swept_wall_gaps
from cosmop.control.paths import GlobalPath, plan_path, straight_path
from cosmop.control.safety import is_safe, stopping_horizon
from cosmop.planning.plan_types import Pose
from cosmop.sim.replan import replan_stalled
from cosmop.sim.world import TOUCH, Action, Agent, World

__all__ = [
    "HOLD",
    "REPLANNED",
    "StraightOn",
    "back_onto_segment",
    "brake",
    "crawl",
    "creep_is_safe",
    "creep_onto_goal",
    "creep_out",
    "creep_to",
    "detour",
    "drive",
    "find_way_out",
    "route",
]

HOLD: Action = ("move", (0.0, 0.0))
"""Stand still (a robot at rest; one that moves brakes with :func:`brake` first)."""

REPLANNED: Action = ("replanned", None)
"""Not a command: the robot has a new plan, whose first step decides this cycle's command."""

_GRAZE = 1.0  # mm: a straight way closer than this to an obstacle is not trusted off the plan
_EXIT_HEADINGS = np.radians(np.arange(0.0, 360.0, 5.0))  # directions a way out is looked for in
_EXIT_REACH = 80  # mm: how far a way out is looked for
_REJOIN_AHEAD = (4000.0, 8000.0, 16000.0)  # mm along the path: where a detour may rejoin it


@dataclass(frozen=True)
class StraightOn:
    """Where a robot that passes its waypoint drives on to in a straight line.

    Attributes
    ----------
    far : (float, float)
        The farthest waypoint on the drive's line the robot passes to without stopping, mm.
    stops : bool
        Whether it stops there (a message it must wait for, or its last drive).
    """

    far: tuple[float, float]
    stops: bool


REACH = 1.25
"""How far ahead of the robot its dynamic window's target lies at least, in top-speed horizons
(:attr:`~cosmop.control.dwa.DwaSettings.lookahead` when that is farther)."""


def brake(world: World, i: int) -> Action:
    """Robot `i`'s command to brake with :math:`-b` straight on, the always-safe choice.

    Every brake is straight: the dynamic window admits an arc only when one cycle on it, then
    this brake, keeps clear (:mod:`cosmop.control.dwa`).

    Parameters
    ----------
    world : World
        The running simulation.
    i : int
        The robot's index.
    """
    return ("move", (max(0.0, world.v[i] - world.limits.braking[i] * world.dt), 0.0))


def route(
    world: World, i: int, goal: Pose, origin: Pose | None
) -> tuple[GlobalPath, tuple[float, float] | None]:
    """The global path to `goal` (the plan's own segment where the robot can follow it), and
    the segment's start when the path goes back to it first (``None`` otherwise).

    Straight from where the robot is, unless that is blocked or only grazes an obstacle; else
    back onto the plan's segment at its `origin` (an intermediate waypoint passed within the
    tolerance, or a replan's rounded start, leaves the robot beside it) and along it; else
    around what now stands in the way (:func:`cosmop.control.paths.plan_path`).

    Parameters
    ----------
    world : World
        The running simulation.
    i : int
        The robot's index.
    goal : (float, float, float)
        The goal pose, mm, mm, degrees.
    origin : (float, float, float) or None
        The start of the plan's segment to `goal`, if known.
    """
    xy = world.pose[i, :2]
    here, boxes = (float(xy[0]), float(xy[1])), world.static_boxes(i, goal)
    half, target = float(world.robot_half[i]), (goal[0], goal[1])
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


def drive(
    world: World,
    agent: Agent,
    goal: tuple[float, float, float],
    final: bool,
    heading: bool,
    origin: Pose | None = None,
    ahead: StraightOn | None = None,
) -> Action | None:
    """Drive towards `goal` (mm, mm, degrees); ``None`` once it is reached (and turned to, if
    `heading`).  A `final` goal is reached within ``goal_tolerance`` and the robot stops there;
    an intermediate one is passed within ``pass_tolerance``.  `origin` is the start of the
    plan's segment to `goal` (:func:`route`).

    Parameters
    ----------
    world : World
        The running simulation.
    agent : Agent
        The driving robot.
    goal : (float, float, float)
        The goal pose, mm, mm, degrees.
    final : bool
        Whether the robot stops at `goal` (else it passes it).
    heading : bool
        Whether it turns to the goal's heading there.
    origin : (float, float, float), optional
        The start of the plan's segment to `goal`.
    ahead : StraightOn, optional
        Where a robot that passes `goal` drives on to in a straight line: the window's target
        may lie beyond `goal` on that line (and the robot can stop where the run stops).
    """
    s = world.settings
    i = agent.index
    xy = world.pose[i, :2]
    if agent.drive_phase == "start" or agent.path is None:
        _start_drive(world, agent, goal, origin)
    dist = math.hypot(goal[0] - xy[0], goal[1] - xy[1])
    tolerance = s.goal_tolerance if final else s.pass_tolerance
    if final and agent.drive_phase == "drive" and dist > tolerance:
        action = creep_onto_goal(world, agent, goal, dist)
        if action is not None:
            return action
    if agent.drive_phase == "drive" and dist <= tolerance:
        if not final:
            return None
        agent.drive_phase = "turn"
    if agent.drive_phase == "turn":
        return _turn(world, i, goal, heading)
    if agent.reseat_point is not None:
        action = back_onto_segment(world, agent)
        if action is not None:  # (waiting for someone to pass counts towards a stall)
            waited = action[0] == "move" and world.t - agent.last_progress_t > s.stall_time
            return (_on_stall(world, agent) or action) if waited else action
    # the target lies beyond where the robot gets in one horizon at its top speed: a nearer one
    # would be overshot by a faster arc, so progress alone would hold the robot below its top
    reach = max(s.dwa.lookahead, REACH * world.limits.max_speed[i] * s.dwa.horizon)
    assert agent.path is not None  # set by the drive's start
    target, left = agent.path.lookahead((float(xy[0]), float(xy[1])), reach)
    agent.path_left = left
    if left < agent.best_path_left - s.stall_progress:
        agent.best_path_left = left
        agent.last_progress_t = world.t
    elif world.t - agent.last_progress_t > s.detour_time:
        action = crawl(world, agent)
        if action is not None:
            return action
        if world.t >= agent.detour_until:
            detour(world, agent, goal)
        elif world.t - agent.last_progress_t > s.stall_time:
            action = _on_stall(world, agent)
            if action is not None:
                return action
    stop = left if final else math.inf
    if ahead is not None and not final and _on_line(agent.path, target, ahead, xy, s.pass_tolerance / 2):
        target, stop = _beyond(goal, ahead, reach - left, left)
    return ("drive", (target, stop, agent.goal_clearance))


def _on_line(
    path: GlobalPath, target: tuple[float, float], ahead: StraightOn, xy: NDArray[np.float64], aside: float
) -> bool:
    """Whether the target is the path's end, its last leg points on to ``ahead.far`` (within
    about 11 degrees: a robot that passed the last waypoint a few mm aside comes back onto the
    line; a path round an obstacle that meets the goal from aside does not), and the robot at
    `xy` is at most `aside` mm off that line (so that, aiming past the goal, it still passes
    within ``pass_tolerance`` of it)."""
    end, before = path.points[-1], path.points[-2] if len(path.points) > 1 else path.points[-1]
    if math.dist(target, end) > 1.0:
        return False
    ux, uy = end[0] - before[0], end[1] - before[1]
    vx, vy = ahead.far[0] - end[0], ahead.far[1] - end[1]
    dot = ux * vx + uy * vy
    off = abs((float(xy[0]) - end[0]) * vy - (float(xy[1]) - end[1]) * vx) / max(math.hypot(vx, vy), 1e-9)
    return dot > 0 and abs(ux * vy - uy * vx) <= 0.2 * dot and off <= aside


def _beyond(goal: Pose, ahead: StraightOn, extra: float, left: float) -> tuple[tuple[float, float], float]:
    """The window's target `extra` mm past `goal` on the line on to ``ahead.far`` (at most
    there), and the distance to stop in (mm): to ``ahead.far`` if the robot stops there."""
    dx, dy = ahead.far[0] - goal[0], ahead.far[1] - goal[1]
    length = math.hypot(dx, dy)
    s = min(extra, length) / length if length > 0 else 0.0
    return (goal[0] + s * dx, goal[1] + s * dy), (left + length if ahead.stops else math.inf)


def _start_drive(world: World, agent: Agent, goal: Pose, origin: Pose | None) -> None:
    """A new drive: its global path, and the progress and stall clocks reset."""
    s = world.settings
    i = agent.index
    agent.path, back = route(world, i, goal, origin)
    near = back is not None and math.dist(world.pose[i, :2], back) <= s.pass_tolerance + s.goal_tolerance
    agent.reseat_point = back if near else None
    agent.drive_phase = "drive"
    agent.goal_clearance = float(world.static_gaps(goal[:2], world.robot_half[i])[0])
    agent.best_path_left = math.inf
    agent.last_progress_t = world.t


def _turn(world: World, i: int, goal: Pose, heading: bool) -> Action | None:
    """At the goal: brake to a stop, then turn on the spot to the goal's heading (if `heading`)."""
    if world.v[i] > 0:
        return brake(world, i)
    if not heading:
        return None
    error = world.heading_error(i, math.radians(goal[2]))
    if abs(math.degrees(error)) <= world.settings.heading_tolerance:
        return None
    w = max(-world.limits.turn_rate[i], min(world.limits.turn_rate[i], error / world.dt))
    return ("move", (0.0, w))


def _on_stall(world: World, agent: Agent) -> Action | None:
    """No progress for ``stall_time``: replan; :data:`REPLANNED` when a new plan was taken,
    ``None`` when the robot keeps its plan (its stall clock starts again either way)."""
    replan_stalled(world, agent)
    agent.last_progress_t = world.t
    agent.best_path_left = math.inf
    return REPLANNED if agent.drive_phase == "start" else None


def crawl(world: World, agent: Agent) -> Action | None:
    """A robot held still by the dynamic window in a tight passage: creep a little way along
    its path; ``None`` when that does not apply (something else holds it).

    In a passage barely wider than the robot (goods on both faces of an aisle), a few
    millimetres off its path the robot must move sideways before it can go on, and every arc
    of the window grazes something: it would stand for ever, detours and replans finding the
    same path.  The docking creep (straight, slow, exact) takes it up to ``dock_tolerance``
    along the path, never past a vertex (never round a corner), turned along the way, when that
    move is passively safe and no robot or person is within twice the window's standoff of it:
    a robot held by another waits for it as before (creeping up to it would crowd it).  A robot
    that stands waiting for a message not yet sent does not count: it cannot move before the
    message comes (and may wait for this very robot to pass), nor leave while crowded.

    Parameters
    ----------
    world : World
        The running simulation.
    agent : Agent
        The driving robot, its path set.
    """
    s = world.settings
    i = agent.index
    if world.v[i] > 0 or agent.path is None:
        return None
    xy = (float(world.pose[i, 0]), float(world.pose[i, 1]))
    target, _ = agent.path.lookahead(xy, s.dock_tolerance, corner=0.0)
    if math.dist(target, xy) <= 1e-6:
        return None
    movable = [a.index for a in world.agents if a is not agent and not world.held(a)]
    others = world.robot_boxes()[movable]
    if world.walkers:
        others = np.vstack([others, world.people_boxes()])
    if (swept_box_gaps(xy, target, float(world.robot_half[i]), others) < 2 * s.dwa.standoff).any():
        return None
    pose = (target[0], target[1], math.degrees(math.atan2(target[1] - xy[1], target[0] - xy[0])))
    return ("dock", pose) if creep_is_safe(world, agent, pose) else None


def detour(world: World, agent: Agent, goal: tuple[float, float, float]) -> None:
    """Plan the global path again, around the robots that block this one and have the right of way.

    Two driving robots can block each other for ever, each waiting for the other to clear
    its path.  The one with more path left yields: it plans its global path around the other
    (as if that one stood still) for a while.  Ties go to the robot listed first.  Without
    such blockers the path is simply planned again (parked robots come and go).  The way round
    rejoins the path 4, 8 or 16 m further on where it can (the rest of the path is kept), and
    goes to the goal only where it cannot: on a large map, a route to a far goal is a search
    of the whole map (seconds), and round the blockers is what is needed.

    Parameters
    ----------
    world : World
        The running simulation.
    agent : Agent
        The blocked robot.
    goal : (float, float, float)
        Its goal pose, mm, mm, degrees.
    """
    s = world.settings
    i = agent.index
    agent.detour_until = world.t + s.detour_time
    gaps = world.gaps_to_robots(i)
    parked = world.parked()  # (already in the static boxes)
    blockers = [
        j
        for j, other in enumerate(world.agents)
        if j != i
        and not parked[j]
        and gaps[j] < s.sense_range
        and (other.path_left < agent.path_left or (other.path_left == agent.path_left and j < i))
    ]
    xy = (float(world.pose[i, 0]), float(world.pose[i, 1]))
    boxes = np.vstack([world.static_boxes(i, goal), world.robot_boxes()[blockers]])
    half = float(world.robot_half[i])
    path = None
    # round the blockers back onto the path a little beyond them, not all the way to a far goal
    # (on a large map the search for a route to the goal spans the whole map: seconds)
    current = agent.path
    for ahead in _REJOIN_AHEAD:
        rejoin, rest = current.beyond(xy, ahead) if current is not None else (None, ())
        if current is None or rejoin is None:
            break
        way = plan_path(xy, rejoin, half, world.walls, boxes)
        if way is not None:
            path = GlobalPath(way.points + rest, min(way.margin, current.margin))
            break
    path = path or plan_path(xy, (goal[0], goal[1]), half, world.walls, boxes)
    if path is None:
        return
    agent.path, agent.reseat_point = path, None
    agent.best_path_left = path.length


# -- the docking creep -------------------------------------------------------------------------


def creep_to(world: World, agent: Agent, point: tuple[float, float], heading: float | None = None) -> Action:
    """The docking creep straight to `point`, turning to `heading` (rad; default: keep it);
    brake first, or wait while something passes.

    Parameters
    ----------
    world : World
        The running simulation.
    agent : Agent
        The creeping robot.
    point : (float, float)
        Where it creeps to, mm.
    heading : float, optional
        The heading to turn to, rad.
    """
    i = agent.index
    if world.v[i] > 0:
        return brake(world, i)
    turn = float(world.pose[i, 2]) if heading is None else heading
    pose = (point[0], point[1], math.degrees(turn))
    if creep_is_safe(world, agent, pose):
        return ("dock", pose)
    return HOLD  # something passes: wait for it


def creep_is_safe(world: World, agent: Agent, target: Pose | None = None) -> bool:
    """Passive safety of a slow docking creep, with the gripper's object left out.

    Moving obstacles (robots, people; not a robot that has finished, which stands for good)
    need the paper's ``safe`` at the creep speed.  Towards a
    docking `target` (``x, y`` mm, ...) the creep is a straight move that stops exactly on it,
    so walls and resting objects only need to stay clear of that short segment (touching
    allowed: a docking pose may touch a wall, as the plan allows).  Without a target, the
    robot's square where it is must be safe at the creep speed from everything.

    Parameters
    ----------
    world : World
        The running simulation.
    agent : Agent
        The creeping robot.
    target : (float, float, float), optional
        The docking pose, mm, mm, degrees (only ``x, y`` are read).
    """
    i = agent.index
    sensed = world.with_motion(world.obstacles())
    boxes, speeds, names = sensed.boxes, sensed.speed, sensed.names
    skip = {agent.id}
    if agent.gripped is not None:
        skip.add(world.object_ids[agent.gripped])
    agents = sensed.agents
    assert agents is not None  # the world's obstacles say which boxes are robots or people
    # a robot that has finished stands for good: like a resting object, it may be touched
    skip_agents = {a.id for a in world.agents if a.done}
    movers = [
        b
        for b, n in enumerate(names)
        if n not in skip and (speeds[b] > 0 or (agents[b] and n not in skip_agents))
    ]
    still = [b for b, n in enumerate(names) if n not in skip and b not in movers]
    dyn = world.limits[i]  # this robot's limits
    speed = world.creep_speed(i)
    xy, half = world.pose[i, :2], world.robot_half[i]
    if movers:
        gaps = box_gaps(xy, half, boxes[movers])
        bound = sensed.speed_bound(stopping_horizon(speed, dyn))[movers]
        if not np.all(is_safe(gaps, speed, bound, dyn)):
            return False
    if target is None:
        if still and not np.all(is_safe(box_gaps(xy, half, boxes[still]), speed, 0.0, dyn)):
            return False
        if len(world.walls):
            return bool(np.all(is_safe(point_segment_linf(xy, world.walls) - half, speed, 0.0, dyn)))
        return True
    if still and (swept_box_gaps(xy, target[:2], half, boxes[still]) < -1e-6).any():  # exact
        return False
    if len(world.walls):  # exact too: samples along the way miss a wall's end cut diagonally
        return bool((swept_wall_gaps(xy, target[:2], float(half), world.walls) >= -1e-6).all())
    return True


def creep_onto_goal(world: World, agent: Agent, goal: tuple[float, ...], dist: float) -> Action | None:
    """The last few millimetres onto a final pose beside a wall, a resting object or a robot that
    has finished: creep there.

    The dynamic window stops a braking distance short of what it approaches, and a pose that
    touches something (a docking pose, a home against a wall, a home the scene put against
    another robot's) lies right there; within ``dock_tolerance`` of it (`dist`, mm) the
    docking creep, straight and exact, takes over when its way is clear (``None`` otherwise:
    the window drives on).  Where the way onto the pose itself is not clear, the creep stops
    short of what it would touch, if that is within ``goal_tolerance`` of the pose: a robot
    that came home first stands anywhere within that tolerance of its home, perhaps a few
    millimetres towards this one's.

    Parameters
    ----------
    world : World
        The running simulation.
    agent : Agent
        The driving robot.
    goal : tuple of float
        The final pose ``x, y, ...``, mm.
    dist : float
        The robot's distance to it, mm.
    """
    s = world.settings
    i = agent.index
    if dist > s.dock_tolerance or not _beside_for_good(world, agent, goal):
        return None
    heading = math.degrees(float(world.pose[i, 2]))
    xy, aim = world.pose[i, :2].astype(float), np.asarray(goal[:2], dtype=float)
    if not creep_is_safe(world, agent, (aim[0], aim[1], heading)):
        # the creep is safe up to some fraction of the way (a shorter creep sweeps less)
        lo, hi = 0.0, 1.0
        for _ in range(12):
            mid = (lo + hi) / 2
            q = xy + mid * (aim - xy)
            lo, hi = (mid, hi) if creep_is_safe(world, agent, (q[0], q[1], heading)) else (lo, mid)
        aim = xy + lo * (aim - xy)
        if lo == 0.0 or math.dist(aim, goal[:2]) > s.goal_tolerance:
            return None
    pose = (float(aim[0]), float(aim[1]), heading)
    return brake(world, i) if world.v[i] > 0 else ("dock", pose)


def _beside_for_good(world: World, agent: Agent, goal: tuple[float, ...]) -> bool:
    """Whether the pose `goal` lies beside something that stands for good: a wall or resting
    object within ``leave_gap``, or a robot that has finished within the standoff (it never
    moves again, like a wall: robots the scene parks closer than the standoff come home to
    that gap, as their plans allow, :mod:`cosmop.team.conflicts`)."""
    s = world.settings
    half = float(world.robot_half[agent.index])
    if float(world.static_gaps(goal[:2], half)[0]) < s.leave_gap:
        return True
    finished = [a.index for a in world.agents if a.done and a is not agent]
    if not finished:
        return False
    gaps = box_gaps(np.asarray(goal[:2], dtype=float), half, world.robot_boxes()[finished])
    return bool((gaps < s.dwa.standoff).any())


def back_onto_segment(world: World, agent: Agent) -> Action | None:
    """Creep straight back onto the start of the plan's segment, turned along it; ``None`` once there.

    A robot stops within a tolerance of its waypoint, and the plan's next segment may touch a
    wall (the plan allows touching): a few millimetres off it, or turned a few degrees towards
    the wall, the robot's first move along that segment runs into the corner, and the
    controller, aiming along the path, never finds the sideways move out.  The docking creep
    is that move: straight, slow, exact at the end.

    Parameters
    ----------
    world : World
        The running simulation.
    agent : Agent
        The robot, with its ``reseat_point`` and path set.
    """
    i = agent.index
    assert agent.reseat_point is not None and agent.path is not None  # the drive found the segment
    (sx, sy), (tx, ty) = agent.reseat_point, agent.path.points[-1]
    heading = math.atan2(ty - sy, tx - sx)
    if math.dist(world.pose[i, :2], (sx, sy)) <= 1e-9 and abs(world.heading_error(i, heading)) <= 1e-9:
        agent.reseat_point = None
        agent.way_out = None  # the segment's start may touch what the segment leaves: creep out first
        agent.path = GlobalPath(agent.path.points[1:], agent.path.margin)
        agent.last_progress_t = world.t
        return None
    return creep_to(world, agent, (sx, sy), heading)


def creep_out(world: World, agent: Agent, goal: tuple[float, float, float]) -> Action | None:
    """Before driving off a pose that touches a wall or resting object, creep clear of it.

    A plan may start a motion touching what it then leaves (a docking pose, a home against a
    wall), and a controller cannot drive off along a face it touches: it first creeps straight
    out (:func:`find_way_out`, towards the goal where it can) to ``leave_gap`` from everything
    static.  ``None`` when there is nothing to leave or once out.

    Parameters
    ----------
    world : World
        The running simulation.
    agent : Agent
        The robot about to drive.
    goal : (float, float, float)
        The goal of its drive, mm, mm, degrees.
    """
    s = world.settings
    i = agent.index
    if agent.way_out is None:
        agent.way_out = False
        if float(world.static_gaps(world.pose[i, :2], world.robot_half[i])[0]) < s.leave_gap:
            agent.way_out = find_way_out(world, i, np.asarray(goal[:2]), s.leave_gap) or False
    if agent.way_out is False or math.dist(world.pose[i, :2], agent.way_out) <= 1e-9:
        agent.way_out = False
        return None
    return creep_to(world, agent, agent.way_out)


def find_way_out(world: World, i: int, toward: NDArray[np.float64], gap: float) -> tuple[float, float] | None:
    """The nearest point straight out from robot `i` at `gap` (mm) from everything static, or ``None``.

    Headings every 5 degrees and distances every millimetre up to :data:`_EXIT_REACH` are
    tried; the way to the point must not touch a wall or resting object.  Of the points within
    2 mm of the nearest, the one most towards `toward` is taken.

    Parameters
    ----------
    world : World
        The running simulation.
    i : int
        The robot's index.
    toward : ndarray, shape (2,)
        The point the way out should head towards, mm.
    gap : float
        The gap wanted from everything static, mm.
    """
    xy, half = world.pose[i, :2], float(world.robot_half[i])
    units = np.column_stack([np.cos(_EXIT_HEADINGS), np.sin(_EXIT_HEADINGS)])
    steps = np.arange(1.0, _EXIT_REACH + 1.0)
    points = xy[None, None, :] + steps[:, None, None] * units[None, :, :]  # (distance, heading, 2)
    flat = points.reshape(-1, 2)
    # never touching on the way (the first millimetre already opens every gap that is shut):
    # creeping along a face it touches would be a contact while moving
    gaps = world.static_gaps(flat, half).reshape(len(steps), len(units))
    good = np.logical_and.accumulate(gaps > TOUCH, axis=0) & (gaps >= gap)
    if not good.any():
        return None
    first = np.where(good.any(axis=0), good.argmax(axis=0), len(steps))
    distance = np.where(first < len(steps), steps[np.minimum(first, len(steps) - 1)], np.inf)
    aim = np.asarray(toward, dtype=float) - xy
    towards = units @ (aim / max(float(np.hypot(*aim)), 1e-9))
    best = int(np.argmin(np.where(distance <= distance.min() + 2.0, -towards, np.inf)))
    x, y = points[first[best], best]
    return (float(x), float(y))
