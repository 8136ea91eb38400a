"""Grid maps: MovingAI ``.map`` files and ROS ``map_server`` maps as cosmop scenes.

:func:`import_map` reads a map into an :class:`OccupancyGrid`, covers its blocked cells with
rectangles and walls them in; :func:`scenario_text` writes the walls as a scenario's
``scene.obstacles`` (``cosmop import-map``).
"""

from cosmop.maps.cover import boundary_walls, rectangle_cover, rectangle_walls
from cosmop.maps.grid import MapError, OccupancyGrid
from cosmop.maps.movingai import parse_movingai, read_movingai
from cosmop.maps.rosmap import read_pgm, read_ros_map
from cosmop.maps.to_scenario import ImportedMap, import_map, scenario_text

__all__ = [
    "ImportedMap",
    "MapError",
    "OccupancyGrid",
    "boundary_walls",
    "import_map",
    "parse_movingai",
    "read_movingai",
    "read_pgm",
    "read_ros_map",
    "rectangle_cover",
    "rectangle_walls",
    "scenario_text",
]
