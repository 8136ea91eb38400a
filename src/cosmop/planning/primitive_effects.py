"""What the motion primitives do to a robot's state: their nominal effects.

:func:`initial_state` gives instant 0 of a robot's plan (the scenario, with goods other robots
move as the plan knows them); :func:`successor` applies one primitive's nominal effect to a
state and :func:`plan_from_actions` a whole list of them (handy for hand-made plans and for
decoding a solver's model).  ``GoTo`` moves the robot, ``PickUp`` marks its object carried,
``DropOff`` puts it down in front of the robot, ``Req`` marks it moved away and ``Res`` changes
nothing.  No rule is checked here: that is :mod:`cosmop.planning.checker`'s business.
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Collection, Iterable, Mapping, Sequence
from collections.abc import Set as AbstractSet
from typing import Any

from cosmop.docking import in_front
from cosmop.events import Event, Primitive
from cosmop.planning.plan_types import PRIMITIVES, ObjectState, ObjectStates, Pose, RobotPlan, State, Step
from cosmop.scene import Scene

__all__ = ["Action", "initial_state", "plan_from_actions", "scenario_objects", "successor"]


def initial_state(
    scene: Scene,
    robot_id: str,
    plan: RobotPlan | Sequence[Step] | None = None,
    moved: Collection[str] | None = None,
) -> State:
    """Instant 0 of a robot's plan: the scenario, with goods that robots move as the plan knows them.

    Each robot is planned alone, against the objects as it knows them: goods another robot
    hands over to it lie where the other puts them down, goods others drop in a dock it shares
    lie in their slots (:mod:`cosmop.team.handover`, :func:`cosmop.team.aside.dock_slots`).
    Its plan lists that model at every step; instant 0 is the model before the first step.

    Parameters
    ----------
    scene : Scene
        The scene the plan is for.
    robot_id : str
        The robot whose plan it is.
    plan : RobotPlan or sequence of Step, optional
        The plan (or its steps).
    moved : collection of str, optional
        The goods whose place at instant 0 is the plan's own (as its first step lists them,
        before that step's effect): goods the team moves, whose real places the team's checker
        verifies (:mod:`cosmop.team.plan_set_checker`).  By default the goods the plan picks up.

    Returns
    -------
    State
        The robot at its initial pose (mm, degrees); every object at its scenario position
        (or, the `moved` ones, as the plan lists them), not carried and not away.

    Raises
    ------
    KeyError
        If the scene has no robot `robot_id`.
    """
    robot = scene.robots[robot_id]
    objects = base = scenario_objects(scene)
    steps = plan.steps if isinstance(plan, RobotPlan) else tuple(plan or ())
    if steps:
        if moved is None:
            moved = {s.object for s in steps if s.primitive == Primitive.PICKUP and s.object is not None}
        first = steps[0].objects
        if not isinstance(moved, AbstractSet | Mapping):
            moved = set(moved)  # looked up once per object listed
        # only goods the plan lists elsewhere change (often none of thousands)
        objects = base.updated(
            {
                oid: ObjectState(state.position)
                for oid, state in first.items()
                if oid in moved and oid in base and state.position != base[oid].position
            }
        )
    return State(robot=robot.pose, objects=objects)


_AT_REST: dict[int, tuple[weakref.ReferenceType[Scene], ObjectStates]] = {}
"""The scenario's objects of the scenes asked about lately, by identity (scenes are not hashable)."""


def scenario_objects(scene: Scene) -> ObjectStates:
    """Every object of `scene` where the scenario puts it, resting and not away.

    Made once per scene: every plan's instant 0 starts from it, and a warehouse holds thousands
    of goods.

    Parameters
    ----------
    scene : Scene
        The scene.
    """
    hit = _AT_REST.get(id(scene))
    if hit is not None and hit[0]() is scene:
        return hit[1]
    states = ObjectStates({o: ObjectState(obj.position) for o, obj in scene.objects.items()})
    if len(_AT_REST) >= 32:  # scenes come and go (a replan's sensed scene): keep a few
        _AT_REST.clear()
    _AT_REST[id(scene)] = (weakref.ref(scene), states)
    return states


Action = tuple[str, Any] | tuple[str]
"""A primitive to apply: ``("GoTo", (x, y, heading))``, ``("PickUp", "O1")``, ... (see :func:`successor`)."""


