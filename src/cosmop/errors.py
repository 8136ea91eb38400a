"""Exceptions raised on bad user input.

Every error a user can fix by editing a file derives from :class:`CosmopInputError` and says
*where* (the file and the field inside it) and *what* (what was expected, or what is wrong).
The command line prints such errors as one line and exits with status 2.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass

__all__ = [
    "CosmopInputError",
    "EventSyntaxError",
    "InputWarning",
    "MissionTooLargeError",
    "OutputPathError",
    "ScenarioError",
]


class CosmopInputError(Exception):
    """Bad user input: a file, a field inside it, and what was expected there.

    Parameters
    ----------
    expected : str
        What was expected, or what is wrong, in words a user can act on.
    file : str or os.PathLike, optional
        The file the input came from; ``None`` for input that came from memory.
    field : str, optional
        The dotted and indexed path of the offending field, e.g. ``scene.robots.R1.size`` or
        ``mission.tasks.R2[1]``; ``None`` when the problem concerns the whole file.
    line : int, optional
        The 1-based line in `file` where the offending field starts, when known.
    column : int, optional
        The 1-based column in `file`, when known (only meaningful together with `line`).

    Notes
    -----
    ``str(err)`` is ``"{file}: {field}: {expected}"`` with the parts that are ``None`` left out,
    followed by ``" (line L)"`` or ``" (line L, column C)"`` when the position is known.
    """

    def __init__(
        self,
        expected: str,
        *,
        file: str | os.PathLike[str] | None = None,
        field: str | None = None,
        line: int | None = None,
        column: int | None = None,
    ) -> None:
        self.expected = expected
        self.file = None if file is None else os.fspath(file)
        self.field = field
        self.line = line
        self.column = column
        super().__init__(self._message())

    def _message(self) -> str:
        return _located(self.file, self.field, self.expected, self.line, self.column)

    def __str__(self) -> str:
        return self._message()

    def __reduce__(self) -> tuple[Callable[..., CosmopInputError], tuple[object, ...]]:
        # keyword-only arguments: teach pickle (multiprocessing) to rebuild us
        return (
            _rebuild,
            (type(self), self.expected, self.file, self.field, self.line, self.column),
        )


def _rebuild(
    cls: type[CosmopInputError],
    expected: str,
    file: str | None,
    field: str | None,
    line: int | None,
    column: int | None,
) -> CosmopInputError:
    return cls(expected, file=file, field=field, line=line, column=column)


@dataclass(frozen=True)
class InputWarning:
    """Input that loads but is probably a mistake: a file, a field inside it, and why.

    The library never prints these; a loader returns them as values (e.g.
    ``Scenario.warnings``) and the command line prints each as one line, ``warning: ...``,
    leaving the exit status alone.

    Parameters
    ----------
    problem : str
        What looks wrong and the likely mistake, e.g. "looks like millimetres in a metres file".
    file : str, optional
        The file the input came from.
    field : str, optional
        The dotted and indexed path of the field, e.g. ``scene.robots.R1.size``.
    line, column : int, optional
        The 1-based position of the field in `file`, when known.

    Notes
    -----
    ``str(warning)`` is written as :class:`CosmopInputError`'s: ``"{file}: {field}: {problem}"``
    with the parts that are ``None`` left out, then ``" (line L, column C)"``.
    """

    problem: str
    file: str | None = None
    field: str | None = None
    line: int | None = None
    column: int | None = None

    def __str__(self) -> str:
        return _located(self.file, self.field, self.problem, self.line, self.column)


def _located(file: str | None, field: str | None, text: str, line: int | None, column: int | None) -> str:
    """``"{file}: {field}: {text} (line L, column C)"``, leaving out the parts not known."""
    text = ": ".join(part for part in (file, field, text) if part is not None)
    if line is not None:
        where = f"line {line}" if column is None else f"line {line}, column {column}"
        text = f"{text} ({where})"
    return text


class ScenarioError(CosmopInputError):
    """A scenario file (or scenario mapping) that cannot be loaded or is invalid."""


class OutputPathError(CosmopInputError):
    """An output path that cannot be written: its folder is missing or read-only, or it is a folder."""


class EventSyntaxError(ValueError):
    """Text that is not a mission event, or an event whose parts are inconsistent.

    The message quotes the offending text and lists the accepted forms.
    """


class MissionTooLargeError(ScenarioError):
    """A mission beyond what the top-down layer decides within its bounds (team states explored,
    counterexamples used): the user can split it or write it more compactly."""
