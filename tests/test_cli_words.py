"""The command line says what a verdict means first, the formal terms after, statistics with --verbose."""

from __future__ import annotations

import json
import types
from pathlib import Path

import pytest
from typer.testing import CliRunner

from cosmop.cli import app
from cosmop.cli.words import plan_verdict
from run_2x2 import run_2x2
from test_cli_decompose import choice_scenario, ordered_scenario

ROOT = Path(__file__).resolve().parents[1]
TASKS_FILE = ROOT / "examples" / "01_warehouse_2x2" / "scenario.yaml"
runner = CliRunner()


def _lines(text: str) -> list[str]:
    return [" ".join(line.split()) for line in " ".join(text.split("\n")).split("  ") if line.strip()]


def test_decompose_says_first_what_the_verdict_means():
    result = runner.invoke(app, ["decompose", str(TASKS_FILE)])
    assert result.exit_code == 0, result.output
    flat = " ".join(result.stdout.split())
    assert flat.startswith("The robots' missions together do exactly the team mission")
    assert flat.index("exactly the team mission") < flat.index("formally: separable: yes")
    assert "assumption sizes" not in flat and "membership" not in flat  # statistics: --verbose only
    verbose = " ".join(runner.invoke(app, ["decompose", str(TASKS_FILE), "--verbose"]).stdout.split())
    assert "assumption sizes" in verbose and "membership" in verbose


def test_a_mission_that_orders_robots_says_so_in_plain_words(tmp_path):
    result = runner.invoke(app, ["decompose", str(ordered_scenario(tmp_path))])
    assert result.exit_code == 0
    flat = " ".join(result.stdout.split())
    assert flat.startswith(
        "The robots' missions together do exactly the team mission once they tell each other"
    )
    assert "no task is dropped (proven)" in flat and "formally: separable: no" in flat


def test_a_mission_that_cannot_be_split_says_so_in_plain_words(tmp_path):
    result = runner.invoke(app, ["decompose", str(choice_scenario(tmp_path))])
    assert result.exit_code == 1
    flat = " ".join(result.stdout.split())
    assert flat.startswith("The team mission cannot be split into independent robot missions")
    assert "formally: separable: no" in flat


def test_dot_says_where_it_wrote(tmp_path):
    out = tmp_path / "dot"
    result = runner.invoke(app, ["decompose", str(TASKS_FILE), "--dot", str(out)])
    assert f"wrote the local missions as Graphviz DOT to {out}/: R1.dot, R2.dot" in " ".join(
        result.stdout.split()
    )
    as_json = runner.invoke(app, ["decompose", str(TASKS_FILE), "--dot", str(out), "--json"])
    json.loads(as_json.stdout)  # stdout stays one JSON object; the note goes to stderr
    assert f"DOT to {out}/" in as_json.stderr


def test_plan_verdict_in_words():
    _, plans, _ = run_2x2()
    holds = types.SimpleNamespace(holds=True)
    text = plan_verdict(plans, holds)
    assert text.startswith("Every robot has a safe plan; 1 hand-over")
    assert "no robot can wait forever" in text and "do exactly the team mission (proven)" in text
    assert "could not prove" in plan_verdict(plans, types.SimpleNamespace(holds=False))


@pytest.mark.parametrize(
    "command", ["validate", "decompose", "check", "plan", "simulate", "run", "import-map", "export", "view"]
)
def test_help_is_prose_for_the_user_not_the_docstrings_sections(command):
    result = CliRunner().invoke(app, [command, "--help"], env={"COLUMNS": "100"})
    assert result.exit_code == 0
    assert "Usage: cosmop" in result.output
    assert "----------" not in result.output  # no numpydoc section heading
    assert "``" not in result.output  # no reStructuredText literal marks
    assert "Options" in result.output


def test_command_help_cuts_the_sections_and_joins_each_paragraph():
    from cosmop.cli._app import command_help

    doc = """Do it.

        First line
        of a paragraph with ``code``.

        Parameters
        ----------
        x : int
            The x.
        """
    assert command_help(doc) == "Do it.\n\nFirst line of a paragraph with code."
