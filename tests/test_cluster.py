"""The syntheses on a Dask cluster: the same plans as in local processes, and clear refusals.

A ``LocalCluster`` of two worker processes (one thread each) stands in for a cluster of
machines; the planner reaches it by its scheduler's address, as a user's would.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

import cosmop._version
from cosmop.cli import app
from cosmop.scenario import load_scenario
from cosmop.team.cluster import ClusterError, dask_executor
from cosmop.team.loop import plan_team

distributed = pytest.importorskip("distributed")

ROOT = Path(__file__).resolve().parents[1]
SCENARIO = ROOT / "examples" / "01_warehouse_2x2" / "scenario.yaml"
runner = CliRunner()


@pytest.fixture(scope="module")
def cluster():
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
    ) as local:
        yield local


@pytest.fixture(scope="module")
def local_plans(tmp_path_factory):
    """The scenario planned here, in this process, and written as a user would."""
    target = tmp_path_factory.mktemp("local") / "plans.json"
    plan_team(load_scenario(SCENARIO), workers=1).plans.save(target)
    return {SCENARIO: target.read_bytes()}


def test_the_cluster_plans_exactly_what_local_processes_plan(cluster, local_plans, tmp_path):
    path = SCENARIO  # two robots, a request answered, conflicts ordered: two rounds of syntheses
    submitted = []
    with dask_executor(cluster.scheduler_address) as executor:

        class Counting:  # the cluster's executor, counting what it is given
            def submit(self, fn, *args):
                submitted.append(args[0].robot)
                return executor.submit(fn, *args)

        result = plan_team(load_scenario(path), executor=Counting())
    assert result.plans.feasible and result.report.ok
    assert set(submitted) == set(result.plans.robots)  # every robot was planned on the cluster
    target = tmp_path / "plans.json"
    result.plans.save(target)
    assert target.read_bytes() == local_plans[path]


def test_cosmop_plan_on_a_scheduler_writes_the_local_plan_file(cluster, local_plans, tmp_path):
    out = tmp_path / "plans.json"
    args = ["plan", str(SCENARIO), "-o", str(out), "--scheduler", cluster.scheduler_address]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    assert out.read_bytes() == local_plans[SCENARIO]


def test_local_worker_count_does_not_change_the_plan(local_plans, tmp_path):
    out = tmp_path / "plans.json"
    result = runner.invoke(app, ["plan", str(SCENARIO), "-o", str(out), "--workers", "2"])
    assert result.exit_code == 0, result.output
    assert out.read_bytes() == local_plans[SCENARIO]


def test_an_unreachable_scheduler_is_bad_input_and_nothing_is_written(monkeypatch, tmp_path):
    monkeypatch.setattr("cosmop.team.cluster.DEFAULT_TIMEOUT", 0.5)
    out = tmp_path / "plans.json"
    result = runner.invoke(app, ["plan", str(SCENARIO), "-o", str(out), "--scheduler", "tcp://127.0.0.1:9"])
    assert result.exit_code == 2
    assert "--scheduler: expected a Dask scheduler at tcp://127.0.0.1:9" in result.output
    assert "Traceback" not in result.output and not out.exists()


def test_workers_and_a_scheduler_exclude_each_other(tmp_path):
    out = tmp_path / "plans.json"
    args = ["plan", str(SCENARIO), "-o", str(out), "--workers", "2", "--scheduler", "tcp://127.0.0.1:9"]
    result = runner.invoke(app, args)
    assert result.exit_code == 2
    assert "--workers" in result.output and not out.exists()


def test_a_scheduler_without_workers_is_named():
    with (
        distributed.LocalCluster(n_workers=0, processes=False, dashboard_address=":0") as empty,
        pytest.raises(ClusterError, match="has no workers") as caught,
        dask_executor(empty.scheduler_address, timeout=0.5),
    ):
        pass
    assert f"dask worker {empty.scheduler_address}" in str(caught.value)


def test_workers_running_another_cosmop_are_refused(cluster, monkeypatch):
    # the workers are other processes: they report the installed version, not this one
    monkeypatch.setattr(cosmop._version, "__version__", "0.0.0-other")
    with (
        pytest.raises(ClusterError, match=r"must run cosmop 0\.0\.0-other; tcp://"),
        dask_executor(cluster.scheduler_address),
    ):
        pass


def test_without_dask_the_message_says_how_to_install_it(monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed -> ImportError
    with (
        pytest.raises(ClusterError, match=r"pip install 'cosmop\[cluster\]'"),
        dask_executor("tcp://127.0.0.1:9"),
    ):
        pass
