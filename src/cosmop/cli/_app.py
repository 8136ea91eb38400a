"""The command group every ``cosmop`` command registers on, and what the commands share.

Input errors (:class:`~cosmop.errors.CosmopInputError`, an event typed on the command line, a file
the system refuses to write) and usage errors become one line on standard error and exit
status 2; Ctrl-C is the program's (:mod:`cosmop._entry`).  Commands load their scenario with
:func:`load` and print with :func:`stdout`.
"""

from __future__ import annotations

import inspect
import math
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, NoReturn, cast

import typer
from rich.console import Console
from typer.core import TyperGroup

from cosmop import __version__
from cosmop.errors import CosmopInputError, EventSyntaxError, ScenarioError
from cosmop.scenario import load_scenario
from cosmop.scene import Scenario

__all__ = ["EXIT_INPUT_ERROR", "ScenarioArgument", "app", "finite", "load", "stderr", "stdout"]

EXIT_INPUT_ERROR = 2
"""Exit status for bad input (also the status of command-line usage errors)."""


if TYPE_CHECKING:

    class _ClickError(Exception):
        """What click's error base class offers us, whichever click typer uses."""

        exit_code: int

        def format_message(self) -> str: ...


def finite(value: float | None) -> float | None:
    """A number option's check (a typer ``callback``): ``inf`` passes a lower bound, yet no run
    lasts for ever and no rate is infinite."""
    if value is not None and not math.isfinite(value):
        raise typer.BadParameter(f"expected a finite number, got {value}")
    return value


# click's error base class, from typer's own BadParameter (typer may bundle its own click)
_ClickException = cast(
    "type[_ClickError]", next(c for c in typer.BadParameter.__mro__ if c.__name__ == "ClickException")
)


def _usage_error(err: _ClickError) -> NoReturn:
    """A command-line usage error (an option out of range, a missing argument, an unknown
    command) as one line naming the command and the option, with click's exit status (2).

    The help that ``cosmop`` with no arguments prints is shown as it is."""
    if type(err).__name__ == "NoArgsIsHelpError":
        raise err
    ctx = getattr(err, "ctx", None)
    where = f"{ctx.command_path}: " if ctx is not None else ""
    message = " ".join(err.format_message().split())  # one line, whatever click wrapped
    typer.echo(f"error: {where}{message}", err=True)
    raise typer.Exit(err.exit_code) from None


class _Group(TyperGroup):
    """Command group that turns usage and input errors into one line on stderr and exit status 2.

    Usage errors are click's (an option out of its range, an unknown option or command); input
    errors are :class:`~cosmop.errors.CosmopInputError` (bad files) and
    :class:`~cosmop.errors.EventSyntaxError` (an event typed on the command line); a file the
    system refuses to write (:class:`OSError`, e.g. a full disk) is reported the same way.
    Ctrl-C is the program's (:mod:`cosmop._entry`): KeyboardInterrupt passes through.
    """

    # click's Context is typer's bundled one or click's own, as installed: no one public name for it
    def make_context(self, info_name: str | None, args: list[str], parent: Any = None, **extra: Any) -> Any:
        try:  # the group's own options and arguments
            return super().make_context(info_name, args, parent=parent, **extra)
        except _ClickException as err:
            _usage_error(err)

    def invoke(self, ctx: Any) -> Any:
        try:
            return super().invoke(ctx)
        except _ClickException as err:  # a command's options and arguments, or its own checks
            _usage_error(err)
        except (CosmopInputError, EventSyntaxError) as err:
            # plain echo, not rich: field paths such as tasks.R1[0] must not be read as markup
            typer.echo(f"error: {err}", err=True)
            raise typer.Exit(EXIT_INPUT_ERROR) from None
        except OSError as err:
            where = f"{err.filename}: " if err.filename else ""
            typer.echo(f"error: {where}{err.strerror or err}", err=True)
            raise typer.Exit(EXIT_INPUT_ERROR) from None


app = typer.Typer(
    cls=_Group,
    name="cosmop",
    help="Cooperative multi-robot mission and motion planning with formal guarantees.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_show_locals=False,
)


def _version_callback(value: bool) -> None:
    if value:
        typer.echo(f"cosmop {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: Annotated[
        bool,
        typer.Option(
            "--version", callback=_version_callback, is_eager=True, help="Print the version and exit."
        ),
    ] = False,
) -> None:
    """Cooperative multi-robot mission and motion planning with formal guarantees."""


def stdout() -> Console:
    """A console on the current standard output (looked up late, so test runners can capture it)."""
    return Console(file=sys.stdout, highlight=False)


def load(path: Path, *, mission: bool = True) -> Scenario:
    """Load a scenario for a command; a bad file raises ScenarioError, reported by the group.

    What the loader found implausible (``Scenario.warnings``) is printed on standard error, one
    line each, ``warning: ...``; it changes nothing else.  A command that plans a mission
    (`mission`) refuses a file that holds only orders, naming ``cosmop run``.
    """
    scenario = load_scenario(path)
    if mission and scenario.mission is None:
        raise ScenarioError(
            "expected a mission (tasks, dfa or deliveries): this file holds only orders, "
            "which a lifelong run serves (cosmop run)",
            file=path,
            field="mission",
        )
    for warning in scenario.warnings:
        typer.echo(f"warning: {warning}", err=True)  # plain echo: field paths are not markup
    return scenario


ScenarioArgument = Annotated[
    Path, typer.Argument(metavar="SCENARIO", help="Scenario file (YAML).", show_default=False)
]


def stderr() -> Console:
    """A console on the current standard error, for progress bars and spinners."""
    return Console(file=sys.stderr, highlight=False)


def command_help(doc: str | None) -> str:
    """A command's help for ``--help``, from its docstring: the prose before the numpydoc
    sections, each paragraph on one line (the terminal wraps it), literals without their marks.

    The docstring's ``Parameters`` section documents the function for readers of the code; the
    user reads the same thing, in plain words, beside each option.

    Parameters
    ----------
    doc : str or None
        The command function's docstring.

    Returns
    -------
    str
        Paragraphs separated by blank lines.
    """
    lines = inspect.cleandoc(doc or "").splitlines()
    for at in range(len(lines) - 1):
        if lines[at].strip() in _SECTIONS and set(lines[at + 1].strip()) == {"-"}:
            lines = lines[:at]
            break
    paragraphs = "\n".join(lines).strip().split("\n\n")
    return "\n\n".join(" ".join(p.split()).replace("``", "") for p in paragraphs)


_SECTIONS = {"Parameters", "Returns", "Raises", "Notes", "Examples", "See Also"}
