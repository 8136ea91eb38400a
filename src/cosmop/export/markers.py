"""The scene as ``visualization_msgs/MarkerArray``: walls, workspaces, objects, people, robots, messages.

Every array holds the whole scene at one instant, so that a viewer that jumps to any time
(Foxglove shows the latest message of each topic) draws all of it. Markers are keyed by
namespace and id and re-added each time; an arrow for a message lives
:data:`MESSAGE_SHOWN_S` seconds after the message was sent. Lengths are metres (REP 103).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

from cosmop.units import m_from_mm
from cosmop.viz.palette import robot_colours
from cosmop.viz.scene_drawing import DEFAULT_ROBOT_SIZE

if TYPE_CHECKING:
    from cosmop.scene import Scene
    from cosmop.traces import RobotState, Trace

__all__ = ["MESSAGE_SHOWN_S", "SceneMarkers"]

MESSAGE_SHOWN_S = 2.0
"""Seconds an arrow from sender to receiver stays after a message."""

_ROBOT_HEIGHT = 0.3  # m, drawn height of a robot's box
_HUMAN_HEIGHT = 1.7  # m
_WALL_WIDTH = 0.04  # m
_TEXT_HEIGHT = 0.25  # m
_BLACK = (0.1, 0.1, 0.1, 1.0)
_GREY = (0.6, 0.6, 0.6, 0.45)
_BROWN = (0.55, 0.27, 0.07, 1.0)
_ORANGE = (1.0, 0.6, 0.1, 0.9)

_Triple = tuple[float, float, float]  # a marker's scale, m
_Rgba = tuple[float, float, float, float]  # a colour, each in [0, 1]


class SceneMarkers:
    """Builds the ``/scene`` marker array of any frame of a trace.

    Parameters
    ----------
    ros : object
        The message types (:class:`cosmop.export.rosbag._Ros`).
    scene : Scene
        Walls, workspaces and sizes (mm).
    trace : Trace
        The run: poses (mm, degrees), what the robots carry, people, objects and the messages
        (``t`` s, ``from``, ``to``).
    robot_ids : sequence of str
        Every robot, in the order that fixes its colour (the scene's order first).
    """

    def __init__(self, ros: Any, scene: Scene, trace: Trace, robot_ids: Sequence[str]) -> None:
        self.ros, self.scene, self.trace = ros, scene, trace
        self.robot_ids = list(robot_ids)
        self.colours = dict(zip(self.robot_ids, robot_colours(len(self.robot_ids)), strict=True))
        self.messages = sorted(trace.messages, key=lambda m: float(m["t"]))

    # -- builders ---------------------------------------------------------------------------

    def _marker(
        self,
        ns: int,
        space: str,
        ident: int,
        kind: str,
        pose: Any,
        scale: _Triple,
        colour: _Rgba,
        **extra: Any,
    ) -> Any:
        t = self.ros.t
        marker_type = t["visualization_msgs/msg/Marker"]
        return marker_type(
            header=self.ros.header(ns),
            ns=space,
            id=ident,
            type=getattr(marker_type, kind),
            action=marker_type.ADD,
            pose=pose,
            scale=t["geometry_msgs/msg/Vector3"](x=scale[0], y=scale[1], z=scale[2]),
            color=t["std_msgs/msg/ColorRGBA"](r=colour[0], g=colour[1], b=colour[2], a=colour[3]),
            lifetime=extra.get("lifetime", t["builtin_interfaces/msg/Duration"](sec=0, nanosec=0)),
            frame_locked=False,
            points=extra.get("points", []),
            colors=[],
            texture_resource="",
            texture=t["sensor_msgs/msg/CompressedImage"](
                header=self.ros.header(0, ""), format="", data=_no_bytes()
            ),
            uv_coordinates=[],
            text=extra.get("text", ""),
            mesh_resource="",
            mesh_file=t["visualization_msgs/msg/MeshFile"](filename="", data=_no_bytes()),
            mesh_use_embedded_materials=False,
        )

    def _at(self, x_mm: float, y_mm: float, z_m: float = 0.0, heading_deg: float = 0.0) -> Any:
        pose = self.ros.pose(x_mm, y_mm, heading_deg)
        pose.position.z = z_m
        return pose

    def _point(self, x_mm: float, y_mm: float, z_m: float = 0.0) -> Any:
        return self.ros.t["geometry_msgs/msg/Point"](x=m_from_mm(x_mm), y=m_from_mm(y_mm), z=z_m)

    def _text(
        self, ns: int, space: str, ident: int, x: float, y: float, z: float, text: str, colour: _Rgba
    ) -> Any:
        scale = (0.0, 0.0, _TEXT_HEIGHT)
        return self._marker(ns, space, ident, "TEXT_VIEW_FACING", self._at(x, y, z), scale, colour, text=text)

    # -- parts of the scene ------------------------------------------------------------------

    def _fixed(self, ns: int) -> list[Any]:
        """Walls and workspaces (with their labels)."""
        out = []
        if self.scene.obstacles:
            points = [
                self._point(*end, 0.05) for wall in self.scene.obstacles for end in (wall.start, wall.end)
            ]
            out.append(
                self._marker(
                    ns, "walls", 0, "LINE_LIST", self._at(0, 0), (_WALL_WIDTH, 0, 0), _BLACK, points=points
                )
            )
        for k, (wid, ws) in enumerate(self.scene.workspaces.items()):
            cx, cy = ws.center
            if ws.is_point:
                scale = (0.1, 0.1, 0.01)
            else:
                x, y = ws.ranges
                scale = (m_from_mm(x[1] - x[0]), m_from_mm(y[1] - y[0]), 0.01)
            out.append(self._marker(ns, "workspaces", k, "CUBE", self._at(cx, cy, 0.005), scale, _GREY))
            out.append(self._text(ns, "workspace_labels", k, cx, cy, 0.1, wid, _BLACK))
        return out

    def _objects(self, ns: int, k: int, carried: Mapping[str, str]) -> list[Any]:
        """The scene's objects where frame `k` shows them (else where the scene puts them)."""
        out = []
        positions = self.trace.points_at("objects", k)
        for n, (oid, obj) in enumerate(self.scene.objects.items()):
            x, y = positions.get(oid, obj.position)
            side = m_from_mm(obj.size)
            z = _ROBOT_HEIGHT + side / 2 if oid in carried else side / 2  # a carried object rides on top
            out.append(self._marker(ns, "objects", n, "CUBE", self._at(x, y, z), (side, side, side), _BROWN))
            out.append(self._text(ns, "object_labels", n, x, y, z + side / 2 + 0.15, oid, _BROWN))
        return out

    def _robots(self, ns: int, k: int, robots: Mapping[str, RobotState]) -> list[Any]:
        """The robots and people that frame `k` shows; `robots` are its robots' states."""
        out = []
        for n, rid in enumerate(self.robot_ids):
            state = robots.get(rid)
            if state is None:
                continue
            x, y, heading = state.pose
            robot = self.scene.robots.get(rid)
            side = m_from_mm(robot.size if robot is not None else DEFAULT_ROBOT_SIZE)
            colour = (*self.colours[rid], 0.7)
            body = self._at(x, y, _ROBOT_HEIGHT / 2, heading)
            out.append(self._marker(ns, "robots", n, "CUBE", body, (side, side, _ROBOT_HEIGHT), colour))
            label = rid if not state.carrying else f"{rid} carries {state.carrying}"
            if state.waiting:
                label += " (waiting)"
            out.append(
                self._text(ns, "robot_labels", n, x, y, _ROBOT_HEIGHT + 0.35, label, (*colour[:3], 1.0))
            )
        humans = self.trace.points_at("humans", k)
        for n, hid in enumerate(getattr(self.scene, "humans", {}) or {}):
            where = humans.get(hid)
            if where is None:
                continue
            d = m_from_mm(self.scene.humans[hid].size)
            pose = self._at(where[0], where[1], _HUMAN_HEIGHT / 2)
            out.append(self._marker(ns, "people", n, "CYLINDER", pose, (d, d, _HUMAN_HEIGHT), _ORANGE))
        return out

    def _arrows(self, ns: int, t: float, robots: Mapping[str, RobotState]) -> list[Any]:
        """An arrow from sender to receiver for each message sent less than 2 s before `t` (s)."""
        out = []
        for k, message in enumerate(self.messages):
            age = t - float(message["t"])
            sender, receiver = robots.get(message["from"]), robots.get(message["to"])
            if not (0 <= age < MESSAGE_SHOWN_S) or sender is None or receiver is None:
                continue
            z = _ROBOT_HEIGHT + 0.6
            points = [self._point(*sender.pose[:2], z), self._point(*receiver.pose[:2], z)]
            left = MESSAGE_SHOWN_S - age
            lifetime = self.ros.t["builtin_interfaces/msg/Duration"](
                sec=int(left), nanosec=round((left - math.floor(left)) * 1e9) % 1_000_000_000
            )
            colour = (*self.colours.get(message["from"], (0.0, 0.0, 0.0)), 1.0)
            out.append(
                self._marker(
                    ns,
                    "messages",
                    k,
                    "ARROW",
                    self._at(0, 0),
                    (0.05, 0.12, 0.15),
                    colour,
                    points=points,
                    lifetime=lifetime,
                )
            )
        return out

    def array(self, ns: int, k: int) -> Any:
        """The ``MarkerArray`` of frame `k` of the trace, stamped `ns` nanoseconds.

        Parameters
        ----------
        ns : int
            The time stamp, ns.
        k : int
            The frame's index in the trace.

        Returns
        -------
        visualization_msgs/msg/MarkerArray
            The message (a ``rosbags`` object).
        """
        robots = self.trace.robots_at(k)
        markers = self._fixed(ns) + self._objects(ns, k, self.trace.carried_at(k))
        markers += self._robots(ns, k, robots) + self._arrows(ns, float(self.trace.t[k]), robots)
        return self.ros.t["visualization_msgs/msg/MarkerArray"](markers=markers)


def _no_bytes() -> Any:
    import numpy as np

    return np.zeros(0, dtype=np.uint8)
