"""Why a robot stands, in plain words: what the pictures write beside a waiting robot.

A robot of a simulated run stands for one of three reasons the trace records
(:class:`cosmop.traces.Trace`): it waits for a message (``awaits``), it gives way to a robot or
a person its controller will not come closer to (``yields_to``), or a delay has stopped it
(``delayed``).  The plan file says why each message exists (:class:`cosmop.planning.plan_types.PlanMessage`:
its kind, what it protects and the place two robots share); :func:`waiting_words` turns that
into a sentence a newcomer reads without knowing the formal terms, "waits for R2 to clear the
way near W3", in the scenario file's units.  The web viewer and the animations write these
sentences; they never parse the ``protects`` text.
"""

from __future__ import annotations

from dataclasses import dataclass

from cosmop.errors import EventSyntaxError
from cosmop.events import Event, Primitive, parse_event
from cosmop.planning.plan_types import PlanMessage, PlanSet, RobotPlan
from cosmop.scene import Scene
from cosmop.units import length_unit, show_point

__all__ = ["NEAR_MM", "Explainer", "waiting_words"]

NEAR_MM = 1000.0
"""A shared place within this L-infinity distance (mm) of a workspace is said to be "near" it."""


def waiting_words(scene: Scene, plans: PlanSet | None = None) -> dict[str, str]:
    """For every message the plans wait for, why a robot waits for it, in plain words.

    Parameters
    ----------
    scene : Scene
        Its workspaces name the places; its ``units`` are the units of the words.
    plans : PlanSet, optional
        The messages (``messages``: conflicts, orders, the mission's own) and the requests to
        move goods away (``away`` events of the missions).

    Returns
    -------
    dict of str to str
        ``{message name: "waits for R2 to clear the way near W3"}``; a message the plans do not
        know gets :meth:`Explainer.awaits`'s fallback.
    """
    explainer = Explainer(scene, plans)
    events = [m.event for m in (plans.messages if plans is not None else ())]
    events += [e for plan in (plans.robots.values() if plans is not None else ()) for e in plan.mission]
    return {e.name: explainer.awaits_event(e) for e in dict.fromkeys(events) if e.is_message}


@dataclass(frozen=True)
class Explainer:
    """Plain words for why a robot stands, given the scene and (optionally) the plans.

    Attributes
    ----------
    scene : Scene
    plans : PlanSet or None
    """

    scene: Scene
    plans: PlanSet | None = None

    def awaits(self, name: str) -> str:
        """Why a robot waits for the message `name` (``msg(A,B,x)`` or ``away(O,A,B)``).

        Parameters
        ----------
        name : str
            The message event's canonical name (as a trace writes it).

        Returns
        -------
        str
            A sentence such as "waits for R2 to clear the way near W3".
        """
        try:
            event = parse_event(name)
        except EventSyntaxError:
            return f"waits for the message {name}"
        return self.awaits_event(event)

    def awaits_event(self, event: Event) -> str:
        """Why a robot waits for the message `event` (:meth:`awaits`, for an event already read).

        Parameters
        ----------
        event : Event
            The message event (``msg`` or ``away``).

        Returns
        -------
        str
            A sentence such as "waits for R2 to clear the way near W3".
        """
        name = event.name
        if event.kind == "away":
            return f"waits for {event.responder} to move {event.obj} out of its way"
        known = self._message(event)
        sender = event.sender
        if known is None:
            return f"waits for a message from {sender} ({event.tag or name})"
        if known.kind == "conflict":
            return f"waits for {sender} to clear the way {self._where(known)}".rstrip()
        done = self._sender_did(event)
        if known.kind == "order":
            return f"waits for {sender} to {done or 'go first'} first (the mission's order)"
        return f"waits for {sender}'s message {event.tag or name} (the mission's)"

    def yields(self, who: str) -> str:
        """Why a robot stands for the robot or person `who` near it.

        Parameters
        ----------
        who : str
            The id of the robot or person it gives way to.
        """
        if who in self.scene.humans:
            return f"waits for {who} (a person) to pass"
        return f"gives way to {who}"

    def _message(self, event: Event) -> PlanMessage | None:
        if self.plans is None:
            return None
        return next((m for m in self.plans.messages if m.event == event), None)

    def _where(self, message: PlanMessage) -> str:
        """ "near W3" when the shared place lies near a workspace, else "at (x, y)" in the file's units."""
        if message.place is None:
            return ""
        x0, y0, x1, y1 = message.place
        cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
        best, gap = None, NEAR_MM
        for wid, ws in self.scene.workspaces.items():
            (wx0, wx1), (wy0, wy1) = ws.ranges
            d = max(wx0 - cx, cx - wx1, wy0 - cy, cy - wy1, 0.0)
            if d <= gap:
                best, gap = wid, d
        if best is not None:
            return f"near {best}"
        # to the centimetre: a place shared for a moment needs no finer address
        where = show_point((round(cx, -1), round(cy, -1)), self.scene.units)
        return f"at {where} {length_unit(self.scene.units)}"

    def _sender_did(self, event: Event) -> str | None:
        """What the sender does just before it sends `event`: "drop O1 in W1", "pick up O2"."""
        plans, sender = self.plans, event.sender
        plan: RobotPlan | None = (
            plans.robots.get(sender) if plans is not None and sender is not None else None
        )
        if plan is None:
            return None
        send = next((k for k, s in enumerate(plan.steps) if s.message == event), None)
        for step in reversed(plan.steps[:send] if send is not None else ()):
            if step.primitive == Primitive.DROPOFF:
                where = _drop_workspace(plan, step.object)
                return f"drop {step.object}" + (f" in {where}" if where else "")
            if step.primitive == Primitive.PICKUP:
                return f"pick up {step.object}"
        return None


def _drop_workspace(plan: RobotPlan, obj: str | None) -> str | None:
    """The workspace the plan's mission drops `obj` in (its first drop of it)."""
    for event in plan.mission:
        if event.kind == "drop" and event.obj == obj:
            return event.workspace
    return None
