"""The local layer's controllers: passive safety, the extended DWA and global paths.

:mod:`cosmop.control.safety` is the paper's ``safe`` condition and its Corollary (the
admissible speed); :mod:`cosmop.control.dwa` samples arcs in the dynamic window, admits only
passive-safe ones and scores them against a global path from :mod:`cosmop.control.paths`;
:mod:`cosmop.control.geometry` measures L-infinity gaps between squares, walls and boxes.
Units are millimetres, seconds and radians.
"""

from cosmop.control.dwa import Drivers, DwaCommand, DwaSettings, Obstacles, dwa_commands
from cosmop.control.geometry import box_gaps, point_segment_linf, segment_array
from cosmop.control.paths import GlobalPath, plan_path
from cosmop.control.safety import (
    Limits,
    admissible_speed,
    is_safe,
    obstacle_speed,
    stopping_horizon,
    stopping_margin,
)

__all__ = [
    "Drivers",
    "DwaCommand",
    "DwaSettings",
    "GlobalPath",
    "Limits",
    "Obstacles",
    "admissible_speed",
    "box_gaps",
    "dwa_commands",
    "is_safe",
    "obstacle_speed",
    "plan_path",
    "point_segment_linf",
    "segment_array",
    "stopping_horizon",
    "stopping_margin",
]
