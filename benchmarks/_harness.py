"""What the benchmark scripts share: a workload in a fresh subprocess, results saved atomically,
and the generators' scenario output."""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import yaml

RESULTS = Path(__file__).resolve().parent / "results"


def child_row(script: str, *args: str, timeout: float | None = None, env: dict | None = None) -> dict:
    """Run ``python SCRIPT ARGS`` in a fresh process; its last line of output is a JSON row.

    `env` adds to the environment (e.g. ``PYTHONPATH`` to run an older checkout's code)."""
    proc = subprocess.run(
        [sys.executable, script, *args],
        capture_output=True,
        text=True,
        check=True,
        timeout=timeout,
        env={**os.environ, **env} if env else None,
    )
    return json.loads(proc.stdout.strip().splitlines()[-1])


def alternate(
    script: str, n: int | str, variants: tuple[str, ...], repeats: int, *args: str, timeout=None, env_of=None
) -> dict:
    """Side by side: `repeats` rounds of ``python SCRIPT --child N VARIANT ARGS``, one fresh
    process per variant in turn (so that the machine's drift hits every variant alike).
    ``env_of(variant)``, when given, is the environment a variant's process adds.

    Returns the rows in run order (each tagged with its ``variant``) and, per variant, the
    runs' rows, for :func:`median_of`.
    """
    rows = []
    for _ in range(repeats):
        for variant in variants:
            env = env_of(variant) if env_of else None
            row = child_row(script, "--child", str(n), variant, *args, timeout=timeout, env=env)
            rows.append({**row, "variant": variant})
    return {"rows": rows, "by": {v: [r for r in rows if r["variant"] == v] for v in variants}}


def median_of(runs: dict, key: str) -> dict[str, float]:
    """The median of `key` per variant of :func:`alternate`'s `runs`."""
    return {variant: statistics.median(r[key] for r in rows) for variant, rows in runs["by"].items()}


def save_results(name: str, rows: list[dict]) -> Path:
    """Write ``results/NAME.json`` (date, cores, rows) atomically."""
    RESULTS.mkdir(exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=RESULTS, suffix=".tmp")
    with os.fdopen(fd, "w") as fh:
        json.dump(
            {"date": time.strftime("%Y-%m-%d"), "cpu_count": os.cpu_count(), "runs": rows}, fh, indent=2
        )
    path = RESULTS / f"{name}.json"
    os.replace(tmp, path)
    return path


def emit_scenario(data: dict, output: Path | None) -> None:
    """A generated scenario as YAML, to `output` or to standard output."""
    text = yaml.safe_dump(data, sort_keys=False, default_flow_style=None)
    if output:
        output.write_text(text)
    else:
        sys.stdout.write(text)


def generator_main(doc: str, build, sizes: tuple[str, ...], argv: list[str] | None, *, map_text=None) -> int:
    """The command line of a scenario generator: ``SIZES... [--seed S] [-o FILE]``; with
    `map_text` (a function giving the text of the generator's map file), also ``--map FILE``,
    which writes that file instead of a scenario."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    for name in sizes:  # (not needed for the map file alone)
        parser.add_argument(name, type=int, nargs=None if map_text is None else "?")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("-o", "--output", type=Path)
    if map_text is not None:
        parser.add_argument("--map", type=Path, help="write the .map file here instead of a scenario")
    args = parser.parse_args(argv)
    if getattr(args, "map", None):
        args.map.write_text(map_text())
        return 0
    if any(getattr(args, name) is None for name in sizes):
        parser.error(f"the scenario needs {', '.join(sizes)}")
    emit_scenario(build(*(getattr(args, name) for name in sizes), args.seed), args.output)
    return 0


def plan_and_simulate(data: dict, stem: Path, timeout: float, max_time: float | None = None) -> dict:
    """Plan a scenario and simulate its plan as a user does: ``cosmop plan``, then ``cosmop
    simulate --plan``, one fresh process each; files at ``stem`` + suffix.

    The row: ``plan`` (feasible, infeasible, timeout, exit N), ``plan_s`` (wall seconds, process
    start and file writing included), ``added`` (tasks the planner added), and when feasible
    ``completed``, ``contacts_while_moving``, ``sim_time_s``, ``replans``, ``drops``, ``sim_s``,
    ``sim``.  `max_time` is the simulated seconds allowed (default: the simulator's).
    """
    path, plan, summary = (stem.with_name(stem.name + s) for s in (".yaml", "_plan.json", "_summary.json"))
    path.write_text(yaml.safe_dump(data, sort_keys=False, default_flow_style=None))
    cosmop = [sys.executable, "-m", "cosmop"]
    start = time.perf_counter()
    try:
        planned = subprocess.run(
            [*cosmop, "plan", str(path), "-o", str(plan)], capture_output=True, timeout=timeout
        )
    except subprocess.TimeoutExpired:
        return {"plan": "timeout", "plan_s": timeout}
    row = {"plan": {0: "feasible", 1: "infeasible"}.get(planned.returncode, f"exit {planned.returncode}")}
    row["plan_s"] = round(time.perf_counter() - start, 2)
    if plan.exists():
        row["added"] = len(json.loads(plan.read_text()).get("added", []))
    if planned.returncode != 0:
        return row
    start = time.perf_counter()
    try:
        sim = subprocess.run(
            [*cosmop, "simulate", str(path), "--plan", str(plan), "--summary", str(summary)]
            + ([] if max_time is None else ["--max-time", str(max_time)]),
            capture_output=True,
            timeout=timeout,
        )
    except subprocess.TimeoutExpired:
        return row | {"completed": False, "sim": "timeout"}
    row["sim_s"] = round(time.perf_counter() - start, 2)
    if not summary.exists():
        return row | {"completed": False, "sim": f"exit {sim.returncode}"}
    result = json.loads(summary.read_text())
    return row | {
        "completed": bool(result["completed"]),
        "contacts_while_moving": result["contacts_while_moving"],
        "sim_time_s": result["sim_time_s"],
        "replans": result["replans"],
        "drops": sum(1 for e in result["events"] if e["event"].startswith("drop(")),
        "sim": f"exit {sim.returncode}",
    }
