"""Lifelong runs on seeds nobody tuned to: every delivery as ordered, nothing lost, no contact.

Each seed draws a stream of orders on the small warehouse of ``examples/13_lifelong`` (the
goods in random order, each released after an exponential gap of mean ``--gap`` seconds, to
one dock or a choice of two, now and then only for some robots) and a robot failing for good
at a random time; the run lasts ``--until`` simulated seconds.  Each row says what was
delivered, what was lost and why, what is still pending and why, whether every delivery's
events are a word of its order's delivery mission, and the contacts while moving.  A lost order
is one the failed robot carried; anything else lost, a delivery not as ordered or a contact
while moving is a failure of the sweep (exit 1).

    python benchmarks/sweep_lifelong.py --seeds 0:20 [--until 600] [--scene FILE] [--out NAME]

``--scene`` takes the scene (robots, goods, docks) of any scenario file instead of the
example's; its mission or orders are not used.

Raw rows go to ``results/NAME.json`` (default ``sweep_lifelong``).
"""

from __future__ import annotations

import argparse
import random
import time
from pathlib import Path

from _harness import save_results
from cosmop.lifelong import Failure, FleetSettings, run_fleet
from cosmop.scenario import load_scenario
from cosmop.scene import Order, Scenario

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "13_lifelong" / "scenario.yaml"


def draw(scenario: Scenario, seed: int, until: float, gap: float) -> tuple[list[Order], Failure]:
    """A seeded stream of orders on `scenario`'s goods and docks, and a robot failing."""
    rng = random.Random(seed)
    goods = list(scenario.scene.objects)
    rng.shuffle(goods)
    docks, robots = sorted(scenario.scene.workspaces), sorted(scenario.scene.robots)
    orders, at = [], 0.0
    for obj in goods:
        if at > until:
            break
        to = tuple(rng.sample(docks, rng.choice((1, 1, 2))))
        by = tuple(sorted(rng.sample(robots, 2))) if rng.random() < 0.15 else tuple(robots)
        orders.append(Order(round(at, 1), obj, to, by))
        at += rng.expovariate(1.0 / gap)
    failure = Failure(rng.choice(robots), round(rng.uniform(60.0, until - 100.0), 1))
    return orders, failure


def run_one(scenario: Scenario, seed: int, until: float, gap: float) -> dict:
    """One seed's run, as a row."""
    orders, failure = draw(scenario, seed, until, gap)
    t0 = time.perf_counter()
    result = run_fleet(scenario, orders, fleet=FleetSettings(until=until), failures=[failure])
    carried = set(result.failures[failure.robot]["carrying"])
    lost = [o for o in result.orders if o.lost is not None]
    pending = [o for o in result.orders if o.at <= result.until and o.delivered is None and o.lost is None]
    return {
        "seed": seed,
        "orders": len(orders),
        "fail": f"{failure.robot}@{failure.at:g}",
        "released": result.released,
        "delivered": result.delivered,
        "lost": [o.lost for o in lost],
        "lost_not_carried": sum(1 for o in lost if o.object not in carried),
        "pending": [f"{o.object} (released at {o.at:g} s): {o.refused}" for o in pending],
        "not_as_ordered": [" ".join(e.name for e in o.word) for o in result.not_as_ordered],
        "contacts": len(result.contacts),
        "contacts_while_moving": result.contacts_while_moving,
        "wait_p50_s": result.wait_s()["p50"],
        "wall_s": round(time.perf_counter() - t0, 2),
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seeds", default="0:20", help="first:last (exclusive)")
    parser.add_argument("--until", type=float, default=600.0)
    parser.add_argument("--gap", type=float, default=25.0, help="mean seconds between orders")
    parser.add_argument("--scene", type=Path, default=EXAMPLE, help="a scenario file whose scene to use")
    parser.add_argument("--out", default="sweep_lifelong")
    args = parser.parse_args()
    first, last = (int(v) for v in args.seeds.split(":"))
    scenario = load_scenario(args.scene)
    rows = []
    for seed in range(first, last):
        row = run_one(scenario, seed, args.until, args.gap)
        rows.append(row)
        print(row, flush=True)
    bad = [r for r in rows if r["lost_not_carried"] or r["not_as_ordered"] or r["contacts_while_moving"]]
    pending = sum(len(r["pending"]) for r in rows)
    print(
        f"{len(rows)} runs: {sum(r['delivered'] for r in rows)} of {sum(r['released'] for r in rows)} "
        f"delivered, {sum(len(r['lost']) for r in rows)} lost (carried by the failed robot: "
        f"{sum(len(r['lost']) - r['lost_not_carried'] for r in rows)}), {pending} pending at the end, "
        f"{len(bad)} runs with a failure (a loss not carried, a delivery not as ordered, a contact "
        "while moving)"
    )
    save_results(args.out, [{"until_s": args.until, "gap_s": args.gap, **row} for row in rows])
    return 1 if bad else 0


if __name__ == "__main__":
    raise SystemExit(main())
