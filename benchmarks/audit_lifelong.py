"""An audit of a lifelong run: does any hand-over leave two robots' committed plans unordered?

Every hand-over (and stall re-plan, and failure) replaces one robot's plan and orders it with
the rests the others have committed to; every re-ordering of a robot that waits long orders its
conflicts again.  This runs a stream (``orders_gen.py``: the MovingAI
warehouse, N robots, a Poisson stream) in-process and, around every accepted re-coordination,
applies the exact conflict rule to every robot's committed rest
(:func:`cosmop.sim.recoordinate.unordered_now`) before and after it.  A pair of robots with an
unordered conflict after and none before was broken by that re-coordination: it must never
happen.  Conflicts that were there before (a robot tracking its plan a few millimetres off its
line makes slivers of new overlap) are counted apart.  After each, every robot's rest as
installed is also checked by the exact single-robot checker (walls and resting goods), from the
start of its current step on its plan, with the goods where they are then: a rest cut on a line
nobody checked fails it.

The audit wraps the function the run calls to re-coordinate (instrumentation, not a feature),
and costs two looks at every conflict per hand-over: it is a check, not a timing.

``python benchmarks/audit_lifelong.py [--robots 20] [--rate 1500] [--until 600] [--seed 0]
[--segment MM] [--out NAME]`` prints a line per broken pair and a summary, and writes
``results/NAME.json``.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from collections import Counter

import cosmop.lifelong.fleet as fleet_module
import cosmop.sim.replan as replan_module
from _harness import save_results
from cosmop.lifelong import FleetSettings, run_fleet
from cosmop.scenario import parse_scenario
from cosmop.sim.recoordinate import recoordinate_world, reorder_world, unordered_now
from cosmop.sim.replan import rest_collisions
from orders_gen import orders_warehouse


def rests_failing(world) -> list[str]:
    """Why each robot's rest as installed fails the single-robot checker (walls, resting goods;
    :func:`cosmop.sim.replan.rest_collisions`), the first violation per robot."""
    first = {}
    for violation in rest_collisions(world):
        first.setdefault(violation.robot, violation.message)
    return list(first.values())


def audited(call, depth: float, report: dict) -> object:
    """`call` (`recoordinate_world` or `reorder_world`) with the audit around it, counting into
    `report`."""

    def pairs(world: object) -> dict[tuple[str, ...], float]:
        """Each unordered pair with its deepest overlap (mm, the smaller side of the box)."""
        out: dict[tuple[str, ...], float] = {}
        for c in unordered_now(world, depth):
            x0, y0, x1, y1 = c.place
            out[c.robots] = max(out.get(c.robots, 0.0), min(x1 - x0, y1 - y0))
        return out

    def wrapper(world, agent, *args, **kwargs):
        before = pairs(world)
        accepted, why, added = call(world, agent, *args, **kwargs)
        if accepted:
            after = pairs(world)
            broken = sorted(after.keys() - before.keys())
            report["audited"] += 1
            for why in rests_failing(world):
                report["rests_failing"].append({"t": round(world.t, 1), "replanned": agent.id, "why": why})
                print(f"  {world.t:7.1f} s: after {agent.id}'s new order, {why}")
            report["standing"] += len(after.keys() & before.keys())
            report["deepest_standing_mm"] = max(
                [report["deepest_standing_mm"], *(after[k] for k in after.keys() & before.keys())]
            )
            for robots in broken:
                report["broken"].append(
                    {
                        "t": round(world.t, 1),
                        "replanned": agent.id,
                        "pair": list(robots),
                        "mm": round(after[robots], 1),
                    }
                )
                print(f"  {world.t:7.1f} s: {agent.id}'s new order leaves {'/'.join(robots)} unordered")
        return accepted, why, added

    return wrapper


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", type=int, default=20)
    parser.add_argument("--rate", type=float, default=1500.0, help="orders per hour")
    parser.add_argument("--until", type=float, default=600.0, help="simulated seconds")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--segment", type=float, default=None, help="cut drives into pieces of MM")
    parser.add_argument("--depth", type=float, default=1.0, help="smallest overlap counted, mm")
    parser.add_argument("--out", default=None)
    args = parser.parse_args(argv)
    scenario = parse_scenario(orders_warehouse(args.robots, args.seed, args.rate, args.until / 3600.0 + 0.1))
    report: dict = {
        "audited": 0,
        "standing": 0,
        "deepest_standing_mm": 0.0,
        "broken": [],
        "rests_failing": [],
    }
    wrapper = audited(recoordinate_world, args.depth, report)
    fleet_module.recoordinate_world = wrapper
    replan_module.recoordinate_world = wrapper
    fleet_module.reorder_world = audited(reorder_world, args.depth, report)
    if args.segment is not None:
        settings = fleet_module.ConflictSettings
        fleet_module.ConflictSettings = lambda **kw: dataclasses.replace(settings(**kw), segment=args.segment)
    began = time.perf_counter()
    result = run_fleet(scenario, fleet=FleetSettings(until=args.until), seed=args.seed)
    reorders = result.summary()["reorders"]
    row = {
        "robots": args.robots,
        "rate": args.rate,
        "until": args.until,
        "seed": args.seed,
        "segment": args.segment,
        "depth_mm": args.depth,
        "delivered": result.delivered,
        "reorders_accepted": reorders["accepted"],
        "re_coordinations_audited": report["audited"],
        "pairs_broken": len(report["broken"]),
        "broken": report["broken"],
        "rests_failing_checker": len(report["rests_failing"]),
        "rests_failing": report["rests_failing"],
        "unordered_pairs_standing": report["standing"],
        "deepest_standing_mm": round(report["deepest_standing_mm"], 1),
        "wall_s": round(time.perf_counter() - began, 1),
    }
    by_robot = Counter(b["replanned"] for b in report["broken"])
    print(
        f"N={args.robots}, {args.until:g} s: {report['audited']} re-coordinations audited, "
        f"{len(report['broken'])} left a pair unordered ({dict(by_robot)}), "
        f"{report['standing']} unordered pairs already there "
        f"(deepest {report['deepest_standing_mm']:.1f} mm), "
        f"{len(report['rests_failing'])} rests failing the checker; "
        f"{result.delivered} delivered"
    )
    if args.out:
        print(save_results(args.out, [row]))
    return 1 if report["broken"] or report["rests_failing"] else 0


if __name__ == "__main__":
    sys.exit(main())
