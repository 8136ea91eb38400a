"""How long each step of a plan takes: the execution model the coordination layer reasons with.

The simulator drives unicycles with the limits of :class:`~cosmop.scene.Dynamics`; this
module estimates the same motions in closed form, so that plans can be ordered by when their
steps are expected to happen (and shared as itineraries):

``GoTo`` from pose :math:`p` to pose :math:`q`
    turn on the spot to face :math:`q` (at the turn rate :math:`\\Omega`), drive the straight
    distance :math:`d` with a trapezoidal speed profile (accelerate at :math:`A` up to the top
    speed :math:`v_{max}`, brake at :math:`b` to a stop), then turn to :math:`q`'s heading.  The
    drive takes :math:`v/A + v/b + (d - v^2/(2A) - v^2/(2b))/v_{max}` with :math:`v = v_{max}`
    when :math:`d \\ge v_{max}^2/(2A) + v_{max}^2/(2b)`, else the triangle profile
    :math:`v = \\sqrt{2dAb/(A+b)}`, :math:`t = v/A + v/b`.
``PickUp``, ``DropOff``
    docking and the gripper: :attr:`ExecutionModel.handling_time`.
``Req``, ``Res``
    no time of their own (a ``Req`` lasts until its message has been sent).

Consecutive GoTo steps in one direction (a drive cut into pieces, with messages sent or awaited
between them) are one drive, shared by the pieces in proportion to their lengths; a change of
direction is estimated stop to stop (the controller passes intermediate waypoints without
stopping, so real runs are usually faster).
The estimates order events; they are not a promise.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from cosmop.events import Primitive
from cosmop.planning.plan_types import Itinerary, RobotPlan, State
from cosmop.planning.realisation import message_links
from cosmop.scene import Dynamics, Scene
from cosmop.team.precedence import Precedence

__all__ = [
    "ExecutionModel",
    "drive_time",
    "durations",
    "itinerary",
    "start_pose",
    "step_durations",
    "turn_time",
]


@dataclass(frozen=True)
class ExecutionModel:
    """Times of the primitives that do not drive.

    Attributes
    ----------
    handling_time : float
        Seconds a PickUp or DropOff takes: docking, the gripper, backing off (default 2).
    """

    handling_time: float = 2.0


def turn_time(angle_deg: float, dynamics: Dynamics) -> float:
    """Seconds to turn on the spot by `angle_deg` degrees (the shorter way round).

    Parameters
    ----------
    angle_deg : float
        The turn (degrees, any sign and size).
    dynamics : Dynamics
        The robot's limits (its turn rate).
    """
    angle = abs((angle_deg + 180.0) % 360.0 - 180.0)
    return angle / dynamics.turn_rate


def drive_time(distance: float, dynamics: Dynamics) -> float:
    """Seconds to drive `distance` mm in a straight line from standstill to standstill.

    Parameters
    ----------
    distance : float
        The length of the drive (mm).
    dynamics : Dynamics
        The robot's limits (top speed, acceleration, braking).

    >>> round(drive_time(1500.0, Dynamics(max_speed=750, acceleration=300, braking=500)), 3)
    4.0
    """
    if distance <= 0.0:
        return 0.0
    vmax, a, b = dynamics.max_speed, dynamics.acceleration, dynamics.braking
    ramps = vmax * vmax / (2.0 * a) + vmax * vmax / (2.0 * b)
    if distance >= ramps:
        return vmax / a + vmax / b + (distance - ramps) / vmax
    v = math.sqrt(2.0 * distance * a * b / (a + b))
    return v / a + v / b


def _goto_time(start: tuple[float, ...], end: tuple[float, ...], dynamics: Dynamics) -> float:
    dx, dy = end[0] - start[0], end[1] - start[1]
    distance = math.hypot(dx, dy)
    if distance == 0.0:
        return turn_time(end[2] - start[2], dynamics)
    facing = math.degrees(math.atan2(dy, dx))
    return (
        turn_time(facing - start[2], dynamics)
        + drive_time(distance, dynamics)
        + turn_time(end[2] - facing, dynamics)
    )


_Piece = tuple[int, tuple[float, ...], tuple[float, ...]]
"""A piece of one straight drive: the step's index, the pose it starts from and the one it ends at."""


def step_durations(
    plan: RobotPlan,
    start: tuple[float, float, float],
    dynamics: Dynamics,
    model: ExecutionModel | None = None,
) -> list[float]:
    """Expected seconds of every step of `plan` (``[d_1, ..., d_K]``), without waiting.

    Parameters
    ----------
    plan : RobotPlan
        The plan.
    start : tuple of float
        The pose at instant 0 ``(x, y, heading)``, mm and degrees.
    dynamics : Dynamics
        The robot's limits.
    model : ExecutionModel, optional
        The times of PickUp and DropOff (default :class:`ExecutionModel`).

    Returns
    -------
    list of float
    """
    model = model or ExecutionModel()
    out: list[float] = []
    pose = tuple(start)
    run: list[_Piece] = []  # pieces of one straight drive: (index, from, to)
    for step in plan.steps:
        if step.primitive == Primitive.GOTO and run and not _collinear(run[-1][1], run[-1][2], step.robot):
            _close(run, out, dynamics)
            run = []
        out.append(0.0)
        if step.primitive == Primitive.GOTO:
            run.append((len(out) - 1, pose, step.robot))
        elif step.primitive in (Primitive.PICKUP, Primitive.DROPOFF):
            _close(run, out, dynamics)
            run = []
            out[-1] = model.handling_time
        # a message between two pieces of one drive is sent or received on the way: a robot
        # whose message has come drives on (waiting, when it must, is the order's, not the drive's)
        pose = step.robot
    _close(run, out, dynamics)
    return out


