"""The command group every ``cosmop`` command registers on, and what the commands share.

Input errors (:class:`~cosmop.errors.CosmopInputError`, an event typed on the command line, a file
the system refuses to write) become one line on standard error and exit status 2; Ctrl-C ends
with status 130.  Commands load their scenario with :func:`load` and print with :func:`stdout`.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.console import Console
from typer.core import TyperGroup

from cosmop import __version__
from cosmop.errors import CosmopInputError, EventSyntaxError
from cosmop.scenario import load_scenario
from cosmop.scene import Scenario

__all__ = ["EXIT_INPUT_ERROR", "ScenarioArgument", "app", "load", "stderr", "stdout"]

EXIT_INPUT_ERROR = 2
"""Exit status for bad input (also the status of command-line usage errors)."""


class _Group(TyperGroup):
    """Command group that turns input errors into one line on stderr and exit status 2.

    Input errors are :class:`~cosmop.errors.CosmopInputError` (bad files) and
    :class:`~cosmop.errors.EventSyntaxError` (an event typed on the command line); a file the
    system refuses to write (:class:`OSError`, e.g. a full disk) is reported the same way.
    Ctrl-C ends with one line and status 130 (128 + SIGINT), as shells expect.
    """

    def invoke(self, ctx: typer.Context) -> Any:
        try:
            return super().invoke(ctx)
        except (CosmopInputError, EventSyntaxError) as err:
            # plain echo, not rich: field paths such as tasks.R1[0] must not be read as markup
            typer.echo(f"error: {err}", err=True)
            raise typer.Exit(EXIT_INPUT_ERROR) from None
        except OSError as err:
            where = f"{err.filename}: " if err.filename else ""
            typer.echo(f"error: {where}{err.strerror or err}", err=True)
            raise typer.Exit(EXIT_INPUT_ERROR) from None
        except KeyboardInterrupt:
            typer.echo("interrupted", err=True)
            raise typer.Exit(130) from None


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


def load(path: Path) -> Scenario:
    """Load a scenario for a command; a bad file raises ScenarioError, reported by the group.

    What the loader found implausible (``Scenario.warnings``) is printed on standard error, one
    line each, ``warning: ...``; it changes nothing else.
    """
    scenario = load_scenario(path)
    for warning in scenario.warnings:
        typer.echo(f"warning: {warning}", err=True)  # plain echo: field paths are not markup
    return scenario


ScenarioArgument = Annotated[
    Path, typer.Argument(metavar="SCENARIO", help="Scenario file (YAML).", show_default=False)
]


def stderr() -> Console:
    """A console on the current standard error, for progress bars and spinners."""
    return Console(file=sys.stderr, highlight=False)
