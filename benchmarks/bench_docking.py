"""Docking from any side: shortest K, requests and synthesis time per robot of the examples.

Every robot of every example whose mission is a task list is planned alone (shortest K, fewest
requests), as the pipeline's first pass does, and its plan is checked with the exact checker.
Run it once with the version under test and once with an older checkout on ``PYTHONPATH`` to
compare (the script uses only ``synthesize`` and ``check_robot_plan``, which both have)::

    python benchmarks/bench_docking.py --repeats 3 --out after.json
    PYTHONPATH=/tmp/before/src python benchmarks/bench_docking.py --repeats 3 --out before.json
    python benchmarks/bench_docking.py --compare before.json after.json

Times are medians of ``--repeats`` runs in one process (Z3 seeded, so K and requests are the
same every run).
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ("01_warehouse_2x2", "02_warehouse_10x10", "04_doorway_2x2", "07_corridor")


def measure(repeats: int) -> list[dict]:
    from cosmop.planning.checker import check_robot_plan
    from cosmop.planning.synthesis import synthesize
    from cosmop.scenario import load_scenario

    rows = []
    for name in EXAMPLES:
        scenario = load_scenario(ROOT / "examples" / name / "scenario.yaml")
        for robot, tasks in scenario.mission.tasks.items():
            times, result = [], None
            for _ in range(repeats):
                t = time.perf_counter()
                result = synthesize(scenario.scene, robot, tasks, max_horizon=16)
                times.append(time.perf_counter() - t)
            sound = result.feasible and check_robot_plan(scenario.scene, robot, result.plan) == []
            headings = sorted(
                {round(s.robot[2]) % 360 for s in result.plan.steps if s.primitive in ("PickUp", "DropOff")}
                if result.feasible
                else set()
            )
            rows.append(
                {
                    "example": name,
                    "robot": robot,
                    "feasible": result.feasible,
                    "checked": sound,
                    "K": result.horizon if result.feasible else None,
                    "requests": list(result.requests) if result.feasible else [],
                    "docking_headings": headings,
                    "s": statistics.median(times),
                }
            )
    return rows


def compare(before: list[dict], after: list[dict]) -> str:
    old = {(r["example"], r["robot"]): r for r in before}
    lines = [
        "| example | robot | K before → after | requests before → after | headings used "
        "| time before → after |",
        "|---|---|---|---|---|---|",
    ]
    totals = {}
    for r in after:
        b = old[(r["example"], r["robot"])]
        req = lambda x: ", ".join(x["requests"]) or "–"  # noqa: E731
        lines.append(
            f"| {r['example']} | {r['robot']} | {b['K']} → {r['K']} | {req(b)} → {req(r)} | "
            f"{', '.join(map(str, r['docking_headings'])) or '–'} | {b['s']:.2f} s → {r['s']:.2f} s |"
        )
        t = totals.setdefault(r["example"], [0.0, 0.0])
        t[0] += b["s"]
        t[1] += r["s"]
    for example, (b, a) in totals.items():
        lines.append(f"| **{example}** | all | | | | {b:.2f} s → {a:.2f} s ({a / b:.2f}×) |")
    return "\n".join(lines)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--out", type=Path)
    parser.add_argument("--compare", nargs=2, type=Path, metavar=("BEFORE", "AFTER"))
    args = parser.parse_args()
    if args.compare:
        before, after = (json.loads(p.read_text()) for p in args.compare)
        print(compare(before, after))
        return 0
    rows = measure(args.repeats)
    text = json.dumps(rows, indent=1)
    if args.out:
        args.out.write_text(text + "\n")
    print(text)
    return 0 if all(r["checked"] or not r["feasible"] for r in rows) else 1


if __name__ == "__main__":
    raise SystemExit(main())
