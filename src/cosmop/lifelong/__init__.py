"""Lifelong operation: a stream of orders served by a fleet that keeps working.

:func:`run_fleet` runs the scenario's world while orders (:class:`cosmop.scene.Order`, from the
scenario's ``orders`` or a file of their own, :func:`cosmop.scenario.load_orders`) are released
over time: a dispatcher gives each to an idle robot (:mod:`.dispatch`), whose next mission is
planned from where it stands and ordered against the plans the others have committed to, with
the same messages, exact checks and deadlock proof as a planned team, while the others keep
moving (:mod:`.fleet`); robots may fail for good (:class:`Failure`); Ctrl-C ends the run with
what it did so far (:class:`FleetInterrupted`).  :class:`FleetResult`
reports throughput, waits, utilisation and safety (:mod:`.fleet_result`).
"""

from cosmop.lifelong.dispatch import OrderState
from cosmop.lifelong.fleet import Failure, FleetInterrupted, FleetSettings, run_fleet
from cosmop.lifelong.fleet_result import RUN_FORMAT, FleetResult, OrderRecord

__all__ = [
    "RUN_FORMAT",
    "Failure",
    "FleetInterrupted",
    "FleetResult",
    "FleetSettings",
    "OrderRecord",
    "OrderState",
    "run_fleet",
]
