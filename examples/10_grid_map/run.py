"""A scene from a grid map: a MovingAI ``.map`` of my own drawing, walled in and planned.

Run from anywhere: ``python examples/10_grid_map/run.py``. ``warehouse.map`` is a 20 x 12 map
(two rows of shelves ``@`` and a T-shaped pillar ``T``); with 500 mm cells it is a 10 m x 6 m
hall. ``scenario.yaml`` was written by ``cosmop import-map`` (see its header); this script
imports the map again with the library, checks that the scenario's walls are exactly the
map's, and plans the two robots' missions.
"""

from pathlib import Path

import cosmop
from cosmop.maps import import_map
from cosmop.team.loop import plan_team

HERE = Path(__file__).resolve().parent

imported = import_map(HERE / "warehouse.map", cell_size=500)
scenario = cosmop.load(HERE / "scenario.yaml")
walls = {(w.start, w.end) for w in scenario.scene.obstacles}
rows, cols = imported.grid.shape
print(
    f"{cols} x {rows} cells, {int(imported.grid.blocked.sum())} blocked, in {len(imported.rectangles)} "
    f"rectangles; {len(imported.walls)} walls instead of {imported.outline_walls} rectangle outlines"
)
print(f"the scenario's walls are the map's: {walls == set(imported.walls)}")
result = plan_team(scenario)
print(f"feasible, verified and checked: {result.plans.feasible and result.report.ok}")
for robot, plan in result.plans.robots.items():
    print(f"  {robot}: {', '.join(step.label for step in plan.steps)}")
