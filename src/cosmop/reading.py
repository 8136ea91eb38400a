"""Reading untrusted text: YAML and JSON with bounded size, depth and numbers.

Every file cosmop reads comes from a user and may be hostile: nested thousands of levels deep,
an alias that expands to billions of values (a "billion laughs"), an integer of thousands of
digits, control characters.  The readers here answer such input with the caller's
:class:`~cosmop.errors.CosmopInputError` (exit 2 on the command line) in time and memory that
grow with the file, never with what it expands to:

* text must be printable (tab, line feed and carriage return are the only control characters);
* values nest at most :data:`MAX_DEPTH` levels;
* a YAML document holds at most :data:`MAX_NODES` values, counted *after* alias expansion, and
  an alias may not refer to a value that contains it (a cycle);
* a YAML scalar has at most :data:`MAX_TEXT` characters, an integer at most :data:`MAX_DIGITS`
  digits.

The YAML bound is checked on the parser's event stream before any value is built: the size of
every anchored value is known when it closes, so an alias adds that size without being expanded.

The YAML dialect is close to YAML 1.2's core schema: only ``true``/``false`` are booleans
(``yes``, ``no``, ``on``, ``off``, ``y``, ``n`` stay text), integers are decimal, dates stay
text, and a key repeated inside one mapping is an error instead of silently overriding.

Once parsed, a file is checked against its format's :class:`Structure`: pydantic models (or
TypedDicts) of the format and, per field, what it expects in words.  The first wrong field in
the file's order is one line, ``<file>: <field>: expected <what>, got <what>`` (with its line
and column when the JSON text is at hand); the plan files (:mod:`cosmop.planning.plan_file`)
and the traces (:mod:`cosmop.traces`) are read so.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Callable, Iterator, Mapping, Sequence
from types import NoneType, UnionType
from typing import (
    Annotated,
    Any,
    NoReturn,
    NotRequired,
    Required,
    Union,
    get_args,
    get_origin,
    get_type_hints,
)

import yaml
from pydantic import BaseModel, TypeAdapter, ValidationError
from pydantic_core import ErrorDetails, PydanticCustomError
from typing_extensions import is_typeddict

from cosmop.errors import CosmopInputError

__all__ = [
    "MAX_DEPTH",
    "MAX_DIGITS",
    "MAX_NODES",
    "MAX_TEXT",
    "UNPRINTABLE",
    "Expectations",
    "FieldPath",
    "Marks",
    "Structure",
    "check_printable",
    "first_in_data",
    "format_path",
    "json_position",
    "json_problem",
    "load_json",
    "load_yaml",
    "lookup",
    "printable",
    "show",
    "unprintable",
]

MAX_DEPTH = 64
"""Deepest nesting of lists and mappings a file may have (a scenario needs 7)."""

MAX_NODES = 150_000
"""Most values one YAML document may hold, aliases expanded (the 816-wall warehouse holds 6,000)."""

MAX_TEXT = 1_000
"""Most characters one YAML scalar (a name, an id, an event, a number) may have."""

MAX_DIGITS = 30
"""Most digits an integer may have (a coordinate in millimetres needs 10)."""

FieldPath = tuple[str | int, ...]
Marks = dict[FieldPath, tuple[int, int]]

_NOT_PRINTABLE = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\x7f-\x84\x86-\x9f\ud800-\udfff\ufffe\uffff]")


def format_path(path: FieldPath) -> str | None:
    """The dotted, indexed text of a field path; ``None`` for the whole file.

    Parameters
    ----------
    path : FieldPath
        Keys (text) and list indices (int) from the top of the file down to the field.

    >>> format_path(("scene", "robots", "R1", "pose", 0))
    'scene.robots.R1.pose[0]'
    >>> format_path(("tasks", "a b"))
    "tasks['a b']"
    """
    text = ""
    for part in path:
        if isinstance(part, int) and not isinstance(part, bool):
            text += f"[{part}]"
        elif isinstance(part, str) and re.fullmatch(r"[A-Za-z0-9_-]+", part):
            text += f".{part}" if text else part
        else:
            text += f"[{part!r}]"
    return text or None


def unprintable(text: str) -> str | None:
    r"""Why a name or id `text` would not show as itself on a terminal, or ``None`` if it would.

    Every character must be printable (:meth:`str.isprintable`): a control character such as
    ESC (``"ware\e[31m"`` in YAML, ``"\u001b"`` in JSON) would reach the terminal and the files
    written, and tabs, line breaks and invisible format characters would misalign or hide text.

    Parameters
    ----------
    text : str
        A name, id or other text a file gives, to be shown as it is.

    >>> unprintable("warehouse"), unprintable("ware\x1b[31m")
    (None, "expected printable text, got 'ware\\x1b[31m' (U+001B at character 5)")
    """
    if text.isprintable():
        return None
    index, char = next((i, c) for i, c in enumerate(text) if not c.isprintable())
    shown = repr(text) if len(text) <= 80 else repr(text[:77]) + "..."
    return f"expected printable text, got {shown} (U+{ord(char):04X} at character {index + 1})"


def check_printable(text: str, error: type[CosmopInputError], file: str | None) -> None:
    """Raise ``error`` at the first control character of `text` (tab, LF and CR are allowed).

    Parameters
    ----------
    text : str
        A whole file's text.
    error : type of CosmopInputError
        What to raise, with the character's line and column.
    file : str or None
        Named in the error.
    """
    found = _NOT_PRINTABLE.search(text)
    if found is None:
        return
    line = text.count("\n", 0, found.start()) + 1
    column = found.start() - (text.rfind("\n", 0, found.start()) + 1) + 1
    raise error(
        f"control character U+{ord(found.group()):04X}; expected printable text",
        file=file,
        line=line,
        column=column,
    )


# ----------------------------------------------------------------------------------------------
# YAML
# ----------------------------------------------------------------------------------------------

_TAG = "tag:yaml.org,2002:"
_REPLACED_TAGS = {_TAG + "bool", _TAG + "int", _TAG + "float", _TAG + "timestamp", _TAG + "value"}
_FAST = getattr(yaml, "CSafeLoader", None)  # libyaml's parser when the wheel has it


class _Loader(_FAST or yaml.SafeLoader):  # type: ignore[misc]
    """A safe loader with core-schema scalars: booleans are only true/false, ints are decimal."""

    def construct_object(self, node: yaml.Node, deep: bool = False) -> Any:
        try:
            return super().construct_object(node, deep=deep)
        except yaml.YAMLError:
            raise
        except (ValueError, LookupError, TypeError, ArithmeticError) as err:  # "!!int ''", "!!bool x"
            tag = node.tag.rpartition(":")[2]
            what = repr(node.value)[:40] if isinstance(node, yaml.ScalarNode) else "this value"
            problem = f"{what} is not a valid {tag} ({err})"
            raise yaml.constructor.ConstructorError(None, None, problem, node.start_mark) from None


_Loader.yaml_implicit_resolvers = {
    first: [(tag, regexp) for tag, regexp in resolvers if tag not in _REPLACED_TAGS]
    for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
}
_BOOL = re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$")
_Loader.add_implicit_resolver(_TAG + "bool", _BOOL, list("tTfF"))
_Loader.add_implicit_resolver(_TAG + "int", re.compile(r"^[-+]?[0-9]+$"), list("-+0123456789"))
_Loader.add_implicit_resolver(
    _TAG + "float",
    re.compile(
        r"^(?:[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?"
        r"|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))$"
    ),
    list("-+0123456789."),
)


def _construct_int(loader: _Loader, node: yaml.ScalarNode) -> int:
    text = loader.construct_scalar(node)
    digits = len(text.lstrip("+-"))
    if digits > MAX_DIGITS:
        raise yaml.constructor.ConstructorError(
            None, None, f"an integer of {digits} digits; at most {MAX_DIGITS} are allowed", node.start_mark
        )
    if re.fullmatch(r"[-+]?[0-9]+", text):
        return int(text, 10)  # "012" is twelve, not YAML 1.1's octal ten
    # an explicit !!int tag: accept YAML 1.1's other notations (0x1F, 0o17, ...)
    return int(yaml.SafeLoader.construct_yaml_int(loader, node))


_Loader.add_constructor(_TAG + "int", _construct_int)

_OPEN = (yaml.SequenceStartEvent, yaml.MappingStartEvent)
_CLOSE = (yaml.SequenceEndEvent, yaml.MappingEndEvent)


def _bound_events(text: str, file: str | None, error: type[CosmopInputError]) -> None:
    """Raise ``error`` if `text` is too big to build: its depth, expanded size, a long scalar or a cycle.

    One pass over the parser's events: each value counts one, an alias counts the size of the
    value its anchor closed (so nothing is expanded), an alias to a value still open is a cycle.
    """
    parser = _Loader(text)

    def fail(problem: str, event: Any) -> NoReturn:
        mark = event.start_mark
        raise error(problem, file=file, line=mark.line + 1, column=mark.column + 1)

    try:
        nodes = 0
        open_: list[tuple[str | None, int]] = []
        sizes: dict[str, int] = {}
        while (event := parser.get_event()) is not None:
            if isinstance(event, yaml.ScalarEvent):
                nodes += 1
                if len(event.value) > MAX_TEXT:
                    fail(f"a value of {len(event.value):,} characters; at most {MAX_TEXT:,} are read", event)
                if event.anchor is not None:
                    sizes[event.anchor] = 1
            elif isinstance(event, _OPEN):
                nodes += 1
                open_.append((event.anchor, nodes))
                if len(open_) > MAX_DEPTH:
                    fail(f"values nest more than {MAX_DEPTH} levels deep", event)
            elif isinstance(event, _CLOSE):
                anchor, first = open_.pop()
                if anchor is not None:
                    sizes[anchor] = nodes - first + 1
            elif isinstance(event, yaml.AliasEvent):
                if any(anchor == event.anchor for anchor, _ in open_):
                    fail(f"the alias *{event.anchor} refers to a value that contains it", event)
                nodes += sizes.get(event.anchor, 1)  # an undefined alias: the composer says so
            if nodes > MAX_NODES:
                fail(f"more than {MAX_NODES:,} values (aliases expanded); at most that many are read", event)
    finally:
        parser.dispose()


def load_yaml(text: str, file: str | None, error: type[CosmopInputError]) -> tuple[Any, Marks]:
    """Parse one YAML document of untrusted text within the bounds of this module.

    Parameters
    ----------
    text : str
        The file's text.
    file : str or None
        Named in the errors.
    error : type of CosmopInputError
        What to raise, e.g. :class:`~cosmop.errors.ScenarioError`.

    Returns
    -------
    data : object
        The document (``None`` for an empty one).
    marks : dict
        The 1-based ``(line, column)`` of every field path, e.g. ``("scene", "robots", "R1")``.

    Raises
    ------
    error
        For text that is not printable, not YAML (with the line), beyond the bounds, or that
        repeats a key within one mapping.
    """
    check_printable(text, error, file)
    loader = None
    try:
        _bound_events(text, file, error)
        loader = _Loader(text)
        node = loader.get_single_node()
        marks: Marks = {}
        if node is not None:
            _index_nodes(loader, node, (), marks, set(), file, error)
        data = loader.construct_document(node) if node is not None else None
    except yaml.MarkedYAMLError as err:
        mark = err.problem_mark or err.context_mark
        problem = err.problem or err.context or "malformed YAML"
        if err.context and err.problem:
            problem = f"{problem} ({err.context})"
        raise error(
            f"invalid YAML: {problem}",
            file=file,
            line=None if mark is None else mark.line + 1,
            column=None if mark is None else mark.column + 1,
        ) from None
    except yaml.YAMLError as err:
        raise error(f"invalid YAML: {err}", file=file) from None
    finally:
        if loader is not None:
            loader.dispose()
    return data, marks


def _index_nodes(
    loader: _Loader,
    node: yaml.Node,
    path: FieldPath,
    marks: Marks,
    visited: set[int],
    file: str | None,
    error: type[CosmopInputError],
) -> None:
    """Record the position of every field and reject keys repeated within one mapping.

    Recursive, but over at most :data:`MAX_DEPTH` levels (checked before).
    """
    if id(node) in visited:  # an alias of an anchored node: already indexed
        return
    visited.add(id(node))
    if isinstance(node, yaml.SequenceNode):
        for index, item in enumerate(node.value):
            marks.setdefault((*path, index), _position(item))
            _index_nodes(loader, item, (*path, index), marks, visited, file, error)
    elif isinstance(node, yaml.MappingNode):
        first_seen: dict[Any, int] = {}
        for key_node, value_node in node.value:
            if key_node.tag == _TAG + "merge":  # "<<: *anchor": merged keys may be overridden
                _index_nodes(loader, value_node, path, {}, visited, file, error)
                continue
            if not isinstance(key_node, yaml.ScalarNode):
                continue  # complex keys: the constructor rejects unhashable ones
            key = loader.construct_object(key_node, deep=True)
            line, column = _position(key_node)
            if key in first_seen:
                raise error(
                    f"duplicate key {key!r} (first defined on line {first_seen[key]}); "
                    "every key and id must appear once in its mapping",
                    file=file,
                    field=format_path((*path, key)),
                    line=line,
                    column=column,
                )
            first_seen[key] = line
            marks.setdefault((*path, key), (line, column))
            _index_nodes(loader, value_node, (*path, key), marks, visited, file, error)


def _position(node: yaml.Node) -> tuple[int, int]:
    return node.start_mark.line + 1, node.start_mark.column + 1


# ----------------------------------------------------------------------------------------------
# JSON
# ----------------------------------------------------------------------------------------------


class _Refused(ValueError):
    pass


def _parse_int(text: str) -> int:
    digits = len(text.lstrip("-"))
    if digits > MAX_DIGITS:
        raise _Refused(f"an integer of {digits} digits; at most {MAX_DIGITS} are allowed")
    return int(text)


def _parse_float(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):  # 1e999
        raise _Refused(f"{text[:40]} is beyond the range of numbers; numbers must be finite")
    return value


def _refuse_constant(name: str) -> Any:
    raise _Refused(f"{name} is not a number; numbers must be finite")


def load_json(
    text: str, file: str | None, error: type[CosmopInputError], *, unique_keys: bool = False
) -> Any:
    """Parse untrusted JSON text within the bounds of this module.

    ``NaN``, ``Infinity`` and numbers beyond the floats' range (``1e999``) are refused, and with
    `unique_keys` a key repeated within one object; such an error names the field path and
    its line and column (:func:`json_problem`).

    Parameters
    ----------
    text : str
        The file's text.
    file : str or None
        Named in the errors.
    error : type of CosmopInputError
        What to raise, e.g. :class:`~cosmop.errors.ScenarioError`.
    unique_keys : bool
        Refuse a key repeated within one object (else the last one wins, as in :func:`json.loads`).

    Returns
    -------
    Any
        The parsed value: dicts, lists, text, ints, floats, booleans and None.

    Raises
    ------
    error
        For text that is not printable, not JSON (with the line and column), nested deeper than
        :data:`MAX_DEPTH`, with an integer of more than :data:`MAX_DIGITS` digits, a number
        that is not finite, or (with `unique_keys`) a repeated key.
    """
    check_printable(text, error, file)
    try:
        data = json.loads(
            text,
            object_pairs_hook=_unique_keys if unique_keys else None,
            parse_int=_parse_int,
            parse_float=_parse_float,
            parse_constant=_refuse_constant,
        )
    except json.JSONDecodeError as err:
        raise error(f"invalid JSON: {err.msg}", file=file, line=err.lineno, column=err.colno) from None
    except RecursionError:
        raise error(f"invalid JSON: values nest more than {MAX_DEPTH} levels deep", file=file) from None
    except _Refused as err:
        found = json_problem(text, unique_keys)
        if found is None:  # cannot happen: the scan refuses what the parser refused
            raise error(f"invalid JSON: {err}", file=file) from None
        problem, path, (line, column) = found
        raise error(
            f"invalid JSON: {problem}", file=file, field=format_path(path), line=line, column=column
        ) from None
    if _depth(data) > MAX_DEPTH:
        raise error(f"invalid JSON: values nest more than {MAX_DEPTH} levels deep", file=file)
    return data


def _unique_keys(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    result: dict[str, Any] = {}
    for key, value in pairs:
        if key in result:
            raise _Refused(f"duplicate key {key!r}")
        result[key] = value
    return result


_SPACE = re.compile(r"[ \t\n\r]*")


_scanstring: Callable[[str, int], tuple[str, int]] = json.decoder.scanstring  # type: ignore[attr-defined]  # typeshed omits it


def _space_end(text: str, at: int = 0) -> int:
    """Where the JSON white space at ``text[at]`` ends (`at` itself when there is none)."""
    found = _SPACE.match(text, at)
    assert found is not None  # the pattern matches the empty string
    return found.end()


_WORD = re.compile(r"-?[A-Za-z0-9_.+-]+")  # a number or a literal (NaN and Infinity too)


def _decoder(unique_keys: bool) -> json.JSONDecoder:
    """A decoder that refuses what :func:`load_json` refuses, raising :class:`_Refused`."""
    return json.JSONDecoder(
        object_pairs_hook=_unique_keys if unique_keys else None,
        parse_int=_parse_int,
        parse_float=_parse_float,
        parse_constant=_refuse_constant,
    )


def _members(text: str, at: int, skip: Callable[[int], int | None]) -> Iterator[tuple[str | int, int, int]]:
    """The members of the object or list that starts at ``text[at]``, in order: ``(key or index,
    where the member (its key) starts, where its value starts)``.

    Between two members the value is skipped with ``skip(start)``, its end (the C parser's), so
    finding a member costs a parse of the members before it, not a Python step per token.
    Stops where `skip` says ``None`` and at text that is not JSON (the parser reports that).
    """
    close = "}" if text[at] == "{" else "]"
    position, index = _space_end(text, at + 1), 0
    if text.startswith(close, position):
        return
    part: str | int
    while True:
        first, part = position, index
        if close == "}":
            if not text.startswith('"', position):
                return
            part, position = _scanstring(text, position + 1)
            position = _space_end(text, position)
            if not text.startswith(":", position):
                return
            position = _space_end(text, position + 1)
        yield part, first, position
        end = skip(position)
        if end is None:
            return
        position = _space_end(text, end)
        if not text.startswith(",", position):
            return
        position, index = _space_end(text, position + 1), index + 1


def _skipper(text: str, decoder: json.JSONDecoder, refused: list[int]) -> Callable[[int], int | None]:
    """A `skip` for :func:`_members`: the end of the value at a position of `text`, or ``None``
    when `decoder` refuses it (its position is then added to `refused`) or it is not JSON."""

    scan: Callable[[str, int], tuple[Any, int]] = decoder.scan_once  # type: ignore[attr-defined]  # set by __init__

    def skip(start: int) -> int | None:
        try:
            return scan(text, start)[1]
        except _Refused:
            refused.append(start)
        except (StopIteration, ValueError, RecursionError):
            pass
        return None

    return skip


def _refusal(word: str) -> str | None:
    """Why the bare JSON word `word` (a number or literal) is refused, or ``None``."""
    try:
        if word in ("NaN", "Infinity", "-Infinity"):
            _refuse_constant(word)
        elif re.fullmatch(r"-?[0-9]+", word):
            _parse_int(word)
        elif word not in ("true", "false", "null"):
            _parse_float(word)
    except (_Refused, ValueError) as err:
        return str(err)
    return None


def _line_and_column(text: str, offset: int) -> tuple[int, int]:
    return text.count("\n", 0, offset) + 1, offset - (text.rfind("\n", 0, offset) + 1) + 1


def json_problem(text: str, unique_keys: bool = False) -> tuple[str, FieldPath, tuple[int, int]] | None:
    """The first value of JSON `text` that :func:`load_json` refuses: ``(why, field path, (line,
    column))``, or ``None`` if there is none.

    It descends from the top into the member whose value the parser refuses: a parse (in C) of
    the text before the refusal per level of nesting.

    Parameters
    ----------
    text : str
        JSON text that :func:`load_json` refused.
    unique_keys : bool
        Whether a repeated key is refused too.
    """
    refused: list[int] = []
    skip, path = _skipper(text, _decoder(unique_keys), refused), list[str | int]()
    at = _space_end(text)
    while text.startswith(("{", "["), at):
        keys: dict[str | int, int] = {}
        for part, first, _ in _members(text, at, skip):  # stops after a refused member
            if unique_keys and part in keys:  # a list's indices never repeat
                line = _line_and_column(text, keys[part])[0]
                problem = (
                    f"duplicate key {part!r} (first on line {line}); every key appears once in its object"
                )
                return problem, (*path, part), _line_and_column(text, first)
            keys[part] = first
        if not refused:
            return None
        at = refused.pop()  # the last member's value: descend into it
        path.append(part)
    word = _WORD.match(text, at)
    refusal = None if word is None else _refusal(word.group())
    return None if refusal is None else (refusal, tuple(path), _line_and_column(text, at))


def json_position(text: str, path: FieldPath) -> tuple[int, int] | None:
    """The ``(line, column)`` where the value at field `path` of JSON `text` starts, if it has one.

    For error messages: it parses (in C) the members before each part of the path.

    Parameters
    ----------
    text : str
        JSON text.
    path : FieldPath
        Keys and list indices from the top down.

    >>> json_position('{"a": [1,\\n  2]}', ("a", 1))
    (2, 3)
    """
    skip, at = _skipper(text, json.JSONDecoder(), []), _space_end(text)
    for part in path:
        if not text.startswith(("{", "["), at):
            return None
        found = next((start for key, _, start in _members(text, at, skip) if key == part), None)
        if found is None:
            return None
        at = found
    return _line_and_column(text, at)


def _depth(data: Any) -> int:
    """The nesting depth of parsed JSON, without recursion."""
    deepest, todo = 0, [(data, 0)]
    while todo:
        value, depth = todo.pop()
        if isinstance(value, dict):
            value = value.values()
        elif not isinstance(value, list):
            continue
        deepest = max(deepest, depth + 1)
        todo.extend((item, depth + 1) for item in value)
    return deepest


# ----------------------------------------------------------------------------------------------
# Structure: a file format as pydantic types, and its first error as one line
# ----------------------------------------------------------------------------------------------

UNPRINTABLE = "unprintable"
"""The pydantic error type of text that is not printable (its message says where and why)."""

Expectations = Mapping[tuple[str, ...], str]
"""What a file expects at each field, in words, by field pattern (see :class:`Structure`)."""


def printable(value: str) -> str:
    """`value` itself if it is printable text, for a pydantic ``AfterValidator``.

    Names, ids and events are shown on terminals and written into files: an escape such as
    ``"\\u001b[31m"`` must not smuggle a control sequence through them (:func:`unprintable`).

    Parameters
    ----------
    value : str
        Text a file gives.

    Returns
    -------
    str
        `value`.

    Raises
    ------
    pydantic_core.PydanticCustomError
        Of type :data:`UNPRINTABLE`, whose message says which character and where.
    """
    if (problem := unprintable(value)) is not None:
        raise PydanticCustomError(UNPRINTABLE, problem)
    return value


def show(value: Any) -> str:
    """A value as an error message quotes it after "got".

    Parameters
    ----------
    value : Any
        A parsed value (text, number, boolean, null, list or mapping).

    Returns
    -------
    str
        ``nothing (null)`` for null, ``true`` or ``false``, else the value's repr, cut to 80
        characters.

    Examples
    --------
    >>> show(None), show(True), show("R1"), show([1, 2])
    ('nothing (null)', 'true', "'R1'", '[1, 2]')
    """
    if value is None:
        return "nothing (null)"
    if isinstance(value, bool):
        return "true" if value else "false"
    text = repr(value)
    return text if len(text) <= 80 else text[:77] + "..."


def lookup(data: Any, path: FieldPath) -> tuple[bool, Any]:
    """Whether parsed `data` has a value at `path`, and that value.

    Parameters
    ----------
    data : Any
        A parsed file: mappings, lists and scalars.
    path : FieldPath
        Keys and list indices from the top down.

    Returns
    -------
    found : bool
        Whether every part of `path` is there.
    value : Any
        The value at `path`; None when it is not found.
    """
    for part in path:
        if isinstance(data, Mapping):
            if part not in data:
                return False, None
        elif not (isinstance(data, list) and isinstance(part, int) and 0 <= part < len(data)):
            return False, None
        data = data[part]
    return True, data


def first_in_data(errors: Sequence[ErrorDetails], data: Any) -> ErrorDetails:
    """The error whose field comes first in `data`'s order (a parsed file's order: the first in
    the file), of a pydantic validation of `data`.

    A key a mapping lacks comes after the keys it has; on a tie the earlier error wins.  Each
    mapping on the way is indexed once, so even millions of errors cost time in proportion to
    the file.

    Parameters
    ----------
    errors : sequence of pydantic_core.ErrorDetails
        The errors of :meth:`pydantic.ValidationError.errors`, at least one.
    data : Any
        What was validated.

    Returns
    -------
    pydantic_core.ErrorDetails
        The first error.
    """
    orders: dict[int, dict[Any, int]] = {}

    def where(loc: tuple[int | str, ...]) -> tuple[int, ...]:
        out, node = [], data
        for part in loc:
            if part == "[key]":  # a mapping's key: where its entry is
                break
            if isinstance(node, Mapping):
                order = orders.get(id(node))
                if order is None:
                    order = orders[id(node)] = {key: i for i, key in enumerate(node)}
                if part not in order:
                    out.append(len(order))  # a missing key (or "[key]"): after the keys given
                    break
                out.append(order[part])
            elif isinstance(node, list | tuple) and isinstance(part, int) and 0 <= part < len(node):
                out.append(part)
            else:
                break
            node = node[part]
        return tuple(out)

    return min(enumerate(errors), key=lambda item: (where(item[1]["loc"]), item[0]))[1]


def _unwrap(annotation: Any) -> Any:
    """`annotation` without ``Annotated``, ``Required``, ``NotRequired`` and ``| None``."""
    while True:
        origin = get_origin(annotation)
        if origin in (Annotated, Required, NotRequired):
            annotation = get_args(annotation)[0]
        elif origin in (Union, UnionType):
            members = [arg for arg in get_args(annotation) if arg is not NoneType]
            if len(members) != 1:
                return annotation
            annotation = members[0]
        else:
            return annotation


def _fields(annotation: Any) -> dict[str, tuple[Any, bool]] | None:
    """The fields of a pydantic model or a TypedDict, in order: ``{key: (annotation, required)}``;
    None for any other type."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return {
            info.alias or name: (info.annotation, info.is_required())
            for name, info in annotation.model_fields.items()
        }
    if is_typeddict(annotation):
        total = getattr(annotation, "__total__", True)
        return {
            name: (hint, get_origin(hint) is Required or (total and get_origin(hint) is not NotRequired))
            for name, hint in get_type_hints(annotation, include_extras=True).items()
        }
    return None


