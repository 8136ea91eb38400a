"""Bottom-up motion layer: plans of safe motion primitives and their exact checking.

A robot's plan is a sequence of the paper's motion primitives -- ``GoTo``, ``PickUp``,
``DropOff``, ``Req`` (request an object away, ``?ObjAway``) and ``Res`` (answer that it has been
moved, ``!ObjAway``) -- with the state after each one (:mod:`cosmop.planning.plan_types`; what
each primitive does to the state, :mod:`cosmop.planning.primitive_effects`; the plan file
``cosmop.plan/1``, :mod:`cosmop.planning.plan_file`). :func:`check_robot_plan` decides exactly, with
shapely geometry and without any SMT encoding, whether one robot's plan is sound for its scene and
realises its mission (:mod:`cosmop.planning.checker`; a whole plan set is checked by
:mod:`cosmop.team.plan_set_checker`). :mod:`cosmop.planning.regions` holds the sound GoTo region
constraints used by the bounded encoding. Units are millimetres and degrees throughout.
"""

from cosmop.planning.checker import (
    RULES,
    TOLERANCE,
    CheckReport,
    Violation,
    check_robot_plan,
    overlaps,
    square,
    swept_square,
)
from cosmop.planning.plan_file import PlanError, load_plan
from cosmop.planning.plan_types import (
    OBJECT_PRIMITIVES,
    PLAN_FORMAT,
    PRIMITIVES,
    Coordination,
    ObjectState,
    ObjectStates,
    PlanSet,
    RobotPlan,
    State,
    Step,
)
from cosmop.planning.primitive_effects import initial_state, plan_from_actions, successor

__all__ = [
    "OBJECT_PRIMITIVES",
    "PLAN_FORMAT",
    "PRIMITIVES",
    "RULES",
    "TOLERANCE",
    "CheckReport",
    "Coordination",
    "ObjectState",
    "ObjectStates",
    "PlanError",
    "PlanSet",
    "RobotPlan",
    "State",
    "Step",
    "Violation",
    "check_robot_plan",
    "initial_state",
    "load_plan",
    "overlaps",
    "plan_from_actions",
    "square",
    "successor",
    "swept_square",
]
