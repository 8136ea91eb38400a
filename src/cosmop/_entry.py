"""The ``cosmop`` program: the command line, with Ctrl-C answered the same way at every moment.

A terminal sends Ctrl-C (SIGINT) to every process of its foreground job: this program and the
planner's worker processes, which ignore it (:class:`cosmop.team.planner.Workers`).  The program
answers it with ``interrupted`` on standard error and exit status 130 (128 + SIGINT, as shells
expect), no traceback, no process left and nothing half-written, in one of two ways:

- The first Ctrl-C raises KeyboardInterrupt in the main thread.  The library's ``finally``
  blocks run as it unwinds: the worker processes are killed and their pool shut down, the
  staging folder of an output being written is removed (:func:`cosmop.io.atomic_path`).  Then
  the program prints ``interrupted`` and ends at once (:func:`os._exit`, after flushing its
  output), without the interpreter's teardown: nothing is left to do, and the teardown joins
  threads and processes, which an interrupt can only leave half joined.
- A Ctrl-C that comes when the program is already ending (a second one, while the first
  unwinds; or one when the command is done) ends it on the spot: its child processes killed,
  the staging folders removed, ``interrupted``, 130.
- A first Ctrl-C that lands where Python cannot raise (in a finaliser such as a Z3 term's
  ``__del__``, or in the import system's lock callback, while a module loads) would be
  swallowed, with an "Exception ignored" traceback, and the program would go on: it ends the
  program on the spot instead, as a second one does (:data:`sys.unraisablehook`).
- A Ctrl-C that lands while an object is being built (a Z3 context, say) leaves it half built,
  and its finaliser may then fail as the program unwinds ("Exception ignored" and a traceback):
  after a Ctrl-C such failures are the interrupt's doing and are not shown.

A command that is done ends the program the same way, at once (:func:`os._exit` with the
command's status, its output flushed): the interpreter's teardown would wait for any thread
left, and in its last part Python gives Ctrl-C back to the system, which would kill the
program with no word.

This module imports nothing heavy: the handler is in place before the command line loads
numpy, shapely, Z3 and pydantic (about a second).  Before it, while Python itself starts (its
first 50 ms or so), Ctrl-C is Python's: the process ends by the signal, or, in a narrow part of
that time, with Python's own KeyboardInterrupt traceback.
"""

from __future__ import annotations

import os
import signal
import sys

TYPE_CHECKING = False  # (typing itself is not imported at run time)
if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Any

EXIT_INTERRUPTED = 130
"""Exit status after Ctrl-C (128 + SIGINT)."""


class _CtrlC:
    """The program's SIGINT handler: the first raises KeyboardInterrupt, any later one ends it."""

    def __init__(self) -> None:
        self.taken = 0  # Ctrl-Cs this handler has taken
        self.ending = False  # the program is ending: a Ctrl-C now ends it on the spot

    def __call__(self, number: int, frame: object) -> None:
        self.taken += 1
        if self.ending:
            _end()
        self.ending = True
        raise KeyboardInterrupt


def _end() -> None:
    """End the interrupted program now (no return): child processes killed, staging folders
    removed, ``interrupted``, status 130."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # ending: a further Ctrl-C has nothing to add
    # modules looked up, not imported: one not loaded yet has started nothing to clean up
    processes = sys.modules.get("multiprocessing")
    if processes is not None:
        children = processes.active_children()
        for child in children:
            child.kill()
        for child in children:
            child.join(1.0)
    io = sys.modules.get("cosmop.io")
    if io is not None:
        io.abandon_staging()
    _flush()
    # on a terminal, a progress display may be cut short: clear its line, show the cursor
    _quietly(os.write, 2, (b"\r\x1b[2K\x1b[?25h" if os.isatty(2) else b"") + b"interrupted\n")
    os._exit(EXIT_INTERRUPTED)


def _ending_when_swallowed(default: Callable[[Any], object], ctrl_c: _CtrlC) -> Callable[[Any], None]:
    """A :data:`sys.unraisablehook` that ends the program (:func:`_end`) when the exception
    Python could not raise is the Ctrl-C's KeyboardInterrupt, keeps quiet about the others once
    `ctrl_c` has taken a Ctrl-C (a finaliser of an object it left half built), and leaves the
    others to `default`."""

    def hook(unraisable: Any) -> None:
        if isinstance(unraisable.exc_value, KeyboardInterrupt):
            _end()
        if not ctrl_c.taken:
            default(unraisable)

    return hook


def _finish(code: object) -> None:
    """End the program whose command is done (no return), with the command's exit status
    (`code` as :class:`SystemExit` holds it), at once: the interpreter's teardown is skipped."""
    if code is not None and not isinstance(code, int):
        print(code, file=sys.stderr)
    _flush()
    os._exit(0 if code is None else code if isinstance(code, int) else 1)


def _flush() -> None:
    for stream in (sys.stdout, sys.stderr):
        _quietly(stream.flush)


def _quietly(action: Callable[..., object], *args: object) -> None:
    """``action(*args)``, where a closed pipe or stream has nothing more to take (contextlib's
    ``suppress`` would load a module before the handler is in place)."""
    try:
        action(*args)
    except (OSError, ValueError):
        return


def run() -> None:
    """Run :func:`cosmop.cli.main` and answer Ctrl-C as the module docstring says; the program
    ends here (no return)."""
    ctrl_c = _CtrlC()
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:  # not ignored by the caller
        signal.signal(signal.SIGINT, ctrl_c)
        sys.unraisablehook = _ending_when_swallowed(sys.unraisablehook, ctrl_c)
    try:
        from cosmop.cli import main

        main()
    except KeyboardInterrupt:
        pass
    except SystemExit as done:  # how the command line ends, with its status
        ctrl_c.ending = True
        if not ctrl_c.taken:
            _finish(done.code)
    except BaseException:  # a bug: Python prints its traceback
        ctrl_c.ending = True
        if not ctrl_c.taken:
            raise
    else:
        ctrl_c.ending = True
        _finish(0)
    # after a Ctrl-C, whatever ends the command is the interrupt's doing: a library may have
    # turned it into another exception (ctypes, inside a call to Z3, makes it an ArgumentError)
    # and the command line into exit status 130
    _end()
