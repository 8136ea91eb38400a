"""Hypothesis profiles for the test-suite.

``ci`` (the default) is derandomized, so every run draws the same examples, and keeps no
example database; ``dev`` draws fresh random examples and keeps the database.  Choose one
with ``HYPOTHESIS_PROFILE=dev pytest``.  Per-test budgets are set with ``@settings`` in the
test modules; a profile only fixes how examples are drawn.
"""

from __future__ import annotations

import os

from hypothesis import settings

settings.register_profile("ci", derandomize=True, database=None, deadline=None, print_blob=True)
settings.register_profile("dev", deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))