def _collinear(a: Sequence[float], b: Sequence[float], c: Sequence[float]) -> bool:
    """Whether going on from `b` to `c` continues the drive from `a` to `b` (within 1 degree)."""
    u = (b[0] - a[0], b[1] - a[1])
    v = (c[0] - b[0], c[1] - b[1])
    nu, nv = math.hypot(*u), math.hypot(*v)
    if nu == 0.0 or nv == 0.0:
        return False
    return (u[0] * v[0] + u[1] * v[1]) / (nu * nv) >= math.cos(math.radians(1.0))


def _close(run: list[_Piece], out: list[float], dynamics: Dynamics) -> None:
    """Share the time of one straight drive among its pieces, by length."""
    if not run:
        return
    total = _goto_time(run[0][1], run[-1][2], dynamics)
    lengths = [math.dist(p[:2], q[:2]) for _, p, q in run]
    whole = sum(lengths)
    for (index, _, _), length in zip(run, lengths, strict=True):
        out[index] = total * (length / whole if whole > 0 else 1.0 / len(run))


def start_pose(
    scene: Scene, robot: str, starts: Mapping[str, State] | None = None
) -> tuple[float, float, float]:
    """Where `robot` starts: its state in `starts`, else the scenario's pose (mm, degrees).

    Parameters
    ----------
    scene : Scene
        The scenario.
    robot : str
        The robot's id.
    starts : Mapping[str, State], optional
        Where robots start, by id, if not at the scenario's poses.
    """
    state = (starts or {}).get(robot)
    return state.robot if state is not None else scene.robots[robot].pose


def durations(
    scene: Scene,
    plans: Mapping[str, RobotPlan],
    model: ExecutionModel | None = None,
    starts: Mapping[str, State] | None = None,
) -> dict[str, list[float]]:
    """Expected seconds of every step of every plan (:func:`step_durations`), by robot.

    Parameters
    ----------
    scene : Scene
        The scenario (start poses, each robot's dynamics).
    plans : Mapping[str, RobotPlan]
        Every robot's plan, by id.
    model : ExecutionModel, optional
        The times of PickUp and DropOff (default :class:`ExecutionModel`).
    starts : Mapping[str, State], optional
        Where robots start, by id, if not at the scenario's poses.
    """
    return {
        r: step_durations(p, start_pose(scene, r, starts), scene.robots[r].dynamics, model)
        for r, p in plans.items()
    }


def itinerary(
    scene: Scene,
    plans: Mapping[str, RobotPlan],
    model: ExecutionModel | None = None,
    starts: Mapping[str, State] | None = None,
) -> Itinerary:
    """When every step of a team's plans is expected to start and end, messages included.

    Every robot starts at time 0.  Step *k* of robot *r* starts when its step *k-1* ends,
    :math:`s_{r,k} = e_{r,k-1}` (:math:`e_{r,0} = 0`), and ends after its expected duration
    :math:`d_{r,k}` (:func:`step_durations`) -- a ``Req`` not before its message has been sent:
    :math:`e_{r,k} = \\max(s_{r,k} + d_{r,k}, e_{q,j})` where step *j* of robot *q* is the
    ``Res`` that sends it.  That is the earliest schedule of the plans' partial order
    (:class:`~cosmop.team.precedence.Precedence`), the one robots that never wait longer
    than they must follow.  Times are rounded to the millisecond.

    Parameters
    ----------
    scene : Scene
        The scenario (start poses, each robot's dynamics).
    plans : Mapping[str, RobotPlan]
        Every robot's plan; their messages must not deadlock.
    model : ExecutionModel, optional
        The times of PickUp and DropOff (default :class:`ExecutionModel`).
    starts : Mapping[str, State], optional
        Where robots start, if not at the scenario's poses.

    Returns
    -------
    Itinerary

    Raises
    ------
    ValueError
        If a ``Req`` waits for a message that is never sent, or the messages wait in a cycle.
    """
    order = Precedence(
        {r: p.horizon for r, p in plans.items()},
        message_links(plans),
        (),
        durations(scene, plans, model, starts),
    )
    if not order.complete:
        stuck = ", ".join(f"{r} at instant {k}" for r, k in order.stuck.items())
        raise ValueError(f"the plans' messages deadlock ({stuck}); they have no itinerary")
    return Itinerary(
        {
            r: tuple(
                (round(float(order.started[r][k]), 3), round(float(order.finish[r][k]), 3))
                for k in range(1, p.horizon + 1)
            )
            for r, p in plans.items()
        }
    )
