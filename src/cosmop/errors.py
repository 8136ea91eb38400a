"""Exceptions raised on bad user input.

Every error a user can fix by editing a file derives from :class:`CosmopInputError` and says
*where* (the file and the field inside it) and *what* (what was expected, or what is wrong).
The command line prints such errors as one line and exits with status 2.
"""

from __future__ import annotations

import os

__all__ = ["CosmopInputError", "EventSyntaxError", "MissionTooLargeError", "OutputPathError", "ScenarioError"]


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
        text = ": ".join(part for part in (self.file, self.field, self.expected) if part is not None)
        if self.line is not None:
            where = f"line {self.line}" if self.column is None else f"line {self.line}, column {self.column}"
            text = f"{text} ({where})"
        return text

    def __str__(self) -> str:
        return self._message()

    def __reduce__(self):  # keyword-only arguments: teach pickle (multiprocessing) to rebuild us
        return (
            _rebuild,
            (type(self), self.expected, self.file, self.field, self.line, self.column),
        )


def _rebuild(cls, expected, file, field, line, column):
    return cls(expected, file=file, field=field, line=line, column=column)


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
