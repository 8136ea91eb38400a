"""A lifelong run: orders released over time, served by a fleet that keeps working.

Run from anywhere: ``python examples/13_lifelong/run.py``.  Runs the 2x2 warehouse for four
simulated minutes while four orders arrive, prints who delivered what and when, the deliveries
per hour and the waits, and checks that every order was delivered with no contact while a robot
moved.  Then runs it again with R1 failing for good after 20 s: its order goes back to the pool
unless R1 carries the goods, and the run says which.
"""

from pathlib import Path

import cosmop
from cosmop.lifelong import Failure, FleetSettings, run_fleet

HERE = Path(__file__).resolve().parent

scenario = cosmop.load(HERE / "scenario.yaml")
result = run_fleet(scenario, fleet=FleetSettings(until=240))
for order in result.orders:
    when = f"{order.delivered:.1f} s" if order.delivered is not None else "not yet"
    print(
        f"order {order.index} ({order.object}, released at {order.at:g} s): {order.robot}, delivered {when}"
    )
wait = result.wait_s()
rate = result.deliveries_per_hour
print(
    f"{result.delivered} delivered, {rate:.0f} per hour; "
    f"wait p50 {wait['p50']:.1f} s, max {wait['max']:.1f} s"
)
print(f"every order delivered: {result.delivered == len(result.orders)}")
print(f"no contact while moving: {result.contacts_while_moving == 0}")

failed = run_fleet(scenario, fleet=FleetSettings(until=240), failures=[Failure("R1", 20.0)])
report = failed.failures["R1"]
lost = [o for o in failed.orders if o.lost is not None]
carrying = ", ".join(report["carrying"]) or "nothing"
print(f"R1 fails at {report['t']:.0f} s carrying {carrying}; lost orders: {[o.lost for o in lost]}")
print(f"a lost order is one R1 carried: {all(o.object in report['carrying'] for o in lost)}")
print(f"no contact while moving with R1 failed: {failed.contacts_while_moving == 0}")
