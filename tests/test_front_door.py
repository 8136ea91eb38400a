"""``import cosmop``: the front door (load, plan, simulate, check, the result types, run.plot())."""

from __future__ import annotations

import subprocess
import sys

import pytest

import cosmop
from run_2x2 import EXAMPLE


def test_import_cosmop_loads_nothing_until_a_verb_is_used():
    code = "import sys, cosmop; print(sorted(m for m in sys.modules if m.startswith('cosmop.')))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    # only the one-line module that holds the version, which every layer may read
    assert out.strip() == "['cosmop._version']"


def test_the_result_types_are_the_layers_own():
    from cosmop.planning.plan_types import PlanSet
    from cosmop.planning.report import CheckReport
    from cosmop.scene import Scenario
    from cosmop.sim import SimResult
    from cosmop.team.loop import TeamResult

    assert (cosmop.PlanSet, cosmop.Scenario, cosmop.SimResult) == (PlanSet, Scenario, SimResult)
    assert (cosmop.TeamResult, cosmop.CheckReport) == (TeamResult, CheckReport)
    assert set(cosmop.__all__) >= {"load", "plan", "simulate", "check", "PlanSet", "SimResult"}
    with pytest.raises(AttributeError, match="no attribute 'Planner'"):
        _ = cosmop.Planner


def test_a_script_reads_load_plan_simulate_plot():
    pytest.importorskip("matplotlib")
    scn = cosmop.load(EXAMPLE)
    plans = cosmop.plan(scn, workers=1)
    assert isinstance(plans, cosmop.PlanSet) and plans.feasible
    assert cosmop.check(scn, plans).ok
    run = cosmop.simulate(scn, plans)
    assert run.completed and run.contacts_while_moving == 0
    fig = run.plot()  # the end of the run
    ax = fig.axes[0]
    assert ax.get_title().startswith(f"{scn.name}    t = {run.sim_time_s:.1f} s")
    first = run.plot(0)
    assert first.axes[0].get_title().endswith("t = 0.0 s")


def test_plot_needs_the_scene():
    from dataclasses import replace

    from run_2x2 import run_2x2

    _, _, result = run_2x2()
    with pytest.raises(ValueError, match="no scene to draw"):
        replace(result, scene=None).plot()
