"""The simulator's cycle with and without the neighbourhood cut-off, side by side.

For each team size N, the generated warehouse of ``bench_sim.bay_drives`` (robots driving a
GoTo across their bay and back; plans built directly: only the local layer is timed) is
simulated for ``--cycles`` cycles of 0.1 s, once with the cut-off
(``SimSettings.neighbourhood``) and once without, in fresh processes, alternating, ``--repeats``
times.  Recorded: wall time per cycle (median), real-time factor (simulated / wall time),
contacts while moving, and a hash of the robots' poses in every frame, which must be the same
with and without the cut-off.

Usage: ``python benchmarks/bench_neighbourhood.py [--sizes 10,20,50,100] [--cycles 300] [--repeats 3]``.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
import time
from pathlib import Path

from _harness import alternate, median_of, save_results

HERE = Path(__file__).resolve().parent


def child(n: int, cycles: int, cut: bool) -> dict:
    sys.path.insert(0, str(HERE))
    from bench_sim import bay_drives
    from cosmop.sim import SimSettings, simulate

    scenario, plans = bay_drives(n)
    settings = SimSettings(max_time=cycles * 0.1, replan=False, neighbourhood=cut)
    t = time.perf_counter()
    result = simulate(scenario, plans, settings=settings)
    wall = time.perf_counter() - t
    return {
        "n": n,
        "cut_off": cut,
        "walls": len(scenario.scene.obstacles),
        "cycles": result.cycles,
        "ms_per_cycle": 1000 * wall / result.cycles,
        "real_time_factor": result.sim_time_s / wall,
        "contacts_while_moving": result.contacts_while_moving,
        "poses_sha256": hashlib.sha256(result.frames["pose"].tobytes()).hexdigest(),
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="10,20,50,100")
    parser.add_argument("--cycles", type=int, default=300)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--child", nargs=2, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        print(json.dumps(child(int(args.child[0]), args.cycles, args.child[1] == "on")))
        return 0
    rows, summary = [], []
    for n in (int(s) for s in args.sizes.split(",")):
        runs = alternate(__file__, n, ("on", "off"), args.repeats, "--cycles", str(args.cycles))
        rows += runs["rows"]
        med = median_of(runs, "ms_per_cycle")
        same = len({r["poses_sha256"] for r in runs["rows"]}) == 1
        row = {
            "n": n,
            "on_ms": med["on"],
            "off_ms": med["off"],
            "speed_up": med["off"] / med["on"],
            "same": same,
        }
        summary.append(row)
        print(
            f"N={n:3d}  cut-off {med['on']:7.1f} ms/cycle ({100 / med['on']:5.1f}x real time)  "
            f"without {med['off']:7.1f} ms/cycle ({100 / med['off']:5.1f}x)  speed-up {row['speed_up']:.2f}  "
            f"same poses: {same}",
            flush=True,
        )
    save_results("neighbourhood", [*rows, *({"summary": s} for s in summary)])
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
