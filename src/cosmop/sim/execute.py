"""The executors: what each robot does this cycle to carry out the step of its plan it is at.

One executor per primitive (:data:`EXECUTORS`, keyed by :class:`~cosmop.events.Primitive` as
the specification's :data:`~cosmop.planning.specification.ENCODINGS` is); each returns the robot's
:data:`~cosmop.sim.world.Action` for this cycle, or ``None`` once the step is done.
:func:`decide` runs the robot's executors until one has something to do.

``GoTo``
    drives to the step's waypoint (:func:`cosmop.sim.motion.drive`).  A waypoint followed by
    another ``GoTo`` is passed within ``pass_tolerance``, aiming past it where the next drives
    continue its straight segment (:func:`_straight_on`); the last one of a run is reached
    within ``goal_tolerance`` and turned to its heading within ``heading_tolerance``, and so is
    one from which the plan approaches a pose that touches something (not turned).
``PickUp`` / ``DropOff``
    dock: the docking pose (facing the object from the plan's side, touching it:
    :func:`cosmop.docking.docking_pose`; the plan's pose for a drop) is closed at
    ``dock_speed`` by the docking creep, then the gripper works for ``handling_time``.
``Req`` / ``Res``
    stop, then wait for the message / send it.

Units: mm, mm/s, seconds; plan poses in degrees.

Every primitive of the plan format has its executor:

>>> from cosmop.events import Primitive
>>> tuple(EXECUTORS) == tuple(Primitive)
True
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from types import MappingProxyType

import numpy as np

from cosmop.control.geometry import box_gaps
from cosmop.control.safety import stopping_margin
from cosmop.docking import docking_pose, in_front
from cosmop.events import Primitive
from cosmop.planning.plan_types import Pose, Step
from cosmop.sim.motion import HOLD, REPLANNED, StraightOn, brake, creep_is_safe, creep_out, drive
from cosmop.sim.world import TOUCH, Action, Agent, World

__all__ = [
    "EXECUTORS",
    "Executor",
    "decide",
    "drop_off",
    "go_to",
    "let_go",
    "pick_up",
    "send_message",
    "wait_for_message",
]

_COLLINEAR = 0.01  # a waypoint this far off the line per mm along it (0.6 degrees) continues it

Executor = Callable[[World, Agent, Step], Action | None]
"""Executes one step for one cycle: the robot's action, or ``None`` once the step is done."""


def decide(world: World, agent: Agent) -> Action:
    """What `agent`'s robot does this cycle: ``("drive", (target, stop, room))``,
    ``("move", (v, w))`` or ``("dock", pose)`` (:data:`~cosmop.sim.world.Action`).

    Steps that are done at once (a message sent, a drive already at its goal) are completed in
    the same cycle; a robot that has finished brakes.  A robot a delay has stopped
    (:mod:`cosmop.sim.delays`) brakes straight on and stands, its step left as it was.

    Parameters
    ----------
    world : World
        The running simulation.
    agent : Agent
        The robot deciding.
    """
    if agent.stopped_until is not None:
        return brake(world, agent.index)
    while not agent.done:
        step = agent.step
        action = EXECUTORS[step.primitive](world, agent, step)
        if action is REPLANNED:  # a new plan: its first step decides
            continue
        if action is not None:
            return action
        _complete(world, agent, step)
    return brake(world, agent.index)


def _complete(world: World, agent: Agent, step: Step) -> None:
    """Log the step done (with its start and end, s) and its mission events; go to the next."""
    agent.step_log.append((agent.plan_instants[agent.step_index], step.label, agent.step_began, world.t))
    agent.step_began = world.t
    agent.step_index += 1
    world.log_events(agent, step)
    agent.path_left = 0.0
    agent.waiting = False
    agent.restart_step()


# -- GoTo ----------------------------------------------------------------------------------------


