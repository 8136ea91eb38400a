"""Two versions of cosmop side by side: the same workloads, fresh processes, alternating.

For a change meant to keep behaviour and speed (a restructuring), each workload runs in a new
Python process with ``PYTHONPATH`` set to one tree's ``src``, the two versions alternating run
by run so that the machine's load falls on both alike.  Each run reports the time of its timed
part (from :func:`time.perf_counter` inside the child) and the parent also times the whole
process.  The table gives medians and the ratio after / before, and the results file keeps
every run and a fingerprint of each run's output (the two versions must agree).

Workloads (the paper's 10×10 example unless named otherwise):

``synthesis``
    every robot's shortest plan, one after the other, in one process (`synthesize`);
``plan``
    `plan_team` end to end with its default worker processes;
``simulate``
    `simulate` of a plan file made once beforehand (ε = 0.1 s); also the real-time ratio;
``simulate_people``
    `simulate` of the 2×2 warehouse with people crossing (five seeds);
``simulate_crowd``
    300 cycles of the 50-robot warehouse of ``bench_sim.bay_drives`` (every robot driving at
    once, beside its neighbours: issue 13's stress case); also the real-time ratio;
``cli_simulate``
    ``python -m cosmop simulate`` of the 2×2 example with its plan, writing the trace and the
    summary: as a user runs it, process start included;
``cli_simulate_ten``
    the same for the paper's 10×10 with its plan: issue 13's row "as a user runs it";
``cli_validate``
    ``python -m cosmop validate`` of the 10×10 example (start-up and loading).

``python benchmarks/bench_sidebyside.py --before /path/to/old/src --repeats 3
--out benchmarks/results/restructure.json``
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
TEN = ROOT / "examples" / "02_warehouse_10x10" / "scenario.yaml"
TWO = ROOT / "examples" / "01_warehouse_2x2" / "scenario.yaml"
PEOPLE = ROOT / "examples" / "03_people_2x2" / "scenario.yaml"
WORKLOADS = (
    "synthesis",
    "plan",
    "simulate",
    "simulate_people",
    "simulate_crowd",
    "cli_simulate",
    "cli_simulate_ten",
    "cli_validate",
)


def _digest(data) -> str:
    return hashlib.sha256(json.dumps(data, sort_keys=True, default=str).encode()).hexdigest()[:16]


def _trace_json(result) -> dict:
    trace = result.trace()
    return trace.to_json() if hasattr(trace, "to_json") else trace


def child(workload: str, plans_dir: str) -> dict:
    """Run one workload in this process and return its timing and fingerprint."""
    from cosmop.scenario import load_scenario

    if workload == "synthesis":
        from cosmop.planning.synthesis import synthesize

        sc = load_scenario(TEN)
        t0 = time.perf_counter()
        results = [synthesize(sc.scene, r, tasks, max_horizon=12) for r, tasks in sc.mission.tasks.items()]
        seconds = time.perf_counter() - t0
        return {"s": seconds, "out": _digest([(r.horizon, list(r.requests)) for r in results])}
    if workload == "plan":
        from cosmop.team.loop import plan_team

        sc = load_scenario(TEN)
        t0 = time.perf_counter()
        plans = plan_team(sc).plans
        return {"s": time.perf_counter() - t0, "out": _digest(plans.to_dict())}
    from cosmop.planning.plan_file import load_plan
    from cosmop.sim import simulate

    if workload == "simulate":
        sc, plans = load_scenario(TEN), load_plan(Path(plans_dir) / "ten.json")
        t0 = time.perf_counter()
        result = simulate(sc, plans)
        seconds = time.perf_counter() - t0
        return {"s": seconds, "ratio": result.sim_time_s / seconds, "out": _digest(_trace_json(result))}
    if workload == "simulate_people":
        sc, plans = load_scenario(PEOPLE), load_plan(Path(plans_dir) / "people.json")
        t0 = time.perf_counter()
        results = [simulate(sc, plans, seed=seed) for seed in range(5)]
        seconds = time.perf_counter() - t0
        return {"s": seconds, "out": _digest([_trace_json(r) for r in results])}
    if workload == "simulate_crowd":
        sys.path.insert(0, str(HERE))
        from bench_sim import bay_drives
        from cosmop.sim import SimSettings

        sc, plans = bay_drives(50)
        t0 = time.perf_counter()
        result = simulate(sc, plans, settings=SimSettings(max_time=30.0, replan=False))
        seconds = time.perf_counter() - t0
        return {"s": seconds, "ratio": result.sim_time_s / seconds, "out": _digest(_trace_json(result))}
    raise ValueError(f"unknown workload {workload!r}")


def _cli(workload: str, plans_dir: Path, work: Path) -> list[str]:
    if workload.startswith("cli_simulate"):
        scenario, plan = (TEN, "ten.json") if workload == "cli_simulate_ten" else (TWO, "two.json")
        return [
            *("simulate", str(scenario), "--plan", str(plans_dir / plan)),
            *("--trace", str(work / "trace.json"), "--summary", str(work / "summary.json")),
        ]
    return ["validate", str(TEN)]


def run_once(src: str, workload: str, plans_dir: Path) -> dict:
    """One fresh process of `workload` with the tree `src`; the whole process is timed too."""
    env = dict(os.environ, PYTHONPATH=src)
    with tempfile.TemporaryDirectory() as work:
        if workload.startswith("cli_"):
            command = [sys.executable, "-m", "cosmop", *_cli(workload, plans_dir, Path(work))]
        else:
            command = [sys.executable, __file__, "--child", workload, "--plans", str(plans_dir)]
        t0 = time.perf_counter()
        done = subprocess.run(command, env=env, capture_output=True, text=True, check=False)
        process = time.perf_counter() - t0
        row = {"process_s": process, "returncode": done.returncode}
        if workload.startswith("cli_"):
            trace = Path(work) / "trace.json"
            row |= {
                "s": process,
                "out": hashlib.sha256(trace.read_bytes()).hexdigest()[:16] if trace.exists() else None,
            }
        elif done.returncode == 0:
            row |= json.loads(done.stdout.strip().splitlines()[-1])
        else:
            row["error"] = done.stderr[-2000:]
    return row


def make_plans(src: str, plans_dir: Path) -> None:
    """The plan files the simulation workloads execute, made once with the tree `src`."""
    code = (
        "import sys; from cosmop.scenario import load_scenario; from cosmop.team.loop import plan_team\n"
        "for path, name in zip(sys.argv[1::2], sys.argv[2::2]):\n"
        "    plan_team(load_scenario(path)).plans.save(name)\n"
    )
    args = [str(TEN), str(plans_dir / "ten.json"), str(PEOPLE), str(plans_dir / "people.json")]
    args += [str(TWO), str(plans_dir / "two.json")]
    subprocess.run([sys.executable, "-c", code, *args], env=dict(os.environ, PYTHONPATH=src), check=True)


def summarise(runs: dict[str, dict[str, list[dict]]]) -> list[dict]:
    rows = []
    for workload, sides in runs.items():
        med = {side: statistics.median(r["s"] for r in rs) for side, rs in sides.items()}
        proc = {side: statistics.median(r["process_s"] for r in rs) for side, rs in sides.items()}
        outs = {side: {r.get("out") for r in rs} for side, rs in sides.items()}
        rows.append(
            {
                "workload": workload,
                "before_s": med["before"],
                "after_s": med["after"],
                "ratio": med["after"] / med["before"],
                "process_ratio": proc["after"] / proc["before"],
                "same_output": outs["before"] == outs["after"] and len(outs["after"]) == 1,
            }
        )
    return rows


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", help="src folder of the version before")
    parser.add_argument("--after", default=str(ROOT / "src"), help="src folder of the version after")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--workloads", default=",".join(WORKLOADS))
    parser.add_argument("--out", type=Path, default=HERE / "results" / "sidebyside.json")
    parser.add_argument("--child", choices=WORKLOADS, help=argparse.SUPPRESS)
    parser.add_argument("--plans", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        print(json.dumps(child(args.child, args.plans)))
        return 0
    if not args.before:
        parser.error("--before is required")
    sides = {"before": args.before, "after": args.after}
    runs: dict[str, dict[str, list[dict]]] = {}
    with tempfile.TemporaryDirectory() as plans_dir:
        make_plans(args.after, Path(plans_dir))
        for workload in args.workloads.split(","):
            runs[workload] = {side: [] for side in sides}
            for repeat in range(args.repeats):
                for side, src in sides.items():
                    row = run_once(src, workload, Path(plans_dir))
                    runs[workload][side].append(row)
                    print(f"{workload} {side} #{repeat + 1}: {row.get('s', float('nan')):.3f} s", flush=True)
    table = summarise(runs)
    for row in table:
        print(
            f"{row['workload']:16} before {row['before_s']:8.3f} s  after {row['after_s']:8.3f} s  "
            f"ratio {row['ratio']:.3f}  (process {row['process_ratio']:.3f})  "
            f"same output: {row['same_output']}"
        )
    data = {
        "date": time.strftime("%Y-%m-%d"),
        "machine": {
            "cpus": os.cpu_count(),
            "python": platform.python_version(),
            "platform": platform.platform(),
        },
        "sides": sides,
        "repeats": args.repeats,
        "summary": table,
        "runs": runs,
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    tmp = args.out.with_suffix(".tmp")
    tmp.write_text(json.dumps(data, indent=2) + "\n")
    tmp.replace(args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
