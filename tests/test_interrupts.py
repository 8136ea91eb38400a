"""Ctrl-C at any moment: ``interrupted``, exit status 130, no traceback, no process left, nothing
half-written (issue 39, point 4).

A small seeded sample of the moments ``benchmarks/sweep_sigint.py`` sweeps (100 of them on the
MovingAI warehouse): each run is a fresh ``cosmop`` process in a process group of its own, and
SIGINT goes to the whole group, as a terminal's Ctrl-C does (the worker processes get it too).
"""

from __future__ import annotations

import json
import multiprocessing
import os
import random
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
from cosmop.scenario import load_scenario  # noqa: E402
from cosmop.team.loop import plan_team  # noqa: E402
from cosmop.team.planner import Workers  # noqa: E402
from sweep_sigint import commands, interrupt  # noqa: E402

pytestmark = pytest.mark.skipif(os.name != "posix", reason="process groups and SIGINT are POSIX's")

EXAMPLES = ROOT / "examples"
_RNG = random.Random(39)
MOMENTS = [_RNG.uniform(low, high) for low, high in ((0.2, 1.5), (1.5, 4.0), (4.0, 7.0))]
"""Seconds after the start, one while the command line loads (a second or two), two later,
while it plans or simulates (the 10x10 plans for 30 s and more; the runs below take 10 s and
more)."""
SIMULATE_MOMENTS = [_RNG.uniform(low, high) for low, high in ((0.2, 1.5), (1.5, 2.5), (2.5, 3.2))]
"""The same for ``simulate`` of the 2x2 with its plan given, which ends after about 4 s on an
idle machine: a later moment would find it done and test nothing."""


def _clean(row: dict) -> None:
    assert not row["finished"], "the run ended before its interrupt: nothing was tested"
    assert row["problems"] == [], f"{row['problems']}\n{row['stderr']}"


@pytest.mark.parametrize("at", MOMENTS, ids=lambda at: f"{at:.1f}s")
def test_ctrl_c_during_plan_with_png_ends_cleanly(tmp_path, at):
    command, outputs = commands(EXAMPLES / "02_warehouse_10x10" / "scenario.yaml", tmp_path, False)
    _clean(interrupt(command, outputs, at))


@pytest.fixture(scope="module")
def plan_2x2(tmp_path_factory) -> Path:
    scenario = EXAMPLES / "01_warehouse_2x2" / "scenario.yaml"
    path = tmp_path_factory.mktemp("plan") / "plan.json"
    plan_team(load_scenario(scenario), workers=1).plans.save(path)
    return path


@pytest.mark.parametrize("at", SIMULATE_MOMENTS, ids=lambda at: f"{at:.1f}s")
def test_ctrl_c_during_simulate_with_gif_ends_cleanly(tmp_path, plan_2x2, at):
    command, outputs = commands(EXAMPLES / "01_warehouse_2x2" / "scenario.yaml", tmp_path, True)
    _clean(interrupt([*command, "--plan", str(plan_2x2)], outputs, at))


@pytest.mark.parametrize("second", [0.2, 0.01])
def test_a_second_ctrl_c_ends_at_once_and_cleanly(tmp_path, second):
    # the 10x10 with its two workers, the case of issue 39: cosmop and its workers were left running
    command, outputs = commands(EXAMPLES / "02_warehouse_10x10" / "scenario.yaml", tmp_path, False)
    row = interrupt(command, outputs, 4.0, second=second)
    _clean(row)
    assert row["latency_s"] < 10


def _sleep(seconds: float) -> float:
    time.sleep(seconds)
    return seconds


def test_stopping_the_workers_ends_a_running_synthesis_at_once():
    pool = Workers(2)
    futures = [pool.submit(_sleep, 60.0) for _ in range(3)]  # two run, one waits
    workers, manager = list(pool._processes.values()), pool._executor_manager_thread
    time.sleep(0.5)
    start = time.perf_counter()
    pool.stop()
    assert time.perf_counter() - start < 10
    assert not any(w.is_alive() for w in workers) and not manager.is_alive()
    assert all(f.done() for f in futures)


def test_an_interrupt_inside_the_planner_leaves_no_worker_and_no_thread():
    # the interrupt comes in the progress callback, after the first synthesis, while the other
    # robots' still run in the workers (which the planner used to leave running)
    scenario = load_scenario(EXAMPLES / "02_warehouse_10x10" / "scenario.yaml")
    threads = set(threading.enumerate())

    def interrupted(robot, result):
        raise KeyboardInterrupt

    start = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        plan_team(scenario, workers=2, on_robot=interrupted)
    assert time.perf_counter() - start < 60
    assert multiprocessing.active_children() == []
    assert set(threading.enumerate()) <= threads


@pytest.mark.parametrize("at", MOMENTS[1:], ids=lambda at: f"{at:.1f}s")
def test_ctrl_c_during_a_lifelong_run_writes_what_was_delivered_so_far(tmp_path, at):
    # issue 37: "interrupted", 130, and the summary of the run so far written whole, also when
    # Ctrl-C comes inside a hand-over's call to Z3 (it is answered at the next cycle)
    summary, trace = tmp_path / "summary.json", tmp_path / "trace.json"
    scenario = EXAMPLES / "13_lifelong" / "scenario.yaml"
    command = [sys.executable, "-m", "cosmop", "run", str(scenario), "--until", "1000000"]
    row = interrupt([*command, "--summary", str(summary), "--trace", str(trace)], [summary, trace], at)
    _clean(row)
    data = json.loads(summary.read_text())
    assert data["interrupted"] is True and 0 < data["until_s"] < 1_000_000
    assert data["orders"]["released"] == sum(o["at"] <= data["until_s"] for o in data["order_log"])
    assert json.loads(trace.read_text())["frames"]  # the trace of the same run so far


def test_a_finaliser_that_fails_after_a_ctrl_c_is_not_shown():
    # a Ctrl-C that lands while an object is built (a Z3 context, seen in a run) leaves it half
    # built; its finaliser fails as the program unwinds, and only "interrupted" is said
    code = (
        "import os, signal, time, cosmop.cli, cosmop._entry as entry\n"
        "class HalfBuilt:\n"
        "    def __init__(self):\n"
        "        os.kill(os.getpid(), signal.SIGINT)\n"
        "        time.sleep(20)\n"
        "        self.owner = True\n"
        "    def __del__(self):\n"
        "        self.owner\n"
        "def main():\n"
        "    HalfBuilt()\n"
        "cosmop.cli.main = main\n"
        "entry.run()\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        timeout=60,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),  # as from a terminal
    )
    assert (done.returncode, done.stderr) == (130, "interrupted\n")


def test_a_ctrl_c_python_had_to_swallow_still_ends_the_program():
    # a KeyboardInterrupt raised in a finaliser cannot propagate (Python prints "Exception
    # ignored" and goes on); the program ends as a second Ctrl-C would, without a traceback
    code = (
        "import time, cosmop.cli, cosmop._entry as entry\n"
        "class Finaliser:\n"
        "    def __del__(self):\n"
        "        raise KeyboardInterrupt\n"
        "def main():\n"
        "    Finaliser()\n"
        "    time.sleep(20)\n"
        "cosmop.cli.main = main\n"
        "entry.run()\n"
    )
    start = time.perf_counter()
    done = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        timeout=60,
        # a terminal's Ctrl-C: the program's default handler (a suite run in the background
        # hands its children SIGINT ignored, and the program rightly leaves that alone)
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    assert (done.returncode, done.stderr) == (130, "interrupted\n")
    assert time.perf_counter() - start < 15