def go_to(world: World, agent: Agent, step: Step) -> Action | None:
    """Drive to the step's waypoint: passed if another GoTo follows, else reached and turned to.

    A waypoint from which the plan approaches a pose that touches something is reached too
    (not turned): cutting its corner would cut into what that pose touches.  A robot that
    starts off touching something creeps out first (:func:`cosmop.sim.motion.creep_out`).

    Parameters
    ----------
    world : World
        The running simulation.
    agent : Agent
        The robot executing the step.
    step : Step
        Its current step.
    """
    k = agent.step_index
    agent.through = False
    after = _next_drive(world, agent, k)
    last = after is None
    goal = step.robot
    stop = after is None or bool(
        world.static_gaps(agent.steps[after].robot[:2], world.robot_half[agent.index])[0]
        < world.settings.leave_gap
    )
    origin = agent.origin
    if agent.way_out is not False:  # at the start, and after creeping back onto the plan's segment
        action = creep_out(world, agent, goal)
        if action is not None:
            return action
    ahead = None if stop else _straight_on(world, agent, k, origin, after)
    action = drive(world, agent, goal, stop, heading=last, origin=origin, ahead=ahead)
    agent.through = action is None and not stop
    return action


def _straight_on(
    world: World, agent: Agent, k: int, origin: Pose | None, after: int | None
) -> StraightOn | None:
    """How far the robot drives on in a straight line past step `k`'s waypoint: the farthest
    waypoint of the GoTos that continue the segment from `origin` (``None``: where the robot
    stands) to the waypoint in its direction and that it passes without stopping (messages
    come, nothing held), and whether it stops there.

    A drive cut where it enters and leaves places shared with other robots is a run of short
    collinear steps; aiming only at the next cut, the window would slow the robot at every one
    of them although it drives straight on (:func:`cosmop.sim.motion.drive`).  ``None`` when
    the next drive turns.
    """
    # the segment's start: the previous waypoint, or where the robot stands on its first drive
    start = np.asarray(origin[:2] if origin else world.pose[agent.index, :2], dtype=float)
    end = np.asarray(agent.steps[k].robot[:2], dtype=float)
    direction = end - start
    length = float(np.hypot(*direction))
    if length <= 0.0:
        return None
    direction /= length
    far: tuple[float, float] | None = None
    stops = False
    n = after
    while n is not None:
        point = np.asarray(agent.steps[n].robot[:2], dtype=float)
        leg = point - end
        along = float(leg @ direction)
        if along <= 0.0 or abs(float(leg[0] * direction[1] - leg[1] * direction[0])) > _COLLINEAR * along:
            break
        far, end = (float(point[0]), float(point[1])), point
        n = _next_drive(world, agent, n)
        stops = n is None or bool(
            world.static_gaps(agent.steps[n].robot[:2], world.robot_half[agent.index])[0]
            < world.settings.leave_gap
        )
        if stops:
            break
    return None if far is None else StraightOn(far, stops)


def _next_drive(world: World, agent: Agent, k: int) -> int | None:
    """The index of the GoTo the robot drives on to from step `k`'s waypoint without stopping:
    the next step, or the first after messages that hold nothing up (one it sends, one it
    awaits that has come).  ``None`` when it stops at the waypoint."""
    for n in range(k + 1, len(agent.steps)):
        step = agent.steps[n]
        if step.primitive == Primitive.GOTO:
            return n
        holds = step.primitive != Primitive.RES and not (
            step.primitive == Primitive.REQ and step.message is not None and world.received(agent, step)
        )
        if holds:
            return None
    return None


# -- PickUp and DropOff --------------------------------------------------------------------------


def pick_up(world: World, agent: Agent, step: Step) -> Action | None:
    """Dock facing the object where it is now (from the side the plan faces), then lift it.

    The gripper touches the object from the docking on; a pick-up whose docking is blocked
    within ``reach`` of its pose still picks the object up.  A carried object rides on its
    robot, inside the robot's square, as in the plan model where a carried object takes no room.

    Parameters
    ----------
    world : World
        The running simulation.
    agent : Agent
        The robot executing the step.
    step : Step
        Its current step.
    """
    i = agent.index
    j = world.object_ids.index(step.object)
    heading = float(step.robot[2]) % 360.0
    gap = world.robot_half[i] + world.object_half[j]
    x, y = docking_pose(world.object_xy[j], gap, heading)
    dock = (float(x), float(y), heading)

    def lift() -> None:
        world.carried_by[j] = i
        agent.gripped = None

    return _dock_and_handle(world, agent, dock, grip=j, reach=world.settings.reach, clear=None, handle=lift)


