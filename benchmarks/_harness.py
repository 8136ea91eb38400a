"""What the benchmark scripts share: a workload in a fresh subprocess, results saved atomically,
and the generators' scenario output."""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import yaml

RESULTS = Path(__file__).resolve().parent / "results"


def child_row(script: str, *args: str, timeout: float | None = None) -> dict:
    """Run ``python SCRIPT ARGS`` in a fresh process; its last line of output is a JSON row."""
    proc = subprocess.run(
        [sys.executable, script, *args], capture_output=True, text=True, check=True, timeout=timeout
    )
    return json.loads(proc.stdout.strip().splitlines()[-1])


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


def generator_main(doc: str, build, sizes: tuple[str, ...], argv: list[str] | None) -> int:
    """The command line of a scenario generator: ``SIZES... [--seed S] [-o FILE]``."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    for name in sizes:
        parser.add_argument(name, type=int)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("-o", "--output", type=Path)
    args = parser.parse_args(argv)
    emit_scenario(build(*(getattr(args, name) for name in sizes), args.seed), args.output)
    return 0
