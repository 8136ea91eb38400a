"""Tasks-form missions at scale: decomposition and verification without the 4^N product.

For N robots with the sequences ``pick(Ri,Oi) drop(Ri,Oi,Wi) return(Ri)`` given in tasks form
(the global mission is their synchronous product, kept as factors), and for the same team
where every robot i > 1 must first be told by robot i-1 that object O(i-1) is away (a chain of
coordination events ``away(O(i-1),Ri,R(i-1))`` linking all robots), run
:func:`cosmop.missions.decomposition.decompose` and :func:`cosmop.missions.verification.verify`
and record time, the largest automaton ever built and peak memory.  Each run is a fresh
subprocess (peak RSS belongs to it alone).

Usage: ``python benchmarks/bench_tasks_form.py --sizes 10,20,50,100 [--out FILE]``
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent


def tasks(n: int, chained: bool) -> dict[str, list[str]]:
    """The N-robot tasks (with the coordination chain when ``chained``)."""
    out = {}
    for i in range(1, n + 1):
        seq = [f"pick(R{i},O{i})", f"drop(R{i},O{i},W{i})", f"return(R{i})"]
        if chained and i > 1:
            seq.insert(0, f"away(O{i - 1},R{i},R{i - 1})")  # Ri waits for R(i-1) ...
        if chained and i < n:
            seq.insert(
                seq.index(f"pick(R{i},O{i})") + 1, f"away(O{i},R{i + 1},R{i})"
            )  # ... who answers after its pick
        out[f"R{i}"] = seq
    return out


def job(n: int, chained: bool) -> dict:
    """Decompose and verify one mission; times in seconds."""
    from cosmop.missions.decomposition import decompose
    from cosmop.missions.mission import GlobalMission
    from cosmop.missions.verification import verify

    mission = GlobalMission.from_tasks(tasks(n, chained))
    t0 = time.perf_counter()
    result = decompose(mission)
    t1 = time.perf_counter()
    proof = verify(mission, result.local_missions)
    t2 = time.perf_counter()
    return {
        "n": n,
        "chained": chained,
        "decompose_s": t1 - t0,
        "verify_s": t2 - t1,
        "total_s": t2 - t0,
        "separable": result.separable,
        "holds": proof.holds,
        "method": proof.method,
        "largest_decompose": result.stats.largest_automaton,
        "largest_verify": proof.largest_automaton,
        "membership_queries": proof.membership_queries,
        "equivalence_queries": proof.equivalence_queries,
        "peak_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="10,20,50,100")
    parser.add_argument("--out", type=Path, default=HERE / "results" / "tasks_form.json")
    parser.add_argument("--child", nargs=2, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        print(json.dumps(job(int(args.child[0]), args.child[1] == "1")))
        return 0
    rows = []
    for chained in (False, True):
        for n in (int(s) for s in args.sizes.split(",")):
            proc = subprocess.run(
                [sys.executable, __file__, "--child", str(n), "1" if chained else "0"],
                capture_output=True,
                text=True,
                check=True,
                timeout=1800,
            )
            row = json.loads(proc.stdout)
            rows.append(row)
            print(
                f"N={n:4d} chained={chained!s:5} decompose {row['decompose_s']:7.3f} s  "
                f"verify {row['verify_s']:7.3f} s  "
                f"largest {row['largest_decompose']}/{row['largest_verify']} states  {row['method']:>16}  "
                f"mq {row['membership_queries']:6d}  peak {row['peak_mib']:.0f} MiB  holds={row['holds']}"
            )
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=args.out.parent, suffix=".tmp")
    with os.fdopen(fd, "w") as fh:
        json.dump({"date": time.strftime("%Y-%m-%d"), "runs": rows}, fh, indent=2)
    os.replace(tmp, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