class Structure:
    """A file format's structure: pydantic types, what each field expects in words, and the error
    that says so in one line, ``<file>: <field>: expected <what>, got <what>``.

    Parameters
    ----------
    root : type
        The pydantic model or TypedDict of the whole file.
    expected : Expectations
        What is expected at a field, in words (``"a positive number (mm)"``), by field pattern:
        the keys from the top down, ``"*"`` standing for any key, ``"#"`` for any list index and
        ``"[key]"`` for the key itself of a mapping's entry (``("robots", "*", "[key]")``: a
        robot's id).  Where no pattern matches a field, the words of the nearest field above it
        that has some (or the keys of its model) are used.
    error : type of CosmopInputError
        What to raise.
    """

    def __init__(self, root: Any, expected: Expectations, error: type[CosmopInputError]) -> None:
        self.root = root
        self.expected = dict(expected)
        self.error = error
        self._adapter: TypeAdapter[Any] | None = None  # built when first used: importing stays quick

    @property
    def adapter(self) -> TypeAdapter[Any]:
        """The pydantic validator of the root type."""
        if self._adapter is None:
            self._adapter = TypeAdapter(self.root)
        return self._adapter

    def validate(self, data: Any, file: str | None = None, text: str | None = None) -> Any:
        """`data` validated as the root type; the first wrong field in file order fails.

        Parameters
        ----------
        data : Any
            The parsed file.
        file : str, optional
            The file's name, for the error.
        text : str, optional
            The file's text, when it is JSON: the error then says the field's line and column.

        Returns
        -------
        Any
            What the root type's validator returns (a model, or the TypedDict's dict).

        Raises
        ------
        CosmopInputError
            Of this structure's `error` type, naming `file`, the field and what was expected.
        """
        try:
            return self.adapter.validate_python(data)
        except ValidationError as exc:
            first = first_in_data(exc.errors(include_url=False), data)
            path, problem = self.problem(first, data)
            raise self.fail(path, problem, file, text) from None

    def fail(
        self, path: FieldPath, problem: str, file: str | None = None, text: str | None = None
    ) -> CosmopInputError:
        """The error at `path` (for the caller to raise).

        Parameters
        ----------
        path : FieldPath
            The field; ``()`` for the whole file.
        problem : str
            What was expected there and what was found.
        file : str, optional
            The file's name.
        text : str, optional
            The file's JSON text: the error says where the field (or, if absent, its nearest
            parent) starts.

        Returns
        -------
        CosmopInputError
            Of this structure's `error` type.
        """
        line = column = None
        if text is not None:
            for length in range(len(path), 0, -1):  # the whole file (path ()) has no line of its own
                found = json_position(text, path[:length])
                if found is not None:
                    line, column = found
                    break
        return self.error(problem, file=file, field=format_path(path), line=line, column=column)

    def problem(self, error: ErrorDetails, data: Any) -> tuple[FieldPath, str]:
        """The field to name for a pydantic error, and what was expected there and found.

        Parameters
        ----------
        error : pydantic_core.ErrorDetails
            One error of a validation of `data`.
        data : Any
            What was validated.

        Returns
        -------
        path : FieldPath
            The field.
        problem : str
            ``expected <what>, got <what>``; ``missing required key 'k': expected <what>``;
            ``unknown key 'k'; expected one of: ...``; or an unprintable text's message.
        """
        loc: FieldPath = tuple(error["loc"])
        kind = error["type"]
        if kind == "missing" and loc and isinstance(loc[-1], int):  # a fixed-length list too short
            loc, kind = loc[:-1], "too_short"
        if "[key]" in loc:  # a mapping's key: the field is the entry it names
            cut = loc.index("[key]")
            if kind == UNPRINTABLE:
                return loc[:cut], str(error["msg"])
            text = self._pattern_text(loc[: cut + 1])
            return loc[:cut], f"expected {text or 'an id (text)'}, got {show(loc[cut - 1])}"
        if kind == UNPRINTABLE:
            return loc, str(error["msg"])
        if kind == "extra_forbidden" and loc:
            fields = _fields(self.model_at(loc[:-1])) or {}
            allowed = ", ".join(fields) or "none"
            return loc, f"unknown key {loc[-1]!r}; expected one of: {allowed}"
        if kind == "missing" and loc and isinstance(loc[-1], str):
            path, text = self.expected_at(loc)
            detail = f": expected {text}" if text is not None and path == loc else ""
            return loc, f"missing required key {loc[-1]!r}{detail}"
        path, text = self.expected_at(loc)
        if text is None:
            return loc, str(error["msg"])
        found, value = lookup(data, path)
        got = show(value) if found else "nothing"
        if kind in ("too_long", "too_short") and isinstance(value, list | Mapping) and len(got) >= 80:
            got = f"{len(value):,} items"  # too many to show
        return path, f"expected {text}, got {got}"

    def expected_at(self, loc: FieldPath) -> tuple[FieldPath, str | None]:
        """The field to report for an error at `loc`, and what is expected there in words.

        Parameters
        ----------
        loc : FieldPath
            Where pydantic found the error.

        Returns
        -------
        path : FieldPath
            `loc`, or the nearest field above it with words.
        expected : str or None
            The words; None when no field on the way has any.
        """
        for length in range(len(loc), -1, -1):
            prefix = loc[:length]
            text = self._pattern_text(prefix)
            if text is not None:
                return prefix, text
            fields = _fields(self.model_at(prefix))
            if fields is not None:
                keys = [key if required else f"{key} (optional)" for key, (_, required) in fields.items()]
                return prefix, "a mapping with keys " + ", ".join(keys)
        return loc, None

    def _pattern_text(self, path: FieldPath) -> str | None:
        for pattern, text in self.expected.items():
            if len(pattern) == len(path) and all(
                _matches(p, part) for p, part in zip(pattern, path, strict=True)
            ):
                return text
        return None

    def model_at(self, path: FieldPath) -> Any:
        """The type at `path` of the root type (a model, a TypedDict, ...), or None.

        Parameters
        ----------
        path : FieldPath
            Keys and list indices from the top down.

        Returns
        -------
        Any
            The annotation found there, without ``Annotated`` or ``| None``; None when `path`
            leads outside the structure.
        """
        annotation: Any = self.root
        for part in path:
            annotation = _unwrap(annotation)
            fields = _fields(annotation)
            origin = get_origin(annotation)
            if fields is not None:
                if not isinstance(part, str) or part not in fields:
                    return None
                annotation = fields[part][0]
            elif origin is dict:
                annotation = get_args(annotation)[1]
            elif origin is list:
                annotation = get_args(annotation)[0]
            elif origin is tuple and isinstance(part, int):
                args = get_args(annotation)
                if len(args) == 2 and args[1] is Ellipsis:
                    annotation = args[0]
                elif 0 <= part < len(args):
                    annotation = args[part]
                else:
                    return None
            else:
                return None
        return _unwrap(annotation)


def _matches(pattern: str, part: str | int) -> bool:
    if pattern == "#":
        return isinstance(part, int)
    if pattern == "[key]":
        return part == "[key]"
    return pattern == "*" or pattern == part
