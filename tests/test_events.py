"""Mission events: construction, canonical names, parsing of every accepted form."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from cosmop.errors import EventSyntaxError
from cosmop.events import ACCEPTED_FORMS, ID_PATTERN, Event, parse_event

PICK = Event("pick", "R1", "O1")
DROP = Event("drop", "R1", "O1", "W1")
RETURN = Event("return", "R1")
AWAY = Event("away", "R1", "O2", responder="R2")


# -- construction and properties --------------------------------------------------------------


@pytest.mark.parametrize(
    ("event", "name", "owners"),
    [
        (PICK, "pick(R1,O1)", {"R1"}),
        (DROP, "drop(R1,O1,W1)", {"R1"}),
        (RETURN, "return(R1)", {"R1"}),
        (AWAY, "away(O2,R1,R2)", {"R1", "R2"}),
    ],
)
def test_name_str_and_owners(event: Event, name: str, owners: set[str]) -> None:
    assert event.name == name
    assert str(event) == name
    assert event.owners == frozenset(owners)
    assert isinstance(event.owners, frozenset)


def test_events_are_frozen_hashable_and_ordered() -> None:
    with pytest.raises(AttributeError):
        PICK.robot = "R2"  # type: ignore[misc]
    assert {PICK, Event("pick", "R1", "O1")} == {PICK}
    events = [RETURN, PICK, AWAY, DROP, Event("pick", "R1", "O0")]
    assert sorted(events) == [AWAY, DROP, Event("pick", "R1", "O0"), PICK, RETURN]


def test_compact_names() -> None:
    assert PICK.compact == "R1pO1"
    assert DROP.compact == "R1dO1aW1"
    assert RETURN.compact == "r1"
    assert Event("return", "R12").compact == "r12"
    assert AWAY.compact is None
    assert Event("pick", "robot", "O1").compact is None  # ids not of the paper's pattern
    assert Event("return", "Rx").compact is None


@pytest.mark.parametrize(
    "kwargs",
    [
        {"kind": "fly", "robot": "R1"},
        {"kind": "pick", "robot": "R1"},  # no object
        {"kind": "pick", "robot": "R1", "obj": "O1", "workspace": "W1"},  # a pick has no workspace
        {"kind": "drop", "robot": "R1", "obj": "O1"},  # no workspace
        {"kind": "return", "robot": "R1", "obj": "O1"},
        {"kind": "away", "robot": "R1", "obj": "O1"},  # no responder
        {"kind": "pick", "robot": "1R", "obj": "O1"},  # not an id
        {"kind": "pick", "robot": "R1", "obj": "O 1"},
        {"kind": "pick", "robot": 1, "obj": "O1"},
    ],
)
def test_inconsistent_events_are_rejected(kwargs: dict) -> None:
    with pytest.raises(EventSyntaxError):
        Event(**kwargs)


def test_away_with_requester_equal_to_responder_is_rejected() -> None:
    with pytest.raises(EventSyntaxError, match="must be different robots"):
        Event("away", "R1", "O2", responder="R1")
    with pytest.raises(EventSyntaxError, match=r"'away\(O2,R1,R1\)'") as info:
        parse_event("away(O2,R1,R1)")
    assert "accepted forms" in str(info.value)


def test_event_syntax_error_is_a_value_error() -> None:
    assert issubclass(EventSyntaxError, ValueError)


# -- parsing -----------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("pick(R1,O1)", PICK),
        ("drop(R1,O1,W1)", DROP),
        ("return(R1)", RETURN),
        ("away(O2,R1,R2)", AWAY),
        (" pick ( R1 , O1 ) ", PICK),
        ("drop(R1,  O1,\tW1)", DROP),
        ("return( R1 )", RETURN),
        ("away( O2 , R1 , R2 )", AWAY),
        ("R1pO1", PICK),
        ("R1dO1aW1", DROP),
        ("r1", RETURN),
        ("  R1pO1  ", PICK),
        ("R10dO7aW3", Event("drop", "R10", "O7", "W3")),
        ("r10", Event("return", "R10")),
        ("pick(robot_a,box-7)", Event("pick", "robot_a", "box-7")),
    ],
)
def test_parse_without_robot(text: str, expected: Event) -> None:
    assert parse_event(text) == expected


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("pick O1", PICK),
        ("drop O1 at W1", DROP),
        ("return", RETURN),
        ("  pick   O1 ", PICK),
        ("drop\tO1   at  W1", DROP),
        ("pick(R1,O1)", PICK),  # the full form is accepted in a task list too
        ("R1dO1aW1", DROP),  # and so is the compact one
        ("r1", RETURN),
    ],
)
def test_parse_task_steps_with_implied_robot(text: str, expected: Event) -> None:
    assert parse_event(text, robot="R1") == expected


def test_implied_robot_does_not_restrict_explicit_forms() -> None:
    # ownership is checked by the caller (the scenario loader), not by the parser
    assert parse_event("pick(R2,O2)", robot="R1") == Event("pick", "R2", "O2")
    assert parse_event("drop O2 at W2", robot="R2") == Event("drop", "R2", "O2", "W2")


@pytest.mark.parametrize("text", ["pick O1", "drop O1 at W1", "return"])
def test_task_steps_need_a_robot(text: str) -> None:
    with pytest.raises(EventSyntaxError, match="implied only inside a robot's task list"):
        parse_event(text)


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        ("fly(R1)", "unknown event kind 'fly'"),
        ("Pick(R1,O1)", "unknown event kind 'Pick'"),
        ("pick(R1)", r"pick takes 2 argument\(s\) \(robot, object\), got 1"),
        ("drop(R1,O1)", r"drop takes 3 argument"),
        ("return()", r"return takes 1 argument\(s\) \(robot\), got 0"),
        ("away(O1,R1)", r"away takes 3 argument"),
        ("pick(R1,O1,W1)", r"pick takes 2"),
        ("pick(R1,)", "the object '' is not an id"),
        ("pick(R1,1O)", "the object '1O' is not an id"),
        ("pick(R 1,O1)", "the robot 'R 1' is not an id"),
        ("pick(R1,O1", "not a mission event"),
        ("", "not a mission event"),
        ("R1pO", "not a mission event"),
        ("RapO1", "not a mission event"),
        ("R1xO1", "not a mission event"),
        ("r", "not a mission event"),
        ("drop O1 W1", "a drop task step is written 'drop O at W'"),
        ("pick", "a pick task step is written 'pick O'"),
        ("return R1", "a return task step is written 'return'"),
        ("pick O1 O2", "a pick task step"),
    ],
)
def test_bad_text_quotes_the_text_and_lists_the_forms(text: str, reason: str) -> None:
    with pytest.raises(EventSyntaxError, match=reason) as info:
        parse_event(text, robot="R1")
    message = str(info.value)
    assert repr(text) in message
    for form in ACCEPTED_FORMS:
        assert form in message


@pytest.mark.parametrize("value", [5, None, ["pick", "O1"], b"pick(R1,O1)"])
def test_non_text_is_rejected(value: object) -> None:
    with pytest.raises(EventSyntaxError, match="expected an event as text"):
        parse_event(value)  # type: ignore[arg-type]


def test_bad_implied_robot_is_rejected() -> None:
    with pytest.raises(EventSyntaxError, match="implied robot"):
        parse_event("pick O1", robot="not an id")


# -- round trips -------------------------------------------------------------------------------

ids = st.from_regex(ID_PATTERN.replace("*", "{0,6}"), fullmatch=True)
numbers = st.integers(min_value=0, max_value=10_000)


@st.composite
def events(draw: st.DrawFn) -> Event:
    kind = draw(st.sampled_from(["pick", "drop", "return", "away"]))
    robot = draw(ids)
    if kind == "pick":
        return Event(kind, robot, draw(ids))
    if kind == "drop":
        return Event(kind, robot, draw(ids), draw(ids))
    if kind == "return":
        return Event(kind, robot)
    responder = draw(ids.filter(lambda r: r != robot))
    return Event(kind, robot, draw(ids), responder=responder)


@st.composite
def paper_events(draw: st.DrawFn) -> Event:
    """Events whose ids follow the paper's pattern (R<n>, O<n>, W<n>)."""
    robot, obj, ws = (f"{p}{draw(numbers)}" for p in "ROW")
    kind = draw(st.sampled_from(["pick", "drop", "return"]))
    return {
        "pick": Event("pick", robot, obj),
        "drop": Event("drop", robot, obj, ws),
        "return": Event("return", robot),
    }[kind]