def drop_off(world: World, agent: Agent, step: Step) -> Action | None:
    """Dock on the plan's pose exactly, then put the object down where the plan puts it.

    The object goes down only where it appears safely (:func:`_drop_clear`).  After the drop
    the robot stays where the plan has it, touching the object (a robot that waits there keeps
    the clearances the plan was ordered with), and creeps out when it next drives, so that it
    never drives along the object it touches (:func:`let_go` then frees the gripper).

    Parameters
    ----------
    world : World
        The running simulation.
    agent : Agent
        The robot executing the step.
    step : Step
        Its current step.
    """
    i = agent.index
    j = world.object_ids.index(step.object)
    heading = float(step.robot[2]) % 360.0
    dock = (float(step.robot[0]), float(step.robot[1]), heading)

    def put_down() -> None:
        world.object_xy[j] = _drop_position(world, agent, step, j)
        world.carried_by[j] = -1
        agent.gripped = j  # touching it where the plan stands, until it creeps out

    def clear() -> bool:
        return _drop_clear(world, i, j, _drop_position(world, agent, step, j))

    return _dock_and_handle(world, agent, dock, grip=None, reach=0.0, clear=clear, handle=put_down)


def _dock_and_handle(
    world: World,
    agent: Agent,
    dock: tuple[float, float, float],
    *,
    grip: int | None,
    reach: float,
    clear: Callable[[], bool] | None,
    handle: Callable[[], None],
) -> Action | None:
    """Close the docking pose `dock` (mm, mm, degrees), then let the gripper work; ``None`` once
    `handle` has done its work.

    Stages (``agent.dock_stage``): *approach* -- drive to the pose when the robot is farther
    than ``dock_tolerance`` from it; *dock* -- brake, then creep onto it (the gripper touches
    object `grip` from now on, if given); blocked within `reach` (mm) of the pose, the gripper
    works from there; *docked* -- it stands there for good (parked, :meth:`World.parked`) and
    waits until `clear` allows; *handle* -- stand ``handling_time``
    (and while another robot crowds it: a parked robot keeps its promise), then `handle` once
    `clear` allows again (another robot may have come close during the handling).
    """
    s = world.settings
    i = agent.index
    if agent.dock_stage is None:
        offset = math.hypot(dock[0] - world.pose[i, 0], dock[1] - world.pose[i, 1])
        agent.dock_stage = "dock" if offset <= s.dock_tolerance else "approach"
    if agent.dock_stage == "approach":  # not where the plan said: drive to the docking pose first
        action = drive(world, agent, dock, final=True, heading=True)
        if action is not None:
            return action
        agent.dock_stage = "dock"
    if agent.dock_stage == "dock":
        if grip is not None:
            agent.gripped = grip
        if world.v[i] > 0:
            return brake(world, i)
        offset = math.hypot(dock[0] - world.pose[i, 0], dock[1] - world.pose[i, 1])
        error = abs(world.heading_error(i, math.radians(dock[2])))
        there = offset < 1e-9 and error < 1e-9
        if not there and creep_is_safe(world, agent, dock):
            return ("dock", dock)
        if not there and (offset > reach or error > math.radians(s.heading_tolerance)):
            return HOLD  # blocked: wait (the gripper cannot reach from here)
        # on its pose until the gripper has worked: parked, so that a robot docked beside it
        # may put its goods down (were both to wait for the other to park, neither would drop)
        agent.dock_stage = "docked"
    if agent.dock_stage == "docked":
        if clear is not None and not clear():
            return HOLD
        agent.dock_stage = "handle"
        agent.handling_left = s.handling_time
    if agent.dock_stage == "handle":
        agent.handling_left -= world.dt
        if agent.handling_left > 1e-9 or world.crowded(i):
            return HOLD
        if clear is not None and not clear():  # asked again: others moved during the handling
            return HOLD
        handle()
        return None
    return HOLD


