"""Passive safety of the dynamic window, as a property (hypothesis, seeded).

When ``safe`` holds, every arc of the window can stop in time (the paper's theorem, tested in
``test_control.py`` through its formula).  When it fails, the DWA may still leave on an arc
whose own worst case it has checked: one cycle at the arc's speed and turn rate (moved as the
simulator moves a robot), then braked with :math:`-b` to a stop on a straight line, as every
brake in the simulator is.  When no arc passes, the DWA brakes straight on, the brake the
previous cycle's check covered.  The property: whatever the DWA commands, that worst case never
brings the robot's square into a wall or a resting box it was not already touching.  The
trajectory is checked here at 400 instants, far finer than the DWA's own samples and their
slack.  The states drawn are those the controller can be in: braking straight on from them
keeps clear (what the previous cycle guaranteed).  From a state no command can save -- 220
mm/s towards a wall 0.03 mm away -- the property says nothing.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import HealthCheck, assume, event, given, settings
from hypothesis import strategies as st

from cosmop.control.dwa import Drivers, DwaSettings, Obstacles, dwa_commands
from cosmop.control.geometry import box_gaps, point_segment_linf, segment_array
from cosmop.control.safety import Limits
from cosmop.scene import Dynamics

LIMITS = Limits.of([Dynamics(max_speed=750.0, acceleration=300.0, braking=500.0, turn_rate=100.0, cycle=0.1)])
HALF = 200.0


def _trajectory(pose, v0, v1, w, samples: int = 400) -> np.ndarray:
    """Centres along "one cycle at (`v1`, `w`), then brake straight to a stop".

    In the cycle the speed ramps up to `v1`, or brakes at :math:`-b` until `v1` and holds it
    (:func:`cosmop.sim.unicycle.integrate`); the heading turns at `w` during the cycle only.
    """
    brake, acc, eps = LIMITS.braking[0], LIMITS.acceleration[0], LIMITS.cycle[0]
    v1 = min(max(v1, v0 - brake * eps), v0 + acc * eps)
    total = eps + v1 / brake
    t = np.linspace(0.0, total, samples + 1)
    if v1 < v0:
        reached = (v0 - v1) / brake
        cycle = np.where(t <= reached, v0 - brake * t, v1)
    else:
        cycle = v0 + (v1 - v0) * t / eps
    speed = np.where(t <= eps, cycle, np.maximum(v1 - brake * (t - eps), 0.0))
    dt = np.diff(t)
    mid = (speed[1:] + speed[:-1]) / 2 * dt
    tm = (t[1:] + t[:-1]) / 2
    theta = pose[2] + w * np.minimum(tm, eps)
    x = pose[0] + np.cumsum(mid * np.cos(theta))
    y = pose[1] + np.cumsum(mid * np.sin(theta))
    return np.stack([x, y], axis=-1)


scenes = st.fixed_dictionaries(
    {
        "x": st.floats(-300.0, 300.0),
        "y": st.floats(-300.0, 300.0),
        "heading": st.floats(-math.pi, math.pi),
        "v": st.floats(0.0, 750.0),
        "walls": st.lists(
            st.tuples(st.floats(-900, 900), st.floats(-900, 900), st.floats(-900, 900), st.floats(-900, 900)),
            min_size=1,
            max_size=4,
        ),
        "boxes": st.lists(
            st.tuples(st.floats(-900, 900), st.floats(-900, 900), st.floats(50, 300)), max_size=3
        ),
        "target": st.tuples(st.floats(-2000, 2000), st.floats(-2000, 2000)),
    }
)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(scene=scenes)
def test_an_arc_taken_when_safe_fails_brakes_to_a_stop_without_touching(scene):
    pose = np.array([[scene["x"], scene["y"], scene["heading"]]])
    walls = segment_array([((a, b), (c, d)) for a, b, c, d in scene["walls"]])
    boxes = np.array(scene["boxes"], dtype=float).reshape(-1, 3)
    wall_now = point_segment_linf(pose[:, :2], walls)[0] - HALF
    box_now = box_gaps(pose[0, :2], HALF, boxes) if len(boxes) else np.zeros(0)
    assume(wall_now.min() > 0.0 and (box_now > 0.0).all())  # a physical state: not inside anything
    v = np.array([scene["v"]])
    # a state the controller can be in: the last cycle's check covered braking straight on
    # from here (from a state no command can save, the property says nothing)
    assume(_clear(_trajectory(pose[0], v[0], 0.0, 0.0), walls, boxes))
    drivers = Drivers(pose, v, np.array([HALF]), LIMITS, np.array([scene["target"]]), np.array([math.inf]))
    cmd = dwa_commands(drivers, Obstacles(walls, boxes, np.zeros(len(boxes))), DwaSettings())
    assume(not cmd.safe[0])  # the property is about the case where safe fails
    braked = max(0.0, v[0] - LIMITS.braking[0] * LIMITS.cycle[0])  # the fallback's speed
    event("escape arc" if cmd.w[0] != 0.0 or cmd.v[0] > braked + 1e-9 else "brake straight on")
    path = _trajectory(pose[0], v[0], float(cmd.v[0]), float(cmd.w[0]))
    wall_gap = point_segment_linf(path, walls) - HALF  # (n, W)
    assert (wall_gap > 0.0).all(), f"the arc touches a wall: {wall_gap.min():.3f} mm"
    if len(boxes):
        gap = box_gaps(path, HALF, boxes)
        assert (gap > 0.0).all(), f"the arc touches a box: {gap.min():.3f} mm"


def _clear(path: np.ndarray, walls: np.ndarray, boxes: np.ndarray) -> bool:
    """Whether the square keeps off every wall and box along `path`."""
    if (point_segment_linf(path, walls) - HALF <= 0.0).any():
        return False
    return not len(boxes) or bool((box_gaps(path, HALF, boxes) > 0.0).all())
