"""cosmop: cooperative missions for teams of mobile robots, with formal guarantees.

The top-down layer (:mod:`cosmop.missions`) decomposes a global mission, a regular
language over all robots' events, into local missions by natural projection and proves
that they jointly satisfy it; :mod:`cosmop.automata` is the array-backed DFA library it
is built on.  See ``ARCHITECTURE.md`` for the data flow.
"""

__version__ = "0.1.0"