def _drop_position(world: World, agent: Agent, step: Step, j: int) -> np.ndarray:
    """Where the gripper puts object `j` down (mm): where the plan puts it (within reach of the
    robot), else just in front of the robot."""
    planned = step.objects.get(world.object_ids[j])
    if planned is not None:
        return np.array(planned.position, dtype=float)
    i = agent.index
    front = in_front(world.pose[i], world.robot_half[i] + world.object_half[j], float(step.robot[2]) % 360.0)
    return np.array(front, dtype=float)


def _drop_clear(world: World, i: int, j: int, spot: np.ndarray) -> bool:
    """Whether object `j` may be put at `spot` by robot `i` now.

    A new object must not appear inside another robot's stopping distance (that robot could
    no longer brake in time: passive safety assumes resting obstacles stay where they are) nor
    within the standoff of one that may move, nor on a parked robot or a person.  A parked robot
    does not move while this one is close, and sees the object once it does.
    """
    others = [k for k in range(len(world.robot_ids)) if k != i]
    box = np.array([[*spot, world.object_half[j]]])
    if others:
        gaps = box_gaps(world.pose[others, :2], world.robot_half[others][:, None], box)
        parked = world.parked()
        need = [
            TOUCH
            if parked[k]
            else stopping_margin(world.v[k], 0.0, world.limits[k]) + world.settings.dwa.standoff
            for k in others
        ]
        if (gaps[:, 0] <= np.array(need)).any():
            return False
    people = world.people_boxes() if world.walkers else None
    return people is None or not bool((box_gaps(spot, world.object_half[j], people) <= TOUCH).any())


def let_go(world: World) -> None:
    """Free the gripper of every robot that has crept more than 1 mm off the object it dropped.

    Parameters
    ----------
    world : World
        The running simulation.
    """
    held = [(a, a.gripped) for a in world.agents if a.gripped is not None and a.dock_stage is None]
    held = [(a, j) for a, j in held if world.carried_by[j] < 0]  # dropped, not picked
    if not held:
        return
    robots, objects = [a.index for a, _ in held], [j for _, j in held]
    boxes = np.column_stack([world.object_xy[objects], world.object_half[objects]])[:, None, :]  # one each
    gaps = box_gaps(world.pose[robots, :2], world.robot_half[robots][:, None], boxes)[:, 0]
    for (agent, _), gap in zip(held, gaps.tolist(), strict=True):
        if gap > 1.0:
            agent.gripped = None


# -- Req and Res ---------------------------------------------------------------------------------


def wait_for_message(world: World, agent: Agent, step: Step) -> Action | None:
    """``Req``: stop and wait until the message is sent, and no robot that may move is within
    the standoff (a waiting robot is parked: :meth:`~cosmop.sim.world.World.crowded`).

    Parameters
    ----------
    world : World
        The running simulation.
    agent : Agent
        The robot executing the step.
    step : Step
        Its current step.
    """
    i = agent.index
    if agent.through and step.message is not None and world.received(agent, step):
        return None  # it has come: the robot drives on through the waypoint
    agent.waiting = True
    if world.v[i] > 0 or not world.received(agent, step) or world.crowded(i):
        return brake(world, i)
    agent.waiting = False
    return None


def send_message(world: World, agent: Agent, step: Step) -> Action | None:
    """``Res``: stop, then send the message (:meth:`~cosmop.sim.world.World.send`); a robot
    driving through the waypoint sends it on the way (a cut where a robot leaves a place it
    shares lies a pass tolerance beyond the place: :class:`~cosmop.team.conflicts.ConflictSettings`).

    Parameters
    ----------
    world : World
        The running simulation.
    agent : Agent
        The robot executing the step.
    step : Step
        Its current step.
    """
    if world.v[agent.index] > 0 and not agent.through:
        return brake(world, agent.index)
    world.send(agent, step)
    return None


EXECUTORS: Mapping[Primitive, Executor] = MappingProxyType(
    {
        Primitive.GOTO: go_to,
        Primitive.PICKUP: pick_up,
        Primitive.DROPOFF: drop_off,
        Primitive.REQ: wait_for_message,
        Primitive.RES: send_message,
    }
)
"""The executor of every plan primitive."""
