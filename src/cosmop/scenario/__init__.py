"""Scenarios: the scene (walls, robots, movable objects, workspaces, people) and the mission.

A scenario file (format version 1) is YAML::

    name: warehouse-2x2
    scene:
      obstacles: [[[-2500, -2500], [2500, -2500]], ...]   # wall segments [[x1, y1], [x2, y2]]
      dynamics:   {max_speed: 750, acceleration: 300, braking: 500, turn_rate: 100, cycle: 0.1}
      robots:     {R1: {size: 400, pose: [-2000, -1000, 0]}, ...}   # x, y, heading
      objects:    {O1: {size: 100, position: [2000, -1000]}, O2: {..., sides: [north]}, ...}
      workspaces: {W1: {x: [-1500, -1000], y: [2000, 2500]}, W3: {point: [-4250, 4000]}}
      humans:     {H1: {size: 400, speed: 600, path: [[0, -1500], [0, -2200, 5]]}, ...}
    mission:
      tasks: {R1: [pick O1, drop O1 at W1, return], ...}   # or: dfa: {initial, transitions, ...}
    orders:                     # optional: released over time, for a lifelong run (cosmop run)
      - {at: 0, object: O1, to: W1}
      - {at: 35.5, object: O2, to: [W2, W3], by: [R1, R2]}

Lengths are millimetres, angles degrees and times seconds (a file with ``units: m`` gives
metres and radians instead, converted at load time: :mod:`cosmop.units`); robots, objects and people are
axis-aligned squares of side ``size``. The optional ``dynamics`` (any subset of its keys) are
the unicycle limits of every robot; a robot may override them field by field with its own
``dynamics`` key, e.g. ``R1: {size: 400, pose: [0, 0, 0], dynamics: {max_speed: 500}}``, but
all robots share one control ``cycle``. The optional ``humans`` are people the robots do not
control: each walks along its ``path`` of points ``[x, y]`` or ``[x, y, dwell]`` (standing
``dwell`` seconds on arriving there) and repeats it, unless ``loop: false``; a person given a
``walk: {x: [lo, hi], y: [lo, hi]}`` area roams there at random once its path ends (at once,
if the path is only its start point).  An object's optional ``sides`` are the sides a robot
may stand on to pick it up or drop it off (``west``, ``south``, ``east``, ``north``; all four
by default).  A scenario may hold ``orders`` and no ``mission``: an order makes goods that lie
in the scene from the start due at a workspace from its time ``at`` (s) on; :func:`load_orders`
reads a stream from a file of its own (its key ``orders``, the same form).

:func:`load_scenario` reads such a file and :func:`parse_scenario` validates an already-parsed
mapping; both return an immutable :class:`~cosmop.scene.Scenario` or raise
:class:`~cosmop.errors.ScenarioError` naming the file, the field and what was expected.

The file is read by :func:`cosmop.reading.load_yaml`: a YAML dialect close to YAML 1.2's core
schema, in which a key repeated inside one mapping is an error, with bounds on nesting, size
(aliases expanded) and integer length, so a hostile file is answered quickly and clearly.
"""

from cosmop.scenario.build import load_orders, load_scenario, parse_scenario
from cosmop.scenario.schema import MAX_DFA_STATES, SCENARIO_VERSION

__all__ = ["MAX_DFA_STATES", "SCENARIO_VERSION", "load_orders", "load_scenario", "parse_scenario"]
