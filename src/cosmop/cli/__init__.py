"""The ``cosmop`` command line.

The library is silent; this package is the friendly layer. Errors in the user's input
(:class:`~cosmop.errors.CosmopInputError`) are printed as one line, ``error: <message>``, on
standard error, and the command exits with status 2 -- as does a usage error (an option out of
its range, a missing argument), also one line. Other exit statuses: 0 for success, 1 for a
well-formed problem without a solution (e.g. an infeasible scenario), 130 after Ctrl-C, which
the program answers (:mod:`cosmop._entry`, the ``cosmop`` command).

One module per command (or family of commands), registered here, in order, on the one
:data:`~cosmop.cli._app.app`: ``validate``, ``decompose``, ``plan`` and ``check``, ``simulate``,
``run`` (a lifelong run), and the ecosystem's ``import-map``, ``export`` and ``view``;
:mod:`cosmop.cli.words` says what a verdict means.  To add a command, write a thin function,
list it here, and let it load its input with :func:`cosmop.cli._app.load` and leave the work
to the library; input errors need no handling there.
"""

from cosmop.cli import decompose, ecosystem, plan, run, simulate, validate
from cosmop.cli._app import EXIT_INPUT_ERROR, app, command_help

__all__ = ["EXIT_INPUT_ERROR", "app", "main"]

# The commands, in the order ``cosmop --help`` lists them.
for _name, _command in (
    ("validate", validate.validate),
    ("decompose", decompose.decompose),
    ("check", plan.check),
    ("plan", plan.plan),
    ("simulate", simulate.simulate),
    ("run", run.run),
    ("import-map", ecosystem.import_map),
    ("export", ecosystem.export),
    ("view", ecosystem.view),
):
    app.command(_name, help=command_help(_command.__doc__))(_command)


def main() -> None:
    """Run the command line, with the program name ``cosmop`` (the program, ``cosmop`` and
    ``python -m cosmop``, is :func:`cosmop._entry.run`, which also answers Ctrl-C)."""
    app(prog_name="cosmop")
