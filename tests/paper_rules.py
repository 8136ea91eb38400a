"""The paper's own handling rule, for tests that pin the paper's results.

The paper's robots pick up and drop off facing +x only: they stand on an object's west side.
cosmop lets them use any side an object allows (all four by default), which shortens some of
the paper's plans and removes some of its requests; a test that reproduces the paper's
coordination structure applies :func:`west_only` first.
"""

from __future__ import annotations

from dataclasses import replace

from cosmop.scene import Scenario


def west_only(scenario: Scenario) -> Scenario:
    """`scenario` with every object handled from its west side only (heading 0, the paper's)."""
    objects = {oid: replace(o, sides=("west",)) for oid, o in scenario.scene.objects.items()}
    return replace(scenario, scene=replace(scenario.scene, objects=objects))
