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
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Callable, Iterator
from typing import Any, NoReturn

import yaml

from cosmop.errors import CosmopInputError

__all__ = [
    "MAX_DEPTH",
    "MAX_DIGITS",
    "MAX_NODES",
    "MAX_TEXT",
    "FieldPath",
    "Marks",
    "check_printable",
    "format_path",
    "json_position",
    "json_problem",
    "load_json",
    "load_yaml",
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

    >>> unprintable("warehouse"), unprintable("ware\x1b[31m")
    (None, "expected printable text, got 'ware\\x1b[31m' (U+001B at character 5)")
    """
    if text.isprintable():
        return None
    index, char = next((i, c) for i, c in enumerate(text) if not c.isprintable())
    shown = repr(text) if len(text) <= 80 else repr(text[:77]) + "..."
    return f"expected printable text, got {shown} (U+{ord(char):04X} at character {index + 1})"


def check_printable(text: str, error: type[CosmopInputError], file: str | None) -> None:
    """Raise ``error`` at the first control character of `text` (tab, LF and CR are allowed)."""
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
    return yaml.SafeLoader.construct_yaml_int(loader, node)


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


def _index_nodes(loader, node, path: FieldPath, marks: Marks, visited: set[int], file, error) -> None:
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
    position, index = _SPACE.match(text, at + 1).end(), 0
    if text.startswith(close, position):
        return
    while True:
        first, part = position, index
        if close == "}":
            if not text.startswith('"', position):
                return
            part, position = json.decoder.scanstring(text, position + 1)
            position = _SPACE.match(text, position).end()
            if not text.startswith(":", position):
                return
            position = _SPACE.match(text, position + 1).end()
        yield part, first, position
        end = skip(position)
        if end is None:
            return
        position = _SPACE.match(text, end).end()
        if not text.startswith(",", position):
            return
        position, index = _SPACE.match(text, position + 1).end(), index + 1


def _skipper(text: str, decoder: json.JSONDecoder, refused: list[int]) -> Callable[[int], int | None]:
    """A `skip` for :func:`_members`: the end of the value at a position of `text`, or ``None``
    when `decoder` refuses it (its position is then added to `refused`) or it is not JSON."""

    def skip(start: int) -> int | None:
        try:
            return decoder.scan_once(text, start)[1]
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
    """
    refused: list[int] = []
    skip, path = _skipper(text, _decoder(unique_keys), refused), []
    at = _SPACE.match(text).end()
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
    problem = None if word is None else _refusal(word.group())
    return None if problem is None else (problem, tuple(path), _line_and_column(text, at))


def json_position(text: str, path: FieldPath) -> tuple[int, int] | None:
    """The ``(line, column)`` where the value at field `path` of JSON `text` starts, if it has one.

    For error messages: it parses (in C) the members before each part of the path.

    >>> json_position('{"a": [1,\\n  2]}', ("a", 1))
    (2, 3)
    """
    skip, at = _skipper(text, json.JSONDecoder(), []), _SPACE.match(text).end()
    for part in path:
        if not text.startswith(("{", "["), at):
            return None
        at = next((start for key, _, start in _members(text, at, skip) if key == part), None)
        if at is None:
            return None
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
