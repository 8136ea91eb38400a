"""The library's stated contracts, enforced: documented parameters and no borrowed private names.

Every public function and public method of a public module documents each of its parameters in
a numpydoc ``Parameters`` section (python-control's ``docstrings_test.py`` is the model): a
reader of the reference never meets an argument the text does not explain.  No module imports a
private name (one with a leading underscore) of another module: what crosses a module's border
is its public surface.  The type checker (mypy, strict) runs beside this suite in CI.
"""

from __future__ import annotations

import ast
import importlib
import inspect
import pkgutil
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
from numpydoc.docscrape import FunctionDoc

import cosmop

SOURCE = Path(cosmop.__file__).resolve().parent


def _public_modules() -> Iterator[str]:
    for info in pkgutil.walk_packages(cosmop.__path__, "cosmop."):
        if not any(part.startswith("_") for part in info.name.split(".")[1:]):
            yield info.name


def _public_callables(module: Any) -> Iterator[tuple[str, Callable[..., Any]]]:
    """Functions defined in `module` and the methods its classes define, by qualified name."""
    for name, value in vars(module).items():
        if name.startswith("_") or getattr(value, "__module__", None) != module.__name__:
            continue
        if inspect.isfunction(value):
            yield f"{module.__name__}.{name}", value
        elif inspect.isclass(value):
            for attribute, member in vars(value).items():
                function = member.__func__ if isinstance(member, classmethod | staticmethod) else member
                if not attribute.startswith("_") and inspect.isfunction(function):
                    yield f"{module.__name__}.{name}.{attribute}", function


def _undocumented(function: Callable[..., Any]) -> list[str]:
    """The parameters of `function` (``self``/``cls`` aside) its Parameters section does not name."""
    wanted = [name for name in inspect.signature(function).parameters if name not in ("self", "cls")]
    if not wanted:
        return []
    documented: set[str] = set()
    for entry in FunctionDoc(function)["Parameters"]:
        documented.update(part.strip().lstrip("*") for part in entry.name.split(","))
    return [name for name in wanted if name not in documented]


@pytest.mark.parametrize("module_name", sorted(_public_modules()))
def test_every_parameter_is_documented(module_name: str) -> None:
    module = importlib.import_module(module_name)
    missing = {
        name: lacks for name, function in _public_callables(module) if (lacks := _undocumented(function))
    }
    assert not missing, "parameters missing from the numpydoc Parameters section:\n" + "\n".join(
        f"  {name}: {', '.join(lacks)}" for name, lacks in sorted(missing.items())
    )


def test_the_checker_flags_an_undocumented_parameter() -> None:
    def documented(width: float, *, height: float = 1.0) -> float:
        """Area.

        Parameters
        ----------
        width, height : float
            Sides, in metres.
        """
        return width * height

    def forgotten(width: float, height: float) -> float:
        """Area.

        Parameters
        ----------
        width : float
            One side, in metres.
        """
        return width * height

    assert _undocumented(documented) == []
    assert _undocumented(forgotten) == ["height"]


def _private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__")


_OWN = frozenset({"self", "cls", "os", "sys"})
"""Names whose underscore attributes are no other module's business (an object's own; the standard
library's documented ``os._exit``)."""


def _defined(tree: ast.AST) -> set[str]:
    """Every name `tree` defines: functions, classes, assigned names and attributes, fields."""
    names: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            names.add(node.name)
        elif isinstance(node, ast.Name | ast.Attribute) and isinstance(node.ctx, ast.Store):
            names.add(node.id if isinstance(node, ast.Name) else node.attr)
    return names


def _borrowed(node: ast.AST, own: set[str], lines: list[str]) -> bool:
    """Whether `node` is ``x._name`` with ``_name`` defined elsewhere (``# stdlib:`` marks the
    standard library's private parts, used where it offers no public way)."""
    return (
        isinstance(node, ast.Attribute)
        and _private(node.attr)
        and node.attr not in own
        and isinstance(node.value, ast.Name)
        and node.value.id not in _OWN
        and "# stdlib:" not in lines[node.lineno - 1]
    )


def _private_imports(path: Path) -> list[str]:
    """``line: name`` for each private name `path` takes from another cosmop module.

    An attribute ``x._name`` counts when this module does not define ``_name`` itself: a class may
    read the private state of another instance of itself, not of another module's objects.
    """
    text = path.read_text(encoding="utf-8")
    tree, lines = ast.parse(text), text.splitlines()
    own = _defined(tree)
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and (node.level or (node.module or "").startswith("cosmop")):
            found += [f"{node.lineno}: {node.module}.{a.name}" for a in node.names if _private(a.name)]
        elif _borrowed(node, own, lines):
            found.append(f"{node.lineno}: {ast.unparse(node)}")
    return found


def test_no_module_imports_another_modules_private_name() -> None:
    offenders = {
        str(path.relative_to(SOURCE)): lines
        for path in sorted(SOURCE.rglob("*.py"))
        if (lines := _private_imports(path))
    }
    assert not offenders, f"private names imported across modules: {offenders}"


def test_the_checker_flags_a_borrowed_private_name(tmp_path: Path) -> None:
    module = tmp_path / "borrower.py"
    module.write_text(
        "from cosmop.cli.simulate import _hidden\n"
        "class Own:\n"
        "    def __init__(self):\n"
        "        self._mine = 1\n"
        "    def same(self, other):\n"
        "        return other._mine + self._mine\n"
        "def reads(planner):\n"
        "    return planner._forbidden\n",
        encoding="utf-8",
    )
    assert _private_imports(module) == ["1: cosmop.cli.simulate._hidden", "8: planner._forbidden"]
