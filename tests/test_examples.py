"""Every example runs: its scenarios load and its ``run.py`` exits 0."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from cosmop.scenario import load_scenario

EXAMPLES = sorted(p for p in (Path(__file__).resolve().parents[1] / "examples").iterdir() if p.is_dir())


def test_examples_are_numbered():
    assert EXAMPLES, "no examples found"
    for path in EXAMPLES:
        number, _, name = path.name.partition("_")
        assert number.isdigit() and len(number) == 2 and name, path.name


@pytest.mark.parametrize("scenario", [s for e in EXAMPLES for s in sorted(e.glob("*.yaml"))], ids=str)
def test_example_scenarios_load(scenario: Path):
    loaded = load_scenario(scenario)
    # a mission, or an order stream for a lifelong run (examples/13_lifelong)
    assert loaded.scene.robots and (loaded.mission.events if loaded.mission is not None else loaded.orders)


@pytest.mark.parametrize("script", [e / "run.py" for e in EXAMPLES if (e / "run.py").exists()], ids=str)
def test_example_scripts_run(script: Path):
    proc = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip()
    assert "True" in proc.stdout and "False" not in proc.stdout
