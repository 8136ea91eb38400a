"""Ctrl-C at random moments: does ``cosmop`` always end cleanly?  (issue 39, point 4)

A terminal's Ctrl-C sends SIGINT to every process of the foreground job.  This sweep starts a
``cosmop`` command in a session of its own (its own process group, as a terminal's job), sends
SIGINT to the group at a random moment (seeded), optionally a second one a moment later, and
checks the answer: exit status 130, standard error exactly ``interrupted`` (no traceback, no
``Exception ignored``), no process of the group left, and no output half-written (every output
file either absent or complete, no staging folder beside them).  Moments are drawn uniformly
over the command's uninterrupted run time (measured first, or ``--duration``), so every phase
is hit in proportion to its length: loading, planning with the worker processes, drawing the
PNG, writing.  They start at 0.1 s: before, Python itself is starting, and Ctrl-C is Python's.

Usage::

    python benchmarks/sweep_sigint.py [--scene movingai|10x10|FILE] [--count 100] [--seed 0]
                                      [--second 0.2] [--duration S] [--simulate]

``--scene movingai`` (default) is the MovingAI warehouse of ``movingai_gen.py`` with 12 robots
fetching 12 goods; ``--simulate`` interrupts ``cosmop simulate --gif`` instead of ``cosmop plan
--png``.  Writes ``results/sweep_sigint.json`` (``_simulate``, ``_double`` added to the name
with those options); prints one row per interrupt and the count of clean ones.
:func:`interrupt` is also what ``tests/test_interrupts.py`` runs.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import yaml

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def _group_members(group: int) -> list[int]:
    """The live processes (zombies aside) of process group `group` (psutil if installed, else /proc)."""
    try:
        import psutil
    except ImportError:
        psutil = None
    members = []
    if psutil is not None:
        for process in psutil.process_iter():
            try:
                if os.getpgid(process.pid) == group and process.status() != psutil.STATUS_ZOMBIE:
                    members.append(process.pid)
            except (OSError, psutil.Error):  # ended meanwhile
                continue
        return members
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            stat = Path(f"/proc/{entry}/stat").read_text()
        except OSError:  # ended meanwhile
            continue
        # pid (comm) state ppid pgrp ...: comm may hold spaces and parentheses, so split after it
        fields = stat[stat.rindex(")") + 2 :].split()
        if int(fields[2]) == group and fields[0] != "Z":
            members.append(int(entry))
    return members


def complete(path: Path) -> bool:
    """Whether an output file is whole: JSON that parses, a PNG to its IEND, a GIF to its trailer."""
    data = path.read_bytes()
    if path.suffix == ".json":
        try:
            json.loads(data)
        except ValueError:
            return False
        return True
    if path.suffix == ".png":
        return data.startswith(b"\x89PNG\r\n\x1a\n") and data.endswith(b"IEND\xaeB`\x82")
    if path.suffix == ".gif":
        return data.startswith(b"GIF8") and data.endswith(b";")
    if path.suffix == ".html":
        return data.rstrip().endswith(b"</html>")
    return True


def interrupt(
    command: list[str],
    outputs: list[Path],
    at: float,
    *,
    second: float | None = None,
    timeout: float = 60.0,
    env: dict[str, str] | None = None,
) -> dict:
    """Run `command`, send SIGINT to its process group `at` seconds after the start (and again
    `second` seconds later), and check how it ended.

    Returns a row: ``at_s``, ``status`` (the exit status), ``latency_s`` (seconds from the first
    SIGINT to the exit), ``finished`` (it had ended before the moment: not an interrupt; then
    ``run_s`` is its run time), ``stderr`` and ``problems`` (empty when the end was clean).
    """
    for path in outputs:
        path.unlink(missing_ok=True)
    proc = subprocess.Popen(
        command,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
        start_new_session=True,  # its own process group, as a terminal's job
        # a terminal's Ctrl-C: the program's default handler (a background runner may ignore it)
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    start = time.perf_counter()
    try:
        proc.wait(timeout=at)
        finished = True  # before the moment: no interrupt (its run time says how fast runs are now)
    except subprocess.TimeoutExpired:
        finished = False
    sent = time.perf_counter()
    if not finished:
        os.killpg(proc.pid, signal.SIGINT)
        if second is not None:
            time.sleep(second)
            if proc.poll() is None:
                os.killpg(proc.pid, signal.SIGINT)
    problems = []
    try:
        _, err = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        problems.append(f"still running {timeout:g} s after the interrupt")
        os.killpg(proc.pid, signal.SIGKILL)
        _, err = proc.communicate()
    latency = time.perf_counter() - sent
    deadline = time.perf_counter() + 5.0  # killed children take a moment to die
    while (left := _group_members(proc.pid)) and time.perf_counter() < deadline:
        time.sleep(0.05)
    if left:
        problems.append(f"processes left: {left}")
        for pid in left:
            os.kill(pid, signal.SIGKILL)
    if not finished:
        if proc.returncode != 130:
            problems.append(f"exit status {proc.returncode}")
        lines = [line for line in err.splitlines() if line.strip()]
        if lines != ["interrupted"]:
            problems.append("standard error: " + " | ".join(lines[-6:]))
    for path in outputs:
        if path.exists() and not complete(path):
            problems.append(f"{path.name} half-written")
    for folder in {path.parent for path in outputs}:
        staging = [p.name for p in folder.iterdir() if p.name.startswith(".") and p.name.endswith(".tmp")]
        if staging:
            problems.append(f"staging left: {staging}")
    return {
        "at_s": round(at, 3) if not finished else None,
        "run_s": round(sent - start, 3) if finished else None,
        "status": proc.returncode,
        "latency_s": round(latency, 3),
        "finished": finished,
        "problems": problems,
        "stderr": err[-2000:],
    }


def movingai_scene(folder: Path, robots: int = 12) -> Path:
    """The MovingAI warehouse of ``movingai_gen.py`` with `robots` robots, each fetching one good."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from movingai_gen import movingai_warehouse

    path = folder / f"movingai-{robots}.yaml"
    path.write_text(yaml.safe_dump(movingai_warehouse(robots, seed=0), sort_keys=False))
    return path


