"""The team's expected makespan on many one-lane aisle warehouses, this code beside another checkout's.

A change to the conflict step moves every later choice of the planning loop (which robots are
re-planned, which ways around are kept), so its effect on one scene says little: this sweep
plans the aisle warehouses of ``aisle_gen.py`` for several sizes and seeds, each in a fresh
process, with this checkout's code and (``--before DIR``) with the code of another checkout
(its ``src`` put first on ``PYTHONPATH``), scene by scene in turn.

A row: ``n``, ``seed``, ``variant`` (``now`` or ``before``), ``feasible``, ``makespan`` (the
team's expected makespan, s), ``plan_s`` (wall time of :func:`cosmop.team.loop.plan_team`) and
``conflicts_s`` (its conflict step).  Writes ``results/NAME.json`` (default ``sweep_aisles``) and
prints, per scene, the two makespans, then how many scenes each variant planned sooner.

Usage: ``python benchmarks/sweep_aisles.py [--sizes 8,10,12,16,20] [--seeds 0:10] [--before DIR]
[--out NAME]``.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent


def _child(n: int, seed: int) -> None:
    sys.path.insert(0, str(HERE))
    from aisle_gen import aisle_warehouse
    from cosmop.scenario import parse_scenario
    from cosmop.team.loop import plan_team

    scenario = parse_scenario(aisle_warehouse(n, seed))
    t = time.perf_counter()
    team = plan_team(scenario, max_horizon=20)
    row = {
        "feasible": team.plans.feasible,
        "makespan": round(team.safety.makespan, 1) if team.safety else None,
        "plan_s": round(time.perf_counter() - t, 2),
        "conflicts_s": round(team.phases["conflicts"], 2),
    }
    print(json.dumps(row))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--child", nargs=2, type=int, help=argparse.SUPPRESS)
    parser.add_argument("--sizes", default="8,10,12,16,20")
    parser.add_argument("--seeds", default="0:10")
    parser.add_argument("--before", type=Path, help="another checkout, planned beside this one")
    parser.add_argument("--out", default="sweep_aisles")
    args = parser.parse_args(argv)
    if args.child:
        _child(*args.child)
        return 0
    from _harness import child_row, save_results

    low, high = (int(v) for v in args.seeds.split(":"))
    variants = {"now": {"PYTHONPATH": str(HERE.parent / "src")}}
    if args.before:
        variants["before"] = {"PYTHONPATH": str(args.before.resolve() / "src")}
    rows = []
    for n in (int(v) for v in args.sizes.split(",")):
        for seed in range(low, high):
            got = {}
            for variant, env in variants.items():
                row = child_row(__file__, "--child", str(n), str(seed), env=env)
                rows.append({"n": n, "seed": seed, "variant": variant, **row})
                got[variant] = row["makespan"]
            print(n, seed, "  ".join(f"{v} {m}" for v, m in got.items()), flush=True)
    path = save_results(args.out, rows)
    if args.before:
        pairs = [
            (a["makespan"], b["makespan"])
            for a in rows
            for b in rows
            if (a["n"], a["seed"], a["variant"], b["variant"]) == (b["n"], b["seed"], "now", "before")
            and a["makespan"] is not None
            and b["makespan"] is not None
        ]
        sooner = sum(now < before - 0.05 for now, before in pairs)
        later = sum(now > before + 0.05 for now, before in pairs)
        total = sum(now - before for now, before in pairs)
        print(f"{len(pairs)} scenes: {sooner} sooner now, {later} later, in all {total:+.1f} s")
    print(f"written to {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
