"""``cosmop decompose``: tables, ``--json``, ``--dot``, exit statuses 0 / 1 / 2."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import yaml
from typer.testing import CliRunner

from cosmop.automata import DFA, equivalent, inverse_project, minimize, parallel, product
from cosmop.cli import app
from cosmop.missions.mission import GlobalMission
from cosmop.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[1]
TASKS_FILE = ROOT / "examples" / "01_warehouse_2x2" / "scenario.yaml"
DFA_FILE = ROOT / "examples" / "01_warehouse_2x2" / "scenario_dfa.yaml"

runner = CliRunner()


def ordered_scenario(tmp_path: Path) -> Path:
    """The 2x2 example whose global DFA requires R1 to pick before R2: not separable."""
    data = yaml.safe_load(DFA_FILE.read_text())
    k = GlobalMission.from_scenario(load_scenario(DFA_FILE)).automaton.components[0]
    order = DFA.from_transitions("a", [("a", "pick(R1,O1)", "b"), ("b", "pick(R2,O2)", "c")])
    data["mission"] = {"dfa": minimize(product(k, inverse_project(order, k.alphabet))).to_dict()}
    path = tmp_path / "ordered.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def test_table_output_for_the_paper_example():
    result = runner.invoke(app, ["decompose", str(DFA_FILE), "--verbose"])
    assert result.exit_code == 0, result.output
    out = result.stdout
    assert "pick(R1,O1) -> drop(R1,O1,W1) -> return(R1)" in out
    assert "pick(R2,O2) -> drop(R2,O2,W2) -> return(R2)" in out
    assert "separable: yes" in out
    assert "verification: holds (assume-guarantee" in out
    assert "assumption sizes 4" in out


def test_json_output_has_the_documented_shape():
    result = runner.invoke(app, ["decompose", str(TASKS_FILE), "--json"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    assert data["separable"] is True and data["counterexample"] is None
    r1 = data["local_missions"]["R1"]
    assert set(r1) >= {"initial", "transitions", "alphabet"}
    assert [t[1] for t in r1["transitions"]] == ["pick(R1,O1)", "drop(R1,O1,W1)", "return(R1)"]
    assert data["verification"]["holds"] is True
    for key in (
        "membership_queries",
        "equivalence_queries",
        "assumption_sizes",
        "largest_automaton",
        "time_s",
    ):
        assert key in data["verification"]
    # the local mission read back is the sequence automaton
    assert DFA.from_dict(r1).accepts(["pick(R1,O1)", "drop(R1,O1,W1)"])


def test_not_separable_exits_1_with_counterexample_and_resynthesis(tmp_path):
    path = ordered_scenario(tmp_path)
    result = runner.invoke(app, ["decompose", str(path)])
    assert result.exit_code == 1, result.output
    assert "separable: no" in result.stdout
    assert "counterexample: pick(R2,O2)" in result.stdout
    assert "re-synthesis: sound" in result.stdout
    as_json = runner.invoke(app, ["decompose", str(path), "--json"])
    assert as_json.exit_code == 1
    data = json.loads(as_json.stdout)
    assert data["separable"] is False and data["counterexample"] == ["pick(R2,O2)"]
    assert data["resynthesis"]["converged"] is True
    assert data["verification"]["holds"] is False


def test_dot_files_are_written(tmp_path):
    out = tmp_path / "dot"
    result = runner.invoke(app, ["decompose", str(TASKS_FILE), "--dot", str(out), "--method", "direct"])
    assert result.exit_code == 0, result.output
    text = (out / "R1.dot").read_text()
    assert text.startswith('digraph "K_R1"') and "pick(R1,O1)" in text
    assert sorted(p.name for p in out.iterdir()) == ["R1.dot", "R2.dot"]
    assert "verification: holds (direct" in result.stdout


def test_bad_input_exits_2_without_traceback(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text(TASKS_FILE.read_text().replace("pick O1", "pick O7"))
    proc = subprocess.run(
        [sys.executable, "-m", "cosmop", "decompose", str(bad), "--json"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr + proc.stdout
    assert str(bad) in proc.stderr and "mission.tasks.R1" in proc.stderr and "O7" in proc.stderr
    assert proc.stdout == ""


def test_explicit_product_of_local_missions_matches(tmp_path):
    # the verdict printed is the true one: ||K_i equals K for the paper's example
    data = json.loads(runner.invoke(app, ["decompose", str(DFA_FILE), "--json"]).stdout)
    locals_ = [DFA.from_dict(d) for d in data["local_missions"].values()]
    k = GlobalMission.from_scenario(load_scenario(DFA_FILE)).automaton.components[0]
    assert equivalent(parallel(*locals_), k)