def _spaced(draw: st.DrawFn, event: Event) -> str:
    """The canonical text with random whitespace around the parentheses and commas."""
    pad = st.text(alphabet=" \t", max_size=2)
    args = event.name[event.name.index("(") + 1 : -1].split(",")
    inner = ",".join(draw(pad) + arg + draw(pad) for arg in args)
    return draw(pad) + event.kind + draw(pad) + "(" + inner + ")" + draw(pad)


@given(events())
def test_canonical_name_round_trips(event: Event) -> None:
    assert parse_event(event.name) == event
    assert parse_event(str(event), robot="R1") == event


@given(st.data())
def test_whitespace_is_tolerated(data: st.DataObject) -> None:
    event = data.draw(events())
    assert parse_event(_spaced(data.draw, event)) == event


@given(paper_events())
def test_compact_name_round_trips(event: Event) -> None:
    assert event.compact is not None
    assert parse_event(event.compact) == event
    assert parse_event(event.compact, robot=event.robot) == event


@given(events().filter(lambda e: e.kind != "away"))
def test_task_step_round_trips(event: Event) -> None:
    step = {
        "pick": f"pick {event.obj}",
        "drop": f"drop {event.obj} at {event.workspace}",
        "return": "return",
    }[event.kind]
    assert parse_event(step, robot=event.robot) == event


@given(events(), events())
def test_order_is_total_and_consistent_with_equality(a: Event, b: Event) -> None:
    assert (a < b) + (a == b) + (a > b) == 1
    assert (a == b) == (a.name == b.name)
