"""Timed itineraries against the runs: how close the planned times are to the simulated ones.

Every example with a mission the planner handles is planned (``plan_team``) and simulated (seed
0, the default settings), and each step's planned duration and end (the plan set's itinerary)
is set beside the realised one (``SimResult.steps``).  Per example: the planned and realised
makespan and their ratio; per kind of step, the median ratio of realised to planned duration
(steps planned to last at least 0.5 s) and the median delay of the step's end::

    python benchmarks/bench_itinerary.py --out benchmarks/results/itinerary.json

The run is deterministic (Z3 seeded, people seeded), so one run is the measurement.
"""

from __future__ import annotations

import argparse
import json
import statistics
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = (
    "01_warehouse_2x2",
    "02_warehouse_10x10",
    "03_people_2x2",
    "04_doorway_2x2",
    "05_deliveries",
    "07_corridor",
    "08_ordered",
    "09_blocked_bay",
)
KINDS = {"GoTo": "GoTo", "PickUp": "handling", "DropOff": "handling", "Req": "Req", "Res": "Res"}


def measure(name: str) -> dict:
    from cosmop.scenario import load_scenario
    from cosmop.sim import simulate
    from cosmop.team.loop import plan_team

    scenario = load_scenario(ROOT / "examples" / name / "scenario.yaml")
    plans = plan_team(scenario).plans
    run = simulate(scenario, plans)
    ratios: dict[str, list[float]] = {}
    delays: dict[str, list[float]] = {}
    for rows in run.steps.values():
        for row in rows:
            if row.planned is None or row.realised is None:
                continue
            kind = KINDS[row.step.split("(")[0]]
            delays.setdefault(kind, []).append(row.delay)
            planned = row.planned[1] - row.planned[0]
            if planned >= 0.5:
                ratios.setdefault(kind, []).append((row.realised[1] - row.realised[0]) / planned)
    span = run.makespan
    return {
        "example": name,
        "robots": len(plans.robots),
        "people": len(scenario.scene.humans),
        "completed": run.completed,
        "replans": run.replans,
        "planned_s": span["planned"],
        "realised_s": span["realised"],
        "ratio": round(span["realised"] / span["planned"], 3)
        if span["realised"] and span["planned"]
        else None,
        "duration_ratio": {k: round(statistics.median(v), 3) for k, v in sorted(ratios.items())},
        "end_delay_s": {k: round(statistics.median(v), 2) for k, v in sorted(delays.items())},
        "steps": sum(len(v) for v in delays.values()),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, help="write the rows as JSON here")
    args = parser.parse_args()
    rows = []
    for name in EXAMPLES:
        row = measure(name)
        rows.append(row)
        print(
            f"{row['example']:<20} planned {row['planned_s']:7.1f} s  "
            f"realised {row['realised_s'] or 0:7.1f} s  "
            f"ratio {row['ratio']}  durations {row['duration_ratio']}  delays {row['end_delay_s']}",
            flush=True,
        )
    if args.out is not None:
        args.out.write_text(json.dumps(rows, indent=2) + "\n")


if __name__ == "__main__":
    main()
