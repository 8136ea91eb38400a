"""Mission events: the letters of the mission alphabet.

A mission is a regular language over events. The paper's alphabet (its table of mission
events) has three kinds of robot events and one coordination event:

========================  ===============  ==================  ================================
canonical                 compact (paper)  in a task list      meaning
========================  ===============  ==================  ================================
``pick(R1,O1)``           ``R1pO1``        ``pick O1``         R1 picks up object O1
``drop(R1,O1,W1)``        ``R1dO1aW1``     ``drop O1 at W1``   R1 drops O1 off inside workspace W1
``return(R1)``            ``r1``           ``return``          R1 is back at its initial pose
``msg(R1,R2,t)``          --               --                  R1 sends R2 the message tagged t
``away(O2,R1,R2)``        --               --                  R2 tells R1 that O2 has been moved
========================  ===============  ==================  ================================

*Messages* link robots.  ``msg(S,R,tag)`` is sent by S right after a given step of its plan
(the primitive ``Res``) and awaited by R before a given step of its plan (``Req``); nothing
else changes.  ``away(O,A,B)`` is the paper's message, a message from the responder B to the
requester A whose meaning is fixed: object O has been moved away, so A's model marks O away
(``?O Away`` for A, ``!O Away`` for B).  Both are shared by their sender and receiver
(:attr:`Event.sender`, :attr:`Event.receiver`); one exists per (tag or object, sender,
receiver), so that several robots can wait on the same robot without deadlock.  Messages are
asynchronous: sending never waits, receiving waits until the message has been sent.

A plan realises events with the paper's safe motion primitives (:class:`Primitive`):
:func:`realising_step` is the one map from an event to the step that realises it, used by the
specification, the checker, the coordination and the simulator alike.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from enum import StrEnum
from functools import cached_property, lru_cache

from cosmop.errors import EventSyntaxError

__all__ = [
    "ACCEPTED_FORMS",
    "EVENT_KINDS",
    "ID_PATTERN",
    "MESSAGE_KINDS",
    "Event",
    "Link",
    "Node",
    "Primitive",
    "message",
    "parse_event",
    "realising_step",
]

ID_PATTERN = r"[A-Za-z_][A-Za-z0-9_-]*"
"""Regular expression that robot, object and workspace ids must match."""

EVENT_KINDS = ("pick", "drop", "return", "away", "msg")
"""The kinds of mission events."""

MESSAGE_KINDS = frozenset({"away", "msg"})
"""The kinds of events that are messages between two robots."""

ACCEPTED_FORMS = (
    "pick(R,O)",
    "drop(R,O,W)",
    "return(R)",
    "away(O,A,B)",
    "msg(SENDER,RECEIVER,TAG)",
    "in a robot's task list: 'pick O', 'drop O at W', 'return'",
    "compact: 'R1pO1', 'R1dO1aW1', 'r1'",
)
"""Human-readable list of the accepted textual forms of an event (used in error messages)."""

_ID_RE = re.compile(rf"{ID_PATTERN}\Z")
_CANONICAL_RE = re.compile(r"\s*(?P<kind>[A-Za-z_]\w*)\s*\((?P<args>[^()]*)\)\s*\Z")
_COMPACT_PICK_RE = re.compile(r"(?P<robot>R\d+)p(?P<obj>O\d+)\Z")
_COMPACT_DROP_RE = re.compile(r"(?P<robot>R\d+)d(?P<obj>O\d+)a(?P<ws>W\d+)\Z")
_COMPACT_RETURN_RE = re.compile(r"r(?P<num>\d+)\Z")
_STEP_PICK_RE = re.compile(rf"pick\s+(?P<obj>{ID_PATTERN})\Z")
_STEP_DROP_RE = re.compile(rf"drop\s+(?P<obj>{ID_PATTERN})\s+at\s+(?P<ws>{ID_PATTERN})\Z")
_STEP_RETURN_RE = re.compile(r"return\Z")
_STEP_USAGE = {"pick": "'pick O'", "drop": "'drop O at W'", "return": "'return'"}

# kind -> names of its arguments in canonical order, as (attribute, description)
_SIGNATURES: dict[str, tuple[tuple[str, str], ...]] = {
    "pick": (("robot", "robot"), ("obj", "object")),
    "drop": (("robot", "robot"), ("obj", "object"), ("workspace", "workspace")),
    "return": (("robot", "robot"),),
    "away": (("obj", "object"), ("robot", "requester"), ("responder", "responder")),
    "msg": (("responder", "sender"), ("robot", "receiver"), ("tag", "tag")),
}


@dataclass(frozen=True, order=True)
class Event:
    """A mission event.

    Parameters
    ----------
    kind : {"pick", "drop", "return", "away", "msg"}
        What happens.
    robot : str
        The robot that performs a pick, drop or return; for a message (``away``, ``msg``),
        the robot that receives it (for ``away``, the requester A that asked for the object to
        be moved).
    obj : str, optional
        The object picked, dropped or moved away (required for those kinds, else ``None``).
    workspace : str, optional
        The workspace the object is dropped in (``drop`` only).
    responder : str, optional
        The robot that sends a message: for ``away`` the robot B that moved the object away
        and answers A, for ``msg`` its sender (messages only; sender != receiver).
    tag : str, optional
        What a ``msg`` is about, an id (``msg`` only).

    Raises
    ------
    EventSyntaxError
        If the kind is unknown, an id is not of the form ``[A-Za-z_][A-Za-z0-9_-]*``, the
        fields do not match the kind, or a message has sender == receiver.

    Notes
    -----
    Events are immutable, hashable and totally ordered (by kind, robot, object, workspace,
    responder, tag), so sets of events can be sorted deterministically.
    """

    kind: str
    robot: str
    obj: str | None = None
    workspace: str | None = None
    responder: str | None = None
    tag: str | None = None

    def __post_init__(self) -> None:
        if self.kind not in _SIGNATURES:
            raise EventSyntaxError(
                f"unknown event kind {self.kind!r}; expected one of {', '.join(EVENT_KINDS)}"
            )
        required = {attr for attr, _ in _SIGNATURES[self.kind]}
        for attr, description in _SIGNATURES[self.kind]:
            value = getattr(self, attr)
            if not isinstance(value, str) or not _ID_RE.match(value):
                raise EventSyntaxError(
                    f"{self.kind} event: {description} must be an id matching {ID_PATTERN}, got {value!r}"
                )
        for attr in ("obj", "workspace", "responder", "tag"):
            if attr not in required and getattr(self, attr) is not None:
                raise EventSyntaxError(f"a {self.kind} event has no {attr}, got {getattr(self, attr)!r}")
        if self.kind in MESSAGE_KINDS and self.robot == self.responder:
            roles = "requester and the responder" if self.kind == "away" else "sender and the receiver"
            raise EventSyntaxError(f"the {roles} of {self.name} must be different robots")

    @cached_property  # (made once: the executors compare names every cycle)
    def name(self) -> str:
        """Canonical text, e.g. ``pick(R1,O1)``, ``drop(R1,O1,W1)``, ``return(R1)``,
        ``away(O2,R1,R2)``, ``msg(R1,R2,t)``."""
        args = ",".join(getattr(self, attr) for attr, _ in _SIGNATURES[self.kind])
        return f"{self.kind}({args})"

    @property
    def is_message(self) -> bool:
        """Whether the event is a message between two robots (``away`` or ``msg``)."""
        return self.kind in MESSAGE_KINDS

    @property
    def sender(self) -> str | None:
        """The robot that sends a message (``away``: the responder), else ``None``."""
        return self.responder if self.kind in MESSAGE_KINDS else None

    @property
    def receiver(self) -> str | None:
        """The robot that waits for a message (``away``: the requester), else ``None``."""
        return self.robot if self.kind in MESSAGE_KINDS else None

    @property
    def owners(self) -> frozenset[str]:
        """The robots whose alphabets contain this event: sender and receiver for a message,
        else ``{robot}``."""
        if self.kind in MESSAGE_KINDS:
            assert self.responder is not None  # a message always has one (__post_init__)
            return frozenset((self.robot, self.responder))
        return frozenset((self.robot,))

    @property
    def compact(self) -> str | None:
        """The paper's compact name (``R1pO1``, ``R1dO1aW1``, ``r1``), or ``None`` if it has none.

        Only events whose ids follow the paper's pattern (``R<n>``, ``O<n>``, ``W<n>``) have a
        compact name; messages never do.
        """
        candidate = {
            "pick": f"{self.robot}p{self.obj}",
            "drop": f"{self.robot}d{self.obj}a{self.workspace}",
            "return": f"r{self.robot[1:]}" if self.robot.startswith("R") else "",
            "away": "",
            "msg": "",
        }[self.kind]
        return candidate if candidate and _parse_compact(candidate) == self else None

    def __str__(self) -> str:
        return self.name

    # Events key sets and dicts in the planners' and the simulator's inner loops: hash and
    # compare the cached canonical name (one text per event, as the fields are) rather than a
    # fresh tuple of six fields each time.
    def __hash__(self) -> int:
        return hash(self.name)

    def __eq__(self, other: object) -> bool:
        if self is other:
            return True
        if other.__class__ is not Event:
            return NotImplemented
        assert isinstance(other, Event)  # (for the type checker)
        return self.name == other.name


def parse_event(text: str, robot: str | None = None) -> Event:
    """Parse the textual form of a mission event.

    Parameters
    ----------
    text : str
        One of the accepted forms: canonical (``pick(R1,O1)``, ``drop(R1,O1,W1)``,
        ``return(R1)``, ``away(O2,R1,R2)``, ``msg(R1,R2,t)``; whitespace around the parentheses and commas is
        ignored), the paper's compact names (``R1pO1``, ``R1dO1aW1``, ``r1``; ids must then be
        ``R<n>``, ``O<n>``, ``W<n>``), or, when `robot` is given, a task step with the robot
        implied (``pick O1``, ``drop O1 at W1``, ``return``).
    robot : str, optional
        The robot whose task list `text` comes from; enables the implied-robot forms. It does
        not restrict the other forms: ``parse_event("pick(R2,O2)", robot="R1")`` returns R2's
        event, and checking ownership is the caller's business.

    Returns
    -------
    Event
        The event.

    Raises
    ------
    EventSyntaxError
        If `text` is none of the accepted forms; the message quotes `text` and lists the forms.

    Examples
    --------
    >>> parse_event("drop(R1, O1, W1)")
    Event(kind='drop', robot='R1', obj='O1', workspace='W1', responder=None, tag=None)
    >>> parse_event("drop O1 at W1", robot="R1") == parse_event("R1dO1aW1")
    True
    """
    if not isinstance(text, str):
        raise EventSyntaxError(f"expected an event as text, got {text!r}; {_forms()}")
    if robot is None or isinstance(robot, str):
        return _parse_text(text, robot)  # the same names come back many times: parsed once
    return _parse_text.__wrapped__(text, robot)


@lru_cache(maxsize=8192)
def _parse_text(text: str, robot: str | None) -> Event:
    stripped = text.strip()

    canonical = _CANONICAL_RE.match(stripped)
    if canonical:
        kind = canonical["kind"]
        if kind not in _SIGNATURES:
            raise _error(text, f"unknown event kind {kind!r}")
        args = [arg.strip() for arg in canonical["args"].split(",")]
        signature = _SIGNATURES[kind]
        if len(args) != len(signature) or (len(args) == 1 and not args[0]):
            wanted = ", ".join(description for _, description in signature)
            got = 0 if args == [""] else len(args)
            raise _error(text, f"{kind} takes {len(signature)} argument(s) ({wanted}), got {got}")
        for arg, (_, description) in zip(args, signature, strict=True):
            if not _ID_RE.match(arg):
                raise _error(text, f"the {description} {arg!r} is not an id matching {ID_PATTERN}")
        fields = {attr: arg for arg, (attr, _) in zip(args, signature, strict=True)}
        return _build(text, kind=kind, **fields)

    compact = _parse_compact(stripped)
    if compact is not None:
        return compact

    step = _parse_step(stripped)
    if step is not None:
        if robot is None:
            raise _error(
                text, "the robot is implied only inside a robot's task list; write e.g. pick(R1,O1) or R1pO1"
            )
        if not isinstance(robot, str) or not _ID_RE.match(robot):
            raise _error(text, f"the implied robot {robot!r} is not an id matching {ID_PATTERN}")
        return _build(text, robot=robot, **step)

    words = stripped.split()
    if words and words[0] in _STEP_USAGE and "(" not in stripped:
        raise _error(
            text, f"a {words[0]} task step is written {_STEP_USAGE[words[0]]} with ids matching {ID_PATTERN}"
        )
    raise _error(text, "not a mission event")


def message(sender: str, receiver: str, tag: str) -> Event:
    """The message event ``msg(sender,receiver,tag)``.

    Parameters
    ----------
    sender, receiver : str
        The robots that send and await the message (different ids).
    tag : str
        What the message is about, an id.

    Returns
    -------
    Event

    Examples
    --------
    >>> message("R1", "R2", "after_drop_O1").name
    'msg(R1,R2,after_drop_O1)'
    """
    return Event("msg", receiver, responder=sender, tag=tag)


class Primitive(StrEnum):
    """The paper's safe motion primitives: the steps a plan is made of.

    Members are their names, so ``Primitive.GOTO == "GoTo"`` and a plan file holds the plain
    strings.

    >>> [str(p) for p in Primitive]
    ['GoTo', 'PickUp', 'DropOff', 'Req', 'Res']
    """

    GOTO = "GoTo"
    """Drive to a pose (x, y, heading)."""
    PICKUP = "PickUp"
    """Pick an object up from beside it."""
    DROPOFF = "DropOff"
    """Put the carried object down beside the robot."""
    REQ = "Req"
    """Wait for a message (``?``): an object moved away, or a tagged message."""
    RES = "Res"
    """Send a message (``!``) and go on at once."""


def realising_step(event: Event, robot: str) -> tuple[Primitive, str | None, Event | None] | None:
    """The step that realises `event` in `robot`'s plan: ``(primitive, object, message)``.

    ``pick(R,O)`` is ``PickUp`` of O and ``drop(R,O,W)`` is ``DropOff`` of O (inside W); a message
    is a ``Req`` in its receiver's plan and a ``Res`` in its sender's, of the object for
    ``away(O,A,B)`` and of the tag for ``msg(S,R,tag)``.  ``None`` for ``return(R)``, which a
    pose realises, not a step.

    Parameters
    ----------
    event : Event
        The event to realise.
    robot : str
        The robot whose plan holds the step (for a message: its sender or its receiver).

    Returns
    -------
    tuple of (Primitive, str or None, Event or None) or None
        The step's primitive, the object it handles and the message (``msg`` only): what a
        :class:`~cosmop.planning.plan_types.Step` holds as ``primitive``, ``object`` and
        ``message``.

    Examples
    --------
    >>> realising_step(parse_event("away(O2,R1,R2)"), "R2")
    (<Primitive.RES: 'Res'>, 'O2', None)
    """
    if event.kind == "pick":
        return Primitive.PICKUP, event.obj, None
    if event.kind == "drop":
        return Primitive.DROPOFF, event.obj, None
    if event.kind in MESSAGE_KINDS:
        primitive = Primitive.REQ if robot == event.receiver else Primitive.RES
        return (primitive, event.obj, None) if event.kind == "away" else (primitive, None, event)
    return None


def _parse_compact(text: str) -> Event | None:
    if match := _COMPACT_PICK_RE.match(text):
        return Event("pick", match["robot"], match["obj"])
    if match := _COMPACT_DROP_RE.match(text):
        return Event("drop", match["robot"], match["obj"], match["ws"])
    if match := _COMPACT_RETURN_RE.match(text):
        return Event("return", f"R{match['num']}")
    return None


def _parse_step(text: str) -> dict[str, str] | None:
    """Recognise an implied-robot task step; returns the Event fields other than the robot."""
    if match := _STEP_PICK_RE.match(text):
        return {"kind": "pick", "obj": match["obj"]}
    if match := _STEP_DROP_RE.match(text):
        return {"kind": "drop", "obj": match["obj"], "workspace": match["ws"]}
    if _STEP_RETURN_RE.match(text):
        return {"kind": "return"}
    return None


def _build(text: str, **fields: str) -> Event:
    try:
        return Event(**fields)
    except EventSyntaxError as err:
        raise _error(text, str(err)) from None


def _forms() -> str:
    return "accepted forms: " + "; ".join(ACCEPTED_FORMS)


def _error(text: str, reason: str) -> EventSyntaxError:
    return EventSyntaxError(f"invalid event {text!r}: {reason}; {_forms()}")


Node = tuple[str, int]
"""A step of a plan (or of a robot's word of events): ``(robot, instant)``, instants 1..K (0 is
the start)."""


@dataclass(frozen=True)
class Link:
    """A message between two plans: sent by ``sender`` at instant ``send`` (its ``Res``),
    awaited by ``receiver`` at instant ``wait`` (its ``Req``); ``send`` is ``None`` if no plan
    sends it, ``wait`` ``None`` if no plan waits for it.  ``event`` is the message
    (``msg(S,R,tag)`` or ``away(O,A,B)``)."""

    event: Event
    sender: str
    send: int | None
    receiver: str
    wait: int | None
