"""Executing plans in a multi-robot world: robots, people, messages, safety monitor, replanning.

:func:`simulate` runs a ``cosmop.plan/1`` plan set in the scenario's world
(:mod:`cosmop.sim.simulation`); people walk their paths (:mod:`cosmop.sim.humans`); a stalled
robot replans its remaining mission from where it is (:mod:`cosmop.sim.replan`); robots may be
delayed at random (:mod:`cosmop.sim.delays`).  The result
carries the ``cosmop.sim/1`` summary, with every step's planned and realised times
(:mod:`cosmop.sim.realised_times`), and the ``cosmop.trace/1`` trace (:mod:`cosmop.sim.result`).
"""

from cosmop.sim.delays import Delays
from cosmop.sim.monitor import footprint_overlaps
from cosmop.sim.realised_times import StepTimes
from cosmop.sim.replan import replan, sensed_scene
from cosmop.sim.result import SIM_FORMAT, Contact, Message, SimResult, SimSettings
from cosmop.sim.simulation import simulate, time_limit
from cosmop.traces import TRACE_FORMAT

__all__ = [
    "SIM_FORMAT",
    "TRACE_FORMAT",
    "Contact",
    "Delays",
    "Message",
    "SimResult",
    "SimSettings",
    "StepTimes",
    "footprint_overlaps",
    "replan",
    "sensed_scene",
    "simulate",
    "time_limit",
]