def successor(
    scene: Scene,
    robot_id: str,
    state: State,
    primitive: str,
    obj: str | None = None,
    to: tuple[float, float, float] | None = None,
) -> Step:
    """The step that applies a primitive's nominal effect to `state` (no rule is checked).

    ``GoTo`` moves the robot to `to`; ``PickUp(O)`` marks O carried; ``DropOff(O)`` puts O at
    :math:`(x, y) + d\\,(\\cos h, \\sin h)` in front of the robot facing :math:`h` (a docking
    heading: 0, 90, 180 or 270 degrees), :math:`d = (l + b)/2`, and marks it not carried;
    ``Req(O)`` marks O away; ``Res(O)`` changes nothing. Whether the step is allowed is the
    business of :func:`cosmop.planning.checker.check_robot_plan`.

    Parameters
    ----------
    scene : Scene
        The scene (for the sizes).
    robot_id : str
        The robot taking the step.
    state : State
        The state before the step.
    primitive : {"GoTo", "PickUp", "DropOff", "Req", "Res"}
        The primitive.
    obj : str, optional
        The object, for every primitive but ``GoTo``.
    to : tuple of float, optional
        The target pose ``(x, y, heading)`` (mm, degrees), for ``GoTo`` only.

    Returns
    -------
    Step
    """
    if primitive not in PRIMITIVES:  # as Step says it
        raise ValueError(f"unknown primitive {primitive!r}; expected one of {', '.join(PRIMITIVES)}")
    kind = Primitive(primitive)
    robot = state.robot
    objects: dict[str, ObjectState] = {}  # the objects the step changes
    if kind == Primitive.GOTO:
        if to is None:
            raise ValueError("GoTo needs a target pose `to`")
        robot = to
    elif to is not None:
        raise ValueError(f"{primitive} does not move the robot; give no target pose")
    elif obj is None:  # as Step says it
        raise ValueError(f"{primitive} needs the object it acts on")
    elif kind == Primitive.PICKUP:
        was = state.objects[obj]
        objects[obj] = ObjectState(was.position, carried=True, away=was.away)
    elif kind == Primitive.DROPOFF:
        gap = (scene.robots[robot_id].size + scene.objects[obj].size) / 2.0
        objects[obj] = ObjectState(_ahead(robot, gap), carried=False, away=state.objects[obj].away)
    elif kind == Primitive.REQ:
        objects[obj] = ObjectState(state.objects[obj].position, carried=state.objects[obj].carried, away=True)
    return Step(kind, obj, robot, ObjectStates.of(state.objects).updated(objects))


def _ahead(pose: Pose, gap: float) -> tuple[float, float]:
    """The point `gap` mm ahead of `pose`: exact at a docking heading, in floats at any other
    (a plan written by hand may drop at 45 degrees; the checker names that, not this)."""
    try:
        return in_front(pose, gap, pose[2])
    except ValueError:
        turn = math.radians(pose[2])
        return pose[0] + gap * math.cos(turn), pose[1] + gap * math.sin(turn)


def plan_from_actions(
    scene: Scene, robot_id: str, mission: Iterable[Event], actions: Iterable[Action]
) -> RobotPlan:
    """A robot plan from a list of primitives, each applied with :func:`successor`.

    Parameters
    ----------
    scene : Scene
        The scene; instant 0 is :func:`initial_state`.
    robot_id : str
        The robot.
    mission : iterable of Event
        The mission the plan is meant to realise.
    actions : iterable of tuple
        ``("GoTo", (x, y, heading))`` or ``(primitive, object)`` for the others.

    Returns
    -------
    RobotPlan

    Examples
    --------
    >>> plan = plan_from_actions(scene, "R2", [parse_event("pick(R2,O2)")],
    ...                          [("GoTo", (1650, -1000, 0)), ("PickUp", "O2")])  # doctest: +SKIP
    """
    state = initial_state(scene, robot_id)
    steps = []
    for action in actions:
        primitive, *rest = action
        arg = rest[0] if rest else None
        if primitive == Primitive.GOTO:
            step = successor(scene, robot_id, state, primitive, to=arg)
        else:
            step = successor(scene, robot_id, state, primitive, obj=arg)
        steps.append(step)
        state = step.state
    return RobotPlan.from_steps(mission, steps)
