"""Blocked bays: do crates that no task names get moved aside, and what does it cost?  (issue 11)

For each team size and seed, the warehouse of ``bay_gen.py`` is planned and simulated twice,
as a user runs it (one ``cosmop plan`` and one ``cosmop simulate --plan`` process each): with
a crate in the mouth of 20% of the bays, and the same warehouse without crates.  A row records
the plan's verdict and wall time, the tasks the planner added, whether the run completed, the
drops it realised (every good, plus every crate set aside) and the contacts while moving.
Runs may take up to ``--max-time`` simulated seconds (3600: a team of 20 that takes turns needs
more than the simulator's default 900).  Writes ``results/sweep_blocked.json``.

Usage: ``python benchmarks/sweep_blocked.py [--sizes 10,20] [--seeds 0:2] [--crates 0.2]``.
"""

from __future__ import annotations

import argparse
import json
import statistics
import tempfile
from pathlib import Path

from _harness import plan_and_simulate, save_results
from bay_gen import bays


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="10,20")
    parser.add_argument("--seeds", default="0:2", help="first:last (exclusive)")
    parser.add_argument("--crates", type=float, default=0.2)
    parser.add_argument("--timeout", type=float, default=1800.0)
    parser.add_argument("--max-time", type=float, default=3600.0, help="simulated seconds allowed")
    args = parser.parse_args(argv)
    first, last = (int(v) for v in args.seeds.split(":"))
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for n in (int(v) for v in args.sizes.split(",")):
            for seed in range(first, last):
                for crates in (args.crates, 0.0):
                    data = bays(n, seed, crates)
                    row = {"robots": n, "seed": seed, "crates": round(crates * n)}
                    stem = Path(tmp) / data["name"]
                    rows.append(row | plan_and_simulate(data, stem, args.timeout, args.max_time))
                    print(json.dumps(rows[-1]), flush=True)
    save_results("sweep_blocked", rows)
    for n in sorted({r["robots"] for r in rows}):
        with_, without = (
            [r for r in rows if r["robots"] == n and bool(r["crates"]) == c] for c in (True, False)
        )
        done = sum(1 for r in with_ if r.get("completed"))
        ratio = statistics.median(a["plan_s"] / b["plan_s"] for a, b in zip(with_, without, strict=True))
        print(f"N={n}: {done}/{len(with_)} blocked warehouses completed; ", end="")
        print(f"plan time with/without crates {ratio:.2f}x (median)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
