"""Every field of every public dataclass of the library is documented, and every option the
README's table of commands shows exists.

A field counts as documented when its class's docstring (or a base class's, for inherited
fields) lists it numpydoc-style (``name : type``, possibly with others, ``left, right : LinExpr``)
or names it in backquotes.
"""

from __future__ import annotations

import dataclasses
import importlib
import pkgutil
import re
from pathlib import Path

from typer.testing import CliRunner

import cosmop
from cosmop.cli import app

README = Path(__file__).resolve().parents[1] / "README.md"


def _public_dataclasses():
    for info in pkgutil.walk_packages(cosmop.__path__, "cosmop."):
        if info.name.endswith("__main__"):
            continue
        module = importlib.import_module(info.name)
        for name in getattr(module, "__all__", ()):
            obj = getattr(module, name, None)
            if isinstance(obj, type) and dataclasses.is_dataclass(obj) and obj.__module__ == module.__name__:
                yield obj


def _documented(cls: type, field: str) -> bool:
    entry = re.compile(rf"^\s*(\w+, )*{re.escape(field)}(, \w+)*\s*:", re.MULTILINE)
    for klass in cls.__mro__:
        doc = klass.__doc__ or ""
        if entry.search(doc) or f"`{field}`" in doc:
            return True
    return False


def test_every_public_dataclass_field_is_documented():
    classes = list(_public_dataclasses())
    assert len(classes) > 50  # the walk found the library
    missing = [
        f"{cls.__module__}.{cls.__qualname__}.{f.name}"
        for cls in classes
        for f in dataclasses.fields(cls)
        if not f.name.startswith("_") and not _documented(cls, f.name)
    ]
    assert not missing, "undocumented fields: " + ", ".join(missing)


def test_the_check_can_fail():
    @dataclasses.dataclass(frozen=True)
    class Point:
        """A point.

        Attributes
        ----------
        x : float
        """

        x: float
        y: float

    assert _documented(Point, "x") and not _documented(Point, "y")


def test_every_option_of_the_readme_command_table_exists():
    # a row of the README's table of commands: | `cosmop CMD ARGS [--option ...]` | ... |
    rows = re.findall(r"^\| `cosmop ([a-z-]+) ([^`]*)`", README.read_text(), re.MULTILINE)
    assert len(rows) >= 8  # the table was found
    runner = CliRunner()
    missing = []
    for command, usage in rows:
        shown = runner.invoke(app, [command, "--help"], terminal_width=400)
        assert shown.exit_code == 0, (command, shown.output)
        words = set(re.findall(r"--[a-z0-9-]+", shown.output))
        missing += [f"{command} {o}" for o in re.findall(r"--[a-z0-9-]+", usage) if o not in words]
    assert not missing, "options the README shows but the command lacks: " + ", ".join(missing)
