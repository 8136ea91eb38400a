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


def test_not_separable_is_ordered_by_messages(tmp_path):
    path = ordered_scenario(tmp_path)
    result = runner.invoke(app, ["decompose", str(path)], env={"COLUMNS": "200"})
    assert result.exit_code == 0, result.output
    assert "separable: no" in result.stdout
    assert "counterexample: pick(R2,O2)" in result.stdout
    assert "ordered by 1 message(s) instead of removing tasks" in result.stdout
    assert "R2 waits before pick(R2,O2) until R1 has done pick(R1,O1)" in result.stdout
    as_json = runner.invoke(app, ["decompose", str(path), "--json"])
    assert as_json.exit_code == 0
    data = json.loads(as_json.stdout)
    assert data["separable"] is False and data["counterexample"] == ["pick(R2,O2)"]
    assert data["resynthesis"] is None
    (message,) = data["messages"]
    assert message["sender"] == "R1" and message["receiver"] == "R2"
    assert (message["after"], message["before"]) == ("pick(R1,O1)", "pick(R2,O2)")
    assert data["coordinated_missions"]["R2"][0] == message["event"]
    assert data["verification"]["holds"] is True and data["verification"]["deadlock_free"] is True


def choice_scenario(tmp_path: Path) -> Path:
    """The 2x2 example whose global DFA lets either R1 or R2 move O1 to W1 (never both)."""
    data = yaml.safe_load(DFA_FILE.read_text())
    data["mission"] = {
        "dfa": {
            "initial": "q0",
            "marked": ["q2"],
            "transitions": [
                ["q0", "pick(R1,O1)", "q1"],
                ["q1", "drop(R1,O1,W1)", "q2"],
                ["q0", "pick(R2,O1)", "q3"],
                ["q3", "drop(R2,O1,W1)", "q2"],
            ],
        }
    }
    path = tmp_path / "choice.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def test_not_separable_and_not_orderable_exits_1_with_resynthesis(tmp_path):
    # a choice between robots: no order can make the robots agree on who moves O1, so the
    # paper's pruning runs and the verdict stays "not proven"
    result = runner.invoke(app, ["decompose", str(choice_scenario(tmp_path)), "--json"])
    assert result.exit_code == 1
    data = json.loads(result.stdout)
    assert data["separable"] is False and data["messages"] == []
    assert data["resynthesis"]["converged"] is True


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
