"""Reading simulation traces (``cosmop.trace/1``, what ``cosmop simulate --trace`` writes).

A trace is JSON: ``format``, ``scenario``, ``units`` (absent in older files: mm, degrees, s),
``dt`` (s), ``frames`` (each with ``t`` in s, ``robots`` ``{id: {"pose": [x, y, heading], ...}}``,
``humans`` and ``objects`` ``{id: [x, y]}``) and ``messages`` (each a mapping with at least ``t``,
``from`` and ``to``; other keys are kept as they are, so new kinds of message pass through).
:func:`load_trace` checks that shape and names the first field that is wrong.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from typing import Any

from cosmop.errors import CosmopInputError
from cosmop.io import read_text
from cosmop.reading import load_json
from cosmop.units import check_units_field

__all__ = ["TRACE_FORMAT", "TraceError", "check_trace", "load_trace", "message_label"]

TRACE_FORMAT = "cosmop.trace/1"
"""The ``format`` of the traces this module reads."""


class TraceError(CosmopInputError):
    """A trace file that cannot be read or does not have the ``cosmop.trace/1`` shape."""


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


def _check_frame(frame: Any, k: int, fail) -> None:
    if not isinstance(frame, Mapping) or not _is_number(frame.get("t")):
        fail(f"frames[{k}]", "a mapping with a time t (s)")
    robots = frame.get("robots", {})
    if not isinstance(robots, Mapping):
        fail(f"frames[{k}].robots", "a mapping of robot states by id")
    for rid, state in robots.items():
        pose = state.get("pose") if isinstance(state, Mapping) else None
        if not (isinstance(pose, list) and len(pose) == 3 and all(_is_number(v) for v in pose)):
            fail(f"frames[{k}].robots.{rid}.pose", "[x, y, heading] (mm, mm, degrees)")
    for group in ("humans", "objects"):
        points = frame.get(group, {})
        if not isinstance(points, Mapping) or not all(
            isinstance(p, list) and len(p) == 2 and all(_is_number(v) for v in p) for p in points.values()
        ):
            fail(f"frames[{k}].{group}", "a mapping of positions [x, y] (mm) by id")


def check_trace(data: Any, file: str | os.PathLike[str] | None = None) -> dict[str, Any]:
    """Check the shape of a parsed trace and return it.

    Raises
    ------
    TraceError
        Naming the file, the first wrong field and what was expected there.
    """
    where = None if file is None else os.fspath(file)

    def fail(field: str, expected: str) -> None:
        raise TraceError(f"expected {expected}", file=where, field=field)

    if not isinstance(data, Mapping):
        fail("format", f"a JSON object in the {TRACE_FORMAT} format")
    if data.get("format") != TRACE_FORMAT:
        fail("format", f"{TRACE_FORMAT!r}, got {data.get('format')!r}")
    if (problem := check_units_field(data.get("units"))) is not None:
        raise TraceError(problem, file=where, field="units")
    frames = data.get("frames")
    if not isinstance(frames, list) or not frames:
        fail("frames", "a non-empty list of frames")
    for k, frame in enumerate(frames):
        _check_frame(frame, k, fail)
    if "dt" in data and not (_is_number(data["dt"]) and data["dt"] > 0):
        fail("dt", "the cycle in seconds (a positive number)")
    messages = data.get("messages", [])
    if not isinstance(messages, list):
        fail("messages", "a list of messages")
    for k, message in enumerate(messages):
        if not (isinstance(message, Mapping) and _is_number(message.get("t"))):
            fail(f"messages[{k}]", "a mapping with a time t (s), from and to")
        if not (isinstance(message.get("from"), str) and isinstance(message.get("to"), str)):
            fail(f"messages[{k}]", "a mapping with the robot ids from and to")
    return dict(data)


def load_trace(path: str | os.PathLike[str]) -> dict[str, Any]:
    """Read and check a ``cosmop.trace/1`` file (see :func:`check_trace`)."""
    file = os.fspath(path)
    text = read_text(path, TraceError, "a trace file")
    data = load_json(text, file, TraceError)
    return check_trace(data, file)


def message_label(message: Mapping[str, Any]) -> str:
    """A short text for a message of any kind: its object, else its event, kind or type, else "message"."""
    for key in ("object", "event", "kind", "type"):
        if isinstance(message.get(key), str):
            return message[key]
    return "message"