def commands(scene: Path, folder: Path, simulate: bool) -> tuple[list[str], list[Path]]:
    """The command to interrupt and its outputs."""
    cosmop = [sys.executable, "-m", "cosmop"]
    if simulate:
        outputs = [folder / "summary.json", folder / "trace.json", folder / "run.gif"]
        args = ["simulate", str(scene), "--summary", str(outputs[0]), "--trace", str(outputs[1])]
        return [*cosmop, *args, "--gif", str(outputs[2])], outputs
    outputs = [folder / "plan.json", folder / "plan.png"]
    return [*cosmop, "plan", str(scene), "-o", str(outputs[0]), "--png", str(outputs[1])], outputs


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default="movingai", help="movingai, 10x10, or a scenario file")
    parser.add_argument("--count", type=int, default=100)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--second", type=float, help="send a second SIGINT this many seconds later")
    parser.add_argument("--duration", type=float, help="the uninterrupted run time (else measured)")
    parser.add_argument("--simulate", action="store_true", help="interrupt simulate --gif, not plan --png")
    parser.add_argument("--timeout", type=float, default=60.0, help="seconds an interrupted run may take")
    args = parser.parse_args(argv)
    rng = random.Random(args.seed)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        scene = {
            "movingai": lambda: movingai_scene(folder),
            "10x10": lambda: EXAMPLES / "02_warehouse_10x10" / "scenario.yaml",
        }.get(args.scene, lambda: Path(args.scene))()
        command, outputs = commands(scene, folder, args.simulate)
        duration = args.duration
        if duration is None:
            start = time.perf_counter()
            subprocess.run(command, capture_output=True, check=False)
            duration = time.perf_counter() - start
            print(f"uninterrupted run: {duration:.1f} s", flush=True)
        # a run that ends before its moment is no interrupt: draw again, with its run time as the
        # duration (the machine's speed varies), until `count` interrupts are sent
        while sum(1 for r in rows if not r["finished"]) < args.count and len(rows) < 3 * args.count:
            row = interrupt(command, outputs, rng.uniform(0.1, duration), second=args.second)
            row["try"] = len(rows)
            rows.append(row)
            duration = row["run_s"] or duration
            print(json.dumps({key: v for key, v in row.items() if key != "stderr"}), flush=True)
    from _harness import save_results

    name = "sweep_sigint" + ("_simulate" if args.simulate else "") + ("_double" if args.second else "")
    save_results(name, rows)
    interrupted = [r for r in rows if not r["finished"]]
    clean = sum(1 for r in interrupted if not r["problems"])
    latencies = sorted(r["latency_s"] for r in interrupted)
    print(
        f"{clean} of {len(interrupted)} interrupts clean ({len(rows) - len(interrupted)} runs ended "
        f"before their SIGINT); exit after the SIGINT: median {latencies[len(latencies) // 2]:.2f} s, "
        f"longest {latencies[-1]:.2f} s"
        if latencies
        else "no run was interrupted"
    )
    return 0 if clean == len(interrupted) else 1


if __name__ == "__main__":
    raise SystemExit(main())
