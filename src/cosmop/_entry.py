"""The ``cosmop`` program: the command line, with Ctrl-C answered even while it starts.

Importing the command line loads numpy, shapely, Z3 and pydantic (about a second); an
interrupt then must not print Python's traceback either.  This module imports nothing heavy.
"""

from __future__ import annotations

import sys


def run() -> None:
    """Run :func:`cosmop.cli.main`; Ctrl-C at any moment ends with one line and status 130."""
    try:
        from cosmop.cli import main

        main()
    except KeyboardInterrupt:
        sys.stderr.write("interrupted\n")
        raise SystemExit(130) from None
