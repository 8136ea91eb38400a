"""What the exact plan checker reports: violations of named rules."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

__all__ = ["RULES", "CheckReport", "Violation"]

RULES: Mapping[str, str] = {
    "scenario": "the plan names another scenario",
    "robot": "the plan is for a robot the scene does not have",
    "objects": "a step does not list exactly the scene's objects, or names an unknown object",
    "robot-static": "the robot moved during a primitive other than GoTo",
    "position": "an object moved other than by being dropped off",
    "carried": "a carried flag is wrong (picking, dropping, carrying)",
    "away": "an away flag is wrong (only Req sets one)",
    "wall": "the robot's swept area or a dropped object overlaps a wall, or the gripper reaches through one",
    "object-collision": "the robot's swept area or a dropped object overlaps a resting object",
    "pick-pose": "PickUp from a pose other than facing one of the object's allowed sides at distance d",
    "drop-pose": "DropOff facing none of the object's sides, or the object not put at distance d in front",
    "req-room": "the requester stands where a robot picking the object must stand",
    "mission": "a mission event is not realised in order, or does not belong to the robot or scenario",
    "coordination": "a request/response pair and the missions disagree",
    "message": "a message is sent but never awaited, awaited but never sent, or by the wrong robot",
    "deadlock": "the plans' messages can deadlock the team",
    "conflict": "two robots' plans use one place with no message ordering them",
    "itinerary": "the plan's times have a robot stop waiting for a message before it is sent",
    "infeasible": "the plan file marks the scenario infeasible",
}
"""The rule identifiers of :class:`Violation`, with what each one means."""


@dataclass(frozen=True)
class Violation:
    """One way a plan breaks a rule.

    Parameters
    ----------
    robot : str or None
        The robot whose plan breaks the rule; ``None`` for the plan set as a whole.
    instant : int or None
        The instant *k* (step ``k``, ``steps[k-1]`` in the file) where it happens; ``None``
        when the rule concerns the whole plan (e.g. the mission).
    rule : str
        The rule's identifier, a key of :data:`RULES`.
    message : str
        What is wrong, naming the robot, the instant and the primitive.
    """

    robot: str | None
    instant: int | None
    rule: str
    message: str

    def to_dict(self) -> dict[str, Any]:
        """The JSON form: ``{"robot", "instant", "rule", "message"}``."""
        return {"robot": self.robot, "instant": self.instant, "rule": self.rule, "message": self.message}


@dataclass(frozen=True)
class CheckReport:
    """The result of :func:`check_plan`.

    Parameters
    ----------
    ok : bool
        Whether the plan breaks no rule.
    violations : tuple of Violation
        Every violation found, by robot and instant.
    checked_steps : int
        The number of steps checked (over all robots of the scene).
    """

    ok: bool
    violations: tuple[Violation, ...]
    checked_steps: int

    def to_dict(self) -> dict[str, Any]:
        """The JSON form: ``{"ok", "checked_steps", "violations": [...]}``."""
        return {
            "ok": self.ok,
            "checked_steps": self.checked_steps,
            "violations": [v.to_dict() for v in self.violations],
        }
