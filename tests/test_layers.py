"""The house has floors: every import in the library points down (or stays in its own package).

The layers are written out once, here; ARCHITECTURE.md describes them.  Imports inside
functions count too: a lazy import that runs back up is still an upward edge.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

SOURCE = Path(__file__).resolve().parent.parent / "src" / "cosmop"

LAYERS: tuple[frozenset[str], ...] = tuple(
    frozenset(floor.split())
    for floor in (
        "errors _frozen _version docking automata logic",  # foundations: no scene, no file formats
        "io reading squares events",  # reading and writing files; squares; the mission's events
        "scene",  # the value types of a scenario
        "units missions control",  # SI units; top-down decomposition; reactive control
        "traces maps planning",  # traces; grid maps; one robot's planning and its checker
        "team",  # what coordinates robots: conflicts, precedence, the team's checks and loop
        "scenario viz",  # the scenario loader (with its overlap checks); pictures
        "sim export",  # the simulator (its results draw); ROS 2 bags
        "lifelong",  # a fleet serving a stream of orders
        "cli",  # the command line
        "_entry",  # the program, with Ctrl-C answered while it starts
        "__main__",  # python -m cosmop
    )
)
"""Bottom first.  A unit is a top-level module or package of ``cosmop``."""


def _unit(module: str) -> str | None:
    parts = module.split(".")
    return parts[1] if parts[0] == "cosmop" and len(parts) > 1 else None


def _layer(unit: str) -> int:
    for depth, floor in enumerate(LAYERS):
        if unit in floor:
            return depth
    raise AssertionError(f"cosmop.{unit} is in no layer of tests/test_layers.py: add it to one")


def _imports(source: str, module: str) -> list[tuple[int, str]]:
    """``(line, module)`` of every ``cosmop`` import in `source` (the text of `module`), at any depth."""
    package = module.split(".")
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            found += [(node.lineno, alias.name) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:  # relative: resolve against the importing module's package
                base = package[: -node.level]
                name = ".".join([*base, node.module] if node.module else base)
            else:
                name = node.module or ""
            found.append((node.lineno, name))
            if name == "cosmop":  # ``from cosmop import x`` names the unit x itself
                found += [
                    (node.lineno, f"cosmop.{a.name}") for a in node.names if not a.name.startswith("__")
                ]
    return sorted((line, name) for line, name in found if name.startswith("cosmop."))


def _upward(source: str, module: str) -> list[str]:
    """The imports of `module` that reach a layer at or above its own, in another unit."""
    own = _unit(module)
    if own in (None, "__init__"):
        return []
    upward = []
    for line, name in _imports(source, module):
        target = _unit(name)
        if target not in (None, own) and _layer(target) >= _layer(own):
            upward.append(
                f"line {line}: {module} (layer {_layer(own)}) imports {name} (layer {_layer(target)})"
            )
    return upward


def _module(path: Path) -> str:
    return ".".join(("cosmop", *path.relative_to(SOURCE).with_suffix("").parts))


FILES = sorted(SOURCE.rglob("*.py"))


def test_every_unit_has_a_layer() -> None:
    units = {_unit(_module(p)) for p in FILES} - {None, "__init__"}
    for unit in sorted(units):
        _layer(unit)


@pytest.mark.parametrize("path", FILES, ids=lambda p: str(p.relative_to(SOURCE)))
def test_imports_point_down(path: Path) -> None:
    upward = _upward(path.read_text(encoding="utf-8"), _module(path))
    assert not upward, "\n".join(upward)


def test_an_upward_import_is_seen() -> None:
    """The rule is not vacuous: lazy, relative and package-level upward imports are all found."""
    source = (
        "from cosmop.scene import Scene\n"
        "def f():\n    from cosmop.sim import simulate\n"
        "from ..viz import plans\n"
        "from cosmop import cli\n"
    )
    found = _upward(source, "cosmop.planning.plan_types")
    assert [line.split(":")[0] for line in found] == ["line 3", "line 4", "line 5"]
    assert _upward(source, "cosmop.lifelong.fleet") == [
        "line 5: cosmop.lifelong.fleet (layer 8) imports cosmop.cli (layer 9)"
    ]
