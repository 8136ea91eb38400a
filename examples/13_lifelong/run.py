"""A lifelong run: orders released over time, served by a fleet that keeps working.

Run from anywhere: ``python examples/13_lifelong/run.py``.  Runs the small warehouse (four
robots, two shelves, three docks) for ten simulated minutes while 24 orders arrive, prints who
delivered what and when, the deliveries per hour and the waits, and checks the run: every order
delivered, each delivery's events a word of its order's delivery mission (the goods picked once
by a robot the order allows and dropped by it in one of the order's docks), no contact while a
robot moved.  Then runs it again with R1 failing for good at 150 s, where it stands beside goods
another order needs: its order goes back to the pool unless R1 carries the goods, the others are
ordered around it, and the run says what became of each order.
"""

from pathlib import Path

import cosmop
from cosmop.lifelong import Failure, FleetSettings, run_fleet

HERE = Path(__file__).resolve().parent

scenario = cosmop.load(HERE / "scenario.yaml")
result = run_fleet(scenario, fleet=FleetSettings(until=600))
for order in result.orders:
    when = f"{order.delivered:.1f} s" if order.delivered is not None else "not yet"
    words = " ".join(e.name for e in order.word)
    print(f"order {order.index} ({order.object}, released at {order.at:g} s): {order.robot}, {when}: {words}")
wait = result.wait_s()
print(
    f"{result.delivered} delivered, {result.deliveries_per_hour:.0f} per hour; "
    f"wait p50 {wait['p50']:.1f} s, max {wait['max']:.1f} s; {len(result.messages)} messages"
)
print(f"every order delivered: {result.delivered == len(result.orders)}")
print(f"every delivery a word of its order's mission: {not result.not_as_ordered}")
print(f"no contact while moving: {result.contacts_while_moving == 0}")

failed = run_fleet(scenario, fleet=FleetSettings(until=600), failures=[Failure("R1", 150.0)])
report = failed.failures["R1"]
lost = [o for o in failed.orders if o.lost is not None]
carrying = ", ".join(report["carrying"]) or "nothing"
x, y = report["at"]
print(f"R1 fails at {report['t']:.0f} s at ({x:.0f}, {y:.0f}) mm carrying {carrying}")
print(f"{failed.delivered} of {len(failed.orders)} delivered; lost: {[o.lost for o in lost]}")
print(f"the lost orders are those R1 carried: {all(o.object in report['carrying'] for o in lost)}")
print(f"every other order delivered: {failed.delivered + len(lost) == len(failed.orders)}")
print(f"every delivery a word of its order's mission with R1 failed: {not failed.not_as_ordered}")
print(f"no contact while moving with R1 failed: {failed.contacts_while_moving == 0}")
